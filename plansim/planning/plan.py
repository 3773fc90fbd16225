"""The shortest schedule that meets a lab's uncertainty targets: :func:`plan` (``plansim plan``).

**Targets** (a TOML table ``[targets]``, :func:`parse_targets`): a parameter (``Bgx``) or a group (``Kg``, ``Bg``,
``G``, ``Ka``, ``Ba``, ``P``: each of its parameters) mapped to an expanded uncertainty U with k = 2, a quantity
of the parameter's kind (``"1 deg/h"``; a plain number for the dimensionless Kg and Ka); or
``from_appendix_a = true``: the U that JJF 2003 Appendix A prints for each of the 27 parameters it covers. A
parameter named on its own overrides its group; ``from_appendix_a`` may be combined with either.

**What "meets" means.** A calibration's error E has a bias b (the systematic effects the specification's
estimators leave: the Earth rate on g_ii, the lever arm on p) and a standard deviation u. The figure held against
a target is ``U = 2·√(u² + b²)``, twice the root-mean-square error: predicted from :func:`plansim.predict` (u_c
and the predicted bias), and in the Monte Carlo ``2·√(mean E²)`` over the trials. A target is met in the Monte
Carlo when that figure is not above the target by more than z of its standard errors (the delta method:
SE = √(var(E²)/N)/√(mean E²)), z from :func:`allowance`: a one-sided test at family-wise level 5 % over the
targets.

**The search** (on the prediction; each call takes tens of ms) keeps the structure of the JJF 2003 procedure, so
that the specification's estimators reduce the result: the multi-position test (6 or 12 positions), the rate test
on each axis (symmetric rate sets ±a·(1, 1/2, 1/5, 1/10, 1/20)[:k], k = 1…5, with or without 0, and the
scenario's own rate points; a the largest rate of the scenario: the D- and c-optimal rate points for a line are
the two extremes, plansim.design), and the ω² test, each test with its own dwell from :data:`DWELLS`. A dwell is
always found by scanning the grid from the shortest: U need not fall monotonically with one test's dwell.

0. a start that meets every target: 12 positions, the scenario's own or the fullest rate set, one dwell for all
   tests, the shortest such;
1. each test's structure and dwell chosen on its own, the others as in the start: the one of least table time
   that meets every target (for the positions, 6 or 12; for the rates, the rate set);
2. coordinate descent from there: each test's dwell set to the shortest that meets every target with the others
   held, until nothing changes;
3. pruning: a segment whose removal still leaves a schedule the estimators reduce (``check_design``) and that
   meets every target is removed (the one that saves the most time first), until none can be. So removing any
   segment of the result breaks a target or the reduction.

``compliant=True`` restricts all of this to JJF 2003 §7.2 (:mod:`plansim.schedule.compliance`): 12 positions, 7 to
11 rate points with both maxima, every dwell ≥ 30 s; the pruning keeps compliance.

Table time is :attr:`plansim.schedule.segments.Schedule.duration` (settling and dwell of every segment).
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from collections.abc import Callable, Mapping

import numpy as np
from scipy import special  # the normal quantile; scipy.stats takes 1.4 s to import

from plansim.config import Scenario
from plansim.estimate import check_design
from plansim.model.parameters import GROUPS, PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS
from plansim.planning.predict import predict
from plansim.schedule.builders import multi_position, omega_squared_test, rate_test
from plansim.schedule.compliance import MINIMUM_DWELL, RATE_POINTS_MAX, RATE_POINTS_MIN, jjf2003_compliance
from plansim.schedule.segments import Schedule
from plansim.uncertainty.claims import appendix_a_claims
from plansim.units import parse_quantity

__all__ = ["DWELLS", "Target", "PlanResult", "parse_targets", "load_targets", "plan", "predicted_U", "verify"]

#: the dwell options of each test, s
DWELLS = (5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0, 180.0, 300.0, 600.0)
#: the rate points' fractions of the largest rate, in the order they are added
RATE_FRACTIONS = (1.0, 0.5, 0.2, 0.1, 0.05)
#: coverage factor of the targets
K = 2.0
#: the tests whose dwell the search sets, in order
TESTS = ("multi_position", "rate", "omega_squared")
#: at most this many rounds of search and Monte Carlo verification
ROUNDS = 4


@dataclasses.dataclass(frozen=True)
class Target:
    """An expanded uncertainty (k = 2) not to exceed, in the parameter's SI unit, and where it came from."""

    parameter: str
    U: float
    source: str


