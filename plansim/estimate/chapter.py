"""The textbook procedures of "IMU error analysis and calibration" (chapter 6, §6.1–§6.2), reduced from segment means.

The chapter writes the output of each instrument as a scale-factor term, linear-acceleration terms,
angular-rate terms, a time drift and a random error (its eq. (6-1)–(6-3)), and calibrates them with
procedures that differ from JJF 2003's. Each function here reduces one of them from what a laboratory
has (segment means, the nominal poses), in SI, and its docstring says which parameters of plansim's
model (JJF 2003 eq. (1)/(2): ``Kg, Bg, G, Ka, Ba, P``, :mod:`plansim.model.parameters`) it estimates.

==================================================  ===========================================
chapter                                             function
==================================================  ===========================================
eq. (6-8): misalignment from ± rate turns           :func:`rate_misalignment`, :func:`rate_misalignments`
eq. (6-9): accelerometer up/down test (K0, K1)      :func:`up_down`
8-position test: accelerometer cross-axis terms     :func:`eight_position_fit`
drift model D0 + D1·a_X + D2·a_Y + D3·a_Z           :func:`drift_model_fit`, :func:`drift_model`
eq. (6-6): random drift quoted as 2.7σ              :func:`random_drift`
§6.2 1 (2): the Earth rate as reference input       :data:`CHAPTER_EARTH_RATE`, :func:`earth_rate_inputs`
both: cross-coupling relative to the scale factor   :func:`cross_axis_ratios`
==================================================  ===========================================

Channels are ordered ``gx, gy, gz, ax, ay, az`` (rad/s, m/s²), as everywhere in plansim.
"""

from __future__ import annotations

import math

import numpy as np

from plansim.estimate.jjf1535 import checked_array
from plansim.model.environment import EARTH_RATE, earth_rate_enu
from plansim.schedule.chapter import FULL_TURN
from plansim.schedule.segments import Schedule, Segment, axis_vector, body_to_level
from plansim.units import DEG, HOUR

#: §6.2 1 (2): the Earth rate the chapter takes as the reference angular input, 15.04107 °/h, in rad/s. (The
#: chapter's sidereal day, 23 h 59 min 57.33 s, is a slip: 360°/15.04107 °/h is 23 h 56 min 4.09 s.) It
#: differs from plansim's :data:`plansim.model.environment.EARTH_RATE` by 2.4e-7 relative.
CHAPTER_EARTH_RATE = 15.04107 * DEG / HOUR
#: eq. (6-6): the random drift rate is quoted as 2.7 standard deviations of the repeated drift
RANDOM_DRIFT_FACTOR = 2.7

GYRO = slice(0, 3)
ACCEL = slice(3, 6)


# ----------------------------------------------------------------------------- helpers on segments


def _segments(segments) -> tuple[Segment, ...]:
    if isinstance(segments, Schedule):
        return segments.segments
    out = tuple(segments)
    if not all(isinstance(s, Segment) for s in out):
        raise TypeError(f"segments: expected a Schedule or a sequence of Segment, got {segments!r:.120}")
    return out


def _means(means, segments: tuple[Segment, ...]) -> np.ndarray:
    means = np.asarray(means, dtype=float)
    if means.ndim < 2 or means.shape[-2:] != (len(segments), 6):
        raise ValueError(f"means: expected shape (..., {len(segments)}, 6) (one row of six channel means per "
                         f"segment), got {means.shape}")
    return means


def _indices(segments: tuple[Segment, ...], indices, test: str) -> list[int]:
    if indices is None:
        return [k for k, s in enumerate(segments) if s.test == test]
    chosen = [int(k) for k in indices]
    for k in chosen:
        if not 0 <= k < len(segments):
            raise ValueError(f"indices: {k} is not a segment index (0 to {len(segments) - 1})")
        if segments[k].is_rotating:
            raise ValueError(f"indices: segment {segments[k].label!r} turns (rate {segments[k].rate!r} rad/s); "
                             "a position test uses segments at rest")
    return chosen


