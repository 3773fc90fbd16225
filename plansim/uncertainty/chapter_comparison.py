"""The chapter's procedures against JJF 2003 on the same units: misalignments, accelerometer cross-axis terms, drift.

Each trial simulates one unit through the scenario's JJF 2003 schedule with the chapter's tests appended
(textbook chapter §6.2, :mod:`plansim.schedule.chapter`), after its last segment:

- ``"misalignment"`` — the ± rate turns of eq. (6-8) (:func:`plansim.schedule.chapter.rate_turns`: each
  axis up, whole turns at +Ω then −Ω);
- ``"accelerometer"`` — the 8-position test (:func:`plansim.schedule.chapter.eight_positions`: each axis up
  at four headings, then down at the same four);
- ``"drift"`` — the position test of the drift model D0 + D1·a_X + D2·a_Y + D3·a_Z
  (:func:`plansim.schedule.chapter.drift_positions`, *repeats* times one after the other).

The same segment means are reduced twice:

- JJF 2003 (eq. (4)–(5) and (1)–(3), :func:`plansim.estimate.reduce`) gives ``Kg``, ``Bg``, ``G`` and ``Ka``;
- the chapter: eq. (6-8) (:func:`plansim.estimate.chapter.rate_misalignments`, JJF 2003's scale factors
  ``Kg[b, b]`` as E_1b, as the laboratory has them from the same session); eq. (6-9) over the eight positions
  (:func:`plansim.estimate.chapter.eight_position_fit`); the drift model fitted to each repeat with the Earth
  rate removed at the chapter's 15.04107 °/h (:func:`plansim.estimate.chapter.drift_model`, JJF 2003's whole
  ``Kg`` as the gyros' response; 0 when the scenario switches the Earth rate off), averaged over the repeats,
  and the random drift of eq. (6-6), 2.7 × the standard deviation of D0 over the repeats.

Every quantity is compared with the simulated unit's: the misalignments ``Kg[b, a]/Kg[b, b]``, the
accelerometer cross-axis terms ``Ka[i, j]/Ka[i, i]`` (the chapter's ``K_ji/K_i``), and D0 = ``Bg[i]``,
D1–D3 = ``G[i, :]`` (JJF 2003 eq. (1)). So a laboratory sees, on the same unit, table and noise, which
procedure estimates each better. The random drift has no true value: it is reported as its distribution.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from plansim.config import Scenario
from plansim.estimate import check_design, reduce
from plansim.estimate.chapter import (
    CHAPTER_EARTH_RATE,
    RANDOM_DRIFT_FACTOR,
    cross_axis_ratios,
    drift_model,
    eight_position_fit,
    rate_misalignments,
)
from plansim.model.parameters import unpack
from plansim.schedule.chapter import (
    CHAPTER_TURN_RATE,
    EIGHT_POSITION_HEADINGS,
    drift_positions,
    eight_positions,
    rate_turns,
)
from plansim.schedule.segments import Schedule
from plansim.simulate.chunks import ProgressCallback, check_count, simulate_segment_means
from plansim.simulate.paths import choose_path

#: the six off-diagonal entries (row b, column a) of a 3 × 3 matrix, in the order of the results
OFF_DIAGONAL = ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))
#: the gyro misalignments: plansim's ratio ``Kg<b><a>/Kg<b><b>`` and the chapter's ``E_<a><b>`` (input axis, then gyro)
RATIO_NAMES = tuple(f"Kg{'xyz'[b]}{'xyz'[a]}/Kg{'xyz'[b]}{'xyz'[b]}" for b, a in OFF_DIAGONAL)
CHAPTER_NAMES = tuple(f"E_{'xyz'[a]}{'xyz'[b]}" for b, a in OFF_DIAGONAL)
#: the accelerometer cross-axis terms: ``Ka<i><j>/Ka<i><i>`` and the chapter's ``K_<j><i>/K_<i>``
ACCEL_RATIO_NAMES = tuple(f"Ka{'xyz'[i]}{'xyz'[j]}/Ka{'xyz'[i]}{'xyz'[i]}" for i, j in OFF_DIAGONAL)
ACCEL_CHAPTER_NAMES = tuple(f"K_{'xyz'[j]}{'xyz'[i]}/K_{'xyz'[i]}" for i, j in OFF_DIAGONAL)
#: the drift model per gyro: ``Bg<i>``, ``G<i>x``, ``G<i>y``, ``G<i>z`` and the chapter's D0–D3
DRIFT_NAMES = tuple(name for i in "xyz" for name in (f"Bg{i}", f"G{i}x", f"G{i}y", f"G{i}z"))
DRIFT_CHAPTER_NAMES = tuple(f"D{k} ({i} gyro)" for i in "xyz" for k in range(4))
#: the chapter's tests :func:`compare_chapter` can append, in the order they are appended and reported
CHAPTER_TESTS = ("misalignment", "accelerometer", "drift")
#: default repeats of the drift positions (eq. (6-6) needs >= 2)
DRIFT_REPEATS = 3


def _tests(tests) -> tuple[str, ...]:
    try:
        chosen = (tests,) if isinstance(tests, str) else tuple(tests)
    except TypeError:
        raise TypeError(f"tests = {tests!r}; expected names among {CHAPTER_TESTS}") from None
    bad = [t for t in chosen if t not in CHAPTER_TESTS]
    if bad or not chosen or len(set(chosen)) != len(chosen):
        raise ValueError(f"tests = {tests!r}; give distinct names among {', '.join(CHAPTER_TESTS)}")
    return tuple(p for p in CHAPTER_TESTS if p in chosen)


def with_rate_turns(schedule: Schedule, rate: float = CHAPTER_TURN_RATE, turns: int = 1) -> Schedule:
    """*schedule* with the chapter's ± rate turns about x, y and z appended (see :func:`with_chapter_tests`)."""
    return with_chapter_tests(schedule, ("misalignment",), rate=rate, turns=turns)[0]


