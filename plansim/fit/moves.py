"""The gyros from the moves between poses: the gravity sequence of a hand-held session.

A unit carried by hand from one static pose to the next turns along a path nobody recorded, but both ends
of the path are known in part: the accelerometers say where gravity is in the body at rest before and
after. The gyro outputs over the move, corrected by a candidate gyro calibration and integrated, must turn
the first direction into the second. Over many moves about many axes this identifies the gyros' scale
factors and cross-couplings. It is the gyro half of the method of Tedaldi, Pretto and Menegatti, *A robust
and easy to implement method for IMU calibration without external equipments*, ICRA 2014 (the accelerometer
half is the joint fit's norm-based fit of poses placed by hand), here as a weighted least squares with a GUM
uncertainty.

**Transitions.** Two static segments of the recording with only moving segments between them (``move`` or
``rotation``), none with a settle time (time not recorded) and no gap in the time axis, and no gyro stuck at
its extreme over the recording (three samples or more, or two at a value reached twice, entered or left by a
step of more than 5 times its noise at rest, as ``plansim import`` tells a rail: the rate there is not known).

**Model** (per transition from pose i to pose j; JJF 2003 eq. (1) for the gyros, the joint fit's Ka, Ba and
G as known inputs):

- the gravity direction at rest, û = f/|f|, f = Ka⁻¹·(ā − Ba) from the pose's mean accelerometer output;
- the gyros' bias over the move, interpolated linearly in time between the poses' middle times:
  b_i = ω̄_i − G·f_i (the pose's mean gyro output, which holds Bg and Kg times the Earth rate there);
- the body rate at each sample k, ω̂_k = Kg⁻¹·(y_k − b(t_k) − G·f_k), f_k = Ka⁻¹·(a_k − Ba) (the hand's pushes
  are specific force too);
- the rotation R it integrates to, each rate held over its sample interval
  (:func:`plansim.kernels.trajectory.integrate_rotation`);
- the residual r = Eⱼᵀ·(Rᵀ·ûᵢ − ûⱼ): the two components, across ûⱼ, of the miss (a rotation about gravity
  leaves gravity where it is: the heading turned is not observed).

Kg (9 entries) minimises rᵀV⁻¹r over every transition (``scipy.optimize.least_squares``, with the analytic
Jacobian ∂r/∂Kg = −Eⱼᵀ·Σ_k S_k·Kg⁻¹·e_a·ω̂_k,b from the kernel's sensitivities S_k = ∂(Rᵀû)/∂ω_k).

**Uncertainty** (JCGM 100 5.1.2, independent inputs, as in :mod:`plansim.fit.budget`):

- the gyro noise of the move's own samples: white, per sample variance N²/dt + q²/12 (the motion dithers the
  quantiser), through S_k·Kg⁻¹, and a slow part held over the move, (2 ln 2/π)·B² + K²·T/3 (IEEE Std 952's
  bias instability and rate random walk of the fitted noise model);
- every input of the joint fit (the poses' mean outputs' noise, quantisation, the site, …), through
  ∂r/∂m + ∂r/∂θ·A (m the segment means, θ = A·m the joint estimate: Ka, Ba and G, and the poses' means used
  directly, are correlated through the data, and this carries the correlation);
- the Earth rate during the move, which the linear interpolation of the bias does not follow: a rate of up
  to Ω_E about an axis not known, Type B, u = Ω_E/√3 per axis, held over the move;
- each g-sensitivity entry the joint fit does not identify (every pose with one up axis leaves G with the bias):
  the moves hold it at 0 instead of the joint fit's null-space value, with the Type B u
  ``fit.held.g_sensitivity`` (:class:`plansim.fit.identify.HeldPriors`), through ∂r/∂G, and weigh by it (a
  whole turn about an axis across gravity feels G as an angle of one sign whichever way it turns);
- the symmetric part of each pair of Ka's cross-couplings the joint fit holds at 0 (poses placed by hand near the
  axes do not determine the triad's shear, which bends each pose's gravity direction): its Type B uncertainty
  (``fit.held.accel_cross``, the joint fit's ``held_sources``) through ∂r/∂m + ∂r/∂θ·A like
  the joint fit's inputs, and into the moves' weights (it makes their misses correlated: left out, the χ² of a
  start with two gyro axes flipped came out below the true one's, :data:`SIGN_EVIDENCE`);
- noise between moves beyond all of that (a hand that shakes at the ends of a pose, timing, effects beyond
  eq. (1)): one variance per residual component, estimated by restricted maximum likelihood and taken when
  2·Δlog L passes :data:`plansim.fit.between.BETWEEN_LR_THRESHOLD`, as the joint fit's noise between segments.

**Identifiability and the frame.** ∂r/∂Kg at Kg = I on the recorded motion goes through
:func:`plansim.fit.identify.identifiability`. The moves see the body through the accelerometers, so Kg comes
out in the frame where Ka's cross-couplings take the joint fit's values. Where the joint fit does not
identify them (poses placed by hand: held at 0), Kg's cross-couplings are the gyros' misalignment relative to
the accelerometer triad, not to the case; to first order they estimate Kg_ij − (Ka_ij − Ka_ji)/2. They are
then reported with that frame and are not counted as identified; the scale factors Kg_ii do not depend on
the triad's rotation (to first order) and are. They do depend on its shear (the symmetric part), which is why
that part's held uncertainty is carried. docs/fitting.md.

The moves read the accelerometers with the antisymmetric part of each such pair of Ka's cross-couplings
removed (the joint fit may leave it anywhere in its null space: a common rotation of every pose is a rotation
of the triad), so that the estimate is the same whatever the joint fit's start: the gyros' misalignment in
the frame where the accelerometer triad's matrix is symmetric.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import chi2 as chi2_distribution

from plansim.estimate.segmentation import SATURATION_STEP, stuck_runs
from plansim.estimate.timebase import GAP_FACTOR
from plansim.fit.between import BETWEEN_LR_THRESHOLD
from plansim.fit.budget import Sources, chi2_verdict, propagate
from plansim.fit.identify import SAMPLE_RATE_HINT, UNINFORMATIVE_U, Identifiability, identifiability
from plansim.kernels.trajectory import integrate_rotation, rotate
from plansim.model.environment import EARTH_RATE
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES

METHOD_MOVES = "gravity_sequence"
#: the Kg entries, in the order of their 3×3 matrix (row by row)
KG_NAMES = tuple(f"Kg{a}{b}" for a in "xyz" for b in "xyz")
KG_INDEX = np.array([PARAMETER_INDEX[name] for name in KG_NAMES])
#: the entries of the joint estimate the moves' model reads
_USED_FROM_JOINT = tuple(f"{p}{a}{b}" for p in ("Ka", "g") for a in "xyz" for b in "xyz") + \
    tuple(f"Ba{a}" for a in "xyz")
#: the g-sensitivity entries, which the moves hold at 0 where the joint fit does not identify them
G_NAMES = tuple(f"g{a}{b}" for a in "xyz" for b in "xyz")
#: central-difference steps: a segment mean (gyro rad/s, accelerometer m/s²) and a joint parameter (SI)
_STEP_GYRO, _STEP_ACCEL, _STEP_PARAMETER = 1e-7, 1e-6, 1e-7
#: two moves or fewer cannot identify anything (each gives two numbers)
MIN_TRANSITIONS = 2
#: the first solve starts from Kg = diag(±1, ±1, ±1), each sign pattern, and keeps the smallest χ²
SIGN_STARTS = tuple((a, b, c) for a in (1.0, -1.0) for b in (1.0, -1.0) for c in (1.0, -1.0))
#: … and from each pattern times these: the gyros' units mistaken, deg/s read as rad/s (a log in deg/s imported
#: without --units), where a start at ±1 stops in a local minimum
UNIT_STARTS = (1.0, math.degrees(1.0))
#: … and, last, from every signed permutation that is not diagonal: the gyro columns in another order than the
#: accelerometers' (a logger or a --columns that maps one sensor's axes differently)
PERMUTED_GROUP = len(UNIT_STARTS)
PERMUTED_STARTS = tuple(np.diag(signs)[list(order)] for order in itertools.permutations(range(3))
                        if list(order) != [0, 1, 2] for signs in SIGN_STARTS)
#: a best fit this close to a signed permutation that is not diagonal (each entry) is read as the axes in another
#: order (axes_permuted): a MEMS gyro's scale factor is within a few per cent of 1, its cross-couplings within 1 %
PERMUTATION_TOLERANCE = 0.2
#: … tried only where the starts before them end with a gyro scale factor K far from ±1, |K² − 1| above this
#: (|K| outside 0.71–1.22; the test's log in deg/s read as rad/s ended at −0.056 and +0.44 from ±1; a MEMS gyro's
#: scale factor is within a few per cent of 1)
FAR_OFF = 0.5
#: … or where they end with χ² (against the noise the moves predict, before any between-move noise) beyond this
#: upper-tail probability: gyros read in deg/s as rad/s also stop near diag(−1, −1, +1), every move missing by 25°
POOR_FIT = 1e-3
#: a start that ends with a gyro scale factor beyond this (twice the largest start) ran away, and is not taken: where
#: every move is a whole turn about one axis, no turn at all (Kg_ii → ∞) fits as well as the truth, and on a
#: table's ±360° turns a start at 180/π ran to 2·10⁶ with a χ² below an unconverged start at 1
RUNAWAY = 2.0 * max(UNIT_STARTS)


def _implausible(Kg: np.ndarray) -> bool:
    """Whether a start of the search ended where no gyro triad is: a scale factor beyond :data:`RUNAWAY` (it ran
    away), or a Kg whose smallest singular value is below 1/RUNAWAY (it collapsed: a gyro, or a combination of
    them, that reads no turn at all, as a start at a permutation projected onto the diagonal ends; a table log whose
    moves fit no Kg gave such a Kg, with Kgyy = 4·10⁻¹⁶, as its best). Units read 180/π off still pass (their
    singular values are 1/57.3 or 57.3), and so does a signed permutation (all 1)."""
    if not np.all(np.isfinite(Kg)):
        return True
    return bool(np.any(np.abs(np.diag(Kg)) > RUNAWAY)
                or np.linalg.svd(Kg, compute_uv=False).min() < 1.0 / RUNAWAY)


#: a combination of Kg entries the moves determine no better than this standard uncertainty (dimensionless) at
#: Kg = I, with the noise they predict and no between-move noise (the smallest u they could give), is not
#: identified: a gyro's scale factor is within a few per cent of 1 and its cross-couplings within 1 %, so such a
#: direction says nothing of the unit, and the fit wandered along it (an independent simulator's 12-position log,
#: whose y axis was turned about only while vertical: Kgyy 5.33 ± 13.7, 0.497 ± 0.053, or the moves dropped with
#: advice to check the gyros' units). The identified directions' u is 1e-5 to 1e-2 on the logs we have. The default:
#: a lab's own data sheet for Kg (a scenario's ``[reduction] data_sheet_kg``, HeldPriors.data_sheet) replaces it
WEAK_DIRECTION_U = UNINFORMATIVE_U["Kg"]
#: a start with some gyro axes flipped is taken over the gyros as wired only where its χ² is lower by more than
#: this (the 99 % point of χ² with 1 degree of freedom): with poses near the six axes a half turn of the gyro
#: triad about one axis maps every pose's gravity onto itself, and the moves cannot tell it from none
SIGN_EVIDENCE = 6.63
#: each of the many starts (signs, units, permutations) is run for at most this many evaluations, and only the best
#: of them, where it has not converged, on to MAX_EVALUATIONS: a start that wanders (moves no Kg fits, a start far
#: from the gyros' own) ran to MAX_EVALUATIONS every time, 13 s each on a 135 000-sample table log whose moves no Kg
#: fits (its fit took 551 s, now 145 s); on the Ferraris session every start that ends near the best converges in
#: 10-30
SCREEN_EVALUATIONS = 40
#: moves whose residuals scatter, beyond their predicted noise, by more than this per component (rad) at the Kg that
#: fits them best are left out: the gyros' integral over them does not agree with the change of gravity between the
#: poses (a motion the log does not hold, the unit turned over inside a gap, a gyro read in another unit or order).
#: A hand session's moves scatter by 0.25 deg (the Ferraris session); a scale factor is fitted, so what is left is
#: not a MEMS gyro's scale error
MOVES_SCATTER_LIMIT = math.radians(5.0)
MAX_EVALUATIONS = 200


def axes_permuted(Kg: np.ndarray) -> str:
    """Where the gyro scale-factor matrix *Kg* that fits the moves best is a signed permutation that is not diagonal
    (every entry within :data:`PERMUTATION_TOLERANCE` of it), what that says of the log; else ``""``.

    Row a of Kg is what gyro a reads of the rotation about each accelerometer axis: Kg ≈ [[0, 1, 0], [1, 0, 0],
    [0, 0, 1]] is gx reading the rotation about y and gy about x, the gyros' x and y columns exchanged against the
    accelerometers' (or the accelerometers' against the gyros': the poses, fitted by the norm of their specific
    force, cannot tell a mirrored accelerometer triad from the true one). The order is what the search tells; the
    signs it does not tell reliably (it steps only in the directions the moves identify at Kg = I, so a start at a
    permutation is projected onto them: the Ferraris session with its gyro columns in cyclic order came out with two
    signs reversed, while the re-import in that order with no sign changed fits with χ² 1551 against 2826), so the
    advice is the order alone, and the refit's own notes (:func:`plansim.fit.identify.reversed_axis_notes`) name any
    axis still reversed."""
    P = np.round(Kg)
    if not (np.all(np.abs(Kg - P) <= PERMUTATION_TOLERANCE) and np.all(np.abs(P).sum(axis=0) == 1)
            and np.all(np.abs(P).sum(axis=1) == 1)) or np.all(P == np.diag(np.diag(P))):
        return ""
    order = [int(np.argmax(np.abs(P[a]))) for a in range(3)]  # gyro a reads the rotation about axis order[a]
    reads = ", ".join(f"g{'xyz'[a]} the rotation about {'xyz'[order[a]]}" for a in range(3) if order[a] != a)
    fix = ", ".join(f"g{'xyz'[b]} ← the column now read as g{'xyz'[order.index(b)]}" for b in range(3))
    matrix = _matrix_text(Kg, "+.3f")
    odd = sum(order[a] != a for a in range(3)) == 2  # one exchange of two axes: a mirror
    return ("they fit best with the gyros reading the accelerometers' axes in another order: " + reads
            + f" (Kg = {matrix}; the signs this search finds are not reliable). The log's gyro columns are in another "
            "order than --columns takes them, or its accelerometer columns are. Re-import with the gyro columns as "
            + fix + ", and fit again: its notes name any axis that is still reversed."
            + (" An exchange of two axes mirrors a triad: if it is the accelerometers' columns that are exchanged, "
               "exchange those instead (the fit cannot tell which: the poses are fitted by the norm of their specific "
               "force, the same in a mirror)" if odd else ""))


class MovesNotFitted(Exception):
    """The moves between poses cannot be fitted on this recording (:func:`fit_moves`); the message says why, and
    :func:`plansim.fit.fit_recording` notes it and goes on without them."""


def _matrix_text(Kg: np.ndarray, spec: str) -> str:
    """*Kg* (3, 3) as a note prints it, row by row, each entry in the format *spec*."""
    return "[" + ", ".join("[" + ", ".join(f"{v:{spec}}" for v in row) + "]" for row in Kg) + "]"


def _shown_kg(Kg: np.ndarray) -> str:
    """*Kg* as a note shows it: its diagonal where the cross-couplings are small beside it (below 0.1 of the smallest
    scale factor), else the whole matrix (a search that ended near a permutation, whose diagonal says nothing)."""
    off = np.abs(Kg - np.diag(np.diag(Kg))).max()
    if off <= 0.1 * np.abs(np.diag(Kg)).min():
        return "Kg diagonal " + ", ".join(f"{v:+.4g}" for v in np.diag(Kg))
    return "Kg = " + _matrix_text(Kg, "+.4g")


def _solve_information(information: np.ndarray, right: np.ndarray, Kg: np.ndarray) -> np.ndarray:
    """information⁻¹ · right, or :class:`MovesNotFitted` where the moves do not identify Kg at the solution *Kg*
    (information singular to working precision)."""
    values = np.linalg.eigvalsh(0.5 * (information + information.T))
    if not values.size or values.min() <= 1e-12 * max(values.max(), 1e-300):
        raise MovesNotFitted(
            "the moves between poses were left out: at the gyro scale factors that fit them best "
            f"({_shown_kg(Kg)}) they do not identify them — the angles the gyros integrate over the moves do not "
            "agree with the change of gravity between the poses. Check the gyros' --units (deg/s or rad/s), "
            "--columns and the axes' signs, " + SAMPLE_RATE_HINT + ", and that the segment table's moves are whole "
            "turns between the poses")
    return np.linalg.solve(information, right)


def _floored_eigh(V: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The eigenvalues and eigenvectors of the residuals' covariance *V*, the eigenvalues floored at 1e-14 of the
    largest: the moves' weights, information and gain all read V through this, so that a direction V holds no noise
    on is determined exactly rather than left out (a recording without noise determines everything it excites)."""
    values, vectors = np.linalg.eigh(0.5 * (V + V.T))
    return np.maximum(values, 1e-14 * max(float(values.max()), 1e-300)), vectors


