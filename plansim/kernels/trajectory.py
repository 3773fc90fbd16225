"""A free trajectory: the sensor's outputs along it, and the rotation its rates integrate to (numba, SI arrays).

Hand-held calibration (the unit carried by hand from pose to pose, as in Tedaldi, Pretto and Menegatti,
ICRA 2014) has no table: between two static poses the unit turns along a path no one recorded. Two
kernels serve it:

- :func:`trajectory_outputs` — the noise-free outputs of JJF 2003 eq. (1)/(2) at each sample of a given
  body rate and specific force, through the same :func:`plansim.kernels.physics.sensor_outputs` as every
  other simulation (no effect beyond eq. (1)/(2), no lever arm): one model of the physics.
- :func:`integrate_rotation` — the rotation a sequence of body rates integrates to, each rate held over
  its sample interval (a zero-order hold), and the first-order sensitivity of a rotated vector to every
  rate (:func:`rotate`: the rotation alone, for a residual that needs no Jacobian). With the body frame at
  the start as reference and ``R = E_0·E_1·…·E_{n−1}``, E_k = exp([ω_k·dt_k]×) (Rodrigues), a vector
  fixed in the world that reads ``v`` in the body at the start reads ``Rᵀ·v`` at the end. Perturbing
  ω_k by δ gives E_k·exp([J_r(φ_k)·δ·dt_k]×) (J_r the right Jacobian of SO(3),
  φ_k = ω_k·dt_k), hence

      ∂(Rᵀv)/∂ω_k = dt_k · [Rᵀv]× · B_kᵀ · J_r(φ_k),   B_k = E_{k+1}·…·E_{n−1},

  exact to first order in δ (:func:`plansim.fit.moves` uses it for the Jacobian of its residuals and for
  the propagation of the gyro noise; tests/test_moves.py checks it against finite differences).

Deterministic functions writing into preallocated outputs.
"""

from __future__ import annotations

import math

import numpy as np

from plansim.kernels.layout import EFFECT_ROWS
from plansim.kernels.options import inline_jit, jit
from plansim.kernels.physics import sensor_outputs, unpack_truth


@inline_jit
def _exp_so3(p0, p1, p2, out):
    """``out`` (3, 3) = exp([p]×), Rodrigues; a series below 1e-8 rad."""
    theta2 = p0 * p0 + p1 * p1 + p2 * p2
    theta = math.sqrt(theta2)
    if theta < 1e-8:
        a = 1.0 - theta2 / 6.0
        b = 0.5 - theta2 / 24.0
    else:
        a = math.sin(theta) / theta
        b = (1.0 - math.cos(theta)) / theta2
    out[0, 0] = 1.0 - b * (p1 * p1 + p2 * p2)
    out[1, 1] = 1.0 - b * (p0 * p0 + p2 * p2)
    out[2, 2] = 1.0 - b * (p0 * p0 + p1 * p1)
    out[0, 1] = -a * p2 + b * p0 * p1
    out[1, 0] = a * p2 + b * p0 * p1
    out[0, 2] = a * p1 + b * p0 * p2
    out[2, 0] = -a * p1 + b * p0 * p2
    out[1, 2] = -a * p0 + b * p1 * p2
    out[2, 1] = a * p0 + b * p1 * p2


@inline_jit
def _right_jacobian(p0, p1, p2, out):
    """``out`` (3, 3) = J_r(p) = I − (1 − cos θ)/θ²·[p]× + (θ − sin θ)/θ³·[p]×² (a series below 1e-6 rad)."""
    theta2 = p0 * p0 + p1 * p1 + p2 * p2
    theta = math.sqrt(theta2)
    if theta < 1e-6:
        c1 = 0.5 - theta2 / 24.0
        c2 = 1.0 / 6.0 - theta2 / 120.0
    else:
        c1 = (1.0 - math.cos(theta)) / theta2
        c2 = (theta - math.sin(theta)) / (theta2 * theta)
    # [p]×² = p pᵀ − θ² I
    out[0, 0] = 1.0 + c2 * (p0 * p0 - theta2)
    out[1, 1] = 1.0 + c2 * (p1 * p1 - theta2)
    out[2, 2] = 1.0 + c2 * (p2 * p2 - theta2)
    out[0, 1] = c1 * p2 + c2 * p0 * p1
    out[1, 0] = -c1 * p2 + c2 * p0 * p1
    out[0, 2] = -c1 * p1 + c2 * p0 * p2
    out[2, 0] = c1 * p1 + c2 * p0 * p2
    out[1, 2] = c1 * p0 + c2 * p1 * p2
    out[2, 1] = -c1 * p0 + c2 * p1 * p2


