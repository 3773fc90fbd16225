"""Which of the 39 parameters a recording's segments identify: the rank and null space of the design.

The segment means are linear in the parameters, ``m = J·θ`` (:mod:`plansim.fit.model`). A parameter
θ_k is identified when every θ that fits the noise-free means equally well has the same θ_k, i.e.
when the unit vector e_k is orthogonal to the null space of J (it lies in J's row space). Computed on
J with every column scaled to unit length (so that a rate in rad/s and a bias in m/s² weigh alike),
by the singular value decomposition: singular values below :data:`RANK_TOLERANCE` times the largest
span the null space; θ_k is identified when its component in that null space is below
:data:`NULL_TOLERANCE`.

J is evaluated at the nominal point (Kg = Ka = I, the rest 0) on the recording's *designed*
excitation: the table's rates and gravity, without the Earth rate. The Earth rate (at most 7.3e-5 rad/s,
15 °/h) stays a known input of the fit, but on its own it does not count as identifying a parameter:
it would "identify" Kg from static poses through 15 °/h of input and P through Ω² ≈ 5e-9 (rad/s)²,
with uncertainties of 10 % and 10⁴ m/s² per (rad/s)² for a MEMS unit — mathematically, never usefully
(docs/fitting.md). A parameter that is not identified is reported as NaN with the reason, never given a value.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import chi2 as chi2_distribution

from plansim.model.parameters import GROUPS, PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS

#: standard uncertainty of a Kg entry that a fit holds at its nominal value (1 or 0) while it still matters: one the
#: recording does not identify but the Earth rate reaches, or one the moves between poses determine only weakly:
#: 1 %, the scale-factor error and misalignment a MEMS gyro's data sheet allows (docs/fitting.md); its effect is
#: ≤ 0.01·7.3e-5 rad/s on a segment mean
HELD_KG_UNCERTAINTY = 0.01
#: standard uncertainty of the symmetric part of a pair of Ka's cross-couplings (Ka_ij = Ka_ji: a shear of the
#: triad) that poses placed by hand do not determine (at first order a tilt of an axis-aligned pose is a
#: cross-coupling) but that still moves what the fit uses (a pose a few degrees off its axis; the moves' gravity
#: directions): held at 0 with this Type B uncertainty, 1 %, the cross-axis sensitivity a MEMS accelerometer's data
#: sheet allows (docs/fitting.md)
HELD_KA_UNCERTAINTY = 0.01
#: standard uncertainty of a g-sensitivity entry (rad/s per m/s²) that a fit holds at 0 because the recording does not
#: identify it but a turn still feels it (the moves between poses of a recording whose poses cannot separate it from
#: the bias): 0.1 (°/s)/g, the linear-acceleration sensitivity a consumer MEMS gyro's data sheet states (e.g. the
#: MPU-6050's); a full turn of T seconds about an axis across gravity feels it as an angle of up to 0.1°/s·T
HELD_G_UNCERTAINTY = math.radians(0.1) / 9.80665
#: per parameter group, the standard uncertainty (SI) beyond which an estimate says no more of a MEMS unit than a
#: consumer data sheet does before any calibration (the MPU-6050's: scale factors within ±3 %, cross-axis
#: sensitivity ±2 %, a gyro's zero-rate offset ±20 °/s, an accelerometer's zero-g offset ±50–80 mg, a gyro's
#: linear-acceleration sensitivity 0.1 (°/s)/g typical): scale factors and cross-couplings 0.1; gyro bias 20 °/s;
#: g-sensitivity 1 (°/s)/g, ten times the typical value; accelerometer bias 1 m/s² (0.1 g); accelerometer
#: sensitivity to squared rate 1 m (a lever arm no fixture has). A parameter the segments identify (the design's
#: rank) but leave with a larger u is reported as *determined only weakly* (:func:`weakly_determined`): the rank
#: counts every direction noise-free data would settle, and poses placed by hand whose gravity directions lie in
#: one cap leave an accelerometer's scale factor at 0.9 ± 0.5 and its bias at 6 ± 21 m/s², "identified"
UNINFORMATIVE_U = {"Kg": 0.1, "Bg": math.radians(20.0), "G": math.radians(1.0) / 9.80665, "Ka": 0.1, "Ba": 1.0,
                   "P": 1.0}
#: :data:`UNINFORMATIVE_U` per parameter, in the order of :data:`~plansim.model.parameters.PARAMETER_NAMES` (SI)
UNINFORMATIVE_LIMITS = np.array([UNINFORMATIVE_U[p.group] for p in PARAMETERS])
#: how a report names the nuisance parameters of poses and turns placed by hand, together
HAND_PLACEMENT = "the hand placement (the tilts of poses placed by hand, the axes of turns by hand)"
#: singular values below this fraction of the largest (of the column-scaled design) count as zero: the
#: design's entries are exact sums of gravity and rates, so rounding leaves ~1e-15; 1e-9 keeps every
#: genuine direction down to a rate point of 1e-9 of the largest
RANK_TOLERANCE = 1e-9
#: a parameter is identified when the norm of its unit vector's projection onto the null space is below this
NULL_TOLERANCE = 1e-6


@dataclass(frozen=True)
class HeldPriors:
    """The Type B standard uncertainties of what a fit holds at its nominal value because the recording does not
    determine it, while it still moves what the fit uses (docs/fitting.md): a gyro's scale factor or cross-coupling
    (``gyro``, dimensionless), the symmetric part of a pair of the accelerometers' cross-couplings
    (``accel_cross``, dimensionless), a gyro's g-sensitivity (``g_sensitivity``, rad/s per m/s²). The defaults are
    a consumer MEMS data sheet's (:data:`HELD_KG_UNCERTAINTY`, :data:`HELD_KA_UNCERTAINTY`,
    :data:`HELD_G_UNCERTAINTY`); a lab's scenario may state its own (``[reduction]`` ``held_gyro``,
    ``held_accel_cross``, ``held_g_sensitivity``). ``source`` says where they came from, for the report.

    ``data_sheet``: per parameter group (Kg, Bg, G, Ka, Ba, P), the standard uncertainty (SI) beyond which an
    estimate says no more of the unit than its data sheet — the limits of *determined only weakly* and the data
    sheet's prior of the joint fit (docs/fitting.md, Identifiability); default :data:`UNINFORMATIVE_U`, a consumer
    MEMS data sheet's; a lab's scenario may state its unit's (``[reduction]`` ``data_sheet_kg`` … ``data_sheet_p``).
    """

    gyro: float = HELD_KG_UNCERTAINTY
    accel_cross: float = HELD_KA_UNCERTAINTY
    g_sensitivity: float = HELD_G_UNCERTAINTY
    source: str = "data-sheet defaults"
    data_sheet: dict = field(default_factory=lambda: dict(UNINFORMATIVE_U))

    def __post_init__(self):
        for name in ("gyro", "accel_cross", "g_sensitivity"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeError(f"HeldPriors.{name} = {value!r}: expected a number")
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"HeldPriors.{name} = {value!r}: a standard uncertainty must be finite and >= 0")
        if not isinstance(self.data_sheet, dict):
            raise TypeError(f"HeldPriors.data_sheet = {self.data_sheet!r}: expected a dict of group -> u")
        unknown = set(self.data_sheet) - set(UNINFORMATIVE_U)
        if unknown:
            raise ValueError(f"HeldPriors.data_sheet has group(s) {sorted(unknown)}: allowed "
                             f"{list(UNINFORMATIVE_U)}")
        for group, value in self.data_sheet.items():
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeError(f"HeldPriors.data_sheet[{group!r}] = {value!r}: expected a number")
            if not (math.isfinite(value) and value > 0):
                raise ValueError(f"HeldPriors.data_sheet[{group!r}] = {value!r}: a standard uncertainty must be "
                                 "finite and > 0")
        object.__setattr__(self, "data_sheet", dict(UNINFORMATIVE_U) | dict(self.data_sheet))

    def describe_data_sheet(self) -> str:
        """The data sheet's u per group in display units, for a report: 'Kg 0.1, Bg 7.2e+04 deg/h, …'."""
        parts = []
        for group, value in self.data_sheet.items():
            spec = next(p for p in PARAMETERS if p.group == group)
            unit = spec.unit_suffix
            parts.append(f"{group} {value / spec.display_factor:.3g}{unit}")
        return ", ".join(parts)

    @property
    def limits(self) -> np.ndarray:
        """:attr:`data_sheet` per parameter, in the order of :data:`~plansim.model.parameters.PARAMETER_NAMES`
        (SI)."""
        return np.array([self.data_sheet[p.group] for p in PARAMETERS])


