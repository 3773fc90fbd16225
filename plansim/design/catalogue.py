"""The candidate segments a calibration schedule can be built from, and the information each carries.

A candidate is one dwell of the table: a pose (one of the 24 axis-aligned orientations — up axis × heading —
or a pose tilted 45° about East from one of them) at rest, or a rate about a body axis on the vertical table
axis (a grid of rates with both signs, which also drive the ω² terms), each with a dwell from a list (the
dwell is a continuous variable: :func:`at_dwell` moves a candidate to any dwell, and
:func:`plansim.design.schedule_design.refine_dwells` optimises it between the list's ends). Its cost is its
table time, settling included (``settle + dwell``, as :attr:`plansim.schedule.segments.Schedule.duration`
counts it).

**Information.** The mean of a segment is linear in the 39 parameters of JJF 2003 eq. (1)/(2),
``m = F·θ`` with ``F`` (6 × 39) from the fit's model (:meth:`plansim.fit.model.MeanModel.parameter_jacobian`:
the simulator's own kernel, Earth rate and local gravity of the scenario's site as known inputs). The noise of
the mean, ``Σ`` (6 × 6), is the prediction's (docs/planning.md):

- white noise ``N²/T`` per channel (angle or velocity random walk N, dwell T);
- the drift, as its Allan variance at τ = T (IEEE Std 952: half the mean square difference of adjacent
  T-averages; exact, from :func:`plansim.uncertainty.drift.drift_covariance` of two adjacent segments) of the
  scenario's bias instability, Gauss–Markov drift and random walk. Drift slower than a segment is common to
  neighbouring segments, and what a mean carries against its neighbours is what the Allan variance measures;
  it does not fall with T (it grows, for bias instability up to τ ≈ 1.9 T_c, and for a random walk), so white
  noise plus drift has a minimum over the dwell: the Allan minimum, the longest useful dwell;
- the table's errors of the setting, shared by the six channels of the segment: the position error (accuracy
  and repeatability, about East, North and Up) and, when turning, the rate error of the point
  (:meth:`~plansim.fit.model.MeanModel.segment_sensitivity`, JJF 2003 Table 1 or the scenario's grade).

The information of one candidate about the parameters is ``M_i = F_iᵀ Σ_i⁻¹ F_i``; restricted to some channels
and parameters (the others held known), the same with the rows and columns kept.

What the candidates treat as independent and a schedule does not: the drift correlates neighbouring segments,
the table's per-calibration errors (fixture, platform tilt, axis perpendicularity, systematic rate error) are
shared by every segment, and quantisation the noise does not dither is a systematic no design averages away.
The design allocates table time under the independent approximation; the chosen schedule is then judged by
:func:`plansim.predict` and a Monte Carlo, which have all of these.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from plansim.config import Scenario
from plansim.fit.model import MeanModel
from plansim.kernels.layout import CHANNELS, NOISE_WHITE, SEG_POSITION_ACCURACY, SEG_RATE_ERROR
from plansim.model.parameters import GROUPS, PARAMETERS
from plansim.schedule.segments import AXIS_NAMES, Schedule, Segment
from plansim.simulate.arguments import kernel_arguments
from plansim.uncertainty.drift import drift_covariance

__all__ = ["Candidate", "CandidateInformation", "candidate_information", "default_candidates", "select_parameters"]

#: headings of the axis-aligned poses, rad (0°, 90°, 180°, 270°)
HEADINGS = tuple(k * math.pi / 2.0 for k in range(4))
#: tilt of the tilted poses about East, rad (45°: gravity between two body axes)
TILT = math.pi / 4.0
#: dwell options, s
DWELLS = (10.0, 30.0, 100.0, 300.0)
#: rate grid as fractions of the largest rate, each with both signs
RATE_FRACTIONS = (0.05, 0.1, 0.2, 0.5, 1.0)


@dataclasses.dataclass(frozen=True)
class Candidate:
    """One candidate segment. ``kind``: ``"pose"`` (axis-aligned, at rest), ``"tilted"`` (at rest, the pose
    ``up``/``heading`` turned by ``tilt`` rad about East), ``"rate"`` (the ``rate_axis`` body axis up on the
    vertical table axis, turning at ``rate`` rad/s). ``dwell`` and ``settle`` in s."""

    kind: str
    up: str
    heading: float
    rate: float
    dwell: float
    settle: float
    tilt: float = 0.0

    @property
    def cost(self) -> float:
        """Table time of the segment, s (settling included)."""
        return self.settle + self.dwell

    @property
    def label(self) -> str:
        if self.kind == "rate":
            return f"rate {self.up[1]} {math.degrees(self.rate):+.6g} deg/s, {self.dwell:g} s"
        tilt = f", tilted {math.degrees(self.tilt):g} deg about East" if self.kind == "tilted" else ""
        return f"{self.up} up, heading {math.degrees(self.heading):.0f} deg{tilt}, {self.dwell:g} s"

    def segment(self, sample_rate: float, temperature: float) -> Segment:
        """The candidate as a schedule segment (a tilted pose only as its untilted pose: a schedule has no tilt)."""
        common = dict(up=self.up, heading=self.heading, dwell=self.dwell, settle=self.settle,
                      sample_rate=sample_rate, temperature=temperature)
        if self.kind == "rate":
            return Segment(label=self.label, test="rate", group="xyz".index(self.up[1]), rate=self.rate,
                           rate_axis=self.up, **common)
        return Segment(label=self.label, test="static", group=0, **common)


def default_candidates(scenario: Scenario, dwells=DWELLS, max_rate: float | None = None, tilted: bool = True
                       ) -> tuple[Candidate, ...]:
    """The catalogue: 24 axis-aligned poses (6 up axes × :data:`HEADINGS`), with *tilted* 24 poses tilted 45°
    about East, and rates ± :data:`RATE_FRACTIONS` × *max_rate* about each body axis (default: the largest
    rate of the scenario's schedule), each at every dwell of *dwells* (s) and the scenario's settling time."""
    dwells = tuple(float(d) for d in dwells)
    if not dwells or not all(math.isfinite(d) and d > 0 for d in dwells):
        raise ValueError(f"dwells = {dwells!r}: expected dwell times > 0 s")
    if max_rate is None:
        max_rate = max(abs(s.rate) for s in scenario.schedule.segments)
    if not (math.isfinite(max_rate) and max_rate > 0):
        raise ValueError(f"max_rate = {max_rate!r} rad/s: expected > 0 (the scenario's schedule has no rate "
                         "to take it from)" if max_rate == 0 else f"max_rate = {max_rate!r} rad/s: expected > 0")
    settle = scenario.schedule.segments[0].settle
    out = []
    for dwell in dwells:
        for up in AXIS_NAMES:
            for heading in HEADINGS:
                out.append(Candidate("pose", up, heading, 0.0, dwell, settle))
        if tilted:
            for up in AXIS_NAMES:
                for heading in HEADINGS:
                    out.append(Candidate("tilted", up, heading, 0.0, dwell, settle, TILT))
        for axis in "xyz":
            for fraction in RATE_FRACTIONS:
                for sign in (-1.0, 1.0):
                    out.append(Candidate("rate", f"+{axis}", 0.0, sign * fraction * max_rate, dwell, settle))
    return tuple(out)


@dataclasses.dataclass(frozen=True)
class CandidateInformation:
    """The candidates with what each carries: ``jacobian`` (n, 6, 39) ∂(segment mean)/∂θ in SI, ``covariance``
    (n, 6, 6) the noise of the mean, ``costs`` (n,) s."""

    candidates: tuple[Candidate, ...]
    jacobian: np.ndarray
    covariance: np.ndarray
    costs: np.ndarray

    def blocks(self, parameters=None, channels=None) -> np.ndarray:
        """Information matrices (n, p, p) of one segment of each candidate about *parameters* (indices into the
        39, default all) from *channels* (indices into gx … az, default all), the other parameters held known."""
        parameters = np.arange(self.jacobian.shape[2]) if parameters is None else np.asarray(parameters)
        channels = np.arange(len(CHANNELS)) if channels is None else np.asarray(channels)
        F = self.jacobian[:, channels][:, :, parameters]
        S = self.covariance[:, channels][:, :, channels]
        weighted = np.linalg.solve(S, F)
        out = np.einsum("nci,ncj->nij", F, weighted)
        return (out + out.transpose(0, 2, 1)) / 2.0


def select_parameters(names) -> np.ndarray:
    """Indices into the 39 parameters of parameter names or groups (``Kg``, ``Bg``, ``G``, ``Ka``, ``Ba``, ``P``)."""
    if isinstance(names, str):
        names = [names]
    index = {p.name: i for i, p in enumerate(PARAMETERS)}
    out = []
    for name in names:
        if name in GROUPS:
            out.extend(i for i, p in enumerate(PARAMETERS) if p.group == name)
        elif name in index:
            out.append(index[name])
        else:
            raise ValueError(f"parameter {name!r}: expected one of the 39 parameter names or a group "
                             f"({', '.join(GROUPS)})")
    return np.array(sorted(set(out)), dtype=int)


def _drift_variance(scenario: Scenario, dwell: float) -> np.ndarray:
    """The drift's Allan variance at τ = *dwell* (6,), per channel: half the variance of the difference of two
    adjacent means of *dwell* s, from the exact drift covariance of a two-segment schedule without a gap."""
    segment = dataclasses.replace(scenario.schedule.segments[0], dwell=float(dwell), settle=0.0)
    two = dataclasses.replace(scenario, schedule=Schedule((segment, segment), procedure="custom"))
    C = drift_covariance(two)
    return 0.5 * (C[:, 0, 0] + C[:, 1, 1] - 2.0 * C[:, 0, 1])


def at_dwell(scenario: Scenario, information: CandidateInformation, k: int, dwell: float
             ) -> tuple[Candidate, np.ndarray, np.ndarray]:
    """Candidate *k* of *information* at another *dwell* (s): the candidate, its Jacobian (6, 39) — which the dwell
    does not change — and the covariance of its mean (6, 6), whose white and drift parts follow the dwell (module
    docstring) while the table's part stays."""
    if not (math.isfinite(dwell) and dwell > 0):
        raise ValueError(f"dwell = {dwell!r} s: expected a finite dwell > 0 s")
    c = information.candidates[k]
    white = np.asarray(kernel_arguments(scenario)["noise"])[:, NOISE_WHITE] ** 2
    change = white / dwell - white / c.dwell + _drift_variance(scenario, dwell) - _drift_variance(scenario, c.dwell)
    return (dataclasses.replace(c, dwell=float(dwell)), information.jacobian[k],
            information.covariance[k] + np.diag(change))


def candidate_information(scenario: Scenario, candidates=None) -> CandidateInformation:
    """The information of each candidate segment (:class:`CandidateInformation`) for the scenario's unit, site,
    noise and table (module docstring). *candidates*: default :func:`default_candidates`."""
    candidates = default_candidates(scenario) if candidates is None else tuple(candidates)
    if not candidates or not all(isinstance(c, Candidate) for c in candidates):
        raise TypeError("candidates: expected a non-empty sequence of plansim.design.catalogue.Candidate")
    first = scenario.schedule.segments[0]
    # the mean's dependence on θ does not depend on the dwell (rotating segments are averaged over the start
    # angle): one model over the distinct geometries
    geometry = list(dict.fromkeys((c.kind, c.up, c.heading, c.rate, c.tilt) for c in candidates))
    segments = []
    for kind, up, heading, rate, tilt in geometry:
        seg = Candidate(kind, up, heading, rate, first.dwell, first.settle, tilt).segment(first.sample_rate,
                                                                                           first.temperature)
        segments.append(dataclasses.replace(seg, orientation="approximate") if kind == "tilted" else seg)
    args = kernel_arguments(scenario)
    model = MeanModel(Schedule(tuple(segments), procedure="custom"), float(args["gravity"]), args["earth_enu"])
    tilts = np.zeros(model.n_tilts)
    tilted = [k for k, g in enumerate(geometry) if g[0] == "tilted"]
    tilts[0::2][: len(tilted)] = [geometry[k][4] for k in tilted]  # about East; the placed poses in order
    theta = scenario.truth_nominal
    G = model.n_segments
    J = model.parameter_jacobian(tilts=tilts).reshape(G, 6, -1)
    table = np.zeros((G, 6, 6))
    entries = [(SEG_POSITION_ACCURACY + 2 * axis, scenario.turntable.position_uncertainty) for axis in range(3)]
    entries.append((SEG_RATE_ERROR, scenario.turntable.rate_error_per_point.standard_uncertainty))
    for entry, u in entries:
        if u > 0:
            # (ANGLES, G, 6); a tilted pose's tilt sits in the same entries (about East, North): the derivative is
            # taken on top of it, a rotation-vector derivative, equal to a small rotation to first order in the tilt
            d = model.segment_sensitivity(theta, entry, tilts)
            table += u**2 * np.einsum("ksi,ksj->sij", d, d) / d.shape[0]
    white = np.asarray(args["noise"])[:, NOISE_WHITE] ** 2
    drift = {d: _drift_variance(scenario, d) for d in sorted({c.dwell for c in candidates})}
    row = {g: k for k, g in enumerate(geometry)}
    jac, cov = [], []
    for c in candidates:
        k = row[(c.kind, c.up, c.heading, c.rate, c.tilt)]
        jac.append(J[k])
        cov.append(table[k] + np.diag(white / c.dwell + drift[c.dwell]))
    return CandidateInformation(candidates, np.array(jac), np.array(cov), np.array([c.cost for c in candidates]))