def _floored_inverse(V: np.ndarray) -> np.ndarray:
    """V⁻¹ through :func:`_floored_eigh`."""
    values, vectors = _floored_eigh(V)
    return (vectors / values) @ vectors.T


def _weak_entries(ident: Identifiability, design: np.ndarray, V: np.ndarray, what: str, prior: float,
                  at: str = "Kg = I", scale: float = 1.0,
                  limit: float = WEAK_DIRECTION_U) -> tuple[Identifiability, dict]:
    """The moves' identifiability *ident* with the Kg entries they determine only weakly held at nominal.

    *design* (2M, 39) is ∂r/∂θ at *at* (Kg = I, or the fitted Kg; only the Kg columns non-zero, those held
    already zero; *ident* its identifiability) and *V* (2M, 2M) the residuals' covariance there. With Q an
    orthonormal basis of what the moves determine (so that a unit step of z is a unit step of Kg), the information
    Jzᵀ V⁻¹ Jz (Jz = ∂r/∂Kg · Q; :func:`_floored_eigh`) has eigenvalues λ; while
    the smallest gives u = 1/√λ above *limit* (the unit's data sheet for Kg, :attr:`HeldPriors.data_sheet`;
    default :data:`WEAK_DIRECTION_U`, a consumer MEMS unit's), the Kg entry with the largest share of that
    direction is held (its column zeroed) and the rest looked at again. Returns the identifiability of what is
    left and, per held entry, why (held with the Type B u *prior*, :attr:`HeldPriors.gyro`). *scale* is the size
    of the gyros' scale factors there (1 at Kg = I; at the fitted
    Kg the mean |Kg_ii|, 57.3 for gyros read in deg/s as rad/s), and u is taken relative to it."""
    held: dict[str, str] = {}
    V_inverse = _floored_inverse(V)
    while True:
        basis = ident.basis[KG_INDEX]
        if basis.shape[1] == 0:
            return ident, held
        q, _ = np.linalg.qr(basis)
        Jz = design[:, KG_INDEX] @ q
        information = Jz.T @ V_inverse @ Jz
        values, vectors = np.linalg.eigh(0.5 * (information + information.T))
        u = 1.0 / math.sqrt(max(float(values[0]), 1e-300)) / scale
        if u <= limit:
            return ident, held
        direction = np.abs(q @ vectors[:, 0])
        k = int(np.argmax(direction))
        held[KG_NAMES[k]] = (f"the moves determine it only weakly (u = {u:.3g} at {at} along the combination it "
                             f"leads, above {limit:g}): held at its nominal value with u = "
                             f"{prior:g} (a turn about an axis that is vertical, or tilted by a few "
                             "degrees, does not show its scale factor; a whole turn shows the cross-couplings of its "
                             "axis only at second order)")
        design = design.copy()
        design[:, KG_INDEX[k]] = 0.0
        ident = identifiability(design, what=what)


