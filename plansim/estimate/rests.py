"""Step 6 of the rest detector (:mod:`plansim.estimate.segmentation`): which quiet runs of a log are rests and which
are a table's steady turns.

A table's rate jitter is far below a MEMS gyro's noise, so a steady turn is as quiet as a rest, and the
accelerometers cannot tell a turn about the vertical from rest either. What tells them apart is the gyros' mean
output: a rest reads the bias (plus the Earth rate and the g-sensitivity times gravity), a turn the bias plus its
rate along its own gravity. :func:`at_rest_against` compares one run with a rest (step 6); :func:`first_rest` picks
the run the walk of step 6 starts from, by the runs' agreement with each other; :func:`rests_by_g_sensitivity`
(step 6a) takes back the runs a gyro more g-sensitive than :data:`G_SENSITIVITY_ALLOWANCE` had read as turns.
docs/measured-data.md gives the method, its tests and what it cannot tell.
"""

from __future__ import annotations

import math

import numpy as np

#: two runs are in the same pose when their mean specific forces are within this angle (step 6)
SAME_POSE = math.radians(2.0)
#: the g-sensitivity a MEMS gyro's rests in different poses are allowed, rad/s per m/s²: 0.2 °/s/g, twice a consumer
#: unit's data-sheet figure (InvenSense MPU-6050, "linear acceleration sensitivity" 0.1 °/s/g); rests in different
#: poses may differ by it times the change of specific force (step 6)
G_SENSITIVITY_ALLOWANCE = math.radians(0.2) / 9.80665
#: step 6a fits each gyro's rest output over the runs (bias, drift, three g-sensitivities) only from this many runs
G_FIT_MIN_RUNS = 8


def first_rest(runs: list[tuple[int, int]], medians: list, forces: list, rate_threshold: np.ndarray,
                       quiet: int) -> int:
    """The run taken to be at rest first (step 6).

    Two runs *agree* when each is at rest with the other as the only rest (:func:`at_rest_against` both ways: the gyro
    outputs alike in one pose; in two poses, alike along each run's own gravity up to the g-sensitivity). The quiet
    stretch alone (step 3) cannot tell a rest from a table's steady turn: a table's rate jitter is far below a MEMS
    gyro's noise, so the two are equally quiet. Three things can, in this order:

    1. **Poses.** Rests in different poses agree with each other, while a turn about the vertical differs from every
       run in another pose along its own gravity by its rate. So where some run agrees with runs in two or more
       poses (specific force :data:`SAME_POSE` apart), the candidates are the runs that agree with the most poses. A
       log that starts and ends in the same steady turn but holds rests in two poses is read right.
    2. **The log's ends.** In one pose (a rate table's test, every run about one vertical), a log is started and
       stopped with the unit at rest: where the first and the last quiet runs agree, the candidates are the runs
       that agree with them (a minute at each of ±100 °/s between 10 s rests: the turns hold more of the log).
    3. **Samples.** Among the candidates, the run the most quiet samples agree with; *quiet* (the run nearest the
       quiet stretch) where it has as many as any (a log of poses: every run agrees with it).

    A log in one pose that starts and ends in the same steady turn cannot be told from one at rest throughout its
    turns without the table's rates; the import warns of a rest turning about the vertical, and a logged table
    rate (``segment_log(table_rate=…)``) decides in its place."""
    sizes = np.array([b - a for a, b in runs])
    one_way = [[j for j in range(len(runs)) if at_rest_against(j, [i], medians, forces, None, rate_threshold)]
               for i in range(len(runs))]
    agree = [[j for j in one_way[i] if i in one_way[j]] for i in range(len(runs))]
    poses = [len(pose_clusters([forces[j] for j in agree[i]])) for i in range(len(runs))]
    support = [int(sum(sizes[j] for j in agree[i])) for i in range(len(runs))]
    if max(poses) >= 2:
        candidates = [i for i in range(len(runs)) if poses[i] == max(poses)]
    elif len(runs) > 1 and len(runs) - 1 in agree[0]:
        candidates = agree[0]
    else:
        candidates = list(range(len(runs)))
    best = max(support[i] for i in candidates)
    if quiet in candidates and support[quiet] == best:
        return quiet
    return min((i for i in candidates if support[i] == best), key=lambda i: abs(i - quiet))


