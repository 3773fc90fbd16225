"""A hand-held multi-position session, simulated: static poses anywhere on the sphere and the unit carried
between them by hand, with no table (the procedure of Tedaldi, Pretto and Menegatti, ICRA 2014, that
imu_tk and its descendants calibrate).

The unit rests in pose i (body → world rotation C_i, world East-North-Up) for ``rest`` seconds, then turns
to pose i + 1 in ``move`` seconds along a path of two rotations about fixed body axes (a tumble, not one
turn about one axis: the rates of a real hand move do not commute). Each sub-rotation follows the smooth
profile s(t) = (1 − cos πt/T)/2, and its body rate is held constant over each sample interval at the
increment of s across it, so that the rates a zero-order hold integrates
(:func:`plansim.kernels.trajectory.integrate_rotation`) reproduce the path exactly: with no noise a fit
recovers the truth to rounding. The hand may also push the unit: a linear acceleration
``push``·sin(2πt/T) along a random world direction during each move (zero velocity at both ends).

The outputs are JJF 2003 eq. (1)/(2) through the kernels' own physics
(:func:`plansim.kernels.trajectory.trajectory_outputs`): gyro input = body rate + the Earth rate in the
body, specific force = Cᵀ·(0, 0, g) + Cᵀ·push. White noise of the given standard deviation per sample is
added from numpy's generator seeded with *seed*, then an optional quantiser.

:func:`hand_session` returns the samples and their exact segment table (static poses labelled with their
nearest up axis, ``approximate`` within 15° of it, else ``unknown``; heading not known; moves as ``move``),
which is what ``plansim import`` finds in such a log, give or take a detector window at each edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.estimate.segmentation import APPROXIMATE_TILT, nearest_axis
from plansim.kernels.trajectory import trajectory_outputs
from plansim.model.parameters import PARAMETER_NAMES
from plansim.schedule.segments import Schedule, Segment


@dataclass(frozen=True)
class HandSession:
    """A simulated hand-held session: ``time`` (M,) s, ``samples`` (M, 6) SI (gx gy gz ax ay az),
    ``schedule`` its segment table, ``orientations`` (P, 3, 3) each pose's body → world rotation, ``theta``
    (39,) the unit's parameters (SI)."""

    time: np.ndarray
    samples: np.ndarray
    schedule: Schedule
    orientations: np.ndarray
    theta: np.ndarray


def _rotation(vector: np.ndarray) -> np.ndarray:
    """exp([v]×), Rodrigues."""
    angle = float(np.linalg.norm(vector))
    if angle < 1e-15:
        return np.eye(3)
    k = vector / angle
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


def _log(R: np.ndarray) -> np.ndarray:
    """The rotation vector of R (angle below π)."""
    cos_angle = min(1.0, max(-1.0, (np.trace(R) - 1.0) / 2.0))
    angle = math.acos(cos_angle)
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if angle < 1e-12:
        return 0.5 * w
    if math.pi - angle < 1e-6:  # near π: the axis from the symmetric part
        k = np.sqrt(np.maximum((np.diag(R) + 1.0) / 2.0, 0.0))
        k *= np.where(w >= 0, 1.0, -1.0)
        return angle * k / np.linalg.norm(k)
    return angle * w / (2.0 * math.sin(angle))


def consumer_unit(seed: int, ka_cross: float = 0.0) -> np.ndarray:
    """(39,) SI: a consumer MEMS unit drawn with numpy's generator seeded *seed* — scale factors and gyro
    cross-couplings 3e-3 (1 σ) off, accelerometer scale factors 2e-3, their cross-couplings *ka_cross*, gyro biases
    0.01 rad/s (0.6 °/s), accelerometer biases 0.05 m/s², G 1e-4 rad/s per m/s² (0.1 °/s/g in a few entries),
    P zero."""
    from plansim.model.parameters import PARAMETER_INDEX

    rng = np.random.default_rng(seed)
    theta = np.zeros(len(PARAMETER_NAMES))
    for name in PARAMETER_NAMES:
        k = PARAMETER_INDEX[name]
        if name.startswith("Kg"):
            theta[k] = (1.0 if name[2] == name[3] else 0.0) + rng.normal() * 3e-3
        elif name.startswith("Ka"):
            theta[k] = 1.0 + rng.normal() * 2e-3 if name[2] == name[3] else rng.normal() * ka_cross
        elif name.startswith("Bg"):
            theta[k] = rng.normal() * 0.01
        elif name.startswith("Ba"):
            theta[k] = rng.normal() * 0.05
        elif name.startswith("g"):
            theta[k] = rng.normal() * 1e-4
    return theta