@dataclass(frozen=True)
class Transition:
    """A motion between two static poses: schedule indices ``before``/``after`` and the ``between``
    segments; samples ``start``…``stop − 1`` are integrated (``stop`` is the first sample of ``after``)."""

    before: int
    after: int
    between: tuple[int, ...]
    start: int
    stop: int


@dataclass(frozen=True)
class MoveFit:
    """What the moves say of the gyros (:func:`fit_moves`). Arrays over the transitions used (M of them).

    ``method`` holds the 39 parameters' estimates and u (NaN but for the Kg entries the moves identify);
    ``identified`` the Kg entries identified in the case frame; ``relative`` those estimated only relative
    to the accelerometer triad (module docstring) with the reason; ``residual`` (M, 2) and ``residual_sd``
    (M, 2) rad; ``angle`` (M,) the angle each move turned, rad; χ² against the prediction (without the noise
    between moves estimated from these residuals).
    """

    transitions: tuple[Transition, ...]
    unused: dict
    method: object
    identified: tuple[str, ...]
    relative: dict
    not_identified: dict
    residual: np.ndarray
    residual_sd: np.ndarray
    angle: np.ndarray
    duration: np.ndarray
    chi2: float
    chi2_dof: int
    chi2_verdict: str
    between_sd: float
    between_dof: float
    notes: tuple[str, ...] = ()
    #: the gain of the Kg estimate on the residuals and the residuals' covariance, for what builds on it
    covariance: np.ndarray | None = field(default=None, repr=False)