def allowance(n: int, alpha: float = 0.05) -> float:
    """How many standard errors the Monte Carlo U of one of *n* targets may exceed it and the target still count as
    met: z = Φ⁻¹(1 − α/n), a one-sided test of "the plan's U is above its target" at family-wise level α over the
    n targets (Bonferroni). n = 1: 1.64; 39 targets: 3.02."""
    return float(special.ndtri(1.0 - alpha / n))


def parse_targets(document: Mapping, scenario: Scenario, source: str = "targets") -> dict[str, Target]:
    """Targets from a parsed TOML document with a ``[targets]`` table (module docstring), in SI.

    Raises
    ------
    ValueError, TypeError
        No ``[targets]`` table, an unknown key, a value of the wrong kind or unit, a U that is not > 0, or no
        target at all.
    """
    if not isinstance(document, Mapping) or set(document) != {"targets"} or not isinstance(document["targets"],
                                                                                            Mapping):
        raise ValueError(f"{source}: expected exactly one table, [targets]; got "
                         f"{sorted(document) if isinstance(document, Mapping) else type(document).__name__}")
    table = document["targets"]
    out: dict[str, Target] = {}
    appendix = table.get("from_appendix_a", False)
    if not isinstance(appendix, bool):
        raise TypeError(f"{source}: targets.from_appendix_a = {appendix!r}: expected true or false")
    if appendix:
        for name, claim in appendix_a_claims(scenario).items():
            out[name] = Target(name, claim.expanded_uncertainty / claim.coverage_factor * K, claim.source)
    groups = [(k, v) for k, v in table.items() if k in GROUPS]
    singles = [(k, v) for k, v in table.items() if k in PARAMETER_INDEX]
    unknown = set(table) - set(GROUPS) - set(PARAMETER_INDEX) - {"from_appendix_a"}
    if unknown:
        raise ValueError(f"{source}: unknown target(s) {', '.join(sorted(map(repr, unknown)))}; allowed: a parameter "
                         f"({', '.join(PARAMETER_NAMES[:3])}, …), a group ({', '.join(GROUPS)}) or from_appendix_a")
    for key, raw in groups + singles:  # a parameter named on its own overrides its group
        members = [p for p in PARAMETERS if p.group == key] if key in GROUPS else [PARAMETERS[PARAMETER_INDEX[key]]]
        where = f"{source}: targets.{key}"
        U = parse_quantity(raw, members[0].kind, where)
        if not (math.isfinite(U) and U > 0):
            raise ValueError(f"{where} = {raw!r}: must be > 0")
        for p in members:
            out[p.name] = Target(p.name, U, f"{where} = {raw}")
    if not out:
        raise ValueError(f"{source}: [targets] names no target")
    return out


def load_targets(path: str | os.PathLike, scenario: Scenario) -> dict[str, Target]:
    """Read a targets file (TOML) and :func:`parse_targets` it."""
    try:
        with open(path, "rb") as f:
            document = tomllib.load(f)
    except OSError as error:
        raise ValueError(f"targets file {os.fspath(path)!r}: {error.strerror or error}") from None
    except tomllib.TOMLDecodeError as error:
        raise ValueError(f"targets file {os.fspath(path)!r}: not valid TOML ({error})") from None
    return parse_targets(document, scenario, os.fspath(path))


def predicted_U(scenario: Scenario) -> np.ndarray:
    """``2·√(u_c² + b²)`` (39,) of the scenario's schedule, from :func:`plansim.predict` (SI)."""
    p = predict(scenario)
    return K * np.hypot(p.u_predicted.values, p.bias_predicted.values)


