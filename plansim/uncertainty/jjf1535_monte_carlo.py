"""JJF 1535-2015 simulated: a scenario's unit through the JJF 1535 procedure, reduced by its items, against Appendix A.

The scenario file knows the JJF 2003 procedures only (its schedule must pass
:func:`plansim.estimate.check_design`); a JJF 1535 session is simulated instead by replacing a loaded
scenario's schedule, turntable and acquisition (:func:`jjf1535_scenario`, ``dataclasses.replace``): the unit, its
noise, its effects and the laboratory stay the scenario's.

- :func:`jjf1535_scenario` — the JJF 1535 world: the procedure of :func:`plansim.schedule.jjf1535.jjf1535_procedure`,
  a rate table of Table 2's grade (the Appendix A rate error u = 2.5e-4 as a normal systematic error per session,
  rate smoothness 0.05 %), a two-axis position table of 3″, a 6½-digit acquisition (21 bits);
- :func:`jjf1535_monte_carlo` — N trials, each a different unit, reduced by
  :func:`plansim.estimate.jjf1535_items.reduce_items`, against :func:`~plansim.estimate.jjf1535_items.true_items`;
  :meth:`Jjf1535MonteCarlo.summary` compares the scale factor and the bias with Appendix A's U, and shows the
  distribution of the reported figure for the items without a true value and for threshold, resolution, warm-up
  time and the repeatabilities (:data:`FIGURE_ALSO`).

The unit's JJF 1535 effects (dead zone, resolution, warm-up transient, turn-on bias per power cycle;
:mod:`plansim.model.jjf1535_effects`) are not in the kernels: the kernels simulate the unit without them and
:func:`plansim.simulate.jjf1535_effects.apply_jjf1535_effects` adds them to each trial's segment means in closed
form, before the reduction. With none set, nothing is added and the results are those of the kernels alone.

The angle random walk of 7.2.13 needs the samples of one recording: :func:`plansim.runner.jjf1535_angle_random_walk`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from plansim.config import Scenario
from plansim.config.saturation import saturation_report
from plansim.config.scenario import Acquisition, ErrorDistribution
from plansim.estimate.jjf1535_items import ITEMS, reduce_items, true_items
from plansim.schedule.jjf1535 import Jjf1535Procedure, jjf1535_procedure
from plansim.simulate.chunks import ProgressCallback, check_count, iterate_chunks
from plansim.simulate.jjf1535_effects import apply_jjf1535_effects, input_axis_rates, without_jjf1535_effects
from plansim.simulate.paths import choose_path
from plansim.uncertainty.appendix_a_jjf1535 import BIAS, SCALE_FACTOR
from plansim.units import ARCSEC, DEG

#: the default procedure's largest rate: the R5 point 100 °/s (rad/s), inside the jjf2003 unit's 125 °/s output range
DEFAULT_MAXIMUM_RATE = 100.0 * DEG
#: Appendix A.1.2.2 1): the rate table's U_rel = 5e-4 (k = 2), so u = 2.5e-4
TABLE_RATE_UNCERTAINTY = SCALE_FACTOR.components[0].printed_value
#: JJF 1535 Table 2: rate smoothness 0.05 %; two-axis position table 3″
TABLE_RATE_SMOOTHNESS = 5e-4
POSITION_ACCURACY = 3.0 * ARCSEC
#: a 6½-digit voltmeter resolves about 2·10⁶ counts over its range: 21 bits
ACQUISITION_BITS = 21
#: the items Appendix A budgets, with its budget: Appendix A reads both relative
BUDGETED = {"scale_factor": SCALE_FACTOR, "bias": BIAS, "bias_up_down": BIAS}
#: items with a true value whose reported figure's distribution is shown too: a lab quotes the figure, and the
#: procedure reports a tested rate (7.2.6, 7.2.7) or a sample std of Q values (7.2.4, 7.2.11), not the property
FIGURE_ALSO = ("scale_repeatability", "threshold", "resolution", "warm_up_time", "bias_repeatability")


def jjf1535_scenario(scenario: Scenario, procedure: Jjf1535Procedure | None = None,
                     keep_table: bool = False) -> tuple[Scenario, Jjf1535Procedure]:
    """*scenario*'s unit and laboratory with the JJF 1535 procedure, table and acquisition (module docstring).

    With *keep_table* the scenario's own turntable and acquisition stay (the zero-noise ``ideal`` world keeps its
    perfect table).

    Raises ``ValueError`` if the procedure drives the gyro past its output range or the acquisition's full scale
    (a clipped rate point would bend the line of eq. (5)).
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario, got {type(scenario).__name__}")
    if procedure is None:
        procedure = jjf1535_procedure(DEFAULT_MAXIMUM_RATE)
    if not isinstance(procedure, Jjf1535Procedure):
        raise TypeError(f"procedure: expected a Jjf1535Procedure, got {type(procedure).__name__}")
    if not isinstance(keep_table, bool):
        raise TypeError(f"keep_table = {keep_table!r}: expected True or False")
    table = scenario.turntable
    position = ErrorDistribution("uniform", POSITION_ACCURACY)
    turntable = dataclasses.replace(
        table, position_accuracy=position, position_repeatability=position,
        rate_error_systematic=ErrorDistribution("normal", TABLE_RATE_UNCERTAINTY),
        rate_error_per_point=ErrorDistribution("uniform", 0.0), rate_smoothness=TABLE_RATE_SMOOTHNESS)
    acquisition = Acquisition(bits=ACQUISITION_BITS, gyro_full_scale=scenario.acquisition.gyro_full_scale,
                              accel_full_scale=scenario.acquisition.accel_full_scale)
    if keep_table:
        turntable, acquisition = table, scenario.acquisition
    out = dataclasses.replace(scenario, name=f"{scenario.name} (JJF 1535)", schedule=procedure.schedule,
                              turntable=turntable, acquisition=acquisition)
    clipped = saturation_report(out)
    if clipped:
        raise ValueError(f"procedure: the JJF 1535 schedule drives the unit of {scenario.name!r} past its limits "
                         f"(lower maximum_rate): {'; '.join(clipped[:3])}")
    return out, procedure