def find_transitions(recording) -> tuple[list[Transition], dict]:
    """The transitions of a recording (module docstring) and, for each motion that is not one, why."""
    schedule = recording.schedule
    segments = schedule.segments
    first = np.asarray(recording.first_sample, dtype=np.int64)
    samples = np.asarray(recording.samples, dtype=float)
    static = [k for k, s in enumerate(segments) if s.test != "move" and not s.is_rotating]
    time = recording.time if getattr(recording, "timestamps", None) is not None else None
    # the gyros' extremes over the recording and their per-sample noise at rest (median scatter of the poses)
    rails = [(samples[:, c].min(), samples[:, c].max()) for c in range(3)]
    scatter = np.array([[np.std(recording.segment_samples(k)[:, c]) for c in range(3)] for k in static])
    jump = SATURATION_STEP * np.median(scatter, axis=0) if len(static) else np.zeros(3)
    # the rails over the whole recording (a value reached twice counts, wherever the other time is)
    stuck = [(c, a, b) for c in range(3) for value in rails[c] for a, b in stuck_runs(samples[:, c], value, jump[c])]
    out, unused = [], {}
    for i, j in zip(static[:-1], static[1:]):
        between = tuple(range(i + 1, j))
        if not between:
            continue  # two rests side by side: nothing moved
        where = f"segments {between[0]}-{between[-1]}" if len(between) > 1 else f"segment {between[0]}"
        late = [k for k in between + (j,) if segments[k].settle > 0]
        if late:
            unused[where] = (f"segment {late[0]} starts after a settle time that was not recorded: the motion "
                             "between the poses is not all in the log")
            continue
        start, stop = int(first[between[0]]), int(first[j])
        if time is not None:
            steps = np.diff(time[start - 1:stop + 1])
            period = 1.0 / segments[i].sample_rate
            if np.any(steps > GAP_FACTOR * period):
                unused[where] = "a gap in the time axis: samples are missing, the motion's integral is not known"
                continue
        hit = next((c for c, a, b in stuck if a < stop and b > start), None)
        if hit is not None:
            unused[where] = (f"gyro {'xyz'[hit]} reads its extreme over the recording for several samples in a "
                             "row: saturated? The rate there is not known")
            continue
        out.append(Transition(i, j, between, start, stop))
    return out, unused