@dataclass(frozen=True)
class Identifiability:
    """The outcome of :func:`identifiability`.

    Attributes
    ----------
    identified : tuple of str
        Parameters the segments determine, in the order of :data:`~plansim.model.parameters.PARAMETER_NAMES`.
    not_identified : dict
        Parameter -> the reason it is not identified.
    rank : int
        Rank of the design: the number of independent combinations of parameters the segments determine.
    row_space : (rank, 39 + n) array
        Orthonormal basis of the determined combinations in the column-scaled coordinates (rows), over the
        39 parameters and the n nuisance parameters (the tilts of hand-placed poses).
    scale : (39 + n,) array
        The column norms of the design (0 for a parameter the segments do not depend on): θ_k = z_k / scale_k.
    """

    identified: tuple[str, ...]
    not_identified: dict[str, str]
    rank: int
    row_space: np.ndarray = field(repr=False)
    scale: np.ndarray = field(repr=False)

    @property
    def mask(self) -> np.ndarray:
        """(39,) True where identified."""
        return np.array([name in self.identified for name in PARAMETER_NAMES])

    def outside_row_space(self, scaled: np.ndarray) -> float:
        """The part of *scaled* (39 + n, in the column-scaled coordinates) outside the determined combinations'
        row space, relative to its length (0: wholly within it)."""
        size = float(np.linalg.norm(scaled))
        within = self.row_space.T @ (self.row_space @ scaled)
        return float(np.linalg.norm(scaled - within)) / size if size > 0 else 0.0

    @property
    def basis(self) -> np.ndarray:
        """(39 + n, rank): (θ, nuisance) − their start = basis · z spans exactly what the segments determine."""
        inverse = np.divide(1.0, self.scale, out=np.zeros_like(self.scale), where=self.scale > 0)
        return inverse[:, None] * self.row_space.T