def with_chapter_tests(schedule: Schedule, tests=CHAPTER_TESTS, rate: float = CHAPTER_TURN_RATE, turns: int = 1,
                       headings=EIGHT_POSITION_HEADINGS, repeats: int = DRIFT_REPEATS,
                       dwell: float | None = None) -> tuple[Schedule, dict[str, list[int]]]:
    """*schedule* with the chapter's tests appended after its last segment, and where each test's segments are.

    The tests are ``"rotation"`` and ``"static"`` segments, which the JJF 2003 estimators do not read, so the
    result still passes :func:`plansim.estimate.check_design` when *schedule* does. Settle, sample rate and
    temperature are the last segment's; the positions dwell *dwell* s (default: the last segment's).

    Returns
    -------
    schedule : Schedule
    indices : dict
        Per test the indices of its segments in the result (``"drift"``: one list per repeat, flattened
        in order; group = the repeat).
    """
    chosen = _tests(tests)
    last = schedule.segments[-1]
    common = dict(settle=last.settle, sample_rate=last.sample_rate, temperature=last.temperature)
    dwell = last.dwell if dwell is None else dwell
    segments = list(schedule.segments)
    indices: dict[str, list[int]] = {}
    notes = []
    for test in chosen:
        if test == "misalignment":
            extra = rate_turns(rate, turns, **common)
            notes.append(f"chapter eq. (6-8): ± {math.degrees(rate):g} deg/s, {turns} turn(s) about x, y, z")
        elif test == "accelerometer":
            extra = eight_positions(headings=headings, dwell=dwell, **common)
            notes.append(f"chapter 8-position test: {len(extra)} positions")
        else:
            if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 2:
                raise ValueError(f"repeats = {repeats!r}; the drift model's random drift (eq. (6-6)) needs a "
                                 "whole number >= 2 of repeats")
            extra = drift_positions(repeats=repeats, dwell=dwell, **common)
            notes.append(f"chapter drift model: {len(extra)} positions in {repeats} repeats")
        indices[test] = list(range(len(segments), len(segments) + len(extra)))
        segments.extend(extra)
    out = Schedule(tuple(segments), procedure="custom", notes={**schedule.notes, "appended": "; ".join(notes)})
    check_design(out)
    return out, indices