class _Moves:
    """The transitions' data and the residual model (module docstring)."""

    def __init__(self, recording, transitions, pose_row: dict, means: np.ndarray, theta: np.ndarray,
                 symmetrise=()):
        #: pairs (i, j) of Ka's cross-couplings the joint fit does not identify: the moves read Ka with their
        #: antisymmetric part (a rotation of the triad, which no pose fixes) removed, (Ka_ij + Ka_ji)/2 both
        self.symmetrise = tuple(symmetrise)
        self._cache: dict = {}  # transition -> ((theta, means) bytes, _inputs), :meth:`_inputs`
        segments = recording.schedule.segments
        samples = np.asarray(recording.samples, dtype=float)
        time = np.asarray(recording.time, dtype=float)
        first = np.asarray(recording.first_sample, dtype=np.int64)
        self.transitions = transitions
        self.pose_row = pose_row  # schedule index -> row of the used segments' means
        self.gyro, self.accel, self.dt, self.weight_before, self.duration = [], [], [], [], []
        for t in transitions:
            k = np.arange(t.start, t.stop)
            fs = segments[t.before].sample_rate
            dt = np.diff(time[t.start:t.stop + 1]) if t.stop < time.size else np.r_[np.diff(time[k]), 1.0 / fs]
            mid_time = [float(np.mean(time[int(first[p]):int(first[p]) + segments[p].samples]))
                        for p in (t.before, t.after)]
            self.gyro.append(np.ascontiguousarray(samples[k, :3]))
            self.accel.append(np.ascontiguousarray(samples[k, 3:]))
            self.dt.append(np.ascontiguousarray(dt))
            self.weight_before.append((mid_time[1] - time[k]) / (mid_time[1] - mid_time[0]))
            self.duration.append(float(np.sum(dt)))
        self.duration = np.asarray(self.duration)
        # the basis across gravity at each move's end, fixed at the data and the joint estimate
        self.basis = []
        for t in transitions:
            up = self._direction(means[pose_row[t.after], 3:], theta)
            helper = np.eye(3)[int(np.argmin(np.abs(up)))]
            e1 = np.cross(up, helper)
            e1 /= np.linalg.norm(e1)
            self.basis.append(np.column_stack([e1, np.cross(up, e1)]))

    def _accel_model(self, theta):
        Ka = theta[[PARAMETER_INDEX[f"Ka{a}{b}"] for a in "xyz" for b in "xyz"]].reshape(3, 3).copy()
        for i, j in self.symmetrise:
            Ka[i, j] = Ka[j, i] = 0.5 * (Ka[i, j] + Ka[j, i])
        Ba = theta[[PARAMETER_INDEX[f"Ba{a}"] for a in "xyz"]]
        G = theta[[PARAMETER_INDEX[f"g{a}{b}"] for a in "xyz" for b in "xyz"]].reshape(3, 3)
        return np.linalg.inv(Ka), Ba, G

    def _direction(self, accel_mean, theta):
        Kinv, Ba, _ = self._accel_model(theta)
        f = Kinv @ (accel_mean - Ba)
        return f / np.linalg.norm(f)

    def _inputs(self, m: int, theta: np.ndarray, means: np.ndarray):
        """What transition *m*'s residual takes that Kg does not change, at *theta* and *means*: the gyro outputs
        less the bias and g-sensitivity (n, 3), and the unit gravity directions at both ends. Kept for the last
        (theta, means) of each transition: the search for Kg evaluates them hundreds of times."""
        key = (theta.tobytes(), means.tobytes())
        cached = self._cache.get(m)
        if cached is not None and cached[0] == key:
            return cached[1]
        t = self.transitions[m]
        Kinv, Ba, G = self._accel_model(theta)
        before, after = means[self.pose_row[t.before]], means[self.pose_row[t.after]]
        f_i, f_j = Kinv @ (before[3:] - Ba), Kinv @ (after[3:] - Ba)
        u_i, u_j = f_i / np.linalg.norm(f_i), f_j / np.linalg.norm(f_j)
        b_i, b_j = before[:3] - G @ f_i, after[:3] - G @ f_j
        w = self.weight_before[m][:, None]
        bias = w * b_i[None, :] + (1.0 - w) * b_j[None, :]
        f_k = (self.accel[m] - Ba[None, :]) @ Kinv.T
        value = (self.gyro[m] - bias - f_k @ G.T, u_i, u_j)
        self._cache[m] = (key, value)
        return value

    def _rates(self, m: int, Kg: np.ndarray, theta: np.ndarray, means: np.ndarray):
        """M = Kg⁻¹, the body rates of transition *m* at *Kg* (n, 3), and the unit gravity directions at its ends."""
        corrected, u_i, u_j = self._inputs(m, theta, means)
        M = np.linalg.inv(Kg)
        return M, np.ascontiguousarray(corrected @ M.T), u_i, u_j

    def _integrated(self, m: int, Kg: np.ndarray, theta: np.ndarray, means: np.ndarray):
        """The full pass of transition *m* (rotation and sensitivities): its residual (2,), M, the rates, the
        rotation, the sensitivities (n, 3, 3) and the start's gravity direction."""
        M, rates, u_i, u_j = self._rates(m, Kg, theta, means)
        rotation, end, sens = np.empty((3, 3)), np.empty(3), np.empty((rates.shape[0], 3, 3))
        integrate_rotation(rates, self.dt[m], u_i, rotation, end, sens)
        return self.basis[m].T @ (end - u_j), M, rates, rotation, sens, u_i

    def one(self, m: int, Kg: np.ndarray, theta: np.ndarray, means: np.ndarray, details: bool = False):
        """The residual (2,) of transition *m*; with *details* also the sensitivities (module docstring)."""
        E = self.basis[m]
        if not details:  # the forward pass alone
            _, rates, u_i, u_j = self._rates(m, Kg, theta, means)
            rotation, end = np.empty((3, 3)), np.empty(3)
            rotate(rates, self.dt[m], u_i, rotation, end)
            return E.T @ (end - u_j)
        r, M, rates, rotation, sens, u_i = self._integrated(m, Kg, theta, means)
        SM = sens @ M  # (n, 3, 3): ∂end/∂(gyro output at k)
        angle = float(np.linalg.norm(_log_rotation(rotation)))
        integral = np.sum(rates * np.asarray(self.dt[m], dtype=float)[:, None], axis=0)  # the turn, rad, body axes
        return r, dict(jac=self._kg_jacobian(E, M, sens, rates), SM=SM, S_sum=E.T @ sens.sum(axis=0),
                       SM_sum=E.T @ SM.sum(axis=0), angle=angle, about_vertical=_about_vertical(integral, u_i))

    @staticmethod
    def _kg_jacobian(E, M, sens, rates) -> np.ndarray:
        """∂r/∂Kg (2, 9): ∂r/∂Kg_ab = −Eᵀ Σ_k (S_k M)[:, a] ω̂_k[b] = −Σ_xy E_xi M_ya A_xyb, A_xyb = Σ_k S_k,xy ω̂_k,b
        (one (9, n)·(n, 3) product, not a sum over n of (3, 3, 3) terms)."""
        A = (sens.reshape(sens.shape[0], 9).T @ rates).reshape(3, 3, 3)
        return -np.einsum("xi,ya,xyb->iab", E, M, A).reshape(2, 9)

    def with_jacobian(self, m: int, Kg: np.ndarray, theta: np.ndarray, means: np.ndarray):
        """The residual (2,) of transition *m* and its Jacobian in Kg (2, 9), without the other details."""
        r, M, rates, _, sens, _ = self._integrated(m, Kg, theta, means)
        return r, self._kg_jacobian(self.basis[m], M, sens, rates)

    def residuals(self, Kg, theta, means) -> np.ndarray:
        return np.concatenate([self.one(m, Kg, theta, means) for m in range(len(self.transitions))])


#: a motion whose integrated turn lies within this of the start pose's gravity turns about the vertical, rad
VERTICAL_TURN = math.radians(20.0)


def _about_vertical(integral: np.ndarray, gravity: np.ndarray) -> bool:
    """Whether a motion's integrated turn (3,) lies along gravity (3,, unit) within :data:`VERTICAL_TURN`: it then
    leaves gravity where it was throughout, and tells the moves nothing of the gyros' scale factors."""
    size = float(np.linalg.norm(integral))
    return size > 0 and abs(float(integral @ gravity)) >= math.cos(VERTICAL_TURN) * size


def _log_rotation(R: np.ndarray) -> np.ndarray:
    cos_angle = min(1.0, max(-1.0, (np.trace(R) - 1.0) / 2.0))
    angle = math.acos(cos_angle)
    w = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    s = math.sin(angle)
    return w * (angle / s) if s > 1e-9 else w


def _dark_variance(residual: np.ndarray, V: np.ndarray, hat: np.ndarray, threshold: float) -> float:
    """REML estimate of one variance σ² added to every residual component (independent), 0 unless 2·Δlog L
    against σ² = 0 passes *threshold* (as the joint fit's noise between segments)."""
    from scipy.optimize import minimize_scalar

    R = np.eye(residual.size) - hat
    C = R @ V @ R.T
    values, vectors = np.linalg.eigh(0.5 * (C + C.T))
    keep = values > 1e-9 * values.max()
    if keep.sum() == 0:
        return 0.0
    U = vectors[:, keep] / np.sqrt(values[keep])
    y = U.T @ residual
    lam, Q = np.linalg.eigh(U.T @ R @ R.T @ U)
    lam = np.maximum(lam, 0.0)
    z2 = (Q.T @ y) ** 2
    scale = float(np.median(np.diag(C)))

    def negative_log_likelihood(log_ratio):
        s2 = scale * math.exp(log_ratio)
        return 0.5 * float(np.sum(np.log1p(s2 * lam) + z2 / (1.0 + s2 * lam)))

    result = minimize_scalar(negative_log_likelihood, bounds=(-12 * math.log(10), 8 * math.log(10)), method="bounded")
    gain = -float(result.fun) + 0.5 * float(y @ y)
    return scale * math.exp(result.x) if 2.0 * gain > threshold else 0.0


