"""Optimal calibration schedules: :func:`optimal_design` (approximate, certified), :func:`exact_design` (segments),
:func:`design_efficiency` (how good a given schedule is).

The candidates and their information are :mod:`plansim.design.catalogue`'s; the criteria and algorithms
:mod:`plansim.design.criteria` and :mod:`plansim.design.algorithms`'s. The weights of the design are fractions of
the table time (each candidate's cost is its settling plus dwell), so the information is per second of table
time and the design answers "how should a lab spend its table time".
"""

from __future__ import annotations

import dataclasses

import numpy as np
import xarray as xr

from plansim.config import Scenario
from plansim.design.algorithms import ApproximateDesign, efficient_rounding, exchange, multiplicative
from plansim.design.catalogue import (
    Candidate,
    CandidateInformation,
    at_dwell,
    candidate_information,
    select_parameters,
)
from plansim.design.criteria import Criterion, information
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETERS
from plansim.schedule.segments import Schedule

__all__ = ["DesignResult", "optimal_design", "exact_design", "design_efficiency", "schedule_candidates"]

#: the multiplicative algorithm's stopping rule here (efficiency bound 1 − this): it converges sublinearly
#: (D over the 39 parameters: 0.24 s to 1e-4, 1.1 s to 1e-5; A: 3 s and 30 s), and an efficiency of 0.9999 is
#: more than a schedule of whole segments can keep
DESIGN_TOLERANCE = 1e-4


def _channels(channels) -> np.ndarray:
    if channels is None:
        return np.arange(len(CHANNELS))
    names = [channels] if isinstance(channels, str) else list(channels)
    bad = [c for c in names if c not in CHANNELS]
    if bad:
        raise ValueError(f"channels = {bad!r}: expected names among {', '.join(CHANNELS)}")
    return np.array([CHANNELS.index(c) for c in names])


def _criterion(kind: str, parameters: np.ndarray, c=None) -> Criterion:
    if kind != "c":
        return Criterion(kind)
    if isinstance(c, str):
        index = select_parameters(c)
        if index.size != 1:
            raise ValueError(f"c = {c!r}: the c-criterion needs one parameter name (or a vector)")
        vector = (parameters == index[0]).astype(float)
        if not vector.any():
            raise ValueError(f"c = {c!r}: not among the design's parameters")
        return Criterion("c", c=vector)
    return Criterion("c", c=c)


@dataclasses.dataclass(frozen=True)
class DesignResult:
    """An optimal approximate design over the candidates (:func:`optimal_design`).

    ``design`` the :class:`~plansim.design.algorithms.ApproximateDesign` (weights = fractions of table time,
    certificate); ``information`` the candidates; ``parameters`` and ``channels`` the indices the criterion is on.
    """

    design: ApproximateDesign
    information: CandidateInformation
    parameters: np.ndarray
    channels: np.ndarray

    @property
    def support(self) -> list[tuple[Candidate, float]]:
        """The candidates the design uses, with their fraction of the table time, largest first."""
        s = self.design.support
        order = s[np.argsort(-self.design.weights[s], kind="stable")]
        return [(self.information.candidates[k], float(self.design.weights[k])) for k in order]

    def to_dataset(self) -> xr.Dataset:
        """The design as a self-describing Dataset over ``candidate``."""
        c = self.information.candidates
        d = self.design
        coords = {"candidate": ("candidate", [x.label for x in c]),
                  "kind": ("candidate", [x.kind for x in c]),
                  "dwell": ("candidate", [x.dwell for x in c], {"units": "s"}),
                  "rate": ("candidate", [x.rate for x in c], {"units": "rad/s"})}
        data = {"time_fraction": ("candidate", d.weights, {"units": "1", "long_name": "fraction of the table time"}),
                "cost": ("candidate", d.costs, {"units": "s", "long_name": "table time of a segment (settle, dwell)"}),
                "derivative": ("candidate", d.certificate.derivatives / d.certificate.bound,
                               {"units": "1", "long_name": "equivalence-theorem ratio φ_i/b (≤ 1 at the optimum, "
                                                           "= 1 on its support)"})}
        attrs = {"criterion": d.criterion.kind, "criterion_value": d.value,
                 "efficiency_bound": d.certificate.efficiency_bound,
                 "parameters": " ".join(PARAMETERS[i].name for i in self.parameters),
                 "channels": " ".join(CHANNELS[i] for i in self.channels),
                 "method": "multiplicative algorithm over the candidates' information per second of table time, "
                           "certified by the Kiefer-Wolfowitz equivalence theorem (plansim.design)"}
        return xr.Dataset(data, coords=coords, attrs=attrs)


