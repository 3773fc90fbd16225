"""The GUM (JCGM 100) of the JJF 1535-2015 schedule: the uncertainty of the items that have a true value.

The measurement model of each item is, as for JJF 2003 (:mod:`plansim.uncertainty.gum`),

    Ŷ = R(m̄(X)),   E = Ŷ − Y(truth),

with ``m̄`` the segment means of the JJF 1535 procedure (:mod:`plansim.schedule.jjf1535`) as functions of the
inputs ``X``, ``R`` the JJF 1535 reduction of :func:`plansim.estimate.jjf1535_items.reduce_items` and ``Y`` the
simulated unit's value of the item (:func:`plansim.estimate.jjf1535_items.true_items`). The output quantity is the
error ``E`` of each item, SI.

The items propagated (:data:`GUM_ITEMS`) are those whose reduction is a smooth function of the segment means:

- the scale factor K, eq. (5): for each of the Q room runs the least-squares slope of ``F̄_j − F̄_rest`` on the
  nominal rates Ω_j (the at-rest output, the mean of the records before and after the run, subtracted,
  7.2.1.1 d)), and K the mean of the Q slopes — linear in the means;
- the bias B0, eq. (15)–(17): ``B0 = (1/Q) Σ_q F̄_q / K``, F̄_q the mean of the q-th bias record (input axis up);
- the bias from the 7.2.12 up and down records, ``(F̄_up + F̄_down)/(2K)``, and the g-sensitivity along each body
  axis, ``(F̄_up − F̄_down)/(2gK)`` (7.2.12).

``R`` is linearised at the expected segment means (the noise-free means at the nominal draws, averaged over the
table's start angle, with the unit's deterministic JJF 1535 effects added): its Jacobian ``∂R/∂m̄`` is obtained by
central differences of ``reduce_items`` itself, one segment mean of the gyro under test at a time
(:func:`reduction_jacobian`; K is linear in the means, so its row is exact to rounding). That Jacobian takes the
place of the JJF 2003 estimator matrix in :func:`plansim.uncertainty.budget_lines.model_lines`, which builds every
input line exactly as for JJF 2003:

- **white noise** of every segment mean (type A): ``u = N/√T``, N the angle random walk, T the dwell;
- **quantisation** (type B; JJF 2003 Appendix A eq. (A.3) with the dither of the noise), the 21-bit acquisition;
- **rate table**: the rate error (Table 2 grade: the Appendix A.1.2.2 1) ``U_rel = 5e-4``, k = 2 — a systematic
  error common to every rate setting of the session, or a per-point error acting once per rate setting if the
  table says so), the rate smoothness (per sample), the start angle of the rotations;
- **position table**: the position accuracy and repeatability (3″, per segment and axis), which tilt the input
  axis and so change the Earth-rate and gravity components it senses (the bias records, 7.2.12);
- **drift** (the Allan coefficients), exact covariance of the means;
- **unit-to-unit spread**: the error's dependence on the true parameters, ``∂E/∂Y = R·∂m̄/∂Y − ∂Y_item/∂Y``
  (:func:`truth_jacobian`) — the bias B0 of eq. (16) holds ``G[i, i]·g`` and the vertical Earth rate, so the
  spread of G is a component of its error;

and, not in the kernels, the **turn-on bias** (:mod:`plansim.model.jjf1535_effects`): one normal draw of σ_on per
power cycle, held over the cycle — a covariance ``σ_on²`` between the segment means of one cycle (GUM 5.2.2).

Combined standard uncertainty (JCGM 100 5.1.2, 5.2.2), ν_eff by Welch–Satterthwaite (G.4.1), ``k`` from the
t-distribution (G.3.4), ``U = k·u_c``. The estimate ``y`` is the error at the expected means: the systematic effects
the procedure does not correct (eq. (16)'s ``G[i, i]·g`` and Earth rate; the deterministic dead zone, staircase and
warm-up transient).

Items not propagated, and why (:data:`NOT_PROPAGATED`): nonlinearity and asymmetry (a maximum of residuals, and
of two fits' difference, taken in absolute value: not differentiable at a true value of zero), the temperature
sensitivities and the largest g-sensitivity (the absolute value of a maximum), the repeatabilities (a sample
standard deviation of Q values, whose distribution is a scaled χ, not a linear function of the means), threshold,
resolution and warm-up time (the first tested rate or time that meets a criterion: a step function of the means),
the bias stability (no true value in the model).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from plansim.config import Scenario
from plansim.estimate.jjf1535_items import reduce_items
from plansim.kernels.layout import N_CHANNELS
from plansim.schedule.jjf1535 import Jjf1535Procedure
from plansim.simulate.jjf1535_effects import apply_jjf1535_effects, without_jjf1535_effects
from plansim.uncertainty.budget_lines import Line, model_lines
from plansim.uncertainty.gum import NEGLIGIBLE, _effective_dof
from plansim.uncertainty.jjf1535_monte_carlo import jjf1535_scenario, truth_of
from plansim.uncertainty.metrology.propagation import (
    DEFAULT_COVERAGE_PROBABILITY,
    check_coverage_probability,
    coverage_factors,
)
from plansim.uncertainty.sensitivities import segment_mean_derivatives

__all__ = ["GUM_ITEMS", "NOT_PROPAGATED", "Jjf1535Gum", "jjf1535_gum", "reduction_jacobian", "truth_jacobian"]

#: the JJF 1535 items whose GUM is built: smooth functions of the segment means with a true value
GUM_ITEMS = ("scale_factor", "bias", "bias_up_down", "g_sensitivity_x", "g_sensitivity_y", "g_sensitivity_z")
#: the items with a true value whose GUM is not built, and why (the module docstring)
NOT_PROPAGATED = {
    "nonlinearity": "eq. (6)-(7) is the largest |residual|: not differentiable where the true value is 0",
    "asymmetry": "eq. (8)-(9) is |K+ - K-|/K: not differentiable where the true value is 0",
    "scale_temperature_sensitivity": "eq. (11) is the largest |relative change|: not differentiable at 0",
    "bias_temperature_sensitivity": "eq. (27) is the largest |change|: not differentiable at 0",
    "g_sensitivity": "the largest |g-sensitivity| of three axes (each axis is propagated)",
    "scale_repeatability": "eq. (10) is a sample standard deviation of Q values (a scaled chi, not linear)",
    "bias_repeatability": "eq. (20) is a sample standard deviation of Q values (a scaled chi, not linear)",
    "threshold": "eq. (12)-(13) reports a tested rate: a step function of the means",
    "resolution": "eq. (14) reports a tested rate increment: a step function of the means",
    "warm_up_time": "7.2.9 reports the first period that meets a criterion: a step function of the means",
}
#: step of the segment means in :func:`reduction_jacobian`, rad/s (K is linear in them; B0 = F̄/K is smooth)
MEAN_STEP = 1e-6


def _read_segments(procedure: Jjf1535Procedure) -> list[int]:
    """The segments the :data:`GUM_ITEMS` read: the room rate runs, the room bias records, the 7.2.12 positions."""
    read = set()
    for run in procedure.room_runs:
        read.update((run.rest_before, run.rest_after, *run.points))
    for record in procedure.room_bias:
        read.update(record)
    for up, down in procedure.g_positions.values():
        read.update((up, down))
    return sorted(read)


def reduction_jacobian(means, procedure: Jjf1535Procedure, gravity: float, items=GUM_ITEMS) -> np.ndarray:
    """(P, S, 6): ``∂(item)/∂(segment mean)`` of the JJF 1535 reduction at *means*, by central differences.

    :func:`~plansim.estimate.jjf1535_items.reduce_items` applied to *means* ± :data:`MEAN_STEP` on the gyro under
    test's channel of each segment the items read (:func:`_read_segments`; the other channels and segments are
    not read: their columns are 0).

    Parameters
    ----------
    means : (S, 6) array
        The linearisation point (SI).
    procedure : Jjf1535Procedure
    gravity : float
        The laboratory's 1 g, m/s² (7.2.12).
    items : sequence of str
        Items of :data:`GUM_ITEMS`.
    """
    unknown = [item for item in items if item not in GUM_ITEMS]
    if unknown:
        raise ValueError(f"items: {unknown!r} not propagated; allowed: {', '.join(GUM_ITEMS)}")
    base = np.array(means, dtype=float)
    out = np.zeros((len(items), len(procedure.schedule), N_CHANNELS))
    i = procedure.axis
    for s in _read_segments(procedure):
        values = []
        for sign in (1.0, -1.0):
            base[s, i] += sign * MEAN_STEP
            reduced = reduce_items(base, procedure, gravity)
            values.append(np.array([reduced[item] for item in items]))
            base[s, i] = means[s][i]
        out[:, s, i] = (values[0] - values[1]) / (2.0 * MEAN_STEP)
    return out


def truth_jacobian(world: Scenario, procedure: Jjf1535Procedure, items=GUM_ITEMS) -> np.ndarray:
    """(P, 39): ``∂(true value of each item)/∂(unit parameter)`` at the nominal unit.

    Central differences of :func:`~plansim.uncertainty.jjf1535_monte_carlo.truth_of` (the mapping of
    :func:`~plansim.estimate.jjf1535_items.true_items`: K = Kg_ii·(1 + κ·ΔT) of eq. (5), B0 = (Bg_i + β·ΔT)/K of
    eq. (15)–(17), G_ia/K of 7.2.12) with a step of each parameter's spread; 0 where the unit has no spread (no
    budget line reads it).

    Parameters
    ----------
    world : Scenario
        The JJF 1535 world (:func:`~plansim.uncertainty.jjf1535_monte_carlo.jjf1535_scenario`): its
        ``truth_nominal``, ``truth_spread`` and effects.
    procedure : Jjf1535Procedure
    items : sequence of str
        Items of :data:`GUM_ITEMS`.

    Returns
    -------
    (P, 39) ndarray
        The rows in the order of *items*, the columns of :data:`plansim.model.parameters.PARAMETER_NAMES`.
    """
    nominal = np.asarray(world.truth_nominal, dtype=float)
    spread = np.asarray(world.truth_spread, dtype=float)
    out = np.zeros((len(items), nominal.size))
    for p in np.flatnonzero(spread > 0):
        values = []
        for sign in (1.0, -1.0):
            truth = nominal.copy()
            truth[p] += sign * spread[p]
            true = truth_of(world, procedure, truth)
            values.append(np.array([true[item] for item in items]))
        out[:, p] = (values[0] - values[1]) / (2.0 * spread[p])
    return out


@dataclass(frozen=True)
class Jjf1535Gum:
    """The GUM of the JJF 1535 items (module docstring), SI, one entry per item of ``items``.

    ``contributions[name]`` is the line's ``u_i(y)`` per item (the square root of its variance); ``lines`` the
    budget's input names in order.
    """

    scenario: str
    items: tuple[str, ...]
    estimate: np.ndarray  # y: the error at the expected means (uncorrected systematic effects)
    standard_uncertainty: np.ndarray  # u_c
    effective_dof: np.ndarray
    coverage_factor: np.ndarray
    expanded_uncertainty: np.ndarray
    covariance: np.ndarray
    coverage_probability: float
    contributions: dict  # line name -> (P,) u_i(y)
    evaluations: dict  # line name -> "A" or "B"

    def item(self, name: str) -> dict:
        """One item's figures: y, u_c, ν_eff, k, U and its inputs' contributions (largest first)."""
        if name not in self.items:
            raise ValueError(f"item = {name!r}; allowed: {', '.join(self.items)}")
        p = self.items.index(name)
        uc = float(self.standard_uncertainty[p])
        inputs = sorted(((line, float(u[p])) for line, u in self.contributions.items()
                         if u[p] > NEGLIGIBLE * uc), key=lambda x: -x[1])
        return {"item": name, "y": float(self.estimate[p]), "u_c": uc, "dof": float(self.effective_dof[p]),
                "k": float(self.coverage_factor[p]), "U": float(self.expanded_uncertainty[p]),
                "inputs": [{"name": line, "type": self.evaluations[line], "u_i": u} for line, u in inputs]}


def _turn_on_line(world: Scenario, procedure: Jjf1535Procedure, jacobian: np.ndarray) -> Line | None:
    """The turn-on bias: σ_on² between the segment means of one power cycle (GUM 5.2.2), or None if σ_on = 0."""
    i = procedure.axis
    sigma = float(world.effects.gyro_turn_on_bias[i])
    if sigma <= 0:
        return None
    cycle, _since = procedure.power_cycles()
    same = (cycle[:, None] == cycle[None, :]).astype(float)
    J = jacobian[:, :, i]
    return Line(name="turn-on bias", category="unit", evaluation="B", distribution="normal, one draw per power cycle",
                u=np.array([sigma]), input_unit="rad/s", covariance=sigma**2 * (J @ same @ J.T),
                note="held over each power cycle: the means of one cycle share it")


def _deterministic(world: Scenario) -> Scenario:
    """*world* without the turn-on bias: what the JJF 1535 effects add to every session alike."""
    zero = np.zeros_like(np.asarray(world.effects.gyro_turn_on_bias, dtype=float))
    return dataclasses.replace(world, effects=dataclasses.replace(world.effects, gyro_turn_on_bias=zero))


def jjf1535_gum(scenario: Scenario, procedure: Jjf1535Procedure | None = None,
                coverage_probability: float = DEFAULT_COVERAGE_PROBABILITY, keep_table: bool = False) -> Jjf1535Gum:
    """The GUM of the JJF 1535 items of *scenario*'s gyro (module docstring).

    Parameters
    ----------
    scenario : Scenario
        The unit, noise, effects and laboratory (:func:`~plansim.uncertainty.jjf1535_monte_carlo.jjf1535_scenario`
        replaces its schedule, turntable and acquisition, unless *keep_table*).
    procedure : Jjf1535Procedure, optional
        Default: :func:`~plansim.schedule.jjf1535.jjf1535_procedure` up to
        :data:`~plansim.uncertainty.jjf1535_monte_carlo.DEFAULT_MAXIMUM_RATE`.
    coverage_probability : float
        ``p`` of ``U`` (default 0.95).
    keep_table : bool
        Keep the scenario's own turntable and acquisition.

    Returns
    -------
    Jjf1535Gum

    Raises
    ------
    TypeError
        *scenario* is not a Scenario or *procedure* not a Jjf1535Procedure.
    ValueError
        A coverage probability outside (0, 1); a unit the procedure would drive past its limits.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    check_coverage_probability(coverage_probability)
    world, procedure = jjf1535_scenario(scenario, procedure, keep_table)
    kernel_world = without_jjf1535_effects(world)
    gravity = scenario.reduction.reference_gravity
    # the linearisation point: the expected noise-free means (over the start angle) plus the deterministic effects
    nominal, _first, _second = segment_mean_derivatives(kernel_world, np.zeros(0, dtype=np.int64), np.zeros(0))
    truth = np.asarray(world.truth_nominal, dtype=float)
    deterministic = _deterministic(world)
    point = apply_jjf1535_effects(nominal.mean(axis=0), truth, deterministic, procedure, 0, 0)
    jacobian = reduction_jacobian(point, procedure, gravity)
    lines, expected = model_lines(kernel_world, jacobian, quantisation_correlation=True, describe=False,
                                  truth_jacobian=truth_jacobian(world, procedure))
    turn_on = _turn_on_line(world, procedure, jacobian)
    if turn_on is not None:
        lines.append(turn_on)
    covariance = np.zeros((len(GUM_ITEMS), len(GUM_ITEMS)))
    for line in lines:
        covariance += line.cov()
    covariance = 0.5 * (covariance + covariance.T)
    uc = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    variances = [line.variance() for line in lines]
    dof = _effective_dof(lines, variances, uc)
    k = coverage_factors(dof, coverage_probability)
    reported = reduce_items(apply_jjf1535_effects(expected, truth, deterministic, procedure, 0, 0), procedure,
                            gravity)
    true = truth_of(world, procedure, truth)
    y = np.array([reported[item] - true[item] for item in GUM_ITEMS])
    contributions, evaluations = {}, {}
    for line, variance in zip(lines, variances):
        contributions[line.name] = np.sqrt(variance)
        evaluations[line.name] = line.evaluation
    return Jjf1535Gum(scenario=world.name, items=GUM_ITEMS, estimate=y, standard_uncertainty=uc, effective_dof=dof,
                      coverage_factor=k, expanded_uncertainty=k * uc, covariance=covariance,
                      coverage_probability=coverage_probability, contributions=contributions, evaluations=evaluations)

