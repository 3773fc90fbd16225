"""GUM uncertainty budgets derived from a scenario's schedule and estimators (JCGM 100:2008).

The law of propagation of uncertainty (JCGM 100 5.1.2, eq. (10); 5.2.2, eq. (13) for the correlated
drift) is applied to the *actual* data reduction of JJF 2003-2022 and the *actual* design: the
scenario's schedule, table and fixture errors, noise, drift and acquisition. The measurement model
of every parameter is

    Ŷ = R(m̄(X)),   E = Ŷ − Y,

where ``m̄`` are the segment means (eq. (3)) as functions of the input quantities ``X`` (the unit's
true parameters, every table and fixture error, the noise of each segment mean) and ``R`` is the
JJF 2003 reduction (eq. (4)-(13)), which is linear in the segment means, so its matrix
(:func:`plansim.uncertainty.sensitivities.estimator_matrix`, the estimators' own
:func:`plansim.estimate.reduction_matrix`) is obtained exactly by applying it to unit vectors. The output quantity
of each budget is the measurement error ``E`` of the parameter in SI: its estimate ``y`` is the
error at the expectation of the inputs (the sum of the systematic effects the specification's
estimators do not correct) and ``u_c(y)`` is the standard uncertainty of the calibrated value.

Input quantities (one budget line per group of independent components):

- **Table and fixture errors** (type B, JJF 2003 Table 1, §6.2): position accuracy and
  repeatability (per segment and axis), axis perpendicularity, platform tilt, fixture
  perpendicularity, systematic rate error, rate error per point. Drawn by the simulator from the
  scenario's distributions (``scenario.turntable.<error>``: a ± limit is rectangular, GUM 4.3.7;
  a stated uncertainty is normal, 4.3.3). Sensitivity coefficients by central finite differences
  of :func:`plansim.simulate.arguments.noise_free_segment_means` followed by the reduction, one
  component of the draws vector at a time with a step of its standard uncertainty (GUM 5.1.3
  note 2), around :func:`plansim.simulate.arguments.nominal_draws`. A group's contribution is
  ``sqrt(Σ (c_i u_i)²)`` over its independent components; its *group-equivalent* sensitivity is
  that contribution divided by the components' common ``u``.
- **Table start angle** of the rotating segments (type B, uniform on [0, 2π)). A segment that is
  not a whole number of turns does not average the Earth rate or a tilted gravity vector away. The
  output is a trigonometric polynomial of degree ≤ 3 in the start angle (see
  :mod:`plansim.kernels.segment_path`), so its variance is obtained exactly from
  :data:`~plansim.uncertainty.sensitivities.PHASE_NODES` equally spaced angles rather than
  linearised. Sensitivities of the other inputs are averaged over the same angles (the
  expectation of the linearised model).
- **Unit under calibration** (type B): the spread of the true parameters between units
  (``mimu.truth_spread``) enters only through the error's dependence on the true value
  (``∂E/∂Y = R·∂m̄/∂Y − 1``, zero for an exact estimator).
- **White noise** of every segment mean (type A, GUM 4.2): ``u = N/√T`` per channel (angle or
  velocity random walk ``N``, dwell ``T``), ``ν = n − 1`` from the ``n`` samples of the segment,
  propagated through the estimator matrix.
- **Drift** (type B: the Allan-variance coefficients of the scenario): the bias-instability and
  Gauss–Markov processes and the random walk, held over the drift update interval exactly as the
  simulator holds them. The covariance of all segment means is derived exactly from the state
  recursion (:func:`plansim.uncertainty.drift.drift_covariance`), including the settling gaps, and propagated with GUM
  5.2.2 (correlated inputs).
- **Quantisation** (type B): Appendix A's rectangular model, in the form that holds for a
  quantiser with Gaussian noise at its input (Widrow;
  :func:`plansim.uncertainty.quantisation.quantisation_variance`). Without
  noise (no dither) it is the rectangular ±q/2 of one reading, ``u = q/√12`` per segment mean
  (Appendix A eq. (A.3), A.1.2.2); with full dither each sample adds ``q²/12`` and the mean of
  ``n`` samples ``q²/(12 n)``; in between the part the noise does not average is given by the
  damped Fourier series of the sawtooth. Appendix A treats its readings as independent; the
  segments of one channel are not when they read the same or nearby codes without dither (they
  share the quantiser and the unknown offset of the channel), and
  :func:`~plansim.uncertainty.quantisation.quantisation_covariance`
  gives their covariance exactly (GUM 5.2.2); ``evaluate_gum(..., quantisation_correlation=False)``
  keeps Appendix A's independence.
- **Rate smoothness** (type B, Table 1): the per-sample rate jitter's segment mean, common to the
  channels of a segment, through the outputs' derivative with respect to the rate; the jitter also
  dithers the quantiser of the rotating segments.

Combined standard uncertainty ``u_c`` (5.1.2), effective degrees of freedom by the
Welch–Satterthwaite formula (G.4.1, eq. (G.2b)), coverage factor ``k`` from the
t-distribution (G.3.4, G.4.1; ν_eff not truncated, i.e. interpolated) and ``U = k·u_c`` (6.2.1).
Degrees of freedom of type B inputs given as limits are infinite (G.4.2: the limits are taken as
exactly known); a stated relative uncertainty of an uncertainty is not part of a scenario.

Systematic effects the specification's estimators do not correct (Earth rate, accelerometer lever
arm, the value of g used as reference, the ω² sign convention, temperature and sensor effects
outside eq. (1)/(2)) are reported per parameter as a **bias**, computed from the noise-free
segment means with and without the effect. GUM 3.2.3-3.2.4 asks that such effects be corrected;
plansim reports their size next to ``u_c`` instead of hiding them in it.

Module map: :mod:`~plansim.uncertainty.sensitivities` (the reduction's matrix, derivatives of the
segment means), :mod:`~plansim.uncertainty.budget_lines` (every input as a line),
:mod:`~plansim.uncertainty.drift`, :mod:`~plansim.uncertainty.quantisation`,
:mod:`~plansim.uncertainty.systematic`, :mod:`~plansim.uncertainty.budget` (the result objects);
the arithmetic of JCGM 100 is :mod:`plansim.uncertainty.metrology.propagation`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from plansim.config import Scenario
from plansim.model.parameters import N_PARAMETERS, PARAMETERS
from plansim.uncertainty.appendix_a import APPENDIX_A, AppendixABudget, reading_unit_in_si
from plansim.uncertainty.budget import (
    AppendixAView,
    GumEvaluation,
    GumUncertainties,
    InputContribution,
    ParameterBudget,
    SystematicEffect,
)
from plansim.uncertainty.budget_lines import Line, model_lines
from plansim.uncertainty.metrology.propagation import (
    DEFAULT_COVERAGE_PROBABILITY,
    check_coverage_probability,
    coverage_factors,
    welch_satterthwaite,
)
from plansim.uncertainty.sensitivities import estimator_matrix
from plansim.uncertainty.systematic import expected_error, systematic_effects

__all__ = ["NEGLIGIBLE", "evaluate_gum", "gum_uncertainties"]

#: Budget lines below this fraction of u_c are left out (10⁻¹² of the variance: numerical noise).
NEGLIGIBLE = 1e-6


def _appendix_view(budget: AppendixABudget, name: str, scenario: Scenario, per_category: tuple[float, float, float],
                   uc: float, U: float) -> AppendixAView:
    unit = float(reading_unit_in_si(budget, name, scenario))
    same = math.sqrt(sum(c.gum_standard_uncertainty**2 for c in budget.components))
    printed = tuple(budget.component(sym).printed_value for sym in ("u1", "u2", "u3"))
    return AppendixAView(
        item=budget.item, reading_unit_si=unit, printed_u=printed,
        printed_uc=budget.printed_combined_standard_uncertainty, printed_U=budget.printed_expanded_uncertainty,
        same_inputs_gum_uc=same, same_inputs_gum_U=budget.coverage_factor * same,
        plansim_u=tuple(x / unit for x in per_category), plansim_uc=uc / unit, plansim_U95=U / unit)


def _propagate(scenario: Scenario, coverage_probability: float, quantisation_correlation: bool,
               relative_uncertainty_of_u: Mapping[str, float] | None, describe: bool
               ) -> tuple[list[Line], np.ndarray, np.ndarray]:
    """The budget lines of *scenario* (with the ν the user states), the covariance of the 39 errors
    (GUM 5.2.2) and the expected segment means (:func:`~plansim.uncertainty.budget_lines.model_lines`)."""
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    check_coverage_probability(coverage_probability)
    matrix = estimator_matrix(scenario)
    if not isinstance(quantisation_correlation, bool):
        raise TypeError(f"quantisation_correlation = {quantisation_correlation!r}: expected True or False")
    lines, expected_means = model_lines(scenario, matrix, quantisation_correlation, describe)
    if relative_uncertainty_of_u:
        if not isinstance(relative_uncertainty_of_u, Mapping):
            raise TypeError(f"relative_uncertainty_of_u = {relative_uncertainty_of_u!r}: expected a mapping of "
                            "budget-line name -> relative uncertainty of its u")
        by_name = {line.name: line for line in lines}
        for name, r in relative_uncertainty_of_u.items():
            if name not in by_name:
                raise ValueError(f"relative_uncertainty_of_u: no input {name!r} in this scenario's budget; "
                                 f"inputs: {', '.join(map(repr, by_name))}")
            if isinstance(r, bool) or not isinstance(r, (int, float)) or not (math.isfinite(r) and r > 0):
                raise ValueError(f"relative_uncertainty_of_u[{name!r}] = {r!r}: must be a number > 0")
            line = by_name[name]
            if line.evaluation != "B":
                raise ValueError(f"relative_uncertainty_of_u[{name!r}]: a type A input has its degrees of freedom "
                                 "from its sample count (GUM G.3.3); G.4.2 applies to type B inputs")
            nu = 0.5 / r**2
            if line.columns is not None:
                line.dof = np.full(line.columns.shape[1], nu)
            else:
                line.line_dof = nu
    covariance = np.zeros((N_PARAMETERS, N_PARAMETERS))
    for line in lines:
        covariance += line.cov()
    covariance = 0.5 * (covariance + covariance.T)
    return lines, covariance, expected_means


def _effective_dof(lines: list[Line], variances: list[np.ndarray], uc: np.ndarray) -> np.ndarray:
    """ν_eff (39,) (or one per output of the lines) by the Welch–Satterthwaite formula (JCGM 100 G.4.1, eq. (G.2b)).

    Over every independent component with a finite ν of the lines that count for a parameter (a
    contribution above :data:`NEGLIGIBLE`·u_c): each column of a line with per-component ν, or the
    whole line with its ``line_dof``; ``inf`` where no such component is left or u_c is 0.
    """
    denominator = np.zeros(uc.shape)
    for line, variance in zip(lines, variances):
        if line.columns is not None and line.dof is not None:
            contribution = np.sqrt(variance)
            finite = np.isfinite(line.dof)
            terms = np.sum(np.abs(line.columns[:, finite]) ** 4 / line.dof[finite], axis=1)
        elif math.isfinite(line.line_dof):
            contribution = np.sqrt(variance)
            terms = contribution**4 / line.line_dof
        else:
            continue  # ν = ∞: no term
        counts = (contribution > NEGLIGIBLE * uc) & (contribution != 0.0)  # below: the differences' numerical noise
        denominator += np.where(counts, terms, 0.0)
    finite = (denominator > 0) & (uc > 0)
    return np.divide(uc**4, denominator, out=np.full(uc.shape, math.inf), where=finite)


def gum_uncertainties(scenario: Scenario, coverage_probability: float = DEFAULT_COVERAGE_PROBABILITY,
                      quantisation_correlation: bool = True) -> GumUncertainties:
    """The figures of :func:`evaluate_gum` without the budgets behind them: ``y``, ``u_c``, ``ν_eff``, ``k``, ``U``.

    The same lines, covariance and arithmetic as :func:`evaluate_gum`, so the same numbers (to
    rounding, 1e-15: the table lines' columns by one BLAS product, ``model_lines(describe=False)``),
    without what only a budget shows (each line per parameter, the systematic effects one by one,
    the Appendix A view, the second-order terms), which cost more than the figures themselves: for
    :func:`plansim.planning.predict.predict` and what calls it once per schedule.

    Parameters
    ----------
    scenario : Scenario
        The scenario (schedule, table, noise, acquisition, reduction).
    coverage_probability : float
        ``p`` of the expanded uncertainties (default 0.95).
    quantisation_correlation : bool
        As for :func:`evaluate_gum`.

    Returns
    -------
    GumUncertainties
    """
    lines, covariance, expected_means = _propagate(scenario, coverage_probability, quantisation_correlation, None,
                                                   describe=False)
    uc = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    dof = _effective_dof(lines, [line.variance() for line in lines], uc)
    k = coverage_factors(dof, coverage_probability)
    return GumUncertainties(scenario=scenario.name, estimate=expected_error(scenario, expected_means),
                            standard_uncertainty=uc, effective_dof=dof, coverage_factor=k, expanded_uncertainty=k * uc,
                            covariance=covariance, coverage_probability=coverage_probability)


def evaluate_gum(scenario: Scenario, coverage_probability: float = DEFAULT_COVERAGE_PROBABILITY,
                 quantisation_correlation: bool = True,
                 relative_uncertainty_of_u: Mapping[str, float] | None = None) -> GumEvaluation:
    """GUM budgets of every JJF 2003 parameter for *scenario* (module docstring).

    Parameters
    ----------
    scenario : Scenario
        The scenario (schedule, table, noise, acquisition, reduction).
    coverage_probability : float
        ``p`` of the expanded uncertainties (default 0.95).
    quantisation_correlation : bool
        Correlate the quantisation errors of the segments of a channel through the quantiser's
        shared offset (:func:`plansim.uncertainty.quantisation.quantisation_covariance`, default);
        ``False`` treats every segment mean as an independent rectangular input, as Appendix A
        treats its readings.
    relative_uncertainty_of_u : mapping of input name -> float, optional
        For type B inputs whose standard uncertainty is itself uncertain: the relative
        uncertainty ``Δu/u`` the user states, giving ``ν = ½ (Δu/u)⁻²`` (GUM G.4.2, eq. (G.3)) for
        each component of that budget line (e.g. ``{"rate error, systematic": 0.25}`` gives ν = 8).
        Inputs not named keep ``ν = ∞`` (a ± limit taken as exactly known).

    Returns
    -------
    GumEvaluation
        Per-parameter budgets (inputs, ``u_c``, ``ν_eff``, ``k``, ``U``, uncorrected systematic
        effects, the Appendix A figure) and the covariance of the 39 errors. Only the figures:
        :func:`gum_uncertainties`.
    """
    lines, covariance, expected_means = _propagate(scenario, coverage_probability, quantisation_correlation,
                                                   relative_uncertainty_of_u, describe=True)
    total, effects = systematic_effects(scenario, expected_means)
    appendix = {name: b for b in APPENDIX_A for name in b.parameters}

    budgets = []
    variances = [line.variance() for line in lines]
    ucs = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    dofs = _effective_dof(lines, variances, ucs)
    ks = coverage_factors(dofs, coverage_probability)
    for p, spec in enumerate(PARAMETERS):
        entries = []
        second = 0.0
        uc = float(ucs[p])
        for line, variance in zip(lines, variances):
            contribution = math.sqrt(float(variance[p]))
            if contribution <= NEGLIGIBLE * uc or contribution == 0.0:
                continue  # below the numerical noise of the finite differences
            if line.columns is not None and line.dof is not None:
                group_dof = welch_satterthwaite(line.columns[p], line.dof)
            else:
                group_dof = line.line_dof
            if line.second_order is not None:
                second = max(second, float(line.second_order[p]))
            u_rms = float(np.sqrt(np.mean(line.u**2))) if line.u.size else math.nan
            if line.mixed_units:
                u_rms = sensitivity = math.nan
            elif line.columns is not None and np.count_nonzero(line.columns[p]) == 1:
                k = int(np.flatnonzero(line.columns[p])[0])
                u_rms = float(line.u[k])
                sensitivity = float(line.columns[p, k] / line.u[k])
            elif line.linearised and u_rms > 0:
                sensitivity = contribution / u_rms
            else:
                sensitivity = math.nan
            entries.append(InputContribution(
                name=line.name, category=line.category, evaluation=line.evaluation,
                distribution=line.distribution,
                standard_uncertainty=u_rms if line.linearised else math.nan,
                input_unit=line.input_unit, sensitivity=sensitivity, contribution=contribution,
                dof=group_dof, components=int(line.u.size), note=line.note))
        entries.sort(key=lambda e: -e.contribution)
        dof = float(dofs[p])
        k = float(ks[p])
        U = k * uc
        found = tuple(SystematicEffect(name, float(bias[p]), note) for name, bias, note in effects if bias[p] != 0.0)
        view = None
        if spec.name in appendix:
            budget = appendix[spec.name]
            per_category = tuple(math.sqrt(sum(e.contribution**2 for e in entries if e.category == cat))
                                 for cat in ("table", "acquisition", "repeatability"))
            view = _appendix_view(budget, spec.name, scenario, per_category, uc, U)
        budgets.append(ParameterBudget(
            name=spec.name, unit=spec.si_unit, truth=float(scenario.truth_nominal[p]), estimate=float(total[p]),
            inputs=tuple(entries), combined_standard_uncertainty=uc, effective_dof=dof, coverage_factor=k,
            expanded_uncertainty=U, coverage_probability=coverage_probability, systematic_effects=found,
            largest_second_order=second, appendix_a=view))
    return GumEvaluation(scenario=scenario.name, budgets=tuple(budgets), covariance=covariance,
                         coverage_probability=coverage_probability)