@inline_jit
def _compose(rotation, step, work):
    """``rotation`` (3, 3) ← rotation·step, through ``work`` (3, 3)."""
    for i in range(3):
        for j in range(3):
            work[i, j] = rotation[i, 0] * step[0, j] + rotation[i, 1] * step[1, j] + rotation[i, 2] * step[2, j]
    for i in range(3):
        for j in range(3):
            rotation[i, j] = work[i, j]


@inline_jit
def _rotated(rotation, start, end):
    """``end`` (3,) = rotationᵀ·start."""
    for j in range(3):
        end[j] = rotation[0, j] * start[0] + rotation[1, j] * start[1] + rotation[2, j] * start[2]


@inline_jit
def _identity(rotation):
    for i in range(3):
        for j in range(3):
            rotation[i, j] = 1.0 if i == j else 0.0


@jit
def rotate(rates, dt, start, rotation, end):
    """What :func:`integrate_rotation` writes to ``rotation`` and ``end``, bit for bit, without the sensitivities
    (the forward pass alone: half the work, and no (n, 3, 3) buffer)."""
    n = rates.shape[0]
    step = np.empty((3, 3))
    work = np.empty((3, 3))
    _identity(rotation)
    for k in range(n):
        _exp_so3(rates[k, 0] * dt[k], rates[k, 1] * dt[k], rates[k, 2] * dt[k], step)
        _compose(rotation, step, work)
    _rotated(rotation, start, end)


@jit
def integrate_rotation(rates, dt, start, rotation, end, sensitivity):
    """Integrate body *rates* (n, 3), rad/s, each held over ``dt[k]`` s; write the rotation and sensitivities.

    ``rotation`` (3, 3) = R = E_0·…·E_{n−1} (body at the start ← body at the end); ``end`` (3,) = Rᵀ·start;
    ``sensitivity`` (n, 3, 3) = ∂end/∂rates[k] (module docstring). ``start`` (3,) is any vector.
    """
    n = rates.shape[0]
    steps = np.empty((n, 3, 3))
    work = np.empty((3, 3))
    _identity(rotation)
    for k in range(n):
        _exp_so3(rates[k, 0] * dt[k], rates[k, 1] * dt[k], rates[k, 2] * dt[k], steps[k])
        _compose(rotation, steps[k], work)
    _rotated(rotation, start, end)
    # [end]×
    cross = np.zeros((3, 3))
    cross[0, 1] = -end[2]
    cross[0, 2] = end[1]
    cross[1, 0] = end[2]
    cross[1, 2] = -end[0]
    cross[2, 0] = -end[1]
    cross[2, 1] = end[0]
    later = np.eye(3)  # B_k, from k = n − 1 down
    left = np.empty((3, 3))
    jr = np.empty((3, 3))
    for k in range(n - 1, -1, -1):
        # left = [end]× · B_kᵀ
        for i in range(3):
            for j in range(3):
                left[i, j] = cross[i, 0] * later[j, 0] + cross[i, 1] * later[j, 1] + cross[i, 2] * later[j, 2]
        _right_jacobian(rates[k, 0] * dt[k], rates[k, 1] * dt[k], rates[k, 2] * dt[k], jr)
        for i in range(3):
            for j in range(3):
                sensitivity[k, i, j] = dt[k] * (left[i, 0] * jr[0, j] + left[i, 1] * jr[1, j] + left[i, 2] * jr[2, j])
        # B_{k−1} = E_k · B_k
        for i in range(3):
            for j in range(3):
                work[i, j] = steps[k, i, 0] * later[0, j] + steps[k, i, 1] * later[1, j] + steps[k, i, 2] * later[2, j]
        for i in range(3):
            for j in range(3):
                later[i, j] = work[i, j]


@jit
def trajectory_outputs(theta, rates, specific_force, out):
    """``out`` (n, 6): the noise-free outputs, JJF 2003 eq. (1)/(2), of a unit with parameters *theta* (39, SI;
    order of :mod:`plansim.model.parameters`) at body rates *rates* (n, 3), rad/s, and specific force
    *specific_force* (n, 3), m/s², at the IMU centre; no effect beyond the two equations, no lever arm."""
    Kg, Bg, G, Ka, Ba, P = unpack_truth(theta)
    sensor = np.zeros((len(EFFECT_ROWS), 3))
    S2 = np.zeros((3, 3))
    perp = np.zeros((3, 3))
    y = np.empty(6)
    for k in range(rates.shape[0]):
        sensor_outputs(rates[k], specific_force[k], perp, 0.0, Kg, Bg, G, Ka, Ba, P, sensor, S2, y)
        for c in range(6):
            out[k, c] = y[c]
