"""The linearised measurement model of a schedule: the reduction's matrix and the sensitivities of the segment means.

The model of every JJF 2003 parameter is ``Ŷ = R(m̄(X))``: the segment means ``m̄`` (eq. (3)) as
functions of the inputs ``X``, reduced by ``R`` (eq. (4)-(13)).

- :func:`estimator_matrix` — ``R`` is linear in the segment means; its matrix is the estimators'
  own :func:`plansim.estimate.reduction_matrix`, reshaped per segment and channel;
- :func:`segment_mean_derivatives` (and :func:`finite_differences`) — ``∂m̄/∂x_i`` and ``∂²m̄/∂x_i²``
  of the exact noise-free segment means by central differences with step ``u(x_i)`` (JCGM 100
  5.1.3 note 2), averaged over the table start angle: every component in one kernel call, each
  segment evaluated only where the component enters it;
- :func:`table_groups` — which components of the simulator's draws vector each table and fixture
  error occupies (names of :mod:`plansim.kernels.layout`);
- :func:`rate_derivatives` — the outputs' response to the table rate, for the rate jitter.

The noise-free means are trigonometric polynomials of degree ≤ 3 in the start angle of a rotating
segment, so averages of them and of their products (degree ≤ 6) over :data:`PHASE_NODES`
equally spaced angles are exact.
"""

from __future__ import annotations

import math
import threading

import numpy as np

from plansim.config import ErrorDistribution, Scenario
from plansim.estimate import reduction_key, reduction_matrix
from plansim.kernels.layout import (
    FIXTURE,
    HEAD,
    N_CHANNELS,
    PER_SEGMENT,
    RATE_SYSTEMATIC,
    SEG_PHASE,
    SEG_POSITION_ACCURACY,
    SEG_POSITION_REPEATABILITY,
    SEG_RATE_ERROR,
    TILT,
    draws_length,
    perpendicularity_index,
    segment_base,
)
from plansim.kernels.segment_path import noise_free_mean_derivatives
from plansim.model.parameters import N_PARAMETERS
from plansim.schedule.segments import Schedule
from plansim.simulate.arguments import kernel_arguments, noise_free_arguments, nominal_draws

__all__ = ["PHASE_NODES", "estimator_matrix", "finite_differences", "phase_angles", "phase_grid_draws",
           "rate_derivatives", "segment_mean_derivatives", "table_groups"]

#: Start angles at which the noise-free means are evaluated: the means are trigonometric
#: polynomials of degree ≤ 3 in the start angle, so averages of their products (degree ≤ 6) over
#: ≥ 7 equally spaced angles are exact.
PHASE_NODES = 8

#: Relative step of the table rate for :func:`rate_derivatives`.
RATE_STEP = 1e-6


def estimator_matrix(scenario: Scenario) -> np.ndarray:
    """The JJF 2003 reduction as a matrix: ``(39, S, 6)`` with ``estimate = Σ M[:, s, c]·mean[s, c]``.

    :func:`plansim.estimate.reduction_matrix` (the reduction applied to the ``6·S`` unit vectors,
    eq. (5), (7), (10), (12)-(13) being linear least squares and differences), reshaped. It depends
    on the schedule's :func:`~plansim.estimate.reduction_key` (its segments' tests, groups, up-axes and
    rates: not their dwells), the reference gravity and the ω² sign convention alone, and is built
    once per distinct three (a planner evaluates one schedule under many tables and noise models, and
    many dwells of one schedule).

    Parameters
    ----------
    scenario : Scenario
        Supplies the schedule, the reference gravity and the ω² sign convention.

    Returns
    -------
    (39, S, 6) ndarray
        Read-only (it is shared between the calls that ask for the same schedule).

    Raises
    ------
    TypeError
        *scenario* is not a Scenario.
    ValueError
        The reduction is not linear in the segment means (the law of propagation here needs its matrix).
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    r = scenario.reduction
    key = (reduction_key(scenario.schedule), float(r.reference_gravity), r.omega_squared_sign)
    with _MATRICES_LOCK:  # a sweep predicts on threads
        found = key in _MATRICES
        if found:
            _MATRICES[key] = matrix = _MATRICES.pop(key)  # the most recently used last
    if not found:
        matrix = _estimator_matrix(scenario.schedule, *key[1:])
        with _MATRICES_LOCK:
            _MATRICES[key] = matrix
            if len(_MATRICES) > _MATRICES_KEPT:
                del _MATRICES[next(iter(_MATRICES))]
    if matrix is None:
        raise ValueError(f"scenario {scenario.name!r}: the JJF 2003 reduction of this schedule is not linear in the "
                         "segment means, so it has no matrix to propagate the GUM budget through")
    return matrix


#: :func:`estimator_matrix` per :func:`plansim.estimate.reduction_key`, reference gravity and sign convention
#: (the reduction reads the schedule's tests, groups, up-axes and rates alone: schedules that differ only in
#: their dwells share it), the least recently used dropped beyond :data:`_MATRICES_KEPT`
_MATRICES: dict[tuple, np.ndarray | None] = {}
_MATRICES_KEPT = 64
_MATRICES_LOCK = threading.Lock()


def _estimator_matrix(schedule: Schedule, reference_gravity: float, omega_squared_sign: str) -> np.ndarray | None:
    """:func:`estimator_matrix` of *schedule* (read-only), or None where the reduction has no matrix."""
    matrix = reduction_matrix(schedule, reference_gravity, omega_squared_sign)  # (6S, 39)
    if matrix is None:
        return None
    matrix = np.ascontiguousarray(matrix.T.reshape(N_PARAMETERS, len(schedule), N_CHANNELS))
    matrix.flags.writeable = False
    return matrix


def phase_angles() -> np.ndarray:
    """The :data:`PHASE_NODES` start angles ``2πj/J`` (rad) over which the noise-free means are averaged."""
    return 2.0 * math.pi * np.arange(PHASE_NODES) / PHASE_NODES


def phase_grid_draws(scenario: Scenario, draws: np.ndarray | None = None) -> np.ndarray:
    """(J, D): *draws* (default nominal) with every segment's start angle at 2πj/J, J = :data:`PHASE_NODES`."""
    base = nominal_draws(scenario) if draws is None else np.asarray(draws, dtype=float)
    n_seg = len(scenario.schedule)
    grid = np.tile(base, (PHASE_NODES, 1))
    phases = phase_angles()
    for s in range(n_seg):
        grid[:, segment_base(s) + SEG_PHASE] = phases
    return grid


