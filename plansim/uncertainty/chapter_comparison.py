"""The gyro cross-couplings of one unit by two procedures: JJF 2003's rate test and the chapter's ± rate turns.

Each trial simulates one unit through the scenario's JJF 2003 schedule with the chapter's turns appended
(:func:`plansim.schedule.chapter.rate_turns`: each axis up, whole turns at +Ω then −Ω). The same segment
means are reduced twice:

- JJF 2003 §7.2.3 (eq. (4)–(5), :func:`plansim.estimate.reduce`): the cross-coupling ``Kg[b, a]`` is the
  slope of gyro *b* against the rate about axis *a*; its misalignment ``Kg[b, a]/Kg[b, b]``;
- the chapter's eq. (6-8) (:func:`plansim.estimate.chapter.rate_misalignments`), with JJF 2003's
  scale factors ``Kg[b, b]`` as E_1b (the laboratory has them from the same session).

Both are compared with the simulated unit's ``Kg[b, a]/Kg[b, b]``, so a laboratory sees which procedure
estimates the cross-couplings better on the same unit, table and noise.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from plansim.config import Scenario
from plansim.estimate import check_design, reduce
from plansim.estimate.chapter import cross_axis_ratios, rate_misalignments
from plansim.model.parameters import unpack
from plansim.schedule.chapter import CHAPTER_TURN_RATE, rate_turns
from plansim.schedule.segments import Schedule
from plansim.simulate.chunks import check_count, simulate_segment_means
from plansim.simulate.paths import choose_path

#: the six off-diagonal entries (gyro b, axis a) of Kg, in the order of the results
OFF_DIAGONAL = ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1))
#: their names: plansim's ratio ``Kg<b><a>/Kg<b><b>`` and the chapter's ``E_<a><b>`` (input axis, then gyro)
RATIO_NAMES = tuple(f"Kg{'xyz'[b]}{'xyz'[a]}/Kg{'xyz'[b]}{'xyz'[b]}" for b, a in OFF_DIAGONAL)
CHAPTER_NAMES = tuple(f"E_{'xyz'[a]}{'xyz'[b]}" for b, a in OFF_DIAGONAL)


def with_rate_turns(schedule: Schedule, rate: float = CHAPTER_TURN_RATE, turns: int = 1) -> Schedule:
    """*schedule* with the chapter's ± rate turns about x, y and z appended (at the end, after its last segment).

    The turns are ``"rotation"`` segments, which the JJF 2003 estimators do not read, so the result still
    passes :func:`plansim.estimate.check_design` when *schedule* does. Settle, sample rate and temperature
    are the last segment's.
    """
    last = schedule.segments[-1]
    extra = rate_turns(rate, turns, settle=last.settle, sample_rate=last.sample_rate, temperature=last.temperature)
    out = Schedule(schedule.segments + tuple(extra), procedure="custom",
                   notes={**schedule.notes, "appended": f"chapter eq. (6-8): ± {math.degrees(rate):g} deg/s, "
                                                        f"{turns} turn(s) about x, y, z"})
    check_design(out)
    return out


@dataclass(frozen=True)
class MisalignmentComparison:
    """Per trial, the six gyro misalignments ``Kg[b, a]/Kg[b, b]`` (order :data:`OFF_DIAGONAL`), dimensionless.

    ``truth`` is the simulated unit's, ``jjf2003`` JJF 2003 §7.2.3's estimate, ``chapter`` eq. (6-8)'s.
    """

    scenario: str
    trials: int
    seed: int
    path: str
    rate: float  # rad/s, of the chapter's turns
    turns: int
    truth: np.ndarray  # (trials, 6)
    jjf2003: np.ndarray  # (trials, 6)
    chapter: np.ndarray  # (trials, 6)

    def errors(self, procedure: str) -> np.ndarray:
        """Estimate − truth, (trials, 6), of ``"jjf2003"`` or ``"chapter"``."""
        if procedure not in ("jjf2003", "chapter"):
            raise ValueError(f"procedure = {procedure!r}; allowed: 'jjf2003', 'chapter'")
        return getattr(self, procedure) - self.truth

    def summary(self) -> list[dict]:
        """One row per misalignment: names, and per procedure the mean, standard deviation (n − 1) and root
        mean square of the error, with the standard uncertainty of the mean (σ/√n)."""
        rows = []
        for k, (name, chapter_name) in enumerate(zip(RATIO_NAMES, CHAPTER_NAMES)):
            row = {"name": name, "chapter_name": chapter_name}
            for procedure in ("jjf2003", "chapter"):
                e = self.errors(procedure)[:, k]
                std = float(np.std(e, ddof=1)) if e.size > 1 else math.nan
                row[procedure] = {"mean": float(e.mean()), "std": std, "rms": float(np.sqrt(np.mean(e**2))),
                                  "u_mean": std / math.sqrt(e.size)}
            rows.append(row)
        return rows


def compare_misalignment(scenario: Scenario, trials: int, seed: int, rate: float = CHAPTER_TURN_RATE,
                         turns: int = 1, path: str = "auto", chunk_size: int = 256) -> MisalignmentComparison:
    """Simulate *trials* units of *scenario* through its schedule plus the chapter's turns; reduce both ways.

    Parameters
    ----------
    scenario : Scenario
        Its schedule must be a JJF 2003 one (it passes :func:`plansim.estimate.check_design`).
    trials, seed : int
        Number of trials (>= 2) and root seed (>= 0); trial *i* is the same unit in any run with this seed.
    rate : float
        The chapter's table rate Ω, rad/s (default 10 °/s).
    turns : int
        Whole turns in each direction (default 1, the chapter's).
    path : {"auto", "sample", "segment"}
        Simulation path (:func:`plansim.simulate.paths.choose_path`).
    chunk_size : int
        Trials per chunk.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario, got {type(scenario).__name__}")
    trials = check_count("trials", trials, minimum=2)
    seed = check_count("seed", seed, minimum=0)
    schedule = with_rate_turns(scenario.schedule, rate, turns)
    extended = dataclasses.replace(scenario, schedule=schedule)
    chosen, _reasons = choose_path(extended, path)
    means, truth = simulate_segment_means(extended, trials, seed, chunk_size=chunk_size, path=chosen)
    r = scenario.reduction
    estimate = unpack(reduce(means, schedule, r.reference_gravity, r.omega_squared_sign))
    jjf_ratios = cross_axis_ratios(estimate["Kg"])
    scale = np.diagonal(estimate["Kg"], axis1=-2, axis2=-1)  # E_1b: JJF 2003's scale factors, the same session
    chapter_ratios = rate_misalignments(means, schedule, scale)
    true_ratios = cross_axis_ratios(unpack(truth)["Kg"])
    rows, cols = np.array(OFF_DIAGONAL).T
    return MisalignmentComparison(
        scenario=scenario.name, trials=trials, seed=seed, path=chosen, rate=float(rate), turns=int(turns),
        truth=true_ratios[:, rows, cols], jjf2003=jjf_ratios[:, rows, cols], chapter=chapter_ratios[:, rows, cols])
