"""The data reduction of JJF 2003-2022, exactly as the specification writes it.

Pure functions over NumPy arrays, vectorised over leading (trial) dimensions. They see only what
a laboratory sees: the mean output of each recorded segment (eq. (3)) and the *nominal* schedule,
never the truth. Output channels are ordered ``gx, gy, gz, ax, ay, az`` (gyro in rad/s,
accelerometer in m/s²).
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import numpy as np

from plansim.model.parameters import pack
from plansim.schedule.segments import Schedule, axis_vector

GYRO = slice(0, 3)
ACCEL = slice(3, 6)

#: JJF 2003 eq. (6)/(9): the 4×6 design matrix (rows a_X, a_Y, a_Z in g, then the constant)
DESIGN_MATRIX_A = np.array([[1, -1, 0, 0, 0, 0],
                            [0, 0, 1, -1, 0, 0],
                            [0, 0, 0, 0, 1, -1],
                            [1, 1, 1, 1, 1, 1]], dtype=float)


def segment_mean(samples: np.ndarray) -> np.ndarray:
    """JJF 2003 eq. (3): ``U_k = (1/N) Σ U_ki`` over the last axis (the samples of one point)."""
    return np.mean(samples, axis=-1)


def line_fit(rates: np.ndarray, outputs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """JJF 2003 eq. (4)–(5): least-squares ``U = K X + b``, ``[K b]ᵀ = (HᵀH)⁻¹ HᵀU``, ``H = [X 1]``.

    Parameters
    ----------
    rates : (n,) array
        Nominal input rates X of the rate points.
    outputs : (..., n) array
        Mean outputs U at those points.

    Returns
    -------
    K, b : arrays of shape (...)
        Slope (scale factor) and intercept (fitted bias).
    """
    rates = np.asarray(rates, dtype=float)
    H = np.column_stack([rates, np.ones_like(rates)])
    if np.linalg.matrix_rank(H) < 2:
        raise ValueError(f"rate points {rates.tolist()}: at least 2 distinct rates are needed for eq. (5)")
    pseudo_inverse = np.linalg.solve(H.T @ H, H.T)  # (2, n)
    coefficients = np.asarray(outputs, dtype=float) @ pseudo_inverse.T
    return coefficients[..., 0], coefficients[..., 1]


def multi_position_fit(group_means: np.ndarray, design: np.ndarray) -> np.ndarray:
    """JJF 2003 eq. (7)/(10): ``Ḡ = U Aᵀ (A Aᵀ)⁻¹``.

    Parameters
    ----------
    group_means : (..., 3, m) array
        Mean output of three sensors in each of the m groups (``U_g`` or ``U_a``).
    design : (4, m) array
        Matrix A: rows a_X, a_Y, a_Z (in g) and the constant 1.

    Returns
    -------
    (..., 3, 4) array
        ``[G | B]`` (gyro, eq. (8)) or ``[Ka | Ba]`` (accelerometer, eq. (11)), per g.
    """
    design = np.asarray(design, dtype=float)
    right = design.T @ np.linalg.inv(design @ design.T)  # (m, 4)
    right.flags.writeable = False
    return np.asarray(group_means, dtype=float) @ right


def rate_sensitivity(at_rest: np.ndarray, rotating: np.ndarray, rate: float, sign: str = "model") -> np.ndarray:
    """JJF 2003 eq. (12)–(13): accelerometer angular-rate sensitivity from U7 (at rest) and U8 (rotating).

    ``sign = "as_printed"`` returns ``(U7 − U8)/ω²`` as eq. (12) prints it; ``"model"`` (default)
    returns ``(U8 − U7)/ω²``, the estimator consistent with eq. (2), where the rotating reading is
    ``U8 = U7 + p·ω²``. Eq. (12) as printed in §7.2.5.2 therefore returns −p: the formula and
    eq. (2) of §5.2 disagree in sign (docs/specification.md, "The sign of eq. (12) and (13)").
    """
    if sign not in ("model", "as_printed"):
        raise ValueError(f"reduction.omega_squared_sign = {sign!r}; allowed: 'model', 'as_printed'")
    difference = np.asarray(rotating) - np.asarray(at_rest)
    if sign == "as_printed":
        difference = -difference
    return difference / rate**2


# ----------------------------------------------------------------------------- the design of a schedule


def multi_position_design(schedule: Schedule) -> tuple[list[int], list[list[int]], np.ndarray]:
    """Groups of the multi-position test: (group numbers, segment indices per group, matrix A).

    Column *j* of A is ``[a_X, a_Y, a_Z, 1]`` with the nominal specific force of group *j* in g
    (the up-pointing body axis); for the 12- and 6-position tests it is eq. (6)'s matrix.
    """
    idx = schedule.select("multi_position")
    groups = sorted({schedule.segments[k].group for k in idx})
    members = [[k for k in idx if schedule.segments[k].group == g] for g in groups]
    columns = []
    for g, ks in zip(groups, members):
        ups = {schedule.segments[k].up for k in ks}
        if len(ups) != 1:
            raise ValueError(f"schedule: multi-position group {g} mixes up-axes {sorted(ups)}; "
                             "the positions averaged into one group must share the axis that points up")
        columns.append(np.append(axis_vector(ups.pop()), 1.0))
    design = np.array(columns).T if columns else np.zeros((4, 0))
    return groups, members, design


def check_design(schedule: Schedule) -> None:
    """Raise ``ValueError`` if the schedule cannot give every JJF 2003 parameter."""
    groups, _, design = multi_position_design(schedule)
    rank = int(np.linalg.matrix_rank(design)) if design.size else 0
    if design.shape[1] == 0 or rank < 4:
        raise ValueError(
            f"schedule: the multi-position groups {groups} give a rank-{rank} "
            "design matrix A; eq. (7) needs rank 4 (each axis up and down, e.g. the 6 or 12 positions of Appendix C)")
    for axis in range(3):
        rates = {schedule.segments[k].rate for k in schedule.select("rate") if schedule.segments[k].group == axis}
        if len(rates) < 2:
            raise ValueError(f"schedule: the rate test about {'xyz'[axis]} has {len(rates)} distinct rate point(s) "
                             f"{sorted(rates)}; eq. (5) needs at least 2 (the specification asks for 7 to 11)")
        for k in schedule.select("rate"):
            s = schedule.segments[k]
            if s.group == axis and s.rate_axis != f"+{'xyz'[axis]}":
                raise ValueError(f"segment {s.label!r}: a rate-test segment of group {axis} must turn about "
                                 f"'+{'xyz'[axis]}', not {s.rate_axis!r}")
    for axis in range(3):
        segs = [schedule.segments[k] for k in schedule.select("omega_squared") if schedule.segments[k].group == axis]
        rest = [s for s in segs if not s.is_rotating]
        turning = [s for s in segs if s.is_rotating]
        if not rest or not turning or len({s.rate for s in turning}) != 1:
            raise ValueError(f"schedule: the omega-squared test about {'xyz'[axis]} needs at least one segment at "
                             "rest (U7) and rotating segments at one rate (U8) (JJF 2003 §7.2.5)")
        if any(s.rate_axis != f"+{'xyz'[axis]}" or s.up != f"+{'xyz'[axis]}" for s in segs):
            raise ValueError(f"schedule: the omega-squared test of group {axis} must have +{'xyz'[axis]} up and "
                             "turn about it (JJF 2003 §7.2.5 a))")


# ----------------------------------------------------------------------------- the whole reduction


def reduce(means: np.ndarray, schedule: Schedule, reference_gravity: float,
           omega_squared_sign: str = "model") -> np.ndarray:
    """Every JJF 2003 parameter from the segment means.

    Parameters
    ----------
    means : (..., S, 6) array
        Mean output of every segment, channels gx, gy, gz (rad/s), ax, ay, az (m/s²).
    schedule : Schedule
        The nominal schedule (what the lab commanded).
    reference_gravity : float
        The value of "1 g" the lab uses in matrix A, m/s².
    omega_squared_sign : {"model", "as_printed"}
        See :func:`rate_sensitivity`.

    Returns
    -------
    (..., 39) array
        Estimates in SI, ordered as :data:`plansim.model.parameters.PARAMETER_NAMES`.
    """
    if omega_squared_sign not in ("model", "as_printed"):
        raise ValueError(f"reduction.omega_squared_sign = {omega_squared_sign!r}; allowed: 'model', 'as_printed'")
    return _reduce(np.asarray(means, dtype=float), _reduction_plan(reduction_key(schedule)), reference_gravity,
                   omega_squared_sign)


def _reduce(means: np.ndarray, plan: _ReductionPlan, reference_gravity: float, omega_squared_sign: str) -> np.ndarray:
    """:func:`reduce` with the schedule's side already worked out (*plan*): the arithmetic on the means alone,
    operation for operation that of :func:`line_fit`, :func:`multi_position_fit` and :func:`rate_sensitivity`."""
    lead = means.shape[:-2]
    Kg = np.zeros(lead + (3, 3))
    for axis, (ks, pseudo_inverse) in enumerate(plan.rate_fits):  # eq. (5)
        coefficients = np.moveaxis(means[..., ks, GYRO], -2, -1) @ pseudo_inverse.T
        Kg[..., :, axis] = coefficients[..., 0]  # §7.2.3: column = rate about this table axis

    if plan.group_index is not None:  # groups of one size: their means in one call, laid out as np.stack lays them
        group_means = np.ascontiguousarray(np.swapaxes(means[..., plan.group_index, :].mean(axis=-2), -1, -2))
    else:
        group_means = np.stack([means[..., ks, :].mean(axis=-2) for ks in plan.members], axis=-1)  # (..., 6, m)
    gyro = group_means[..., GYRO, :] @ plan.right  # eq. (7)/(10)
    accel = group_means[..., ACCEL, :] @ plan.right
    G, Bg = gyro[..., :3] / reference_gravity, gyro[..., 3]
    Ka, Ba = accel[..., :3] / reference_gravity, accel[..., 3]

    P = np.zeros(lead + (3, 3))
    for axis, (rest, turning, rate) in enumerate(plan.omega_squared):  # eq. (12)-(13)
        u7 = means[..., rest, ACCEL].mean(axis=-2)
        u8 = means[..., turning, ACCEL].mean(axis=-2)
        P[..., :, axis] = rate_sensitivity(u7, u8, rate, omega_squared_sign)
    P[..., [0, 1, 2], [0, 1, 2]] = 0.0
    return pack(Kg, Bg, G, Ka, Ba, P)


def reduction_key(schedule: Schedule) -> tuple:
    """What :func:`reduce` reads of the schedule: each segment's test, group, up-axis and rate.

    Two schedules with the same key have the same reduction (and :func:`reduction_matrix`), whatever
    their dwells, settling times, sample rates or temperatures; a caller may key a cache on it.
    """
    return tuple((s.test, s.group, s.up, s.rate) for s in schedule.segments)


class _ReductionPlan(NamedTuple):
    """The schedule's side of :func:`reduce`: which segments each estimator reads and its fixed matrices."""

    rate_fits: tuple[tuple[list[int], np.ndarray], ...]  # per axis: the rate-test segments, (HᵀH)⁻¹Hᵀ of eq. (5)
    members: list[list[int]]  # the segments of each multi-position group
    group_index: np.ndarray | None  # (m, n) the same, where every group has n segments
    right: np.ndarray  # Aᵀ(AAᵀ)⁻¹ of eq. (7)/(10)
    omega_squared: tuple[tuple[list[int], list[int], float], ...]  # per axis: U7's and U8's segments, the rate