def spread_poses(count: int, seed: int = 0) -> np.ndarray:
    """(count, 3, 3) body → world rotations whose up axes (the world's up read in the body) lie on a spiral
    that covers the sphere evenly (a Fibonacci lattice), each at a random heading; shuffled. What a careful
    hand does: many different gravity directions, every axis up and down."""
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 2:
        raise ValueError(f"count = {count!r}: expected a whole number of poses, at least 2")
    rng = np.random.default_rng(seed)
    golden = math.pi * (3.0 - math.sqrt(5.0))
    out = np.empty((count, 3, 3))
    for k in range(count):
        z = 1.0 - 2.0 * (k + 0.5) / count
        r = math.sqrt(1.0 - z * z)
        up_body = np.array([r * math.cos(golden * k), r * math.sin(golden * k), z])
        # a rotation taking the body's up_body onto the world's up, then a random heading about the vertical
        axis = np.cross(up_body, [0.0, 0.0, 1.0])
        s = np.linalg.norm(axis)
        tilt = math.atan2(s, up_body[2])
        flip = np.eye(3) if up_body[2] > 0 else _rotation(np.array([math.pi, 0.0, 0.0]))
        align = _rotation(axis / s * tilt) if s > 1e-12 else flip
        out[k] = _rotation(np.array([0.0, 0.0, rng.uniform(-math.pi, math.pi)])) @ align
    return out[rng.permutation(count)]


def _smooth_increments(n: int) -> np.ndarray:
    """(n,) increments of s(t) = (1 − cos πt/T)/2 over n equal sample intervals: they sum to 1."""
    s = 0.5 * (1.0 - np.cos(np.pi * np.arange(n + 1) / n))
    return np.diff(s)