def identifiability(design: np.ndarray, what: str = "the recording's segments", nuisance=None) -> Identifiability:
    """Which parameters the design ``J`` (rows: segment means, columns: the 39 parameters) identifies.

    Parameters
    ----------
    design : (R, 39) array
        ∂(segment means)/∂θ at the nominal point, the Earth rate left out (:meth:`MeanModel.parameter_jacobian`).
    what : str
        How to name the data in the reasons.
    nuisance : (R, n) array, optional
        ∂(segment means)/∂(nuisance parameters) (the tilts of hand-placed poses): they take part in the null
        space — a parameter that a tilt can stand in for is not identified — but are not reported.

    Returns
    -------
    Identifiability
    """
    design = np.asarray(design, dtype=float)
    if design.ndim != 2 or design.shape[1] != len(PARAMETER_NAMES):
        raise ValueError(f"design: expected shape (R, {len(PARAMETER_NAMES)}), got {design.shape}")
    extra = np.zeros((design.shape[0], 0)) if nuisance is None else np.asarray(nuisance, dtype=float)
    names = list(PARAMETER_NAMES) + [f"tilt {k // 2} ({'EN'[k % 2]})" for k in range(extra.shape[1])]
    full = np.hstack([design, extra])
    scale = np.linalg.norm(full, axis=0)
    largest = scale.max() if scale.size else 0.0
    enters = scale > 1e-12 * largest if largest > 0 else np.zeros(len(scale), bool)
    scale = np.where(enters, scale, 0.0)
    scaled = full[:, enters] / scale[enters]
    n = int(enters.sum())
    if n:
        _, singular, vt = np.linalg.svd(scaled, full_matrices=True)
        rank = int(np.sum(singular > RANK_TOLERANCE * singular[0])) if singular.size else 0
        null = vt[rank:].T  # (n, n - rank)
        row = vt[:rank]
    else:
        rank, null, row = 0, np.zeros((0, 0)), np.zeros((0, 0))
    row_space = np.zeros((rank, len(names)))
    row_space[:, enters] = row
    projector = null @ null.T if null.size else np.zeros((n, n))
    entering = [name for name, e in zip(names, enters) if e]
    identified, not_identified = [], {}
    for k, name in enumerate(PARAMETER_NAMES):
        if not enters[k]:
            not_identified[name] = (f"{what} do not excite it: no table rate or gravity reaches it (the Earth rate "
                                    "alone does not count)")
            continue
        j = entering.index(name)
        if np.sqrt(max(projector[j, j], 0.0)) < NULL_TOLERANCE:
            identified.append(name)
            continue
        partners = [entering[i] for i in np.argsort(-np.abs(projector[j]))
                    if i != j and abs(projector[j, i]) > NULL_TOLERANCE]
        tilts = any(p.startswith("tilt") for p in partners)
        partners = [p for p in partners if not p.startswith("tilt")]
        shown = ", ".join(partners[:6]) + (f" and {len(partners) - 6} more" if len(partners) > 6 else "")
        if tilts:
            not_identified[name] = (f"{what} see it only in combination with {HAND_PLACEMENT}"
                                    + (f" and {shown}" if shown else ""))
        elif partners:
            not_identified[name] = f"{what} see it only in combination with {shown}"
        else:
            not_identified[name] = f"{what} see it only in combination with other parameters"
    return Identifiability(tuple(identified), not_identified, rank, row_space, scale)