@functools.lru_cache(maxsize=64)
def _reduction_plan(key: tuple) -> _ReductionPlan:
    """:func:`reduce`'s index lists and matrices of the schedule whose :func:`reduction_key` is *key*,
    computed as :func:`line_fit` and :func:`multi_position_fit` compute them (so bit for bit the same),
    once per distinct schedule (a reduction of a chunk of trials, or of one prediction, then costs only
    its arithmetic on the means)."""
    tests = [k[0] for k in key]
    groups = [k[1] for k in key]
    ups = [k[2] for k in key]
    rates = [k[3] for k in key]
    rate_fits = []
    for axis in range(3):
        ks = [k for k, t in enumerate(tests) if t == "rate" and groups[k] == axis]
        x = np.array([rates[k] for k in ks], dtype=float)
        H = np.column_stack([x, np.ones_like(x)])
        if np.linalg.matrix_rank(H) < 2:
            raise ValueError(f"rate points {x.tolist()}: at least 2 distinct rates are needed for eq. (5)")
        pseudo_inverse = np.linalg.solve(H.T @ H, H.T)
        pseudo_inverse.flags.writeable = False  # shared by every reduction of the schedule
        rate_fits.append((ks, pseudo_inverse))
    idx = [k for k, t in enumerate(tests) if t == "multi_position"]
    numbers = sorted({groups[k] for k in idx})
    members = [[k for k in idx if groups[k] == g] for g in numbers]
    columns = []
    for g, ks in zip(numbers, members):
        up = {ups[k] for k in ks}
        if len(up) != 1:
            raise ValueError(f"schedule: multi-position group {g} mixes up-axes {sorted(up)}; "
                             "the positions averaged into one group must share the axis that points up")
        columns.append(np.append(axis_vector(up.pop()), 1.0))
    design = np.array(columns).T if columns else np.zeros((4, 0))
    right = design.T @ np.linalg.inv(design @ design.T)  # (m, 4)
    right.flags.writeable = False
    omega_squared = []
    for axis in range(3):
        segs = [k for k, t in enumerate(tests) if t == "omega_squared" and groups[k] == axis]
        rest = [k for k in segs if not rates[k] != 0.0]
        turning = [k for k in segs if rates[k] != 0.0]
        omega_squared.append((rest, turning, rates[turning[0]]))
    sizes = {len(ks) for ks in members}
    group_index = np.array(members, dtype=np.intp) if len(sizes) == 1 else None
    return _ReductionPlan(tuple(rate_fits), members, group_index, right, tuple(omega_squared))