@dataclasses.dataclass(frozen=True)
class _Shape:
    """A JJF 2003-structured schedule: positions, the rate set (signed fractions of the largest rate) and a dwell
    per test (index into DWELLS)."""

    positions: int
    rates: tuple[float, ...]
    dwell: tuple[int, int, int]

    def schedule(self, base: Scenario) -> Schedule:
        first = base.schedule.segments[0]
        common = dict(settle=first.settle, sample_rate=first.sample_rate, temperature=first.temperature)
        dwell = [DWELLS[i] for i in self.dwell]
        omega = max(s.rate for s in base.schedule.segments if s.test == "omega_squared")
        largest = _largest_rate(base)
        segments = (multi_position(self.positions, dwell=dwell[0], **common)
                    + rate_test([largest * f for f in self.rates], dwell=dwell[1], **common)
                    + omega_squared_test(omega, dwell=dwell[2], **common))
        return Schedule(tuple(segments), procedure="custom")

    def with_dwell(self, test: int, index: int) -> _Shape:
        dwell = list(self.dwell)
        dwell[test] = index
        return dataclasses.replace(self, dwell=tuple(dwell))


def _largest_rate(scenario: Scenario) -> float:
    return max(abs(s.rate) for s in scenario.schedule.segments if s.test == "rate")


def _own_rates(scenario: Scenario) -> tuple[float, ...]:
    """The scenario's rate points as fractions of the largest."""
    largest = _largest_rate(scenario)
    return tuple(sorted({s.rate / largest for s in scenario.schedule.segments if s.test == "rate"}))


@dataclasses.dataclass(frozen=True)
class PlanResult:
    """The plan: ``scenario`` (the base with the planned schedule), ``table_time`` s, per target
    ``predicted`` U (SI) and, after :func:`verify`, ``monte_carlo`` U with its standard error; ``predictions``
    the number of predictions the search made; ``compliant`` whether it was restricted to JJF 2003 §7.2;
    ``removable`` per segment what its removal breaks; ``limits`` the limit on the predicted U of each target
    (the target, or lower after a Monte Carlo round found the prediction optimistic); ``rounds`` of plan and
    verification; ``time_with_rules`` and ``time_without_rules`` the shortest table time, s, with and without
    JJF 2003 §7.2 (the other one from the prediction alone, with the same limits; inf when none meets)."""

    scenario: Scenario
    targets: dict[str, Target]
    table_time: float
    predicted: dict[str, float]
    compliant: bool
    predictions: int
    removable: tuple[str, ...]
    limits: dict[str, float] = dataclasses.field(default_factory=dict)
    monte_carlo: dict[str, tuple[float, float]] | None = None
    trials: int = 0
    rounds: int = 0
    time_with_rules: float = math.nan
    time_without_rules: float = math.nan

    def met_in_monte_carlo(self) -> dict[str, bool]:
        """Per target: the Monte Carlo U is not above it by more than :func:`allowance` standard errors."""
        if self.monte_carlo is None:
            raise ValueError("the plan has not been verified by a Monte Carlo (verify(plan, trials))")
        z = allowance(len(self.targets))
        return {n: self.monte_carlo[n][0] <= t.U + z * self.monte_carlo[n][1] for n, t in self.targets.items()}


class _Search:
    """The predictions of one search, counted and cached by schedule."""

    def __init__(self, base: Scenario, targets: dict[str, Target], limits: np.ndarray, progress):
        self.base, self.targets, self.progress = base, targets, progress
        self.index = np.array([PARAMETER_INDEX[n] for n in targets])
        self.limit = np.asarray(limits, dtype=float)
        self.calls = 0
        self._cache: dict = {}

    def predicted(self, schedule: Schedule) -> np.ndarray | None:
        """The predicted U (39,) of *schedule* (:func:`predicted_U`, once per schedule), or None when the
        estimators cannot reduce it."""
        key = tuple((s.test, s.up, s.heading, s.rate, s.dwell) for s in schedule.segments)
        if key not in self._cache:
            try:
                check_design(schedule)
            except ValueError:
                self._cache[key] = None
                return None
            self.calls += 1
            if self.progress is not None:
                self.progress(self.calls, None)
            self._cache[key] = predicted_U(dataclasses.replace(self.base, schedule=schedule))
        return self._cache[key]

    def ratios(self, schedule: Schedule) -> np.ndarray:
        """Predicted U / limit per target; inf when the estimators cannot reduce *schedule*."""
        U = self.predicted(schedule)
        return np.full(self.limit.shape, math.inf) if U is None else U[self.index] / self.limit

    def ratio(self, schedule: Schedule) -> float:
        """max over the targets of predicted U / its limit (≤ 1: met); inf when the estimators cannot reduce it."""
        return float(np.max(self.ratios(schedule)))

    def shortest(self, shape: _Shape, test: int, lowest: int) -> _Shape | None:
        """The shape with the shortest dwell of *test* (≥ DWELLS[lowest]) that meets every target, or None. A scan
        from the shortest up, not a bisection: U need not fall monotonically with one test's dwell (a longer test
        lets the drift of the others' segments wander further)."""
        for i in range(lowest, len(DWELLS)):
            candidate = shape.with_dwell(test, i)
            if self.ratio(candidate.schedule(self.base)) <= 1.0:
                return candidate
        return None