def fit_moves(recording, fit, transitions, unused, noise, progress=None) -> MoveFit | None:
    """Kg from the transitions (module docstring), given the joint fit *fit* (its θ̂, gain and sources).

    *noise* is the recording's :class:`plansim.fit.noise.NoiseEstimate` (its channels' N, B, K and q). The
    inputs are kept, propagated and judged as the joint fit's are (:mod:`plansim.fit.budget`), and the noise between
    moves is taken at the joint fit's likelihood-ratio threshold (:data:`plansim.fit.between.BETWEEN_LR_THRESHOLD`).
    Returns None when fewer than :data:`MIN_TRANSITIONS` transitions are usable. *progress*, if given, is called
    as ``progress(starts, None)`` after each start of the search for Kg (a search does not know its length: the
    later groups of starts are tried only where the earlier ones fail).
    """
    if len(transitions) < MIN_TRANSITIONS:
        return None
    used = list(fit.used)
    pose_row = {k: used.index(k) for t in transitions for k in (t.before, t.after)}
    means = np.asarray(fit.observed, dtype=float)
    theta = np.asarray(fit.theta, dtype=float)
    joint_identified = set(fit.identifiability.identified)
    symmetrise = [(i, j) for i in range(3) for j in range(i + 1, 3)
                  if not {f"Ka{'xyz'[i]}{'xyz'[j]}", f"Ka{'xyz'[j]}{'xyz'[i]}"} <= joint_identified]
    # a g-sensitivity the joint fit does not identify is wherever its null space left it (a share of the bias, when
    # every pose has one up axis): the moves hold it at 0 with a Type B u instead (module docstring)
    held_g = [name for name in G_NAMES if name not in joint_identified]
    theta = theta.copy()
    theta[[PARAMETER_INDEX[name] for name in held_g]] = 0.0
    moves = _Moves(recording, transitions, pose_row, means, theta, symmetrise)
    n_moves = len(transitions)
    notes = []

    # identifiability of Kg from the moves: ∂r/∂Kg at Kg = I on the recorded motion
    design = np.zeros((2 * n_moves, len(PARAMETER_NAMES)))
    vertical = []
    for m in range(n_moves):
        _, d = moves.one(m, np.eye(3), theta, means, details=True)
        design[2 * m:2 * m + 2, KG_INDEX] = d["jac"]
        vertical.append(d["about_vertical"])
    if all(vertical):
        raise MovesNotFitted("the moves between poses were left out: every one turns about the vertical, which leaves "
                             "gravity where it was, so they cannot tell the gyros' scale factors (a table's rates or "
                             "the turns' angles can, in the joint fit)")
    ident = identifiability(design, what="the moves between poses")
    kg_mask = ident.mask[KG_INDEX]
    if not kg_mask.any():  # the poses' fit stands; say why the moves add nothing
        samples = np.asarray(recording.samples, dtype=float)
        axes = ", ".join(sorted({"xyz"[int(np.argmax(np.abs(samples[t.start:t.stop, :3].sum(axis=0))))]
                                 for t in transitions}))
        raise MovesNotFitted(f"the {n_moves} moves between poses were left out: together they identify no single "
                             f"entry of the gyros' scale factors Kg (rank {ident.rank} of the 9, in combinations "
                             f"only; they turn mostly about {axes}). More moves, about each of the three axes, would "
                             "(a hand session whose rests are too short for the import leaves them inside its moves: "
                             "its short_rests warning)")
    basis = ident.basis[KG_INDEX]  # (9, rank): Kg = I + basis·z

    S = means.shape[0]

    def mean_sensitivity(Kg):
        """∂r/∂m (2M, 6S): the poses' mean outputs as the moves' model reads them directly."""
        L = np.zeros((2 * n_moves, 6 * S))
        for m, t in enumerate(transitions):
            for pose in (t.before, t.after):
                row = pose_row[pose]
                for c in range(6):
                    h = _STEP_GYRO if c < 3 else _STEP_ACCEL
                    up, down = means.copy(), means.copy()
                    up[row, c] += h
                    down[row, c] -= h
                    L[2 * m:2 * m + 2, 6 * row + c] += (moves.one(m, Kg, theta, up)
                                                        - moves.one(m, Kg, theta, down)) / (2 * h)
        return L

    def joint_sensitivity(Kg):
        """∂r/∂θ (2M, 39) for the entries of the joint estimate the model reads (Ka, Ba, G)."""
        D = np.zeros((2 * n_moves, len(PARAMETER_NAMES)))
        for name in _USED_FROM_JOINT:
            if name in held_g:
                continue
            k = PARAMETER_INDEX[name]
            up, down = theta.copy(), theta.copy()
            up[k] += _STEP_PARAMETER
            down[k] -= _STEP_PARAMETER
            D[:, k] = (moves.residuals(Kg, up, means) - moves.residuals(Kg, down, means)) / (2 * _STEP_PARAMETER)
        return D

    gyro_noise = noise.channels[:3]
    white_var = np.array([ch.white**2 for ch in gyro_noise])
    q2 = np.array([ch.quantisation_step**2 / 12.0 for ch in gyro_noise])

    def slow_var(T):
        """Variance of the gyro noise held over a move of T s: IEEE Std 952's B and K terms of the Allan model."""
        return np.array([(2.0 * math.log(2.0) / math.pi) * ch.bias_instability**2 + ch.rate_random_walk**2 * T / 3.0
                         for ch in gyro_noise])

    white_dof = max(float(sum(ch.static_samples - ch.static_segments for ch in gyro_noise)) / 3.0, 1.0)
    slow_dof = max(float(min(ch.static_segments for ch in gyro_noise)) - 1.0, 1.0)
    joint_gain = fit.gain  # (39, 6S)
    joint_sources = fit.sources
    held_sources = fit.held_sources if fit.held_sources is not None else Sources(joint_gain.shape[1])

    held_kg: list[int] = []

    def build(Kg, dark):
        sources = Sources(2 * n_moves)
        jacobian = np.zeros((2 * n_moves, 9))
        angles = np.zeros(n_moves)
        for m in range(n_moves):
            _, d = moves.one(m, Kg, theta, means, details=True)
            jacobian[2 * m:2 * m + 2] = d["jac"]
            angles[m] = d["angle"]
            E = moves.basis[m]
            per_sample = white_var[None, :] / moves.dt[m][:, None] + q2[None, :]  # (n, 3)
            C = E.T @ np.einsum("kia,ka,kja->ij", d["SM"], per_sample, d["SM"]) @ E
            values, vectors = np.linalg.eigh(0.5 * (C + C.T))
            for value, vector in zip(values, vectors.T):
                if value > 0:
                    column = np.zeros(2 * n_moves)
                    column[2 * m:2 * m + 2] = vector
                    sources.add(column, math.sqrt(value), white_dof, "noise")
            slow = slow_var(moves.duration[m])
            for c in range(3):
                column = np.zeros(2 * n_moves)
                column[2 * m:2 * m + 2] = d["SM_sum"][:, c]
                if slow[c] > 0:
                    sources.add(column, math.sqrt(slow[c]), slow_dof, "noise")
                if fit.site.earth_rate:
                    column = np.zeros(2 * n_moves)
                    column[2 * m:2 * m + 2] = d["S_sum"][:, c]
                    sources.add(column, EARTH_RATE / math.sqrt(3.0), math.inf, "site")
        total = mean_sensitivity(Kg) + joint_sensitivity(Kg) @ joint_gain  # L = ∂r/∂m + ∂r/∂θ·A
        for column, u, dof, kind in zip(joint_sources.columns, joint_sources.u, joint_sources.dof, joint_sources.kind):
            sources.add(total @ column, u, dof, kind)
        if dark > 0:
            for i in range(2 * n_moves):
                column = np.zeros(2 * n_moves)
                column[i] = 1.0
                sources.add(column, math.sqrt(dark), max(2 * n_moves - basis.shape[1], 1), "between")
        if fit.prior_gain is not None:  # the joint fit's data-sheet prior (its estimate's gain on the nominal)
            for column, u in zip((joint_sensitivity(Kg) @ fit.prior_gain).T, fit.held.limits):
                if np.any(column):
                    sources.add(column, u, math.inf, "data_sheet")
        # the joint fit's held_sources (its gain, not its weights, took them): here weighed by and propagated
        for column, u, dof, kind in zip(held_sources.columns, held_sources.u, held_sources.dof, held_sources.kind):
            sources.add(total @ column, u, dof, kind)
        for k in held_kg:  # the Kg entries held at nominal (_weak_entries)
            sources.add(jacobian[:, k], fit.held.gyro, math.inf, "held")
        for name in held_g:  # the g-sensitivities held at 0: ∂r/∂g by central differences
            k = PARAMETER_INDEX[name]
            up, down = theta.copy(), theta.copy()
            up[k] += _STEP_PARAMETER
            down[k] -= _STEP_PARAMETER
            column = (moves.residuals(Kg, up, means) - moves.residuals(Kg, down, means)) / (2 * _STEP_PARAMETER)
            if np.any(column):
                sources.add(column, fit.held.g_sensitivity, math.inf, "held")
        return sources, jacobian, angles

    tried = 0  # starts of the search, over every call of solve: the progress shown

    def solve(V, Kg_start):
        values, vectors = _floored_eigh(V)
        W = (vectors / np.sqrt(values)).T

        def kg(z):
            return np.eye(3) + (basis @ z).reshape(3, 3)

        def fun(z):
            return W @ moves.residuals(kg(z), theta, means)

        def jac(z):
            Kg = kg(z)
            J = np.vstack([moves.with_jacobian(m, Kg, theta, means)[1] for m in range(n_moves)])
            return W @ J @ basis

        best, plain = None, None
        groups = Kg_start if isinstance(Kg_start, list) else [Kg_start]
        poor = chi2_distribution.isf(POOR_FIT, max(2 * n_moves - basis.shape[1], 1))
        for index, group in enumerate(groups):  # a later group only where the earlier ones ended with a scale
            # factor far from ±1, or with misses no noise explains (2·cost = χ² against the predicted noise beyond its
            # POOR_FIT point); the permutations (the last of three groups) only where they ended far from ±1: a real
            # hand session's moves all miss the POOR_FIT point, and the 40 permutations would cost each such fit
            # 9 s (the Ferraris session's, 15 s before) to find the gyros as wired
            near_one = best is not None and np.all(np.abs(np.diag(kg(best.x)) ** 2 - 1.0) <= FAR_OFF)
            if near_one and (2.0 * best.cost <= poor or index == PERMUTED_GROUP):
                break
            many = len(groups) > 1 or np.ndim(group) == 3
            for number, start in enumerate(np.atleast_3d(group).transpose(2, 0, 1) if np.ndim(group) == 3
                                           else [group]):
                z0 = np.linalg.lstsq(basis, (start - np.eye(3)).ravel(), rcond=None)[0]
                try:
                    result = least_squares(fun, z0, jac=jac, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                                           max_nfev=SCREEN_EVALUATIONS if many else MAX_EVALUATIONS)
                except np.linalg.LinAlgError:  # a step landed on a singular Kg: this start is lost, not the fit
                    result = None
                nonlocal tried
                tried += 1
                if progress is not None:
                    progress(tried, None)
                if index == 0 and number == 0:
                    plain = result  # the first start: every gyro as wired, K near +1
                if result is None or (result is not plain and _implausible(kg(result.x))):
                    continue
                if best is None or result.cost < best.cost:
                    best = result
        if best is None:
            raise MovesNotFitted("the moves between poses were left out: from every start, the search for the gyro "
                                 "scale factors that fit them stepped onto a singular Kg — the angles the gyros "
                                 "integrate over the moves do not agree with the change of gravity between the poses. "
                                 "Check the gyros' --units, --columns and signs, and " + SAMPLE_RATE_HINT)

        def polish(result):  # a start screened only (SCREEN_EVALUATIONS, not converged): on to the full budget
            if result is None or result.status != 0 or result.nfev >= MAX_EVALUATIONS:
                return result
            try:
                return least_squares(fun, result.x, jac=jac, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                                     max_nfev=MAX_EVALUATIONS - result.nfev)
            except np.linalg.LinAlgError:
                return result

        # the best start, and the gyros as wired that the next rule compares it with
        best, plain = (polish(best),) * 2 if best is plain else (polish(best), polish(plain))
        # a flipped pair of axes (a half turn of the gyro triad) that fits no better than the gyros as wired is not
        # taken: poses near the six axes cannot tell the two apart (each gravity direction is its own image)
        if plain is not None and best is not plain and np.all(np.diag(kg(plain.x)) > 0) and \
                2.0 * (plain.cost - best.cost) <= SIGN_EVIDENCE:
            best = plain
        return kg(best.x), W

    # the entries the moves determine only weakly (WEAK_DIRECTION_U, from the information at Kg = I with the noise
    # the moves predict, and again at the fitted Kg with the noise between moves) are held at nominal, with a Type B
    # u that the moves weigh by and propagate
    first = build(np.eye(3), 0.0)
    ident, weak = _weak_entries(ident, design, first[0].covariance(), "the moves between poses", fit.held.gyro,
                                limit=fit.held.data_sheet["Kg"])
    while True:
        if weak:
            held_kg[:] = [KG_NAMES.index(name) for name in weak]
            kg_mask = ident.mask[KG_INDEX]
            if not kg_mask.any():
                raise MovesNotFitted("the moves between poses were left out: " + next(iter(weak.values())))
            basis = ident.basis[KG_INDEX]
            first = build(np.eye(3), 0.0)
        Kg = np.eye(3)
        dark = 0.0
        V_predicted = None
        for iteration in range(3):
            sources, jacobian, angles = build(Kg, dark) if iteration else first
            V = sources.covariance()
            if iteration == 0:
                # from each sign of the three scale factors: a gyro wired with its sign flipped against the
                # accelerometers (or an accelerometer against the gyros) sits near Kg_ii = −1, where a start at +1
                # stops in a local minimum (every move's miss of the order of its angle)
                starts = [np.stack([unit * np.diag(signs) for signs in SIGN_STARTS], axis=2) for unit in UNIT_STARTS]
                starts.append(np.stack(PERMUTED_STARTS, axis=2))  # starts[PERMUTED_GROUP]
                Kg, W = solve(V, starts)
                permuted = axes_permuted(Kg)
                if permuted:
                    raise MovesNotFitted("the moves between poses were left out: " + permuted)
                continue
            if iteration == 1:
                V_predicted = V
            Kg, W = solve(V, Kg)
            r = moves.residuals(Kg, theta, means)
            Jz = jacobian @ basis
            Vinv = _floored_inverse(V)
            hat = Jz @ _solve_information(Jz.T @ Vinv @ Jz, Jz.T @ Vinv, Kg)
            if iteration == 1:
                residual_predicted = r
                dark = _dark_variance(r, V, hat, BETWEEN_LR_THRESHOLD)
                if dark == 0.0:
                    break
        if math.sqrt(dark) > MOVES_SCATTER_LIMIT:  # before which entries they determine: they agree with no Kg
            raise MovesNotFitted(f"the moves between poses were left out: at the gyro scale factors that fit them best "
                                 f"({_shown_kg(Kg)}) they still miss the change of gravity between the poses by "
                                 f"{math.degrees(math.sqrt(dark)):.3g} deg per component beyond their noise (more than "
                                 f"{math.degrees(MOVES_SCATTER_LIMIT):g} deg: a hand session's miss by a fraction of a "
                                 "degree) — the angles the gyros integrate over the moves do not agree with the poses. "
                                 "Check the gyros' --units, --columns and signs, " + SAMPLE_RATE_HINT + ", and whether "
                                 "the moves hold motion the log does not (the unit turned over inside a time gap)")
        sources, jacobian, angles = build(Kg, dark)
        V = sources.covariance()
        # a combination the fitted moves, with their noise between moves, still determine only weakly (a cross-coupling
        # that a whole turn shows at second order only: first order at Kg = I passed on the turns' ramps)
        fitted = np.zeros_like(design)
        fitted[:, KG_INDEX] = jacobian
        fitted[:, KG_INDEX[held_kg]] = 0.0
        ident, more = _weak_entries(ident, fitted, V, "the moves between poses", fit.held.gyro, at="the fitted Kg",
                                    scale=float(np.mean(np.abs(np.diag(Kg)))), limit=fit.held.data_sheet["Kg"])
        if not more:
            break
        weak.update(more)
    Vinv = _floored_inverse(V)
    Jz = jacobian @ basis
    information = Jz.T @ Vinv @ Jz
    gain_z = _solve_information(information, Jz.T @ Vinv, Kg)  # (rank, 2M)
    gain = np.zeros((len(PARAMETER_NAMES), 2 * n_moves))
    gain[KG_INDEX] = -basis @ gain_z  # Kg moves against the residual it explains
    mask = np.zeros(len(PARAMETER_NAMES), bool)
    mask[KG_INDEX[kg_mask]] = True
    method = propagate(METHOD_MOVES, gain, sources, mask)
    estimate = np.full(len(PARAMETER_NAMES), math.nan)
    estimate[KG_INDEX[kg_mask]] = Kg.ravel()[kg_mask]
    method = type(method)(METHOD_MOVES, estimate, method.u, method.dof, method.contributions,
                          "Tedaldi et al. 2014, gravity sequence of the moves between poses")
    r = moves.residuals(Kg, theta, means)
    hat = Jz @ gain_z
    project = np.eye(2 * n_moves) - hat
    residual_sd = np.sqrt(np.maximum(np.diag(project @ V @ project.T), 0.0)).reshape(n_moves, 2)
    Vp = V_predicted if V_predicted is not None else V
    chi2 = float(residual_predicted @ np.linalg.pinv(Vp) @ residual_predicted) if V_predicted is not None else \
        float(r @ Vinv @ r)
    dof = 2 * n_moves - basis.shape[1]

    # the frame: Kg's cross-couplings are in the case frame only where the joint fit identifies Ka's
    identified, relative, not_identified = [], {}, {}
    for a in range(3):
        for b in range(3):
            name = f"Kg{'xyz'[a]}{'xyz'[b]}"
            if not kg_mask[3 * a + b]:
                not_identified[name] = weak.get(name) or ident.not_identified.get(name, "the moves do not identify it")
                continue
            if a == b or (min(a, b), max(a, b)) not in symmetrise:
                identified.append(name)
            else:
                x, y = "xyz"[a], "xyz"[b]
                relative[name] = (f"relative to the accelerometer triad only: the moves see the body through the "
                                  "accelerometers, whose rotation no pose placed by hand fixes; the gravity_sequence "
                                  f"estimate is in the frame where Ka is symmetric, i.e. Kg{x}{y} − (Ka{x}{y} − "
                                  f"Ka{y}{x})/2 to first order")
    # a negative scale factor (a gyro or an accelerometer whose sign the log has the other way) is said once, for
    # the moves and the poses' fit together, by plansim.fit.identify.reversed_axis_notes
    scaled = [a for a in range(3) if kg_mask[4 * a] and not 0.5 <= abs(Kg[a, a]) <= 2.0]
    if scaled:
        degrees = [a for a in scaled if abs(abs(Kg[a, a]) / math.degrees(1.0) - 1.0) < 0.02
                   or abs(abs(Kg[a, a]) * math.degrees(1.0) - 1.0) < 0.02]
        several = len(scaled) > 1
        notes.append(f"the scale factor{'s' if several else ''} of the {', '.join('xyz'[a] for a in scaled)} "
                     f"gyro{'s are' if several else ' is'} far from 1 ("
                     + ", ".join(f"{Kg[a, a]:+.4g}" for a in scaled) + "): "
                     + ("a factor of 180/π from 1, the gyros' units mistaken (deg/s read as rad/s, or the reverse; "
                        "check --units)" if degrees else
                        "check the gyros' --units and --scale, " + SAMPLE_RATE_HINT + ", and that the moves are whole "
                        "turns between the poses"))
    if dark > 0:
        notes.append(f"the moves' residuals scatter beyond the predicted noise: {math.degrees(math.sqrt(dark)):.3g} "
                     "deg per component between moves, estimated from them, enters every u (kind 'between')")
    return MoveFit(transitions=tuple(transitions), unused=dict(unused), method=method, identified=tuple(identified),
                   relative=relative, not_identified=not_identified, residual=r.reshape(n_moves, 2),
                   residual_sd=residual_sd, angle=angles, duration=moves.duration, chi2=chi2, chi2_dof=dof,
                   chi2_verdict=chi2_verdict(chi2, dof), between_sd=math.sqrt(dark),
                   between_dof=float(dof), notes=tuple(notes), covariance=V)