def weakly_determined(identified, u: np.ndarray, data_sheet: np.ndarray | None = None,
                      limits: np.ndarray | None = None) -> dict:
    """name -> why, for each parameter in *identified* whose standard uncertainty *u* ((39,) SI, in the order of
    :data:`~plansim.model.parameters.PARAMETER_NAMES`; NaN where not estimated) exceeds its group's
    :data:`UNINFORMATIVE_U`, or, where the fit carried the data sheet as a prior, whose u owes more than half its
    variance to that prior (*data_sheet*: (39,) the prior's part of u; *limits* (39,) the groups' u, default
    :data:`UNINFORMATIVE_LIMITS`, or a lab's :attr:`HeldPriors.limits`): identified by the design's rank, but left
    by the data where its estimate says no more of the unit than a data sheet. The estimate and its u stay in the
    report; this says how to read them."""
    out = {}
    u = np.asarray(u, dtype=float)
    if u.shape != (len(PARAMETERS),):
        raise ValueError(f"u has shape {u.shape}: expected ({len(PARAMETERS)},), one per parameter")
    prior = np.zeros(len(PARAMETERS)) if data_sheet is None else np.nan_to_num(np.asarray(data_sheet, dtype=float))
    if prior.shape != (len(PARAMETERS),):
        raise ValueError(f"data_sheet has shape {prior.shape}: expected ({len(PARAMETERS)},), one per parameter")
    limits = UNINFORMATIVE_LIMITS if limits is None else np.asarray(limits, dtype=float)
    for k, spec in enumerate(PARAMETERS):
        limit = limits[k]
        if spec.name not in identified or not math.isfinite(u[k]):
            continue
        factor = spec.display_factor
        unit = spec.unit_suffix
        if u[k] > limit:
            why = (f"u = {u[k] / factor:.3g}{unit}, above {limit / factor:.3g}{unit}, beyond which an estimate says "
                   "no more of a MEMS unit than its data sheet")
        elif prior[k] ** 2 > 0.5 * u[k] ** 2:
            why = (f"u = {u[k] / factor:.3g}{unit}, of it {prior[k] / factor:.3g}{unit} from the data sheet's prior "
                   f"(u {limit / factor:.3g}{unit}), which holds what the data leave open: the estimate says little "
                   "more of the unit than its data sheet")
        else:
            continue
        out[spec.name] = (f"identified by the segments' geometry, but with {why}: read it as not determined (more "
                          "gravity directions or rates in the schedule would determine it)")
    return out