def cross_axis_ratios(matrix) -> np.ndarray:
    """The chapter's cross-coupling terms relative to the scale factor: ``R[i, j] = K[i, j]/K[i, i]``, diagonal 0.

    The chapter names them by input then output axis over the output's scale factor — ``E_yx/E_x`` is the X
    gyro's response to a rate about Y, ``K_yx/K_x`` the X accelerometer's to an acceleration along Y — which
    in plansim's row = output, column = input convention is ``Kg[x, y]/Kg[x, x]`` and ``Ka[x, y]/Ka[x, x]``.

    Parameters
    ----------
    matrix : (..., 3, 3) array
        ``Kg`` or ``Ka`` (true or estimated).
    """
    m = np.asarray(matrix, dtype=float)
    if m.shape[-2:] != (3, 3):
        raise ValueError(f"matrix: expected shape (..., 3, 3), got {m.shape}")
    diagonal = np.diagonal(m, axis1=-2, axis2=-1)
    if np.any(diagonal == 0):
        raise ValueError("matrix: a scale factor (diagonal element) is 0; the ratios K[i, j]/K[i, i] need it")
    out = m / diagonal[..., :, None]
    out[..., [0, 1, 2], [0, 1, 2]] = 0.0
    return out


# ----------------------------------------------------------------------------- eq. (6-8): ± rate misalignment


def rate_misalignment(output_plus, output_minus, scale_factor, angle: float = FULL_TURN) -> np.ndarray:
    """Eq. (6-8): ``E_ab = (E_b1 − E_b2)/(2·M·E_1b)``, the misalignment of gyro *b* to a rate about axis *a*.

    With axis *a* up on the rate table, the table turns through the angle M at +Ω, then through M at
    −Ω; ``E_b1`` and ``E_b2`` are gyro *b*'s outputs integrated over those turns (output × s), and ``E_1b``
    is gyro *b*'s scale factor. The chapter turns one turn, M = 360°, at ±10 °/s.

    In plansim's model (JJF 2003 eq. (1)), gyro *b* integrates ``Kg[b, a]·(±M)`` from the table rate, plus
    the same bias, g-sensitivity and vertical Earth-rate terms in both turns (they cancel in the difference),
    plus the horizontal Earth rate and any horizontal g, which turn with the table and integrate to zero
    over whole turns. So ``(E_b1 − E_b2)/(2M) = Kg[b, a]`` and, with ``E_1b = Kg[b, b]``,
    ``E_ab = Kg[b, a]/Kg[b, b]`` (:func:`cross_axis_ratios`).

    Parameters
    ----------
    output_plus, output_minus : array
        E_b1 and E_b2: the integrated outputs over the + and the − turns (for a digital gyro reading rad/s,
        in rad; in general the gyro's output unit × s).
    scale_factor : array
        E_1b, the gyro's scale factor (output unit per rad/s; dimensionless for plansim's gyros).
    angle : float
        M, the angle turned in each direction, rad (default one turn, 2π).

    Returns
    -------
    array
        E_ab, dimensionless (rad of misalignment), broadcast over the inputs.
    """
    plus = checked_array("output_plus", output_plus)
    minus = checked_array("output_minus", output_minus)
    scale = checked_array("scale_factor", scale_factor)
    if isinstance(angle, bool) or not isinstance(angle, (int, float)) or not (math.isfinite(angle) and angle > 0):
        raise ValueError(f"angle = {angle!r} rad; it must be finite and > 0 (one turn is 2π)")
    if np.any(scale == 0):
        raise ValueError(f"scale_factor = {scale_factor!r}; it must not be 0")
    return (plus - minus) / (2.0 * angle * scale)