def table_groups(scenario: Scenario) -> list[tuple[str, ErrorDistribution, list[int], str]]:
    """(name, distribution, draws indices, unit) of each table and fixture error group of JJF 2003 Table 1.

    Only groups with a nonzero standard uncertainty and at least one component in this schedule.
    """
    t = scenario.turntable
    segments = scenario.schedule.segments
    n_seg = len(segments)
    per_axis = (segment_base(np.arange(n_seg))[:, None] + 2 * np.arange(3)).ravel()  # segment-major, then axis
    accuracy = (per_axis + SEG_POSITION_ACCURACY).tolist()
    repeatability = (per_axis + SEG_POSITION_REPEATABILITY).tolist()
    axes = sorted({"xyz".index(s.rate_axis[1]) for s in segments if s.rate != 0.0})
    perpendicularity = [perpendicularity_index(a, k) for a in axes for k in range(2)]
    per_point = [segment_base(s) + SEG_RATE_ERROR for s, seg in enumerate(segments) if seg.rate != 0.0]
    rotating = bool(per_point)
    groups = [
        ("position accuracy", t.position_accuracy, accuracy, "rad"),
        ("position repeatability", t.position_repeatability, repeatability, "rad"),
        ("axis perpendicularity", t.axis_perpendicularity, perpendicularity, "rad"),
        ("platform tilt", t.platform_tilt, list(range(TILT.start, TILT.stop)), "rad"),
        ("fixture perpendicularity", t.fixture_perpendicularity, list(range(FIXTURE.start, FIXTURE.stop)), "rad"),
        ("rate error, systematic", t.rate_error_systematic, [RATE_SYSTEMATIC] if rotating else [], "1"),
        ("rate error, per point", t.rate_error_per_point, per_point, "1"),
    ]
    return [g for g in groups if g[1].standard_uncertainty > 0 and g[2]]