#: the family-wise level at which :func:`data_sheet_conflict` says the data contradict a group of the data sheet
#: (Bonferroni over the groups it tests)
DATA_SHEET_CONFLICT_ALPHA = 0.05


def data_sheet_conflict(offset: np.ndarray, limits: np.ndarray, prior_gain: np.ndarray, fitted,
                        alpha: float = DATA_SHEET_CONFLICT_ALPHA) -> dict:
    """group -> ``{statistic, dof, p_value, contradicted}``: does the recording contradict the data sheet's entry for
    each group of eq. (1)/(2) (Kg, Bg, G, Ka, Ba, P), where the joint fit carried the data sheet as a prior?

    The prior enters the fit as whitened pseudo-observations r_k = (θ_k − nominal_k)/U_k of unit variance
    (:func:`plansim.fit.solve.solve`). At the solution their residuals are r = (θ̂ − nominal)/U and, if the data
    sheet is right (the unit's parameter one draw of nominal ± U), their covariance is I − H, with H = P·A·P⁻¹
    the prior rows' block of the augmented system's hat matrix (P = diag(1/U), A = ∂θ̂/∂nominal, *prior_gain*).
    For a group g the statistic is the leverage-corrected residual

        T_g = r_gᵀ (I − H)_gg⁺ r_g,   ~ χ²(rank (I − H)_gg) under the data sheet,

    which is also the fall of the fit's whole objective when the group's prior rows are left out (the deletion
    identity of least squares, Cook & Weisberg 1982, ch. 3): the likelihood ratio of "this group's data sheet
    entry is wrong" against "it holds". A direction the data do not see has leverage 1 and adds no degree of
    freedom: what only the prior says cannot contradict it. A group is *contradicted* where its p-value is below
    *alpha* over the number of groups tested (Bonferroni).

    Parameters
    ----------
    offset : (39,) array
        θ̂ − nominal, SI, in the order of :data:`~plansim.model.parameters.PARAMETER_NAMES`.
    limits : (39,) array
        The data sheet's u per parameter (:attr:`HeldPriors.limits`), SI, > 0.
    prior_gain : (39, 39) array
        ∂θ̂/∂nominal of the fit with the prior.
    fitted : (39,) bool
        The parameters the fit estimates (the others are held and say nothing).
    alpha : float
        Family-wise level over the groups, 0 < alpha < 1.
    """
    n = len(PARAMETERS)
    offset = np.asarray(offset, dtype=float)
    limits = np.asarray(limits, dtype=float)
    gain = np.asarray(prior_gain, dtype=float)
    fitted = np.asarray(fitted, dtype=bool)
    for name, value, shape in (("offset", offset, (n,)), ("limits", limits, (n,)), ("prior_gain", gain, (n, n)),
                               ("fitted", fitted, (n,))):
        if value.shape != shape:
            raise ValueError(f"{name} has shape {value.shape}: expected {shape}")
    if not np.all(limits > 0):
        raise ValueError(f"limits: every data-sheet u must be > 0, got {limits[~(limits > 0)][:3]}")
    if not 0 < alpha < 1:
        raise ValueError(f"alpha = {alpha!r}: must be between 0 and 1")
    r = np.where(fitted, offset / limits, 0.0)
    hat = gain * limits[None, :] / limits[:, None]
    residual_cov = np.eye(n) - 0.5 * (hat + hat.T)
    out = {}
    for group in GROUPS:
        idx = [k for k, p in enumerate(PARAMETERS) if p.group == group and fitted[k] and math.isfinite(r[k])]
        if not idx:
            continue
        block = residual_cov[np.ix_(idx, idx)]
        values, vectors = np.linalg.eigh(0.5 * (block + block.T))
        keep = values > RANK_TOLERANCE  # leverage 1 to rounding: a direction only the prior sees
        if not keep.any():
            continue
        projected = vectors[:, keep].T @ r[idx]
        statistic = float(np.sum(projected**2 / values[keep]))
        dof = int(keep.sum())
        out[group] = {"statistic": statistic, "dof": dof, "p_value": float(chi2_distribution.sf(statistic, dof))}
    for entry in out.values():
        entry["contradicted"] = bool(entry["p_value"] < alpha / len(out))
    return out