def _rate_sets(scenario: Scenario, compliant: bool) -> list[tuple[float, ...]]:
    """The rate sets of the search: the symmetric ±(1, 1/2, 1/5, 1/10, 1/20)[:k] with and without 0, and the
    scenario's own rate points (as fractions of its largest); for *compliant*, those with 7 to 11 points and both
    maxima."""
    sets = []
    for k in range(1, len(RATE_FRACTIONS) + 1):
        for zero in (False, True):
            half = RATE_FRACTIONS[:k]
            sets.append(tuple(sorted([-f for f in half] + ([0.0] if zero else []) + list(half))))
    own = _own_rates(scenario)
    if own not in sets:
        sets.append(own)
    if compliant:
        sets = [r for r in sets if RATE_POINTS_MIN <= len(r) <= RATE_POINTS_MAX and math.isclose(r[0], -r[-1])]
    return sets


def plan(scenario: Scenario, targets: dict[str, Target], compliant: bool = False, trials: int = 0,
         seed: int | None = None, path: str = "auto", progress: Callable[[int, None], None] | None = None
         ) -> PlanResult:
    """The shortest JJF 2003-structured schedule whose predicted U meets every target (module docstring), checked by
    a Monte Carlo when *trials* > 0.

    The prediction is the GUM's, and where the GUM does not hold (a quantiser the noise does not dither) the Monte
    Carlo U differs from it, either way. With *trials* the prediction is first calibrated: a Monte Carlo of the
    scenario's own schedule gives, per target, the ratio of predicted to simulated U, and the search holds the
    predicted U to that ratio times the most the Monte Carlo may show and still meet the target (the target plus
    z standard errors, :func:`allowance`). The plan is then verified by its own Monte Carlo, and a target it misses
    has its limit lowered by the ratio (target + z·SE) / Monte Carlo U and the search is run again, up to
    :data:`ROUNDS` times; the result says how many rounds it took, and whether every target is met.

    Parameters
    ----------
    scenario : Scenario
        The unit, noise, table, site and reduction; its schedule gives the settling time, sample rate,
        temperature, largest rate and ω² rate.
    targets : dict of str -> Target
        :func:`parse_targets`.
    compliant : bool
        Keep to the rules of JJF 2003 §7.2.
    trials, seed, path
        The Monte Carlo of the verification (0: none); *seed* default the scenario's.
    progress : callable, optional
        Called as ``progress(predictions so far, None)`` (a search does not know its length).

    Raises
    ------
    ValueError
        No schedule of the search meets the targets: the message names the targets that the longest schedule
        misses and by how much.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario, got {type(scenario).__name__}")
    if not targets or not all(isinstance(t, Target) for t in targets.values()):
        raise TypeError("targets: expected a non-empty dict of plansim.planning.plan.Target (parse_targets)")
    limits = np.array([t.U for t in targets.values()])
    seed = scenario.seed if seed is None else seed
    calls = 0
    result = None
    if trials > 0:  # calibrate the prediction on the scenario's own schedule first
        names = list(targets)
        mc = _monte_carlo_U(scenario, names, trials, seed, path)
        U = predicted_U(scenario)[[PARAMETER_INDEX[n] for n in names]]
        z = allowance(len(names))
        limits = np.array([(targets[n].U + z * mc[n][1]) / mc[n][0] for n in names]) * U
    for round_ in range(1, ROUNDS + 1):
        result = _search(scenario, targets, limits, compliant, progress, calls)
        calls = result.predictions
        if trials <= 0:
            break
        result = dataclasses.replace(verify(result, trials, seed, path), rounds=round_)
        met = result.met_in_monte_carlo()
        if all(met.values()):
            break
        for i, (name, target) in enumerate(targets.items()):
            if not met[name]:
                U_mc, se = result.monte_carlo[name]
                limits[i] *= (target.U + allowance(len(targets)) * se) / U_mc
    # the cost of compliance: the same limits searched under the other rule set (prediction only)
    try:
        other = _search(scenario, targets, np.array(list(result.limits.values())), not compliant, None, 0)
        other_time = other.table_time
    except ValueError:
        other_time = math.inf
    with_rules, without = (result.table_time, other_time) if compliant else (other_time, result.table_time)
    return dataclasses.replace(result, time_with_rules=with_rules, time_without_rules=without)


def _search(scenario: Scenario, targets: dict[str, Target], limits: np.ndarray, compliant: bool, progress,
            calls: int) -> PlanResult:
    """One search (module docstring, steps 1–3) on the predicted U against *limits* (one per target)."""
    search = _Search(scenario, targets, limits, progress)
    search.calls = calls
    positions = [12] if compliant else [6, 12]
    sets = _rate_sets(scenario, compliant)
    lowest = DWELLS.index(MINIMUM_DWELL) if compliant else 0
    # 0. a start that meets the targets: every test at one dwell, the scenario's own rate set or the fullest one, 12
    # positions; the shortest such
    starts = []
    for rates in dict.fromkeys(r for r in (_own_rates(scenario), max(sets, key=len)) if r in sets):
        for i in range(lowest, len(DWELLS)):
            shape = _Shape(12, rates, (i, i, i))
            if search.ratio(shape.schedule(scenario)) <= 1.0:
                starts.append(shape)
                break
    if not starts:
        raise ValueError(_infeasible(scenario, _Shape(12, max(sets, key=len), (len(DWELLS) - 1,) * 3)
                                     .schedule(scenario), targets, limits))
    start = min(starts, key=lambda shape: shape.schedule(scenario).duration)
    # 1. each test's structure on its own, the others at the start
    best_positions = _best(search, [dataclasses.replace(start, positions=n) for n in positions], 0, lowest,
                           scenario)
    best_rates = _best(search, [dataclasses.replace(start, rates=r) for r in sets], 1, lowest, scenario)
    omega = search.shortest(start, 2, lowest) or start
    shape = _Shape(best_positions.positions, best_rates.rates,
                   (best_positions.dwell[0], best_rates.dwell[1], omega.dwell[2]))
    if search.ratio(shape.schedule(scenario)) > 1.0:  # the tests interact: fall back to the start
        shape = start
    # 2. coordinate descent
    for _ in range(6):
        before = shape
        for test in range(3):
            found = search.shortest(shape, test, lowest)
            shape = found if found is not None else shape
        if shape == before:
            break
    schedule = shape.schedule(scenario)
    if search.ratio(schedule) > 1.0:  # the descent cannot lose the targets, but say so if it did
        raise RuntimeError("plan: the coordinate descent ended on a schedule that misses a target")
    # 3. pruning
    schedule = _prune(search, schedule, compliant)
    planned = dataclasses.replace(scenario, schedule=schedule, name=f"{scenario.name}-plan")
    U = search.predicted(schedule)
    predicted = {n: float(U[PARAMETER_INDEX[n]]) for n in targets}
    return PlanResult(planned, targets, schedule.duration, predicted, compliant, search.calls,
                      _why_needed(search, schedule, compliant), limits=dict(zip(targets, limits.tolist())))


def _best(search: _Search, shapes: list[_Shape], test: int, lowest: int, scenario: Scenario) -> _Shape:
    """Among *shapes* (differing in one test's structure), the one whose shortest meeting dwell of *test* gives the
    least table time."""
    found = [s for s in (search.shortest(shape, test, lowest) for shape in shapes) if s is not None]
    if not found:  # cannot happen: the start met the targets and is among them
        raise RuntimeError("plan: no structure of the test meets the targets")
    return min(found, key=lambda s: s.schedule(scenario).duration)


def _without(schedule: Schedule, k: int) -> Schedule:
    return Schedule(schedule.segments[:k] + schedule.segments[k + 1:], procedure=schedule.procedure)


def _prune(search: _Search, schedule: Schedule, compliant: bool) -> Schedule:
    """Remove segments while the rest still reduces, meets every target (and stays compliant), longest first."""
    while True:
        order = sorted(range(len(schedule)), key=lambda k: -(schedule.segments[k].settle + schedule.segments[k].dwell))
        for k in order:
            smaller = _without(schedule, k)
            if compliant and not jjf2003_compliance(smaller).compliant:
                continue
            if search.ratio(smaller) <= 1.0:
                schedule = smaller
                break
        else:
            return schedule


def _why_needed(search: _Search, schedule: Schedule, compliant: bool) -> tuple[str, ...]:
    """Per segment, what removing it breaks."""
    out = []
    for k in range(len(schedule)):
        smaller = _without(schedule, k)
        failed = jjf2003_compliance(smaller).failed() if compliant else []
        if failed:
            out.append("JJF 2003 compliance: " + "; ".join(failed))
            continue
        ratios = search.ratios(smaller)
        worst = int(np.argmax(ratios))
        if math.isinf(ratios[worst]):
            out.append("the JJF 2003 reduction (check_design)")
        elif ratios[worst] > 1.0:
            out.append(f"{list(search.targets)[worst]}: predicted U {ratios[worst]:.3f}× its limit")
        else:
            out.append("nothing (a removable segment: the pruning would have removed it)")
    return tuple(out)


def _infeasible(scenario: Scenario, schedule: Schedule, targets: dict[str, Target], limits: np.ndarray) -> str:
    U = predicted_U(dataclasses.replace(scenario, schedule=schedule))
    missed = sorted(((U[PARAMETER_INDEX[n]] / lim, n) for n, lim in zip(targets, limits)
                     if U[PARAMETER_INDEX[n]] > lim), reverse=True)
    listed = ", ".join(f"{n} ({r:.3g}× its target)" for r, n in missed[:6])
    return (f"no schedule of the search meets the targets: even the longest ({schedule.duration:.0f} s of table "
            f"time, every dwell {DWELLS[-1]:g} s, 12 positions, {2 * len(RATE_FRACTIONS) + 1} rate points) predicts "
            f"U above the target for {len(missed)} of them: {listed}. These are floors the schedule does not move "
            "(quantisation, table errors, the systematic effects the estimators leave)")


def verify(result: PlanResult, trials: int, seed: int, path: str = "auto") -> PlanResult:
    """The plan's Monte Carlo: U = 2·√(mean E²) per target with its standard error (module docstring)."""
    out = _monte_carlo_U(result.scenario, list(result.targets), trials, seed, path)
    return dataclasses.replace(result, monte_carlo=out, trials=trials)


def _monte_carlo_U(scenario: Scenario, names: list[str], trials: int, seed: int, path: str
                   ) -> dict[str, tuple[float, float]]:
    """Per parameter name: U = 2·√(mean E²) over a Monte Carlo of *trials*, and its standard error."""
    from plansim.runner import run

    if not isinstance(trials, int) or isinstance(trials, bool) or trials < 2:
        raise ValueError(f"trials = {trials!r}: expected an integer ≥ 2")
    error = run(scenario, trials=trials, seed=seed, path=path)["error"].values
    out = {}
    for name in names:
        e2 = error[:, PARAMETER_INDEX[name]] ** 2
        m2 = float(e2.mean())
        se = K * math.sqrt(float(e2.var(ddof=1)) / trials) / (2.0 * math.sqrt(m2)) if m2 > 0 else 0.0
        out[name] = (K * math.sqrt(m2), se)
    return out
