"""The lines of the GUM budget of a schedule: every input quantity, propagated to all 39 parameters at once.

Each :class:`Line` holds either the signed contributions ``c_i·u(x_i)`` of independent components
(JCGM 100 5.1.2, eq. (10)) or, for correlated inputs, the covariance they give the parameters
(5.2.2, eq. (13)). :func:`model_lines` builds them from the scenario: table and fixture errors
(JJF 2003 Table 1) by finite differences, the table start angle exactly, the unit-to-unit spread,
white noise (type A, 4.2), drift (Allan coefficients), rate smoothness, and quantisation
(Appendix A eq. (A.3), with the averaging and correlation of segment means).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.config import ErrorDistribution, Scenario
from plansim.kernels.layout import ACCEL_CHANNELS, GYRO_CHANNELS, N_CHANNELS, NOISE_WHITE
from plansim.simulate.arguments import kernel_arguments
from plansim.uncertainty.drift import drift_covariance
from plansim.uncertainty.quantisation import quantisation_covariance, quantisation_variance
from plansim.uncertainty.sensitivities import (
    PHASE_NODES,
    rate_derivatives,
    segment_mean_derivatives,
    table_groups,
)

__all__ = ["Line", "model_lines"]

_GYROS = range(GYRO_CHANNELS.start, GYRO_CHANNELS.stop)
_ACCELS = range(ACCEL_CHANNELS.start, ACCEL_CHANNELS.stop)


@dataclass
class Line:
    """A budget line for all parameters at once: columns of signed contributions (39, K) or a covariance."""

    name: str
    category: str
    evaluation: str
    distribution: str
    u: np.ndarray  # (K,) standard uncertainty of each component, or empty for covariance lines
    input_unit: str
    columns: np.ndarray | None = None  # (39, K): c_i·u_i
    covariance: np.ndarray | None = None  # (39, 39) for lines that are not a sum of independent columns
    dof: np.ndarray | None = None  # (K,) for type A lines
    note: str = ""
    linearised: bool = True
    second_order: np.ndarray | None = None  # (39,) largest ½|c_ii|u² of the line
    mixed_units: bool = False  # components in different units: no single u(x_i) or c_i to show
    line_dof: float = math.inf  # ν of a covariance line taken as one input (G.4.2 for type B)

    def variance(self) -> np.ndarray:
        if self.columns is not None:
            return np.sum(self.columns**2, axis=1)
        return np.clip(np.diag(self.covariance), 0.0, None)

    def cov(self) -> np.ndarray:
        if self.columns is not None:
            return self.columns @ self.columns.T
        return self.covariance


def _distribution_text(error: ErrorDistribution, unit: str) -> str:
    shown = "" if unit == "1" else f" {unit}"
    if error.kind == "uniform":
        return f"rectangular ±{error.scale:.4g}{shown}"
    return f"normal, σ = {error.scale:.4g}{shown}"


def _through_reduction(matrix: np.ndarray, d_means: np.ndarray, exact_zeros: bool) -> np.ndarray:
    """(39, K): the parameters' response ``R·Δm̄_k`` to each component's change of the means *d_means* (K, S, 6).

    *exact_zeros*: by ``einsum``, which leaves an exact zero where the reduction cancels a component
    (the two halves of a symmetric pair of positions), so that a budget shows that component's own
    signed sensitivity; otherwise by one BLAS product, six times faster, the same to rounding (a
    residue of 1e-17 of the line instead of such zeros).
    """
    if exact_zeros:
        return np.einsum("psc,ksc->pk", matrix, d_means)
    return matrix.reshape(len(matrix), -1) @ d_means.reshape(len(d_means), matrix[0].size).T


def _gram(d_means: np.ndarray) -> np.ndarray:
    """(6, S, S): ``Dᵀ·D`` per channel of the means' changes *d_means* (K, S, 6), ``D = d_means[:, :, c]``.

    One stacked product of the channels' contiguous copies: each channel's the same BLAS product, so the
    same numbers, as the six 2-D products ``d_means[:, :, c].T @ d_means[:, :, c]``.
    """
    return np.ascontiguousarray(d_means.transpose(2, 1, 0)) @ np.ascontiguousarray(d_means.transpose(2, 0, 1))


def _largest_second_order(matrix: np.ndarray, second: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(39,): the largest ``½|∂²E/∂x_k²|·u_k²`` over the components k (*second*: (K, S, 6) ``∂²m̄/∂x_k²``)."""
    return np.max(0.5 * np.abs(np.einsum("psc,ksc->pk", matrix, second)) * u[None, :] ** 2, axis=1)