def describe_conflict(entry: dict) -> str:
    """One group's :func:`data_sheet_conflict` entry in words, the one wording of the note, the report and the
    ``--out`` attribute: 'chi2 3.209e+06 on 3 dof, p < 1e-300' (a p-value the χ² survival function underflows to 0
    is written as that bound), with ', contradicted' where it is, and then the
    group's estimates from the data alone (``data_alone``, :func:`plansim.fit.joint.fit_recording`), in display
    units, each to the last digit of its u's two: '; the data alone: Bax 3270.2 ± 2.6 ug, …' — what the user
    needs to state the data sheet again."""
    p_value = entry["p_value"]
    text = (f"chi2 {entry['statistic']:.4g} on {entry['dof']} dof, p "
            + (f"= {p_value:.3g}" if p_value > 0 else "< 1e-300") + (", contradicted" if entry["contradicted"] else ""))
    alone = entry.get("data_alone") or {}
    if alone and entry["contradicted"]:
        parts = []
        for name, (estimate, u) in alone.items():
            spec = PARAMETERS[PARAMETER_INDEX[name]]
            value, spread = estimate / spec.display_factor, u / spec.display_factor
            # the estimate to the last digit of its u's two (GUM 7.2.6)
            places = min(15, max(0, 1 - math.floor(math.log10(spread)))) if math.isfinite(spread) and spread > 0 \
                else None
            shown = f"{value:.6g}" if places is None else f"{value:.{places}f}"
            parts.append(f"{name} {shown} ± {spread:.2g}{spec.unit_suffix}")
        text += "; the data alone: " + ", ".join(parts)
    return text


#: a scale factor within this of ±1 and cross-couplings within this of 0 are a unit's, read with its axes' signs as
#: logged: only then is a negative scale factor a reversed axis (a MEMS unit's scale errors are a few %, its
#: cross-couplings 1-2 %; a moves' fit that went astray — a log sampled too slowly for its moves, a wrong sample
#: rate — lands anywhere: Kgxx = -2.03 with Kgyx = -0.86, or Kgyy = -0.33, on a real 3 Hz tumble log)
REVERSAL_TOLERANCE = 0.2
#: where the gyros' integrated angles disagree with the poses, the sample rate is a cause as likely as the units:
#: without a time column it is --sample-rate's, and a rate off by a factor scales every angle by it (a real tumble
#: log read at 10 Hz for 3.36 Hz turned each 90° turn into 30°)
SAMPLE_RATE_HINT = ("the sample rate (a log without a time column is read at --sample-rate: a rate off by a factor "
                    "scales every integrated angle by it)")


def _like_signed_identity(estimate, prefix: str) -> bool:
    """Whether the 3×3 block *prefix* (``"Kg"``, ``"Ka"``) of the (39,) *estimate* is a signed identity within
    :data:`REVERSAL_TOLERANCE` (entries not estimated, NaN, are not held against it)."""
    if estimate is None:
        return False
    for a in "xyz":
        for b in "xyz":
            v = float(estimate[PARAMETER_INDEX[f"{prefix}{a}{b}"]])
            if math.isfinite(v) and abs((abs(v) - 1.0) if a == b else v) > REVERSAL_TOLERANCE:
                return False
    return True