def truth_of(scenario: Scenario, procedure: Jjf1535Procedure, truth) -> dict[str, float]:
    """:func:`~plansim.estimate.jjf1535_items.true_items` with the gyro's effects taken from *scenario*."""
    e, i = scenario.effects, procedure.axis
    return true_items(truth, procedure,
                      scale_temperature_coefficient=float(e.gyro_scale_temperature_coefficient[i]),
                      bias_temperature_coefficient=float(e.gyro_bias_temperature_coefficient[i]),
                      reference_temperature=e.reference_temperature, asymmetry=float(e.gyro_asymmetry[i]),
                      nonlinearity_quadratic=float(e.gyro_nonlinearity_quadratic[i]),
                      nonlinearity_cubic=float(e.gyro_nonlinearity_cubic[i]),
                      dead_zone=float(e.gyro_dead_zone[i]), resolution=float(e.gyro_resolution[i]),
                      warm_up_amplitude=float(e.gyro_warm_up_amplitude[i]),
                      warm_up_time_constant=float(e.gyro_warm_up_time_constant[i]),
                      turn_on_bias=float(e.gyro_turn_on_bias[i]))


@dataclass(frozen=True)
class Jjf1535MonteCarlo:
    """Per trial, each item's reported value and the simulated unit's (NaN where the model has none), SI."""

    scenario: str
    trials: int
    seed: int
    path: str
    items: tuple[str, ...]
    values: np.ndarray  # (trials, items)
    truth: np.ndarray  # (trials, items)

    def column(self, item: str, of: str = "values") -> np.ndarray:
        if item not in self.items:
            raise ValueError(f"item = {item!r}; allowed: {', '.join(self.items)}")
        return getattr(self, of)[:, self.items.index(item)]

    def relative_errors(self, item: str) -> np.ndarray:
        """(reported − true)/true per trial: Appendix A reads the scale factor and the bias relative."""
        return self.column(item) / self.column(item, "truth") - 1.0

    def summary(self) -> list[dict]:
        """One row per item, in its JJF 1535 unit (:data:`~plansim.estimate.jjf1535_items.ITEMS`).

        With a true value: the mean, standard deviation (n − 1) and 95 % quantile of |error| of the error, and the
        mean true value. For the budgeted items also the relative error's statistics, Appendix A's printed U and
        the fraction of trials whose |relative error| is within it (its coverage). Without: the mean, standard
        deviation and 2.5 %/97.5 % quantiles of the reported figure. ``undetermined``: the fraction of trials in
        which the procedure could not determine the item (NaN: a threshold or resolution above every tested rate,
        a warm-up never reaching the specified stability); the statistics are those of the other trials (NaN if
        fewer than two).
        """
        rows = []
        for item in self.items:
            clause, equations, unit, scale = ITEMS[item]
            x, t = self.column(item), self.column(item, "truth")
            found = np.isfinite(x)
            row = {"item": item, "clause": clause, "equations": equations, "unit": unit, "trials": self.trials,
                   "undetermined": float(1.0 - found.mean())}
            has_truth = not np.all(np.isnan(t))
            x, t = x[found], t[found]
            row.update(_error_statistics(x, t, scale) if has_truth else {"truth": math.nan})
            if not has_truth or item in FIGURE_ALSO:
                row.update(_figure_statistics(x, scale))
            if item in BUDGETED:
                rel = self.relative_errors(item)
                budget = BUDGETED[item].printed_expanded_uncertainty
                row.update(budget=BUDGETED[item].item, budget_U=budget, mean_relative_error=float(rel.mean()),
                           std_relative_error=float(np.std(rel, ddof=1)),
                           mc_U95_relative=float(np.quantile(np.abs(rel), 0.95)),
                           coverage=float(np.mean(np.abs(rel) <= budget)))
            rows.append(row)
        return rows