def model_lines(scenario: Scenario, matrix: np.ndarray, quantisation_correlation: bool, describe: bool = True,
                truth_jacobian: np.ndarray | None = None) -> tuple[list[Line], np.ndarray]:
    """Every budget line of *scenario*, for all 39 parameters (or the P outputs of *matrix*) at once, and the
    expected segment means.

    Parameters
    ----------
    scenario : Scenario
    matrix : (39, S, 6) ndarray
        The reduction's matrix (:func:`plansim.uncertainty.sensitivities.estimator_matrix`); or, with
        *truth_jacobian*, the (P, S, 6) linearised reduction of P other outputs (the JJF 1535 items,
        :mod:`plansim.uncertainty.jjf1535_gum`).
    quantisation_correlation : bool
        Correlate the quantisation errors of the segments of a channel
        (:func:`plansim.uncertainty.quantisation.quantisation_covariance`), or keep Appendix A's
        independent readings.
    describe : bool
        Also what only a budget shows: the largest second-order term of each linearised line
        (``Line.second_order``), the quantiser's dither regime in the distribution of its line, and
        exact zeros where the reduction cancels a component (:func:`_through_reduction`). ``False``
        leaves them out (``None``; the distribution without the regime; columns the same to
        rounding): the prediction (:func:`plansim.uncertainty.gum.gum_uncertainties`) needs none of them.
    truth_jacobian : (P, 39) ndarray, optional
        ``∂(true value of output p)/∂(parameter)`` of the unit, for the unit-to-unit spread line's
        ``∂E/∂Y = R·∂m̄/∂Y − ∂t/∂Y``; default the identity (output p is parameter p).

    Returns
    -------
    lines : list of Line
        In the order table and fixture errors, start angle, unit-to-unit spread, white noise, drift,
        rate smoothness, quantisation.
    expected_means : (S, 6) ndarray
        The noise-free segment means at the expectation of the inputs (nominal draws), averaged over
        the table start angle: the linearisation point, whose reduction is the predicted bias
        (:func:`plansim.uncertainty.systematic.expected_error`).
    """
    lines: list[Line] = []
    n_out = len(matrix)  # outputs: the 39 parameters, or the rows of another reduction
    segments = scenario.schedule.segments
    n_seg = len(segments)
    arguments = kernel_arguments(scenario)
    samples = arguments["seg_n"].astype(float)
    durations = samples / np.array([s.sample_rate for s in segments])  # s.samples / s.sample_rate
    dts = arguments["seg_dt"]  # 1 / s.sample_rate
    noise = arguments["noise"]  # (6, 4), columns plansim.kernels.layout.NOISE_COLUMNS
    offsets = np.zeros((N_CHANNELS, n_seg, n_seg))  # per channel: covariance of the means' offsets
    with_offsets = bool(scenario.acquisition.bits) and quantisation_correlation  # what they are for

    # every finite difference at once (table and fixture errors, then the unit's spread): one kernel call
    groups = table_groups(scenario)
    spread = np.asarray(scenario.truth_spread, dtype=float)
    idx = np.flatnonzero(spread > 0)
    indices = np.concatenate([np.array(g[2], dtype=np.int64) for g in groups] + [idx])
    steps = np.concatenate([np.full(len(g[2]), g[1].standard_uncertainty) for g in groups] + [spread[idx]])
    # only where the reduction reads a mean (the matrix is not zero): the derivatives elsewhere only ever meet
    # the matrix's zeros (the columns, the start-angle line) or pairs of quantisation errors no estimate reads
    needed = np.any(matrix != 0.0, axis=0)
    nominal, first_all, second_all = segment_mean_derivatives(scenario, indices, steps, arguments,
                                                              needed)  # (J, S, 6), (K, S, 6), (K, S, 6)
    n_table = len(indices) - idx.size
    d_means_all = first_all * steps[:, None, None]  # (K, S, 6): what a step u of each component does to the means
    columns_all = None if describe else _through_reduction(matrix, d_means_all, exact_zeros=False)

    # table and fixture errors: finite differences of the noise-free means
    start = 0
    for name, error, idx_g, unit in groups:
        stop = start + len(idx_g)
        u = steps[start:stop]
        d_means = d_means_all[start:stop]
        # the means' offsets (for the quantiser: its damping is their variance's small difference
        # Var(Δ) = g_ss + g_tt − 2g_st, so summed group by group, in this order)
        if with_offsets:
            offsets += _gram(d_means)
        lines.append(Line(
            name=name, category="table", evaluation="B", distribution=_distribution_text(error, unit),
            u=u, input_unit=unit,
            columns=_through_reduction(matrix, d_means, True) if describe else columns_all[:, start:stop],
            note="c by central differences of the noise-free segment means, step u(x)",
            second_order=_largest_second_order(matrix, second_all[start:stop], u) if describe else None))
        start = stop

    # table start angle of the rotating segments: exact variance over the angle
    rotating = [s for s, seg in enumerate(segments) if seg.rate != 0.0]
    if rotating:
        centre = nominal.mean(axis=0)
        deviation = nominal - centre
        # below 64 ulp of the mean the deviation is rounding, not a start-angle effect
        deviation[np.abs(deviation) <= 64 * np.finfo(float).eps * np.abs(centre)[None]] = 0.0
        d = np.einsum("psc,jsc->sjp", matrix[:, rotating, :], deviation[:, rotating, :])  # (R, J, 39) per angle
        d = d.reshape(-1, n_out)
        cov = d.T @ d / PHASE_NODES  # Σ over the rotating segments of the variance over the angle
        # the variance over the angle of each rotating segment's mean, per channel (the angle last: the
        # same pairwise sum as the mean of each segment and channel alone)
        squares = np.mean(np.ascontiguousarray(np.moveaxis(deviation[:, rotating, :] ** 2, 0, -1)), axis=-1)
        diagonal = np.array(rotating)
        offsets[:, diagonal, diagonal] += squares.T
        if np.any(np.diag(cov) > 0):
            lines.append(Line(
                name="table start angle", category="table", evaluation="B",
                distribution="uniform on [0, 2π) per rotating segment",
                u=np.full(len(rotating), math.pi / math.sqrt(3)),
                input_unit="rad", covariance=cov, linearised=False,
                note=f"exact variance over {PHASE_NODES} start angles (segments not whole turns)"))
    nominal = nominal.mean(axis=0)  # (S, 6): expected noise-free means

    # the unit under calibration: dependence of the error on the true parameters
    if idx.size:
        d_means = d_means_all[n_table:]
        if with_offsets:
            offsets += _gram(d_means)
        columns = _through_reduction(matrix, d_means, True) if describe else columns_all[:, n_table:].copy()
        if truth_jacobian is None:
            columns[idx, np.arange(idx.size)] -= spread[idx]  # E = Ŷ − Y
        else:
            columns -= truth_jacobian[:, idx] * spread[idx]  # E = Ŷ − Y(truth)
        lines.append(Line(
            name="unit-to-unit spread", category="unit", evaluation="B", distribution="normal (mimu.truth_spread)",
            u=spread[idx], input_unit="SI of each parameter", columns=columns, mixed_units=True,
            note="∂E/∂Y = R·∂m/∂Y − ∂Y/∂truth: the error's dependence on the true value",
            second_order=_largest_second_order(matrix, second_all[n_table:], spread[idx]) if describe else None))

    # white noise of the segment means (type A, ν = n − 1)
    for label, channels in (("white noise, gyros", _GYROS), ("white noise, accelerometers", _ACCELS)):
        u = noise[channels, NOISE_WHITE][None, :] / np.sqrt(durations)[:, None]  # (S, 3)
        if not np.any(u > 0):
            continue
        columns = (matrix[:, :, channels] * u[None]).reshape(n_out, -1)  # component (s, channel), s-major
        dof = np.repeat(samples - 1.0, len(channels))
        dof = np.where(dof > 0, dof, np.inf)
        unit = "rad/s" if label.endswith("gyros") else "m/s^2"
        lines.append(Line(
            name=label, category="repeatability", evaluation="A", distribution="normal, N/√T per segment mean",
            u=u.ravel(), input_unit=unit, columns=columns, dof=dof,
            note="u = N/√T (random-walk coefficient N, dwell T); ν = n − 1 samples"))

    # drift: exact covariance of the segment means
    drift = drift_covariance(scenario, arguments)
    offsets += drift
    for label, channels in (("drift, gyros", _GYROS), ("drift, accelerometers", _ACCELS)):
        cov = np.zeros((n_out, n_out))
        for c in channels:
            if np.any(drift[c] != 0):
                cov += matrix[:, :, c] @ drift[c] @ matrix[:, :, c].T
        if np.any(np.diag(cov) > 0):
            lines.append(Line(
                name=label, category="repeatability", evaluation="B",
                distribution="Gauss–Markov / random walk (Allan coefficients)",
                u=np.sqrt(np.array([drift[c].diagonal().mean() for c in channels])),
                input_unit="rad/s" if label.endswith("gyros") else "m/s^2", covariance=cov, linearised=True,
                note="covariance of the segment means derived from the drift model (GUM 5.2.2)"))

    # rate smoothness: jitter of the table rate, common to the channels of a segment
    smoothness = scenario.turntable.rate_smoothness
    jitter = np.zeros((n_seg, N_CHANNELS))
    if smoothness > 0 and rotating:
        # (without describe, only where the reduction reads a mean: elsewhere the jitter only reaches the
        # quantisation errors of means no estimate reads, and the lines' u, which describe alone shows)
        derivative = rate_derivatives(scenario, arguments, None if describe else needed)
        jitter = smoothness * derivative
        u = np.array([smoothness / math.sqrt(samples[s]) for s in rotating])
        columns = np.einsum("psc,sc->ps", matrix[:, rotating, :], derivative[rotating]) * u
        lines.append(Line(
            name="rate smoothness", category="table", evaluation="B", distribution="normal, per sample",
            u=u, input_unit="1", columns=columns,
            note="segment mean of the per-sample relative rate jitter, through ∂(outputs)/∂(rate)"))

    # quantisation (Appendix A's rectangular model, with the averaging the noise provides)
    a = scenario.acquisition
    if a.bits:
        for label, channels, step in (("quantisation, gyros", _GYROS, a.gyro_step),
                                      ("quantisation, accelerometers", _ACCELS, a.accel_step)):
            cov = np.zeros((n_out, n_out))
            sigmas = np.array([np.sqrt(noise[c, NOISE_WHITE] ** 2 / dts + jitter[:, c] ** 2) for c in channels])
            if quantisation_correlation:  # the three channels of the kind at once
                # the pairs no estimate reads (a segment the matrix does not read) only meet its zeros
                q_covs = quantisation_covariance(step, nominal[:, channels].T, sigmas, samples,
                                                 offsets[channels.start:channels.stop], needed[:, channels].T)
            else:
                q_covs = [np.diag([quantisation_variance(step, float(sigma[s]), int(samples[s]))[0]
                                   for s in range(n_seg)]) for sigma in sigmas]
            u_means = []
            for c, q_cov in zip(channels, q_covs):
                cov += matrix[:, :, c] @ q_cov @ matrix[:, :, c].T
                u_means.extend(np.sqrt(np.diag(q_cov)))
            distribution = f"rectangular, q = {step:.4g}"
            if describe:  # the undithered fraction depends on σ alone: once per distinct σ
                worst = max(quantisation_variance(step, float(x), 1)[1] for x in np.unique(sigmas))
                distribution += "; " + ("no dither: rectangular ±q/2 per segment mean" if worst > 1.0 - 1e-6 else
                                        "dithered: q²/12 per sample, averaged" if worst < 1e-6 else
                                        f"partly dithered: up to {worst:.2g} of q²/12 not averaged by the noise")
            correlation = ("segments correlated through the shared quantiser offset" if quantisation_correlation
                           else "segment means independent (Appendix A)")
            lines.append(Line(
                name=label, category="acquisition", evaluation="B",
                distribution=distribution,
                u=np.asarray(u_means), input_unit="rad/s" if label.endswith("gyros") else "m/s^2", covariance=cov,
                note=f"Appendix A eq. (A.3); {correlation}"))
    return lines, nominal