def reversed_axis_notes(joint, moves=None) -> list[str]:
    """What a negative diagonal scale factor says: an axis the log has the other way round.

    A MIMU's gyro and accelerometer axes are built parallel and right-handed, so a scale factor near −1 is not the
    sensor's error but the log's: a column whose sign is reversed, or one mapped to the wrong axis. ``joint`` and
    ``moves`` are the (39,) estimates of the poses' fit and of the moves between poses (NaN where not identified;
    ``moves`` None without them).

    The moves see the gyros through the accelerometers. One accelerometer axis reversed makes that triad
    left-handed, and a rotation read in a mirror is a rotation about the mirrored axis with its sense reversed
    (ω' = det(M)·M·ω): the gyros then come out as diag(−1, +1, −1) for a reversed y accelerometer — two negative,
    the same as a gyro mounted turned 180° about y. So one or three negative gyro scale factors from the moves say
    those gyros are reversed; two say the third axis's accelerometer is (or those two gyros are). A gyro reversed
    in the log also turns the import's proposed angles the other way (they follow its own integral), so the poses'
    fit may give it +1 while the moves give −1: that disagreement is said too. In the poses' fit (a table's known
    turns and poses), a negative scale factor is that sensor's axis against the table's.

    Returns
    -------
    list of str
        The notes (empty when no scale factor is negative).
    """
    notes = []
    fix = "reverse it with a leading '-' on its column in plansim import's --columns and import again"

    def value(estimate, name):
        return math.nan if estimate is None else float(estimate[PARAMETER_INDEX[name]])

    gyro_moves = {a: value(moves, f"Kg{a}{a}") for a in "xyz"}
    negative = [a for a, v in gyro_moves.items() if v < 0.0]
    if negative and not _like_signed_identity(moves, "Kg"):
        entries = {f"Kg{a}{b}": value(moves, f"Kg{a}{b}") for a in "xyz" for b in "xyz"}
        shown = ", ".join(f"{name} = {v:.3g}" for name, v in entries.items()
                          if math.isfinite(v) and (name[2] == name[3] or abs(v) > REVERSAL_TOLERANCE))
        notes.append(f"{shown} (moves): far from a unit's scale factors, reversed axis or not (each within "
                     f"{REVERSAL_TOLERANCE:g} of ±1, cross-couplings within {REVERSAL_TOLERANCE:g}): the moves were "
                     f"not integrated as they were made. Check {SAMPLE_RATE_HINT}, the gyro units and --scale, and "
                     "that the moves are slow for the sample rate (a hand's turn needs tens of samples); do not "
                     "reverse a column on this evidence")
        negative = []
    if negative:
        shown = ", ".join(f"Kg{a}{a} = {gyro_moves[a]:.4g}" for a in negative)
        if len(negative) == 2:
            (other,) = set("xyz") - set(negative)
            notes.append(f"{shown} (moves): two gyros read opposite to how the accelerometers see the unit turn, as "
                         f"they do when the {other} accelerometer is reversed (a mirrored triad turns the rotations "
                         f"seen through it) or the gyros are mounted turned 180° about {other}; a MIMU's axes are "
                         f"built parallel: most likely the {other} accelerometer's sign is reversed in the log — "
                         f"{fix}")
        else:
            notes.append(f"{shown} (moves): the {', '.join(negative)} gyro{'s read' if len(negative) > 1 else ' reads'}"
                         " opposite to how the accelerometers see the unit turn; a MIMU's axes are built parallel, so "
                         "its sign is reversed in the log, or --columns maps another axis to it — " + fix)
        for a in negative if len(negative) != 2 else ():
            joint_value = value(joint, f"Kg{a}{a}")
            if joint_value > 0.0:
                notes.append(f"Kg{a}{a} = {joint_value:.4g} (joint WLS) but {gyro_moves[a]:.4g} (moves): the turns' "
                             f"angles were proposed from the {a} gyro's own integral, so a reversed gyro reads them "
                             "as turned the other way; check them against what was done")
    for name in ("Kgxx", "Kgyy", "Kgzz", "Kaxx", "Kayy", "Kazz"):
        v = value(joint, name)
        if v < 0.0 and abs(v + 1.0) > REVERSAL_TOLERANCE:
            notes.append(f"{name} = {v:.4g} (joint WLS): negative, but far from −1: not a reversed axis; check the "
                         "units, --scale and the segment table's turns and poses")
        elif v < 0.0 and not (name.startswith("Kg") and gyro_moves[name[2]] < 0.0):
            sensor = "gyro" if name.startswith("Kg") else "accelerometer"
            notes.append(f"{name} = {v:.4g} (joint WLS): the {name[2]} {sensor} reads the segment table's turns or "
                         "poses with the opposite sign; a sensor's axes are built parallel, so the table's sign or "
                         f"the {sensor}'s is reversed — check the turns and poses, or {fix}")
    return notes