@dataclass(frozen=True)
class ChapterComparison:
    """Per trial, each compared quantity as the simulated unit has it and as the two procedures estimate it.

    ``names`` are plansim's (``Kgxy/Kgxx``, ``Kaxy/Kaxx``, ``Bgx``, ``Gxy``, …), ``chapter_names`` the chapter's
    (``E_yx``, ``K_yx/K_x``, ``D0 (x gyro)``, …), ``tests`` which of :data:`CHAPTER_TESTS` each belongs to,
    ``units`` its SI unit. ``truth``, ``jjf2003`` and ``chapter`` are ``(trials, n)``. ``random_drift`` is eq.
    (6-6) per trial and gyro, rad/s (``(trials, 3)``; ``None`` without the drift test).
    """

    scenario: str
    trials: int
    seed: int
    path: str
    rate: float  # rad/s, of the chapter's turns
    turns: int
    repeats: int  # of the drift positions
    earth_rate: float  # rad/s, the reference the drift model removed
    names: tuple[str, ...]
    chapter_names: tuple[str, ...]
    tests: tuple[str, ...]
    units: tuple[str, ...]
    truth: np.ndarray
    jjf2003: np.ndarray
    chapter: np.ndarray
    random_drift: np.ndarray | None = None

    def errors(self, procedure: str) -> np.ndarray:
        """Estimate − truth, (trials, n), of ``"jjf2003"`` or ``"chapter"``."""
        if procedure not in ("jjf2003", "chapter"):
            raise ValueError(f"procedure = {procedure!r}; allowed: 'jjf2003', 'chapter'")
        return getattr(self, procedure) - self.truth

    def summary(self) -> list[dict]:
        """One row per quantity: names, test, unit, and per procedure the mean, standard deviation (n − 1) and
        root mean square of the error, with the standard uncertainty of the mean (σ/√n)."""
        rows = []
        for k, name in enumerate(self.names):
            row = {"name": name, "chapter_name": self.chapter_names[k], "test": self.tests[k],
                   "unit": self.units[k], "truth_mean": float(self.truth[:, k].mean())}
            for procedure in ("jjf2003", "chapter"):
                e = self.errors(procedure)[:, k]
                std = float(np.std(e, ddof=1)) if e.size > 1 else math.nan
                row[procedure] = {"mean": float(e.mean()), "std": std, "rms": float(np.sqrt(np.mean(e**2))),
                                  "u_mean": std / math.sqrt(e.size)}
            rows.append(row)
        return rows


def _drift_terms(parameters: dict) -> np.ndarray:
    """``[Bg[i], G[i, x], G[i, y], G[i, z]]`` per gyro, flattened gyro by gyro: (trials, 12), the order of
    :data:`DRIFT_NAMES` (the model's D0–D3, JJF 2003 eq. (1))."""
    return np.concatenate([parameters["Bg"][..., None], parameters["G"]], axis=-1).reshape(-1, 12)


