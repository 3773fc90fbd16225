"""Alias matrices: where effects the estimators do not model go, and which segments would separate them.

An effect outside the estimators' model moves the segment means by ``z·β`` (β its size); a linear estimator
``θ̂ = R·m`` then moves by ``R·z·β``: the **alias matrix** ``A = R·Z`` over the effects' columns Z (Box & Draper
1987, §10.2; Atkinson, Donev & Tobias 2007, §6.5). plansim computes it for two estimators of a schedule:

- ``"jjf2003"``: the specification's reduction (:func:`plansim.estimate.reduction_matrix`, eq. (4)–(13)),
  which models neither the Earth rate nor a lever arm;
- ``"wls"``: the joint weighted least squares of ``plansim fit`` over the 39 parameters, with the Earth rate and
  gravity as known inputs, weights from the noise of :mod:`plansim.design.catalogue`:
  ``A = (XᵀWX)⁻¹XᵀW Z``.

The effects' columns are the change of the noise-free segment means, per unit of the effect, computed by the
simulator's kernel (:meth:`plansim.fit.model.MeanModel.evaluate`): the vertical and North Earth rate (rad/s),
a lever arm of the three accelerometers along a body axis (m), and per axis the gyro g²-sensitivity
(rad/s per (m/s²)²), the accelerometer second-order coefficient K2 (per m/s²), the gyro scale asymmetry
and quadratic nonlinearity. All but the Earth rate enter the kernel linearly, so their columns are exact; the
Earth rate also drives the ω² terms, so its column is the change for a step of the Earth's own rate, divided
by it.

**What would separate an effect**: the effect is estimable together with the parameters when its column is
not in the span of the design's (whitened) columns; plansim adds it as a 40th parameter and, for each
candidate segment of the catalogue, reports the variance of its estimate with one such segment added, and
lists the candidates that make it finite, best first.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import xarray as xr

from plansim.config import Scenario
from plansim.design.catalogue import Candidate, candidate_information, default_candidates
from plansim.design.schedule_design import schedule_candidates
from plansim.estimate import reduction_matrix
from plansim.fit.identify import identifiability
from plansim.fit.model import MeanModel
from plansim.kernels.layout import (
    EFF_ACCEL_SECOND_ORDER,
    EFF_GYRO_ASYMMETRY,
    EFF_GYRO_QUADRATIC,
)
from plansim.model.parameters import PARAMETERS
from plansim.schedule.segments import Schedule
from plansim.simulate.arguments import kernel_arguments

__all__ = ["EFFECTS", "AliasResult", "alias_matrix"]

#: the effects: name -> (description, SI unit of one unit of the effect)
EFFECTS = {
    "earth_rate_up": ("vertical Earth-rate component", "rad/s"),
    "earth_rate_north": ("North Earth-rate component", "rad/s"),
    **{f"lever_arm_{a}": (f"lever arm of the three accelerometers along body {a}", "m") for a in "xyz"},
    **{f"gyro_g2_{a}": (f"gyro {a} sensitivity to the square of the specific force along {a}",
                        "rad/s/(m/s^2)^2") for a in "xyz"},
    **{f"accel_quadratic_{a}": (f"accelerometer {a} second-order coefficient K2", "1/(m/s^2)") for a in "xyz"},
    **{f"gyro_asymmetry_{a}": (f"gyro {a} scale-factor asymmetry", "1") for a in "xyz"},
    **{f"gyro_quadratic_{a}": (f"gyro {a} quadratic scale nonlinearity", "1/(rad/s)") for a in "xyz"},
}
#: the Earth-rate step of the effect columns, rad/s (the Earth's rate: the quadratic ω² terms it drives stay
#: ~1e-8 of the linear ones)
EARTH_RATE_STEP = 7.292115e-5
#: an effect is separable from the parameters when the part of its whitened column off the design's span keeps more
#: than this fraction of its squared norm
RANK_TOLERANCE = 1e-10


def _effect_columns(model: MeanModel, theta: np.ndarray) -> np.ndarray:
    """(S, 6, n_effects) change of the segment means per unit of each effect of :data:`EFFECTS`."""
    draws = model.draws(theta)
    base = model.averaged(draws, earth_enu=np.zeros(3))[0]
    columns = []
    for name in EFFECTS:
        earth = np.zeros(3)
        effects = model.effect_arguments()
        for value in effects.values():
            value[...] = 0.0
        axis = "xyz".index(name[-1]) if name[-2] == "_" else None
        size = 1.0
        if name.startswith("earth_rate"):  # the ω² terms make the Earth rate's effect quadratic: a small step
            size = EARTH_RATE_STEP
            earth[2 if name == "earth_rate_up" else 1] = size
        elif name.startswith("lever_arm"):
            effects["lever"][:, axis] = 1.0
        elif name.startswith("gyro_g2"):
            effects["S2"][axis, axis] = 1.0
        else:
            row = {"accel_quadratic": EFF_ACCEL_SECOND_ORDER, "gyro_asymmetry": EFF_GYRO_ASYMMETRY,
                   "gyro_quadratic": EFF_GYRO_QUADRATIC}[name[:-2]]
            effects["sensor"][row, axis] = 1.0
        columns.append((model.averaged(draws, earth_enu=earth, effects=effects)[0] - base) / size)
    return np.stack(columns, axis=-1)


@dataclasses.dataclass(frozen=True)
class AliasResult:
    """``alias`` (n_effects, 39): parameter error per unit of each effect (NaN for a parameter the estimator does not
    give); ``at_site`` (2, 39) the two Earth-rate
    rows times the site's components; ``separable`` (n_effects,) whether the schedule alone separates the effect
    from the 39 parameters; ``separated_by`` per effect the candidates (label, standard uncertainty of the effect
    per unit noise) that would separate it, best first; ``estimator``."""

    alias: np.ndarray
    at_site: np.ndarray
    separable: np.ndarray
    separated_by: tuple[tuple[tuple[str, float], ...], ...]
    estimator: str

    def to_dataset(self) -> xr.Dataset:
        names = [p.name for p in PARAMETERS]
        coords = {"effect": ("effect", list(EFFECTS)), "parameter": ("parameter", names),
                  "effect_unit": ("effect", [u for _, u in EFFECTS.values()]),
                  "unit": ("parameter", [p.si_unit for p in PARAMETERS])}
        data = {"alias": (("effect", "parameter"), self.alias,
                          {"units": "parameter unit per effect unit",
                           "long_name": f"error of each parameter per unit of the effect ({self.estimator})"}),
                "separable": ("effect", self.separable,
                              {"long_name": "the schedule separates the effect from the 39 parameters"}),
                "separated_by": ("effect", ["; ".join(label for label, _ in s[:3]) for s in self.separated_by],
                                 {"long_name": "candidate segments that would separate the effect, best first"})}
        return xr.Dataset(data, coords=coords, attrs={"estimator": self.estimator,
                                                      "description": "; ".join(f"{k}: {d}" for k, (d, _)
                                                                               in EFFECTS.items())})


def alias_matrix(scenario: Scenario, schedule: Schedule | None = None, estimator: str = "jjf2003",
                 candidates=None) -> AliasResult:
    """The alias matrix of :data:`EFFECTS` for *schedule* (default the scenario's) under *estimator*
    (``"jjf2003"`` or ``"wls"``, module docstring), and the catalogue's segments that would separate each effect.

    Raises
    ------
    ValueError
        Unknown estimator; a schedule the JJF 2003 reduction cannot reduce linearly; a schedule the WLS fit
        cannot identify the 39 parameters from.
    """
    if estimator not in ("jjf2003", "wls"):
        raise ValueError(f"estimator = {estimator!r}; allowed: 'jjf2003', 'wls'")
    schedule = scenario.schedule if schedule is None else schedule
    candidates = tuple(c for c in default_candidates(scenario, tilted=False) if c.dwell == schedule.segments[0].dwell) \
        if candidates is None else tuple(candidates)
    args = kernel_arguments(scenario)
    gravity, earth = float(args["gravity"]), np.asarray(args["earth_enu"])
    theta = scenario.truth_nominal
    model = MeanModel(schedule, gravity, earth)
    Z = _effect_columns(model, theta).reshape(-1, len(EFFECTS))  # (6S, E)
    own = candidate_information(scenario, schedule_candidates(schedule))
    X = own.jacobian.reshape(-1, len(PARAMETERS))
    # the parameters the designed excitation (table rates, gravity; not the Earth rate) identifies: the others
    # are held at their values (plansim.fit.identify)
    known = identifiability(model.parameter_jacobian(earth_rate=False), "the schedule's segments").mask
    Xw, Zw = _whitened(own.covariance, X)[:, known], _whitened(own.covariance, Z)
    if estimator == "jjf2003":
        R = reduction_matrix(schedule, scenario.reduction.reference_gravity, scenario.reduction.omega_squared_sign)
        if R is None:
            raise ValueError("the JJF 2003 reduction of this schedule is not linear: no alias matrix")
        alias = Z.T @ R  # (E, 39)
    else:  # NaN for the parameters the schedule does not identify
        alias = np.full((len(EFFECTS), len(PARAMETERS)), np.nan)
        alias[:, known] = np.linalg.lstsq(Xw, Zw, rcond=None)[0].T
    at_site = alias[:2] * np.array([earth[2], earth[1]])[:, None]
    # separation: the effect as one more parameter, estimable when its whitened column leaves a residual off the
    # span of the design's; for an effect the schedule cannot separate, each candidate segment added in turn
    separable = np.array([np.isfinite(_effect_variance(Xw, Zw[:, e])) for e in range(len(EFFECTS))])
    separated_by = [()] * len(EFFECTS)
    if not separable.all():
        extra = candidate_information(scenario, candidates)
        first = schedule.segments[0]  # the candidates recorded as the schedule's segments are
        cand_model = MeanModel(Schedule(tuple(c.segment(first.sample_rate, first.temperature)
                                              for c in _level(candidates)), procedure="custom"), gravity, earth)
        Zc = _effect_columns(cand_model, theta)  # (C, 6, E)
        Fw = np.linalg.cholesky(np.linalg.inv(extra.covariance)).transpose(0, 2, 1)  # (C, 6, 6): FwᵀFw = Σ⁻¹
        for e in np.flatnonzero(~separable):
            ranked = []
            for k, c in enumerate(candidates):
                v = _effect_variance(np.vstack([Xw, Fw[k] @ extra.jacobian[k][:, known]]),
                                     np.concatenate([Zw[:, e], Fw[k] @ Zc[k, :, e]]))
                if np.isfinite(v):
                    ranked.append((c.label, math.sqrt(v)))
            ranked.sort(key=lambda item: item[1])
            separated_by[e] = tuple(ranked)
    return AliasResult(alias, at_site, separable, tuple(separated_by), estimator)


def _level(candidates) -> tuple[Candidate, ...]:
    """Tilted candidates are not schedule segments: the alias search uses poses and rates only."""
    bad = [c.label for c in candidates if c.kind == "tilted"]
    if bad:
        raise ValueError(f"candidates: the separation search takes poses and rates, not tilted poses ({bad[0]!r})")
    return tuple(candidates)


def _whitened(covariance: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Rows (6S, k) of segment means whitened by their per-segment covariance (S, 6, 6): L⁻¹·rows, Σ = L·Lᵀ."""
    S = covariance.shape[0]
    L = np.linalg.cholesky(covariance)
    blocks = rows.reshape(S, 6, -1)
    return np.linalg.solve(L, blocks).reshape(6 * S, -1)


def _effect_variance(Xw: np.ndarray, zw: np.ndarray) -> float:
    """Variance (per unit noise) of an effect estimated together with the parameters: 1/|r|², r the part of its
    whitened column *zw* off the span of the whitened design *Xw*; inf when |r|² ≤ :data:`RANK_TOLERANCE`·|zw|²
    (the effect is then a combination of the parameters: it aliases, it cannot be separated)."""
    total = float(zw @ zw)
    if total == 0.0:
        return math.inf
    coef = np.linalg.lstsq(Xw, zw, rcond=None)[0]
    r = zw - Xw @ coef
    off = float(r @ r)
    return 1.0 / off if off > RANK_TOLERANCE * total else math.inf