def rate_misalignments(means, segments, scale_factors) -> np.ndarray:
    """Eq. (6-8) for every axis turned: the six misalignments of the three gyros, from a schedule's turns.

    Uses the ``"rotation"`` segments (:func:`plansim.schedule.chapter.rate_turns`): ``group`` = the axis
    turned, on the vertical table axis. For each axis *a*, the + and − turns (by the sign of ``angle``)
    must have the same number of segments, every one the same |angle| M and the same recording time;
    each segment's integrated output is its mean × its recording time (samples / sample rate), and runs in
    one direction are averaged.

    Parameters
    ----------
    means : (..., S, 6) array
        Mean output of every segment of *segments*.
    segments : Schedule or sequence of Segment
        The nominal schedule.
    scale_factors : (..., 3) array
        E_1x, E_1y, E_1z: the gyros' scale factors (e.g. ``diag(Kg)`` from JJF 2003 §7.2.1, or eq. (6-7)).

    Returns
    -------
    (..., 3, 3) array
        ``R[..., b, a] = E_ab`` ≈ ``Kg[b, a]/Kg[b, b]`` (row = gyro, column = axis turned, as ``Kg``), diagonal
        0, NaN in the column of an axis that was not turned.
    """
    segments = _segments(segments)
    means = _means(means, segments)
    scale = checked_array("scale_factors", scale_factors)
    if scale.shape[-1:] != (3,):
        raise ValueError(f"scale_factors: expected shape (..., 3), got {scale.shape}")
    turns = [k for k, s in enumerate(segments) if s.test == "rotation"]
    if not turns:
        raise ValueError("segments: no 'rotation' segment; eq. (6-8) needs a + and a − turn about an axis "
                         "(plansim.schedule.chapter.rate_turns)")
    lead = np.broadcast_shapes(means.shape[:-2], scale.shape[:-1])
    out = np.full(lead + (3, 3), np.nan)
    for a in range(3):
        mine = [k for k in turns if segments[k].group == a]
        if not mine:
            continue
        for k in mine:
            s = segments[k]
            if not s.angle_known or s.rate_axis != f"+{'xyz'[a]}" or s.up != s.rate_axis:
                raise ValueError(f"segment {s.label!r}: a turn of eq. (6-8) about {'xyz'[a]} (group {a}) has "
                                 f"+{'xyz'[a]} up, turns about it and gives its angle; got up = {s.up!r}, "
                                 f"rate_axis = {s.rate_axis!r}, angle = {s.angle!r}")
        plus = [k for k in mine if segments[k].angle > 0]
        minus = [k for k in mine if segments[k].angle < 0]
        angles = {abs(segments[k].angle) for k in mine}
        times = {segments[k].samples / segments[k].sample_rate for k in mine}
        if not plus or len(plus) != len(minus) or len(angles) != 1 or len(times) != 1:
            raise ValueError(f"segments: the turns about {'xyz'[a]} must pair + and − runs of one angle and one "
                             f"recording time; got {len(plus)} + and {len(minus)} − runs, angles "
                             f"{sorted(angles)} rad, times {sorted(times)} s")
        duration = times.pop()
        e_plus = means[..., plus, GYRO].mean(axis=-2) * duration  # E_b1 of each gyro b
        e_minus = means[..., minus, GYRO].mean(axis=-2) * duration  # E_b2
        column = rate_misalignment(e_plus, e_minus, scale, angles.pop())
        column[..., a] = 0.0
        out[..., :, a] = column
    return out


# ----------------------------------------------------------------------------- eq. (6-9) and the 8-position test