def segment_mean_derivatives(scenario: Scenario, indices: np.ndarray, steps: np.ndarray,
                             arguments: dict | None = None, needed: np.ndarray | None = None
                             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The noise-free segment means at the nominal draws, and their first and second derivatives.

    Central differences with step ``steps[k]`` around the nominal draws (JCGM 100 5.1.3 note 2),
    averaged over the table start angle (:data:`PHASE_NODES` angles): the derivatives of the
    expected means. One call of :func:`plansim.kernels.segment_path.noise_free_mean_derivatives`,
    which evaluates a segment only where the component enters it (a position error of one segment
    moves that segment alone), so the result is that of evaluating every perturbed draws vector in
    full, bit for bit, at a fraction of the cost.

    Parameters
    ----------
    scenario : Scenario
    indices : (K,) array of int
        Components of the draws vector (:mod:`plansim.kernels.layout`); not start angles.
    steps : (K,) array
        Step of each component (its standard uncertainty).
    arguments : dict, optional
        :func:`plansim.simulate.arguments.kernel_arguments` of *scenario*, if the caller has them.
    needed : (S, 6) array of bool, optional
        Where the caller uses the derivatives (e.g. where the estimator matrix is not zero): elsewhere
        they are left zero, and a segment none of whose gyros (accelerometers) is needed does not
        evaluate them. Default: everywhere. The derivatives needed are the same numbers either way.

    Returns
    -------
    nominal : (J, S, 6) ndarray
        The noise-free means at the nominal draws with every start angle at ``2πj/J``
        (:func:`phase_grid_draws`).
    first, second : (K, S, 6) ndarray
        ``∂m̄/∂x_k`` and ``∂²m̄/∂x_k²``, averaged over the start angle.

    Raises
    ------
    ValueError
        An index is out of range or is a start angle, or *steps* does not match *indices*.
    """
    n_seg = len(scenario.schedule)
    indices = np.ascontiguousarray(indices, dtype=np.int64)
    steps = np.ascontiguousarray(steps, dtype=float)
    if indices.ndim != 1 or steps.shape != indices.shape:
        raise ValueError(f"indices, steps: shapes {indices.shape}, {steps.shape}; expected two (K,) arrays")
    size = draws_length(n_seg)
    if np.any((indices < 0) | (indices >= size)) or np.any(
            (indices >= HEAD) & ((indices - HEAD) % PER_SEGMENT == SEG_PHASE)):
        raise ValueError(f"indices = {indices.tolist()}: expected components of the draws vector (0 … {size - 1}) "
                         "other than the start angles")
    needed = (np.ones((n_seg, N_CHANNELS), dtype=np.int64) if needed is None
              else np.ascontiguousarray(needed, dtype=np.int64))
    if needed.shape != (n_seg, N_CHANNELS):
        raise ValueError(f"needed: shape {needed.shape}; expected ({n_seg}, {N_CHANNELS})")
    n_in = len(indices)
    nominal = np.empty((PHASE_NODES, n_seg, N_CHANNELS))
    first = np.empty((n_in, n_seg, N_CHANNELS))
    second = np.empty((n_in, n_seg, N_CHANNELS))
    noise_free_mean_derivatives(nominal_draws(scenario), phase_angles(), indices, steps, needed,
                                **noise_free_arguments(scenario, arguments), phase_means_out=nominal,
                                first_out=first, second_out=second)
    return nominal, first, second


def finite_differences(scenario: Scenario, indices: np.ndarray, steps: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivatives (K, S, 6) of the noise-free segment means w.r.t. draws components.

    Central differences with step ``steps[k]`` around the nominal draws (JCGM 100 5.1.3 note 2),
    averaged over the table start angle (:data:`PHASE_NODES` angles): the derivatives of the
    expected means (:func:`segment_mean_derivatives`, without the nominal means).

    Parameters
    ----------
    scenario : Scenario
    indices : (K,) array of int
        Components of the draws vector (:mod:`plansim.kernels.layout`).
    steps : (K,) array
        Step of each component (its standard uncertainty).
    """
    _, first, second = segment_mean_derivatives(scenario, indices, steps)
    return first, second


def rate_derivatives(scenario: Scenario, arguments: dict | None = None, needed: np.ndarray | None = None
                     ) -> np.ndarray:
    """(S, 6): ``rate · ∂(segment mean)/∂(rate)`` of each rotating segment, averaged over the start angle.

    The response of the outputs to the per-sample rate jitter of the table: the gyro input ω·u
    (and with it P·ω²) follows the rate, the centripetal term of the lever arm does not (the
    simulator jitters the gyro input only), so the derivative is taken with the lever arm removed,
    by central differences of the noise-free means in the relative rate error of each point.
    *arguments*: :func:`plansim.simulate.arguments.kernel_arguments` of *scenario*, if the caller has them;
    *needed*: as for :func:`segment_mean_derivatives` (zero elsewhere).
    """
    without_lever = dict(kernel_arguments(scenario) if arguments is None else arguments, lever=np.zeros((3, 3)))
    segments = scenario.schedule.segments
    rotating = [s for s, seg in enumerate(segments) if seg.rate != 0.0]
    out = np.zeros((len(segments), N_CHANNELS))
    if not rotating:
        return out
    indices = np.array([segment_base(s) + SEG_RATE_ERROR for s in rotating], dtype=np.int64)
    _, first, _ = segment_mean_derivatives(scenario, indices, np.full(len(rotating), RATE_STEP), without_lever, needed)
    for k, s in enumerate(rotating):
        out[s] = first[k, s]
    return out