def rests_by_g_sensitivity(medians: list, forces: list, centres: list[float], at_rest: list[bool],
                            rate_threshold: np.ndarray) -> list[bool]:
    """Step 6a: runs read as steady turns in poses no rest shares, that are rests of a gyro more g-sensitive than
    :data:`G_SENSITIVITY_ALLOWANCE` allows.

    The allowance of step 6 is a data-sheet figure; a unit twice as g-sensitive (0.3 °/s/g) had half the poses of
    a 12-pose hand session read as turns about the vertical. Where the runs span enough poses, they tell the unit's
    own g-sensitivity: each run's mean gyro output is modelled as a rest's, b + d·t + G f (bias, a linear drift
    over the log, the g-sensitivity matrix; per axis 5 unknowns, fitted over the runs by least squares), and a run
    whose output is predicted, left out of the fit, to within the rest threshold *along its own gravity* (where a
    turn about the vertical would show) is at rest. The run predicted worst is dropped from the fit while any is
    out of that threshold, and the fit is used only while it holds at least :data:`G_FIT_MIN_RUNS` runs whose
    poses are not coplanar (G is then determined with room to spare). Only runs in a pose of their own are
    decided this way: where a rest shares a run's pose, the comparison of step 6 is exact (no g-sensitivity
    between them), and a run found at rest stays at rest."""
    n = len(medians)
    ups = [np.asarray(f, dtype=float) / max(float(np.linalg.norm(f)), 1e-300) for f in forces]
    lonely = [i for i in range(n) if not at_rest[i] and not any(
        at_rest[j] and float(np.dot(ups[i], ups[j])) >= math.cos(SAME_POSE) for j in range(n))]
    if not lonely:
        return at_rest
    used = [i for i in range(n) if at_rest[i] or i in lonely]
    while len(used) >= G_FIT_MIN_RUNS:
        t = np.array([centres[i] for i in used])
        design = np.column_stack([np.ones(len(used)), t - t.mean(), np.array([forces[i] for i in used])])
        if np.linalg.matrix_rank(design / np.maximum(np.abs(design).max(axis=0), 1e-300)) < design.shape[1]:
            break  # the poses are coplanar (or too few): G is not determined
        outputs = np.array([medians[i] for i in used])
        coefficients, *_ = np.linalg.lstsq(design, outputs, rcond=None)
        hat = np.einsum("ij,jk,ik->i", design, np.linalg.pinv(design.T @ design), design)
        if np.any(hat >= 1.0 - 1e-9):
            break  # a run the fit must pass through: nothing predicts it
        left_out = (outputs - design @ coefficients) / (1.0 - hat)[:, None]  # each run predicted without it
        ratios = np.array([abs(float(np.dot(r, ups[i]))) / float(np.linalg.norm(rate_threshold * ups[i]))
                           for r, i in zip(left_out, used)])
        worst = int(np.argmax(ratios))
        if ratios[worst] <= 1.0:
            return [rest or i in used for i, rest in enumerate(at_rest)]
        used.pop(worst)
    return at_rest


def pose_clusters(forces: list) -> list[np.ndarray]:
    """The distinct poses among mean specific forces: each force joins the first pose within :data:`SAME_POSE` of
    it, or starts a new one. Returns one unit vector per pose."""
    poses: list[np.ndarray] = []
    for f in forces:
        up = np.asarray(f, dtype=float) / max(float(np.linalg.norm(f)), 1e-300)
        if not any(float(np.dot(up, p)) >= math.cos(SAME_POSE) for p in poses):
            poses.append(up)
    return poses


def at_rest_against(i: int, rests: list[int], medians: list, forces: list, bias: np.ndarray | None,
             rate_threshold: np.ndarray) -> bool:
    """Step 6 for run *i*, given the runs at rest it is compared with (*rests*, nearest first: in the walk of step 6
    the nearest one on the walk's side; for a held pose every rest, by distance in time).

    Against the nearest rest in the same pose (specific force within :data:`SAME_POSE` of run i's): at rest
    when the mean gyro outputs agree within *rate_threshold* on every axis, as a bias that drifts slowly
    would. Where no rest shares the pose, the gyro outputs of two rests also differ by the gyros'
    g-sensitivity times the change of specific force, which for consumer MEMS exceeds the threshold (0.1
    °/s/g between two flips is 0.2 °/s); and a rate table holding a rate with gravity steady turns about the
    vertical. So the run is a steady turn only when its gyro output differs from the nearest rest's *along
    its own gravity direction* by more than the threshold there plus :data:`G_SENSITIVITY_ALLOWANCE` times
    the change of specific force."""
    if not rests:
        return bool(np.all(np.abs(medians[i] - bias) <= rate_threshold))
    up = forces[i] / max(np.linalg.norm(forces[i]), 1e-300)
    for j in rests:
        other = forces[j] / max(np.linalg.norm(forces[j]), 1e-300)
        if float(np.dot(up, other)) >= math.cos(SAME_POSE):
            return bool(np.all(np.abs(medians[i] - medians[j]) <= rate_threshold))
    j = rests[0]
    along = abs(float(np.dot(medians[i] - medians[j], up)))
    allowed = float(np.linalg.norm(rate_threshold * up)) + G_SENSITIVITY_ALLOWANCE * float(
        np.linalg.norm(forces[i] - forces[j]))
    return along <= allowed