def up_down(output_up, output_down, gravity: float) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (6-9) ``A = K0 + K1·a`` from the up/down test: ``K0 = (A_up + A_down)/2``, ``K1 = (A_up − A_down)/(2g)``.

    ``A_up``/``A_down`` are the outputs with the axis under test pointing up and then down (specific force
    +g and −g along it). Applied to an accelerometer whose own axis is turned, K1 is its scale factor
    (``Ka[i, i]``) and K0 its bias (``Ba[i]``); applied to another accelerometer *i* while axis *j* is turned,
    K1 is its cross-axis term ``Ka[i, j]`` and K0 again ``Ba[i]`` (JJF 2003 eq. (2): the other axes feel no g).

    Parameters
    ----------
    output_up, output_down : array
        Mean outputs (m/s² in plansim) up and down.
    gravity : float
        The value of g the laboratory uses, m/s² (> 0).

    Returns
    -------
    K0, K1 : arrays
        In the output's unit and in output unit per m/s².
    """
    up = checked_array("output_up", output_up)
    down = checked_array("output_down", output_down)
    if isinstance(gravity, bool) or not isinstance(gravity, (int, float)) or not (math.isfinite(gravity)
                                                                                and gravity > 0):
        raise ValueError(f"gravity = {gravity!r} m/s^2; it must be finite and > 0")
    return 0.5 * (up + down), (up - down) / (2.0 * gravity)


def eight_position_fit(means, segments, gravity: float, indices=None) -> tuple[np.ndarray, np.ndarray]:
    """The 8-position accelerometer test: ``Ka`` column by column and ``Ba``, by eq. (6-9) on every accelerometer.

    For each axis *j*, the positions with ``+j`` up and with ``−j`` up (four headings each in
    :func:`plansim.schedule.chapter.eight_positions`; any number is accepted) are averaged over the headings,
    which cancels to first order a table tilt's share of g in the horizontal accelerometers; then
    :func:`up_down` on accelerometer *i* gives ``Ka[i, j]`` — the scale factor for i = j, the cross-axis terms
    (the chapter's ``K_ji/K_i`` are :func:`cross_axis_ratios` of it) otherwise — and ``Ba[i]``.

    Parameters
    ----------
    means : (..., S, 6) array
    segments : Schedule or sequence of Segment
    gravity : float
        The laboratory's g, m/s².
    indices : sequence of int, optional
        The segments of the test (at rest); default every ``"static"`` segment.

    Returns
    -------
    Ka : (..., 3, 3) array
        NaN in the column of an axis not turned up and down.
    Ba : (..., 3) array
        m/s², the average of K0 over the axes turned.
    """
    segments = _segments(segments)
    means = _means(means, segments)
    chosen = _indices(segments, indices, "static")
    lead = means.shape[:-2]
    Ka = np.full(lead + (3, 3), np.nan)
    biases = []
    for j, axis in enumerate("xyz"):
        up = [k for k in chosen if segments[k].up == f"+{axis}"]
        down = [k for k in chosen if segments[k].up == f"-{axis}"]
        if not up or not down:
            continue
        K0, K1 = up_down(means[..., up, ACCEL].mean(axis=-2), means[..., down, ACCEL].mean(axis=-2), gravity)
        Ka[..., :, j] = K1
        biases.append(K0)
    if not biases:
        raise ValueError("segments: the 8-position test needs an axis both up and down among the static "
                         "segments (plansim.schedule.chapter.eight_positions)")
    return Ka, np.mean(biases, axis=0)


# ----------------------------------------------------------------------------- the drift model and eq. (6-6)


def earth_rate_inputs(segments, latitude: float, earth_rate: float = CHAPTER_EARTH_RATE, indices=None) -> np.ndarray:
    """The Earth rate each nominal pose feels, in the body frame: ``C_nbᵀ · Ω·[0, cos φ, sin φ]`` (rad/s).

    The chapter's reference angular input (§6.2 1 (2)) is the Earth rate, 15.04107 °/h
    (:data:`CHAPTER_EARTH_RATE`); pass plansim's :data:`plansim.model.environment.EARTH_RATE` to match the
    simulation to the last digit, or 0 for a laboratory that neglects it.

    Returns
    -------
    (n, 3) array
        One row per chosen segment (default: every segment at rest).
    """
    segments = _segments(segments)
    if isinstance(latitude, bool) or not isinstance(latitude, (int, float)) or not abs(latitude) <= 0.5 * math.pi:
        raise ValueError(f"latitude = {latitude!r} rad; it must lie in [-pi/2, pi/2]")
    if isinstance(earth_rate, bool) or not isinstance(earth_rate, (int, float)) or not (
            math.isfinite(earth_rate) and earth_rate >= 0):
        raise ValueError(f"earth_rate = {earth_rate!r} rad/s; it must be finite and >= 0 (the chapter: 15.04107 deg/h)")
    chosen = _indices(segments, indices, "static") if indices is not None else [
        k for k, s in enumerate(segments) if not s.is_rotating]
    omega = earth_rate_enu(latitude) * (earth_rate / EARTH_RATE)
    return np.array([body_to_level(segments[k].up, segments[k].heading).T @ omega for k in chosen]).reshape(-1, 3)


def drift_model_fit(drifts, specific_force) -> np.ndarray:
    """The chapter's gyro drift model ``D = D0 + D1·a_X + D2·a_Y + D3·a_Z`` fitted by least squares over positions.

    Parameters
    ----------
    drifts : (..., 3, n) array
        The drift of each gyro in each of the n positions (output less the known rate input), rad/s.
    specific_force : (n, 3) array
        The specific force (a_X, a_Y, a_Z) of each position, m/s²; the design ``[1, a_X, a_Y, a_Z]`` must
        have rank 4 (each axis up and down, for example).

    Returns
    -------
    (..., 3, 4) array
        Per gyro ``[D0, D1, D2, D3]``: D0 in rad/s, D1–D3 in rad/s per m/s² (× g for the chapter's "per g").
        In plansim's model (JJF 2003 eq. (1)) D0 of gyro i is ``Bg[i]`` and D1, D2, D3 are ``G[i, x]``,
        ``G[i, y]``, ``G[i, z]``.
    """
    d = checked_array("drifts", drifts)
    f = checked_array("specific_force", specific_force, ndim=2)
    if f.shape[1] != 3 or d.ndim < 2 or d.shape[-2:] != (3, f.shape[0]):
        raise ValueError(f"drifts {d.shape} and specific_force {f.shape}: expected (..., 3, n) and (n, 3)")
    design = np.column_stack([np.ones(f.shape[0]), f])  # (n, 4)
    rank = int(np.linalg.matrix_rank(design))
    if rank < 4:
        raise ValueError(f"specific_force: the positions give a rank-{rank} design [1, a_X, a_Y, a_Z]; the drift "
                         "model needs rank 4 (turn each axis up and down)")
    pseudo_inverse = np.linalg.solve(design.T @ design, design.T)  # (4, n)
    return d @ pseudo_inverse.T


def drift_model(means, segments, gravity: float, latitude: float, gyro_scale, earth_rate: float = CHAPTER_EARTH_RATE,
                indices=None) -> np.ndarray:
    """The drift model of each gyro from a position test: the Earth rate removed, then :func:`drift_model_fit`.

    Each static position k has the nominal specific force ``g·(up axis)`` and the Earth-rate input ω_k of
    :func:`earth_rate_inputs`; the drift is ``U_k − K·ω_k`` with K the gyros' scale factors (``(3,)``) or
    their whole matrix ``Kg`` (``(3, 3)``, cross-couplings too), as the laboratory knows them.

    Parameters
    ----------
    means : (..., S, 6) array
    segments : Schedule or sequence of Segment
    gravity : float
        The laboratory's g, m/s².
    latitude : float
        rad.
    gyro_scale : (..., 3) or (..., 3, 3) array
        Scale factors or ``Kg``.
    earth_rate : float
        rad/s (default the chapter's 15.04107 °/h).
    indices : sequence of int, optional
        The positions; default every ``"static"`` segment.

    Returns
    -------
    (..., 3, 4) array
        ``[D0, D1, D2, D3]`` per gyro; in the model ``[Bg[i], G[i, x], G[i, y], G[i, z]]``.
    """
    segments = _segments(segments)
    means = _means(means, segments)
    chosen = _indices(segments, indices, "static")
    if not chosen:
        raise ValueError("segments: no static position for the drift model (plansim.schedule.chapter.drift_positions)")
    if isinstance(gravity, bool) or not isinstance(gravity, (int, float)) or not (math.isfinite(gravity)
                                                                                and gravity > 0):
        raise ValueError(f"gravity = {gravity!r} m/s^2; it must be finite and > 0")
    K = checked_array("gyro_scale", gyro_scale)
    if K.shape[-1:] == (3,) and (K.ndim == 1 or K.shape[-2:] != (3, 3)):
        K = K[..., :, None] * np.eye(3)
    if K.shape[-2:] != (3, 3):
        raise ValueError(f"gyro_scale: expected shape (..., 3) (scale factors) or (..., 3, 3) (Kg), got {K.shape}")
    omega = earth_rate_inputs(segments, latitude, earth_rate, chosen)  # (n, 3)
    force = gravity * np.array([axis_vector(segments[k].up) for k in chosen])  # (n, 3)
    outputs = np.swapaxes(means[..., chosen, GYRO], -1, -2)  # (..., 3, n)
    drifts = outputs - K @ omega.T
    return drift_model_fit(drifts, force)


def random_drift(drifts, axis: int = 0) -> np.ndarray:
    """Eq. (6-6): the random drift rate, 2.7 × the standard deviation (n − 1 in the denominator) of the drift
    found in repeated position tests (the chapter repeats them more than 12 h apart).

    It has no true value in plansim's model: it is a property of the noise and drift processes and of how
    the repeats are spaced (the chapter's 2.7 is a coverage factor applied to σ).

    Parameters
    ----------
    drifts : array
        Repeated drift estimates (for example D0 of each repeat), rad/s, repeats along *axis* (at least 2).
    axis : int
        The axis of the repeats.
    """
    d = checked_array("drifts", drifts)
    if isinstance(axis, bool) or not isinstance(axis, int) or not -d.ndim <= axis < d.ndim:
        raise ValueError(f"axis = {axis!r}; drifts has {d.ndim} dimension(s)")
    if d.shape[axis] < 2:
        raise ValueError(f"drifts: {d.shape[axis]} repeat(s) along axis {axis}; a standard deviation needs >= 2")
    return RANDOM_DRIFT_FACTOR * np.std(d, axis=axis, ddof=1)