def optimal_design(scenario: Scenario, criterion: str = "D", parameters=None, channels=None, c=None,
                   candidates=None, tolerance: float = DESIGN_TOLERANCE, continuous_dwell: bool = False
                   ) -> DesignResult:
    """The optimal allocation of table time over the candidate segments, for the scenario's unit, noise and table.

    Parameters
    ----------
    scenario : Scenario
        The unit (truth), site, noise and turntable; its schedule only sets the settling time, sample rate and
        largest rate of the default candidates.
    criterion : {"D", "A", "c"}
        D: the determinant of the information (all parameters at once); A: the sum of their variances;
        c: the variance of one parameter (*c* its name) or of a combination (*c* a vector over *parameters*).
    parameters : str or sequence of str, optional
        Parameter names or groups (``Kg``, ``Bg``, ``G``, ``Ka``, ``Ba``, ``P``); default all 39. The others
        are held known.
    channels : sequence of str, optional
        Output channels used (``gx`` … ``az``); default all six.
    candidates : sequence of Candidate, optional
        Default :func:`plansim.design.catalogue.default_candidates`.
    tolerance : float
        The design's equivalence-theorem efficiency bound is ≥ 1 − *tolerance*.
    continuous_dwell : bool
        Treat the dwell as a continuous variable between the candidates' shortest and longest dwell
        (:func:`refine_dwells`) instead of the candidates' grid of dwells.

    Raises
    ------
    ValueError
        Unknown criterion, parameter or channel; candidates that cannot identify the parameters.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario, got {type(scenario).__name__}")
    index = np.arange(len(PARAMETERS)) if parameters is None else select_parameters(parameters)
    chans = _channels(channels)
    info = candidate_information(scenario, candidates)
    crit = _criterion(criterion, index, c)
    design = multiplicative(info.blocks(index, chans), crit, costs=info.costs, tolerance=tolerance)
    result = DesignResult(design, info, index, chans)
    return refine_dwells(scenario, result, tolerance=tolerance) if continuous_dwell else result


#: rounds of :func:`refine_dwells` (each adds the best dwell of every family in the support, then re-optimises)
DWELL_ROUNDS = 8


def refine_dwells(scenario: Scenario, result: DesignResult, bounds=None, tolerance: float = DESIGN_TOLERANCE,
                  rounds: int = DWELL_ROUNDS) -> DesignResult:
    """The dwell as a continuous variable: an optimal design whose support dwells are free within *bounds*.

    A candidate's information per second of table time, ``M(T)/(settle + T)``, depends on its dwell T through
    the noise of its mean (white ``N²/T`` falls, the drift's Allan variance at τ = T does not, the settling is
    paid once; :func:`plansim.design.catalogue.at_dwell`), so for each geometry (pose or rate point) there is a
    best dwell. By the equivalence theorem (Kiefer & Wolfowitz 1960; with costs, Pukelsheim 1993 §5) a design is
    optimal over the continuum when no dwell of any geometry has a directional derivative per cost
    ``φ(T) = tr(G·M(T))/(settle + T)`` above the bound b. Each round maximises φ(T) over *bounds* for every
    geometry in the support (``scipy.optimize.minimize_scalar``, bounded), adds the dwells that exceed b by more
    than *tolerance* as candidates and runs the multiplicative algorithm again over them all; it stops when none
    does (the design is then certified over those geometries' whole dwell range) or after *rounds*.

    Parameters
    ----------
    scenario : Scenario
        As for :func:`optimal_design` (its noise sets how the information grows with the dwell).
    result : DesignResult
        An optimal design over a dwell grid (:func:`optimal_design`).
    bounds : (float, float), optional
        The dwell range, s; default the smallest and largest dwell of *result*'s candidates.

    Returns
    -------
    DesignResult
        Over the original candidates and the dwells added; ``design.certificate`` holds for all of them.
    """
    info = result.information
    dwells = sorted({c.dwell for c in info.candidates})
    lo, hi = (dwells[0], dwells[-1]) if bounds is None else (float(bounds[0]), float(bounds[1]))
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise ValueError(f"bounds = {bounds!r}: expected two dwells 0 < lower < upper, s")
    if isinstance(rounds, bool) or not isinstance(rounds, int) or rounds < 1:
        raise ValueError(f"rounds = {rounds!r}: expected a whole number >= 1")
    from scipy.optimize import minimize_scalar

    design = result.design
    for _ in range(rounds):
        G, bound = design.criterion.gradient(design.information)
        added, seen = [], set()
        for k in design.support:
            c = info.candidates[k]
            geometry = (c.kind, c.up, c.heading, c.rate, c.tilt)
            if geometry in seen:
                continue
            seen.add(geometry)

            def per_cost(dwell, k=k, info=info, G=G):
                cand, jac, cov = at_dwell(scenario, info, k, dwell)
                one = CandidateInformation((cand,), jac[None], cov[None], np.array([cand.cost]))
                return float(np.sum(G * one.blocks(result.parameters, result.channels)[0])) / cand.cost

            best = minimize_scalar(lambda t: -per_cost(t), bounds=(lo, hi), method="bounded",
                                   options={"xatol": 1e-4 * lo})
            if -best.fun > bound * (1.0 + tolerance):
                added.append(at_dwell(scenario, info, k, float(best.x)))
        if not added:
            break
        info = CandidateInformation(info.candidates + tuple(a[0] for a in added),
                                    np.concatenate([info.jacobian, np.array([a[1] for a in added])]),
                                    np.concatenate([info.covariance, np.array([a[2] for a in added])]),
                                    np.concatenate([info.costs, [a[0].cost for a in added]]))
        design = multiplicative(info.blocks(result.parameters, result.channels), design.criterion,
                                costs=info.costs, tolerance=tolerance)
    return DesignResult(design, info, result.parameters, result.channels)


def exact_design(result: DesignResult, table_time: float, sample_rate: float = 100.0,
                 temperature: float = 20.0) -> Schedule:
    """A schedule of about *table_time* s from an approximate design: efficient rounding of the number of
    segments of each candidate (Pukelsheim & Rieder 1992), then exchange within the same table time.

    The segments are ``static`` and ``rate`` segments of a ``custom`` schedule: what the joint fit
    (``plansim fit``) reduces. A JJF 2003 reduction needs its own tests' structure; :func:`plansim.plan` builds
    those.
    """
    if not (np.isfinite(table_time) and table_time > 0):
        raise ValueError(f"table_time = {table_time!r} s: expected > 0")
    d = result.design
    n = max(int(round(float(np.sum(d.units(table_time))))), len(d.support))
    counts = efficient_rounding(d.weights / d.costs, n)  # weights over segments, not time
    blocks = result.information.blocks(result.parameters, result.channels)
    counts = exchange(blocks, counts, d.criterion, costs=d.costs, budget=max(table_time, float(d.costs @ counts)))
    segments = []
    for k in np.flatnonzero(counts):
        segment = result.information.candidates[k].segment(sample_rate, temperature)
        segments.extend([segment] * int(counts[k]))
    return Schedule(tuple(segments), procedure="custom")


def schedule_candidates(schedule: Schedule) -> tuple[Candidate, ...]:
    """The segments of a schedule as candidates (to measure their information): at rest → ``pose``, turning about
    its up axis → ``rate``. Raises ``ValueError`` for a segment the catalogue cannot describe."""
    out = []
    for k, s in enumerate(schedule.segments):
        if s.rate == 0.0 and s.orientation == "known":
            out.append(Candidate("pose", s.up, s.heading, 0.0, s.dwell, s.settle))
        elif s.rate_axis == s.up and s.heading == 0.0 and np.isfinite(s.rate):
            out.append(Candidate("rate", s.up, 0.0, s.rate, s.dwell, s.settle))
        else:
            raise ValueError(f"schedule segment {k} ({s.label!r}): the design catalogue has poses at rest and rates "
                             f"about the up axis at heading 0; got up={s.up}, rate_axis={s.rate_axis}, "
                             f"heading={s.heading!r}, orientation={s.orientation}")
    return tuple(out)


def design_efficiency(scenario: Scenario, schedule: Schedule | None = None, criterion: str = "D", parameters=None,
                      channels=None, c=None, candidates=None) -> tuple[float, DesignResult]:
    """Efficiency (0…1, per second of table time) of *schedule* (default the scenario's) against the optimal
    design over *candidates*, and that optimum. D: ``(det M / det M*)^{1/p}``; A, c: the ratio of the criteria.

    With candidates of the schedule's own dwell, 1 means the schedule spends its time as well as any choice of
    the candidates could (e.g. the 6 and 12 positions of JJF 2003 Appendix C for the accelerometers' Ka and Ba).
    """
    schedule = scenario.schedule if schedule is None else schedule
    best = optimal_design(scenario, criterion, parameters, channels, c, candidates)
    own = candidate_information(scenario, schedule_candidates(schedule))
    blocks = own.blocks(best.parameters, best.channels)
    M = information(blocks, np.ones(len(blocks))) / float(own.costs.sum())
    return best.design.criterion.efficiency(M, best.design.information), best