def _figure_statistics(x: np.ndarray, scale: float) -> dict[str, float]:
    """Mean, std (n − 1), 2.5 % and 97.5 % quantiles of the reported values *x* (SI) in units of *scale*."""
    if x.size < 2:
        return dict.fromkeys(("mean", "std", "q025", "q975"), math.nan)
    q = np.quantile(x, [0.025, 0.975]) / scale
    return {"mean": float(x.mean() / scale), "std": float(np.std(x, ddof=1) / scale), "q025": float(q[0]),
            "q975": float(q[1])}


def _error_statistics(x: np.ndarray, t: np.ndarray, scale: float) -> dict[str, float]:
    """The mean true value, the error's mean and std (n − 1) and the 95 % quantile of |error|, units of *scale*."""
    if x.size < 2:
        return {"truth": float(np.mean(t) / scale) if t.size else math.nan,
                **dict.fromkeys(("mean_error", "std_error", "mc_U95"), math.nan)}
    err = (x - t) / scale
    return {"truth": float(t.mean() / scale), "mean_error": float(err.mean()), "std_error": float(np.std(err, ddof=1)),
            "mc_U95": float(np.quantile(np.abs(err), 0.95))}


def jjf1535_monte_carlo(scenario: Scenario, trials: int, seed: int, procedure: Jjf1535Procedure | None = None,
                        path: str = "auto", chunk_size: int = 256, keep_table: bool = False,
                        progress: ProgressCallback | None = None) -> Jjf1535MonteCarlo:
    """Simulate *trials* units of *scenario* through the JJF 1535 procedure and reduce each.

    Parameters
    ----------
    scenario : Scenario
        The unit, noise, effects and laboratory (its JJF 2003 schedule, turntable and acquisition are replaced by
        :func:`jjf1535_scenario`).
    trials, seed : int
        Number of trials (>= 2) and root seed (>= 0).
    procedure : Jjf1535Procedure, optional
        Default: :func:`~plansim.schedule.jjf1535.jjf1535_procedure` up to :data:`DEFAULT_MAXIMUM_RATE`.
    path : {"auto", "sample", "segment"}
        Simulation path (:func:`plansim.simulate.paths.choose_path`).
    chunk_size : int
        Trials per chunk (results do not depend on it: trial *i*'s random streams depend on the seed and *i* only).
    keep_table : bool
        Keep the scenario's turntable and acquisition (:func:`jjf1535_scenario`).
    progress : callable, optional
        ``progress(done, total)``, trials simulated and reduced, after each chunk (the threads simulate the next
        chunk while this one is reduced).
    """
    world, procedure = jjf1535_scenario(scenario, procedure, keep_table)
    trials = check_count("trials", trials, minimum=2)
    seed = check_count("seed", seed, minimum=0)
    kernel_world = without_jjf1535_effects(world)  # the kernels' part; the JJF 1535 effects are added to the means
    chosen, _reasons = choose_path(kernel_world, path)
    gravity = scenario.reduction.reference_gravity
    items = tuple(ITEMS)
    values = np.empty((trials, len(items)))
    true = np.empty((trials, len(items)))
    effects = bool(world.effects.jjf1535_effects_set())
    rates = input_axis_rates(world, procedure) if effects else None
    for start, stop, means, truth in iterate_chunks(kernel_world, trials, seed, chunk_size, chosen):
        for n in range(start, stop):
            session = means[n - start]
            if effects:
                session = apply_jjf1535_effects(session, truth[n - start], world, procedure, seed, n, rates)
            v = reduce_items(session, procedure, gravity)
            t = truth_of(world, procedure, truth[n - start])
            values[n] = [v[k] for k in items]
            true[n] = [t[k] for k in items]
        if progress is not None:
            progress(stop, trials)
    return Jjf1535MonteCarlo(scenario=world.name, trials=trials, seed=seed, path=chosen, items=items, values=values,
                             truth=true)