def reduction_matrix(schedule: Schedule, reference_gravity: float,
                     omega_squared_sign: str = "model") -> np.ndarray | None:
    """The whole reduction as one matrix M: ``reduce(means) == means.reshape(n, -1) @ M``.

    Every estimator of eq. (4)–(13) is a fixed linear combination of the segment means: the
    least-squares solutions of eq. (5), (7) and (10) and the differences of eq. (12). So the
    reduction of a chunk of trials is one (n × 6S) @ (6S × 39) product. M is obtained from
    :func:`reduce` itself, applied to the 6S unit vectors, so there is still one implementation of
    the formulas; it is then checked on random means to within rounding
    (``|probe @ M − reduce(probe)| ≤ 1e-12·(|probe| @ |M|)``). On the default schedule the product
    is about 7× faster than :func:`reduce` on the same chunk.

    It depends on the schedule only through :func:`reduction_key`.

    Returns
    -------
    (6S, 39) array, or None
        None if the check fails (a reduction that is not linear); callers then use :func:`reduce`.
    """
    n_seg = len(schedule)
    size = 6 * n_seg
    matrix = reduce(np.eye(size).reshape(size, n_seg, 6), schedule, reference_gravity, omega_squared_sign)
    probe = np.random.default_rng(0).normal(1.0, 0.01, size=(3, n_seg, 6))
    flat = probe.reshape(3, size)
    rounding = 1e-12 * (np.abs(flat) @ np.abs(matrix))
    if not np.all(np.abs(flat @ matrix - reduce(probe, schedule, reference_gravity, omega_squared_sign)) <= rounding):
        return None
    return matrix