def compare_chapter(scenario: Scenario, trials: int, seed: int, tests=CHAPTER_TESTS,
                    rate: float = CHAPTER_TURN_RATE, turns: int = 1, repeats: int = DRIFT_REPEATS,
                    path: str = "auto", chunk_size: int = 256,
                    progress: ProgressCallback | None = None) -> ChapterComparison:
    """Simulate *trials* units of *scenario* through its schedule plus the chapter's tests; reduce both ways.

    Parameters
    ----------
    scenario : Scenario
        Its schedule must be a JJF 2003 one (it passes :func:`plansim.estimate.check_design`).
    trials, seed : int
        Number of trials (>= 2) and root seed (>= 0); trial *i* is the same unit in any run with this seed.
    tests : sequence of str
        Which tests to append, among :data:`CHAPTER_TESTS` (default all three).
    rate : float
        The chapter's table rate Ω, rad/s (default 10 °/s).
    turns : int
        Whole turns in each direction (default 1, the chapter's).
    repeats : int
        Repeats of the drift positions (>= 2; default 3).
    path : {"auto", "sample", "segment"}
        Simulation path (:func:`plansim.simulate.paths.choose_path`).
    chunk_size : int
        Trials per chunk.
    progress : callable, optional
        ``progress(done, total)`` after each chunk.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario, got {type(scenario).__name__}")
    trials = check_count("trials", trials, minimum=2)
    seed = check_count("seed", seed, minimum=0)
    chosen = _tests(tests)
    schedule, indices = with_chapter_tests(scenario.schedule, chosen, rate=rate, turns=turns, repeats=repeats)
    extended = dataclasses.replace(scenario, schedule=schedule)
    path_taken, _reasons = choose_path(extended, path)
    means, truth = simulate_segment_means(extended, trials, seed, chunk_size=chunk_size, path=path_taken,
                                          progress=progress)
    r = scenario.reduction
    estimate = unpack(reduce(means, schedule, r.reference_gravity, r.omega_squared_sign))
    true = unpack(truth)
    rows, cols = np.array(OFF_DIAGONAL).T
    parts = []  # (names, chapter names, unit, truth, jjf2003, chapter)
    random = None
    earth_rate = CHAPTER_EARTH_RATE if scenario.environment.earth_rate else 0.0
    if "misalignment" in chosen:
        scale = np.diagonal(estimate["Kg"], axis1=-2, axis2=-1)  # E_1b: JJF 2003's scale factors, the same session
        chapter = rate_misalignments(means, schedule, scale)
        parts.append((RATIO_NAMES, CHAPTER_NAMES, "1", cross_axis_ratios(true["Kg"])[:, rows, cols],
                      cross_axis_ratios(estimate["Kg"])[:, rows, cols], chapter[:, rows, cols]))
    if "accelerometer" in chosen:
        Ka, _Ba = eight_position_fit(means, schedule, r.reference_gravity, indices["accelerometer"])
        parts.append((ACCEL_RATIO_NAMES, ACCEL_CHAPTER_NAMES, "1", cross_axis_ratios(true["Ka"])[:, rows, cols],
                      cross_axis_ratios(estimate["Ka"])[:, rows, cols], cross_axis_ratios(Ka)[:, rows, cols]))
    if "drift" in chosen:
        latitude = scenario.environment.latitude
        per_repeat = np.stack([
            drift_model(means, schedule, r.reference_gravity, latitude, estimate["Kg"], earth_rate,
                        [k for k in indices["drift"] if schedule.segments[k].group == g])
            for g in range(repeats)], axis=1)  # (trials, repeats, 3, 4)
        random = RANDOM_DRIFT_FACTOR * np.std(per_repeat[..., 0], axis=1, ddof=1)
        units = ("rad/s",) + ("rad/s/(m/s^2)",) * 3
        parts.append((DRIFT_NAMES, DRIFT_CHAPTER_NAMES, units * 3, _drift_terms(true), _drift_terms(estimate),
                      per_repeat.mean(axis=1).reshape(-1, 12)))
    names, chapter_names, kinds, units = [], [], [], []
    for test, (n, c, u, *_arrays) in zip(chosen, parts):
        names += n
        chapter_names += c
        kinds += [test] * len(n)
        units += list(u) if isinstance(u, tuple) else [u] * len(n)
    return ChapterComparison(
        scenario=scenario.name, trials=trials, seed=seed, path=path_taken, rate=float(rate), turns=int(turns),
        repeats=int(repeats), earth_rate=earth_rate, names=tuple(names), chapter_names=tuple(chapter_names),
        tests=tuple(kinds), units=tuple(units),
        truth=np.concatenate([p[3] for p in parts], axis=1), jjf2003=np.concatenate([p[4] for p in parts], axis=1),
        chapter=np.concatenate([p[5] for p in parts], axis=1), random_drift=random)


def compare_misalignment(scenario: Scenario, trials: int, seed: int, rate: float = CHAPTER_TURN_RATE,
                         turns: int = 1, path: str = "auto", chunk_size: int = 256) -> ChapterComparison:
    """:func:`compare_chapter` with the ± rate turns only: the six gyro misalignments (order :data:`OFF_DIAGONAL`)."""
    return compare_chapter(scenario, trials, seed, ("misalignment",), rate=rate, turns=turns, path=path,
                           chunk_size=chunk_size)