def hand_session(theta, orientations, *, rest: float = 5.0, move: float = 3.0, sample_rate: float = 100.0,
                 gyro_noise: float = 0.0, accel_noise: float = 0.0, gravity: float = 9.80665,
                 earth_rate=(0.0, 0.0, 0.0), push: float = 0.0, gyro_step: float = 0.0, accel_step: float = 0.0,
                 tremor: tuple = (0.0, 0.0), seed: int = 0) -> HandSession:
    """Simulate a hand-held session through the poses *orientations* (module docstring).

    Parameters
    ----------
    theta : (39,) array
        The unit's parameters, SI, in the order of :data:`plansim.model.parameters.PARAMETER_NAMES`.
    orientations : (P, 3, 3) array
        Body → world (East-North-Up) rotation of each pose, P ≥ 2 (e.g. :func:`spread_poses`).
    rest, move : float
        Seconds in each pose and in each move between two poses.
    sample_rate : float
        Hz.
    gyro_noise, accel_noise : float
        Standard deviation of the white noise of one sample, rad/s and m/s².
    gravity : float
        Local gravity, m/s².
    earth_rate : (3,) array
        The Earth rate in the world frame (East, North, Up), rad/s (default none).
    push : float
        Amplitude of the hand's linear acceleration during a move, m/s².
    gyro_step, accel_step : float
        Quantiser steps, rad/s and m/s² (0: none).
    tremor : (amplitude, frequency)
        A hand that holds each pose and shakes: the attitude swings by amplitude·sin²(πt/rest)·sin(2πf·t) (rad,
        Hz) about a random body axis, so that it is still at both ends of the rest (default none). The amplitude
        is one number or one per pose (0: that pose rests on the bench).
    seed : int
        Seed of the noise and of each move's path.
    """
    theta = np.asarray(theta, dtype=float)
    if theta.shape != (len(PARAMETER_NAMES),) or not np.all(np.isfinite(theta)):
        raise ValueError(f"theta: expected {len(PARAMETER_NAMES)} finite numbers (SI), got shape {theta.shape}")
    C = np.asarray(orientations, dtype=float)
    if C.ndim != 3 or C.shape[1:] != (3, 3) or C.shape[0] < 2:
        raise ValueError(f"orientations: expected shape (P, 3, 3) with P >= 2, got {C.shape}")
    if not np.allclose(C @ np.transpose(C, (0, 2, 1)), np.eye(3), atol=1e-9):
        raise ValueError("orientations: each must be a rotation matrix (orthonormal)")
    for name, value in (("rest", rest), ("move", move), ("sample_rate", sample_rate), ("gravity", gravity)):
        if not (isinstance(value, (int, float)) and value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} = {value!r}: expected a positive number")
    for name, value in (("gyro_noise", gyro_noise), ("accel_noise", accel_noise), ("push", push),
                        ("gyro_step", gyro_step), ("accel_step", accel_step)):
        if not (isinstance(value, (int, float)) and value >= 0 and math.isfinite(value)):
            raise ValueError(f"{name} = {value!r}: expected a number >= 0")
    rng = np.random.default_rng(seed)
    n_rest = int(round(rest * sample_rate))
    n_move = int(round(move * sample_rate))
    if n_rest < 2 or n_move < 4:
        raise ValueError(f"rest = {rest!r} s, move = {move!r} s at {sample_rate!r} Hz: at least 2 samples at rest "
                         "and 4 in a move")
    dt = 1.0 / sample_rate
    rates, frames, pushes = [], [], []
    amplitudes = np.broadcast_to(np.asarray(tremor[0], dtype=float), (C.shape[0],))
    frequency = float(tremor[1])
    if not (np.all(amplitudes >= 0) and np.all(np.isfinite(amplitudes)) and frequency >= 0
            and math.isfinite(frequency)):
        raise ValueError(f"tremor = {tremor!r}: expected (amplitude rad >= 0, one or one per pose; frequency Hz >= 0)")
    t_rest = np.arange(n_rest + 1) * dt
    shape = np.sin(np.pi * t_rest / (n_rest * dt)) ** 2 * np.sin(2.0 * np.pi * frequency * t_rest)
    for i in range(C.shape[0]):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        swing = amplitudes[i] * shape
        w_rest = np.outer(np.diff(swing) / dt, axis)  # held over each interval: the swing exactly, ends at rest
        rates.append(w_rest)
        frames.append(np.array([C[i] @ _rotation(axis * swing[k]) for k in range(n_rest)]))
        pushes.append(np.zeros((n_rest, 3)))
        if i + 1 == C.shape[0]:
            break
        delta = C[i].T @ C[i + 1]  # the move, in the body frame at its start
        first = rng.normal(size=3)
        first *= rng.uniform(0.2, 0.5) * max(np.linalg.norm(_log(delta)), 0.3) / np.linalg.norm(first)
        second = _log(_rotation(first).T @ delta)
        half = n_move // 2
        frame = C[i].copy()
        for sub, count in ((first, half), (second, n_move - half)):
            steps = _smooth_increments(count)
            for inc in steps:
                w = sub * inc / dt
                rates.append(w[None])
                frames.append(frame[None])
                frame = frame @ _rotation(w * dt)
        direction = rng.normal(size=3)
        direction /= np.linalg.norm(direction)
        phase = np.arange(n_move) / n_move
        pushes.append(push * np.sin(2.0 * math.pi * phase)[:, None] * direction[None, :])
    w_body = np.concatenate(rates)
    frame_at = np.concatenate(frames)  # the frame at the start of each sample interval
    push_world = np.concatenate(pushes)
    up = np.array([0.0, 0.0, gravity])
    specific_force = np.einsum("kji,kj->ki", frame_at, up[None, :] + push_world)
    earth = np.einsum("kji,j->ki", frame_at, np.asarray(earth_rate, dtype=float))
    samples = np.empty((w_body.shape[0], 6))
    trajectory_outputs(theta, np.ascontiguousarray(w_body + earth), np.ascontiguousarray(specific_force), samples)
    samples += rng.normal(size=samples.shape) * np.r_[[gyro_noise] * 3, [accel_noise] * 3]
    for cols, step in ((slice(0, 3), gyro_step), (slice(3, 6), accel_step)):
        if step > 0:
            samples[:, cols] = np.round(samples[:, cols] / step) * step
    segments = []
    for i in range(C.shape[0]):
        up_axis, tilt = nearest_axis(C[i].T @ up)
        orientation = "approximate" if tilt <= APPROXIMATE_TILT else "unknown"
        segments.append(Segment(f"pose {i + 1}: {up_axis} up, tilt {math.degrees(tilt):.1f} deg", "static", 0,
                                up_axis, heading=math.nan, dwell=n_rest / sample_rate, settle=0.0,
                                sample_rate=sample_rate, orientation=orientation))
        if i + 1 < C.shape[0]:
            segments.append(Segment(f"move {i + 1}", "move", 0, up_axis, heading=math.nan, rate=math.nan,
                                    dwell=n_move / sample_rate, settle=0.0, sample_rate=sample_rate,
                                    orientation="unknown"))
    schedule = Schedule(tuple(segments), procedure="hand session")
    time = np.arange(samples.shape[0]) * dt
    return HandSession(time, samples, schedule, C, theta)
