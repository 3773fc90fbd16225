"""The fit's model of the segment means: the simulator's own noise-free physics, nothing else.

JJF 2003-2022 eq. (1) and (2),

    gyro:          ω' = Kg·ω + Bg + G·a
    accelerometer: a' = Ka·a + Ba + P·(ω²),

evaluated for each recorded segment at its nominal pose and table rate, with the site's local gravity
and Earth rate as known inputs, by the same kernel the simulator uses
(:func:`plansim.kernels.segment_path.noise_free_means`, which
:func:`plansim.simulate.arguments.noise_free_segment_means` calls): one model, not two. The unit's
39 parameters go into the truth part of a draws vector (:mod:`plansim.kernels.layout`); every effect
beyond eq. (1)/(2) is off, and every table error zero unless a caller sets it to get a sensitivity.

The mean of a segment is linear in the 39 parameters (every term of eq. (1)/(2) is a parameter times
a known input), so the model is ``m = J·θ`` with ``J`` (6S × 39) evaluated once per schedule:
:meth:`MeanModel.parameter_jacobian`.

Angles nobody recorded: the table angle at which a rotating segment starts (its phase) is not in any
recording, and the segment mean depends on it through the parts of gravity and the Earth rate that
turn with the table (for a vertical table axis, only the horizontal Earth rate, over a dwell that is not
a whole number of turns). The model takes the mean over that angle, uniform over a turn: the average
of :data:`ANGLES` equally spaced angles, exact for outputs of degree < :data:`ANGLES` in the angle
(the kernel's outputs have degree ≤ 3), and the spread over it becomes a Type B term
(:meth:`MeanModel.angle_covariance`; exact for degree < :data:`ANGLES`/2).
"""

from __future__ import annotations

import dataclasses
import math
from functools import lru_cache

import numpy as np

from plansim.config.scenario import parse_scenario
from plansim.kernels import segment_path
from plansim.kernels.layout import (
    FIXTURE,
    HEAD,
    PER_SEGMENT,
    PERPENDICULARITY,
    RATE_SYSTEMATIC,
    SEG_PHASE,
    SEG_POSITION_ACCURACY,
    SEG_RATE_ERROR,
    TILT,
    TRUTH,
    draws_length,
)
from plansim.model.parameters import N_PARAMETERS, pack
from plansim.schedule.segments import Schedule
from plansim.simulate.arguments import noise_free_arguments

#: equally spaced start angles (phases) a rotating segment's mean is averaged over: exact for a mean of
#: degree < 8 in the angle, its variance over the angle exact for degree < 4 (the kernel's is ≤ 3)
ANGLES = 8

#: steps of the central differences for the sensitivities to table errors: rad, relative rate, m/s², rad/s.
#: The outputs are smooth (sines of the angles), so the truncation error is ~h²/6 of the sensitivity
#: (2e-11 for 1e-5 rad) and the rounding ~1e-16·|m|/h.
ANGLE_STEP = 1e-5
RATE_STEP = 1e-6
GRAVITY_STEP = 1e-3
EARTH_RATE_STEP = 1e-7


def nominal_parameters() -> np.ndarray:
    """The nominal point of JJF 2003 eq. (1)/(2): Kg = Ka = I, every bias and sensitivity zero (39,)."""
    eye, zero3, zero33 = np.eye(3), np.zeros(3), np.zeros((3, 3))
    return pack(eye, zero3, zero33, eye, zero3, zero33)


@lru_cache(maxsize=1)
def _template():
    """A scenario with every effect, noise and table error off (only its kernel arguments are used)."""
    return parse_scenario({"name": "fit model"})


@dataclasses.dataclass(frozen=True)
class InputSource:
    """One Type B input of the segment means: its name, its standard uncertainty and the segment means'
    sensitivity to it (6S,) averaged over the start angles, flattened segment by segment (channels gx gy gz
    ax ay az)."""

    name: str
    kind: str  # "table", "site"
    u: float
    sensitivity: np.ndarray
    #: (S, 6, 6) covariance over the unrecorded start angle of the sensitivity per unit input: in a turning
    #: segment a tilt of the table axis turns gravity with the table, so the effect of the input depends on
    #: the angle the segment started at; u²·angle_spread is the variance that interaction adds
    angle_spread: np.ndarray | None = None


class MeanModel:
    """Noise-free segment means of a schedule's segments under eq. (1)/(2), by the simulator's kernel.

    Parameters
    ----------
    schedule : Schedule
        The segments to model, each with a known pose (``up``, ``heading``) and a known rate.
    gravity : float
        Local gravity, m/s².
    earth_enu : (3,) array_like
        Earth rate in East-North-Up, rad/s.
    hand_axes : sequence of int
        Body axes (0 x, 1 y, 2 z) turned by hand: the turn's axis in the case frame is then not known exactly,
        and its two small misalignment angles are nuisance parameters.
    lever_arm : (3, 3) array_like, optional
        Known position of each accelerometer (row i: accelerometer i) from the table axis, m: its centripetal
        acceleration ω×(ω×r) enters as a known input (the lab's fixture drawing, ``[mimu.effects]
        accel_lever_arm`` of its scenario). Default none: the ω²-sensitivities P then absorb it (docs/fitting.md).
    """

    def __init__(self, schedule: Schedule, gravity: float, earth_enu, hand_axes=(), lever_arm=None):
        for k, s in enumerate(schedule.segments):
            if not s.rate_known:
                raise ValueError(f"segment {k} ({s.label!r}): the mean model needs a known rate, got {s.rate!r}")
            if not s.heading_known and s.is_rotating:
                raise ValueError(f"segment {k} ({s.label!r}): a turning segment needs a known heading")
        self.schedule = schedule
        self.n_segments = len(schedule)
        #: poses placed by hand (orientation approximate or unknown): their tilt is a nuisance parameter
        self.placed = np.array([s.orientation != "known" for s in schedule.segments])
        #: poses whose heading is not known: their mean is averaged over the heading like a start angle
        self.heading_unknown = np.array([not s.heading_known for s in schedule.segments])
        known = Schedule(tuple(dataclasses.replace(s, heading=0.0, orientation="known") if not s.heading_known
                               else s for s in schedule.segments), procedure=schedule.procedure)
        scenario = dataclasses.replace(_template(), schedule=known)
        self._args = noise_free_arguments(scenario)
        if lever_arm is not None:
            lever = np.ascontiguousarray(lever_arm, dtype=float)
            if lever.shape != (3, 3) or not np.all(np.isfinite(lever)):
                raise ValueError(f"lever_arm: expected a finite 3x3 array (m), got {lever_arm!r}")
            self._args["lever"] = lever
        self.gravity = float(gravity)
        self.earth_enu = np.ascontiguousarray(earth_enu, dtype=float)
        self.rotating = np.array([s.is_rotating for s in schedule.segments])
        #: the draws entries that are nuisance parameters: each hand-placed pose's tilt about East and North,
        #: then the axis of each body axis turned by hand (two small angles, the kernel's rate-axis perpendicularity)
        placed = np.flatnonzero(self.placed)
        first = HEAD + PER_SEGMENT * placed + SEG_POSITION_ACCURACY
        columns = np.column_stack([first, first + 2]).ravel() if placed.size else np.zeros(0, dtype=int)
        self.hand_axes = tuple(hand_axes)
        axis_columns = [PERPENDICULARITY.start + 2 * a + c for a in self.hand_axes for c in (0, 1)]
        self.nuisance_columns = np.concatenate([columns, np.asarray(axis_columns, dtype=int)]).astype(int)

    @property
    def n_tilts(self) -> int:
        """Number of nuisance parameters: two tilt angles (about East and North, rad) per hand-placed pose and two
        misalignment angles (rad) per body axis turned by hand."""
        return len(self.nuisance_columns)

    def initial_tilts(self, accelerometer_means: np.ndarray) -> np.ndarray:
        """Start values of the nuisance parameters (n_tilts,): for each hand-placed pose the tilt that turns its
        nominal up-axis onto its measured specific force, and zero for each hand-turned axis.

        The pose is C = R(φ)·C0 with φ = (φ_E, φ_N, 0) in East-North-Up; the specific force in the case frame is
        Cᵀ·(0, 0, g), so φ rotates v = C0·d onto Up, d the measured direction: φ = (v × Up)/|v × Up|·acos(v·Up).
        """
        out = np.zeros((int(self.placed.sum()), 2))
        C0 = self._args["seg_C0"]
        for i, k in enumerate(np.flatnonzero(self.placed)):
            a = np.asarray(accelerometer_means[k], dtype=float)
            if not np.linalg.norm(a) > 0:
                continue
            v = C0[k] @ (a / np.linalg.norm(a))
            axis = np.cross(v, [0.0, 0.0, 1.0])
            norm = np.linalg.norm(axis)
            if norm > 0:
                out[i] = (axis / norm * math.atan2(norm, v[2]))[:2]
        return np.concatenate([out.ravel(), np.zeros(2 * len(self.hand_axes))])

    # ------------------------------------------------------------------ evaluation
    def evaluate(self, draws: np.ndarray, gravity: float | None = None, earth_enu=None,
                 effects: dict | None = None) -> np.ndarray:
        """Noise-free segment means (n, S, 6) of draws vectors (n, D), at the given table angles.

        ``effects`` overrides the kernel's effect arguments (every effect beyond eq. (1)/(2) is off otherwise):
        ``sensor`` (len(EFFECT_ROWS), 3) per :data:`plansim.kernels.layout.EFFECT_ROWS`, ``S2`` (3, 3) the gyros'
        g²-sensitivity, rad/s per (m/s²)², ``lever`` (3, 3) the accelerometers' lever arms, m.
        """
        draws = np.ascontiguousarray(np.atleast_2d(draws), dtype=float)
        if draws.shape[1] != draws_length(self.n_segments):
            raise ValueError(f"draws: expected shape (n, {draws_length(self.n_segments)}), got {draws.shape}")
        args = dict(self._args)
        for name, value in (effects or {}).items():
            if name not in ("sensor", "S2", "lever"):
                raise ValueError(f"effects: unknown kernel effect {name!r}; allowed 'sensor', 'S2', 'lever'")
            value = np.ascontiguousarray(value, dtype=float)
            if value.shape != args[name].shape:
                raise ValueError(f"effects[{name!r}]: expected shape {args[name].shape}, got {value.shape}")
            args[name] = value
        args["gravity"] = self.gravity if gravity is None else float(gravity)
        args["earth_enu"] = self.earth_enu if earth_enu is None else np.ascontiguousarray(earth_enu, dtype=float)
        out = np.empty((draws.shape[0], self.n_segments, 6))
        segment_path.noise_free_means(draws, **args, means_out=out)
        return out

    def draws(self, theta: np.ndarray, tilts=None) -> np.ndarray:
        """A draws vector (D,) with the parameters *theta* (39,) and the nuisance parameters *tilts* (n_tilts,),
        every other table error and start angle zero."""
        out = np.zeros(draws_length(self.n_segments))
        out[TRUTH] = theta
        if tilts is not None and self.n_tilts:
            out[self.nuisance_columns] = np.asarray(tilts, dtype=float).ravel()
        return out

    def _at_angles(self, draws: np.ndarray) -> np.ndarray:
        """(n, D) -> (n·ANGLES, D): each draws vector with every rotating segment started at 2πk/ANGLES, and every
        pose of unknown heading turned by 2πk/ANGLES about the vertical (after its own rotation)."""
        draws = np.atleast_2d(draws)
        out = np.repeat(draws, ANGLES, axis=0)
        angles = np.tile(2.0 * math.pi * np.arange(ANGLES) / ANGLES, draws.shape[0])
        rows = np.arange(self.n_segments)[self.rotating]
        out[:, HEAD + PER_SEGMENT * rows + SEG_PHASE] = angles[:, None]
        turned = np.flatnonzero(self.heading_unknown)
        if turned.size:
            from scipy.spatial.transform import Rotation

            first = HEAD + PER_SEGMENT * turned + SEG_POSITION_ACCURACY
            columns = np.stack([first, first + 2, first + 4], axis=-1)  # (m, 3): about E, N, U
            own = out[:, columns].reshape(-1, 3)
            heading = np.repeat(angles, turned.size)
            composed = (Rotation.from_rotvec(np.column_stack([np.zeros_like(heading), np.zeros_like(heading),
                                                              heading])) * Rotation.from_rotvec(own)).as_rotvec()
            out[:, columns] = composed.reshape(out.shape[0], turned.size, 3)
        return out

    def averaged(self, draws: np.ndarray, gravity: float | None = None, earth_enu=None,
                 effects: dict | None = None) -> np.ndarray:
        """Segment means (n, S, 6) averaged over the unrecorded start angle of each rotating segment."""
        draws = np.atleast_2d(draws)
        values = self.evaluate(self._at_angles(draws), gravity, earth_enu, effects)
        return values.reshape(draws.shape[0], ANGLES, self.n_segments, 6).mean(axis=1)

    def means(self, theta: np.ndarray, tilts=None, effects: dict | None = None) -> np.ndarray:
        """The model's segment means (S, 6) for parameters *theta* (39,) and the hand-placed poses' *tilts*, with
        the kernel's *effects* (see :meth:`evaluate`) on."""
        return self.averaged(self.draws(theta, tilts), effects=effects)[0]

    def effect_arguments(self) -> dict:
        """The kernel's effect arguments as this model uses them (copies): ``sensor``, ``S2``, ``lever``."""
        return {name: np.array(self._args[name]) for name in ("sensor", "S2", "lever")}

    # ------------------------------------------------------------------ the design
    def parameter_jacobian(self, earth_rate: bool = True, tilts=None) -> np.ndarray:
        """∂m/∂θ (6S, 39), exact: the model is linear in θ and zero at θ = 0 (at the given tilts).

        ``earth_rate = False`` leaves the Earth rate out: the *designed* excitation (table rates, gravity)
        that :mod:`plansim.fit.identify` judges identifiability on.
        """
        draws = np.tile(self.draws(np.zeros(N_PARAMETERS), tilts), (N_PARAMETERS, 1))
        draws[:, TRUTH] = np.eye(N_PARAMETERS)
        earth = None if earth_rate else np.zeros(3)
        values = self.averaged(draws, earth_enu=earth)  # (39, S, 6)
        return values.reshape(N_PARAMETERS, -1).T.copy()

    def tilt_jacobian(self, theta: np.ndarray, tilts, earth_rate: bool = True) -> np.ndarray:
        """∂m/∂(nuisance parameters) (6S, n_tilts) by central differences."""
        out = np.zeros((6 * self.n_segments, self.n_tilts))
        placed = np.flatnonzero(self.placed)
        for component in range(2):  # the poses' tilts: each moves only its own pose's mean, so all at once
            if not placed.size:
                break
            columns = HEAD + PER_SEGMENT * placed + SEG_POSITION_ACCURACY + 2 * component
            d = self._central(theta, columns, ANGLE_STEP, tilts=tilts, earth_rate=earth_rate).mean(axis=0)  # (S, 6)
            for i, k in enumerate(placed):
                out[6 * k:6 * k + 6, 2 * i + component] = d[k]
        for j in range(2 * placed.size, self.n_tilts):  # the hand-turned axes
            d = self._central(theta, [self.nuisance_columns[j]], ANGLE_STEP, tilts=tilts, earth_rate=earth_rate)
            out[:, j] = d.mean(axis=0).ravel()
        return out

    def angle_covariance(self, theta: np.ndarray, tilts=None) -> np.ndarray:
        """(S, 6, 6) covariance of each segment's mean over its unrecorded start angle or heading (0 otherwise)."""
        values = self.evaluate(self._at_angles(self.draws(theta, tilts)))  # (ANGLES, S, 6)
        centred = values - values.mean(axis=0)
        return np.einsum("ksi,ksj->sij", centred, centred) / ANGLES

    def _central(self, theta: np.ndarray, columns, step: float, gravity_step: float = 0.0,
                 earth_step=None, tilts=None, earth_rate: bool = True) -> np.ndarray:
        """Central-difference sensitivity (ANGLES, S, 6) of the segment means at each start angle to the draws
        entries *columns* (all at once: each segment's entries move only its own mean), or to gravity or the
        Earth rate (``gravity_step``, ``earth_step``, with *step* 1). ``earth_rate = False``: without it."""
        base = self.draws(theta, tilts)
        plus, minus = base.copy(), base.copy()
        if columns is not None:
            plus[columns] += step
            minus[columns] -= step
        earth = self.earth_enu if earth_rate else np.zeros(3)
        if earth_rate and earth_step is not None:
            earth_step = np.asarray(earth_step, dtype=float)
        else:
            earth_step = np.zeros(3)
        # both sides turned in one call (row by row, as two calls would: the same numbers, half the calls' overhead)
        turned = self._at_angles(np.stack([plus, minus]))
        hi = self.evaluate(turned[:ANGLES], self.gravity + gravity_step, earth + earth_step)
        lo = self.evaluate(turned[ANGLES:], self.gravity - gravity_step, earth - earth_step)
        return (hi - lo) / (2.0 * step)

    def segment_sensitivity(self, theta: np.ndarray, entry: int, tilts=None) -> np.ndarray:
        """Sensitivity (ANGLES, S, 6) of each segment's mean, at each start angle, to its own table error *entry*
        (``SEG_POSITION_ACCURACY + 2·axis``: a rotation of the pose about East, North or Up, per rad;
        ``SEG_RATE_ERROR``: the relative rate error of its point), by central differences (all segments at once:
        each segment's entries move only its own mean)."""
        if entry not in (SEG_POSITION_ACCURACY, SEG_POSITION_ACCURACY + 2, SEG_POSITION_ACCURACY + 4, SEG_RATE_ERROR):
            raise ValueError(f"entry = {entry!r}: expected a per-segment position error (SEG_POSITION_ACCURACY + 0, "
                             "2, 4) or SEG_RATE_ERROR")
        step = RATE_STEP if entry == SEG_RATE_ERROR else ANGLE_STEP
        return self._central(theta, HEAD + PER_SEGMENT * np.arange(self.n_segments) + entry, step, tilts=tilts)

    @staticmethod
    def _source(name: str, kind: str, u: float, at_angles: np.ndarray, segment: int | None = None) -> InputSource:
        """An input source from its sensitivities at the start angles (ANGLES, S, 6), for one segment or all."""
        if segment is not None:
            keep = np.zeros_like(at_angles)
            keep[:, segment] = at_angles[:, segment]
            at_angles = keep
        mean = at_angles.mean(axis=0)
        centred = at_angles - mean
        spread = np.einsum("ksi,ksj->sij", centred, centred) / ANGLES
        return InputSource(name, kind, u, mean.ravel(), spread)

    def table_sources(self, theta: np.ndarray, turntable, tilts=None, turn_angles=((), 0.0)) -> list[InputSource]:
        """Type B inputs of the turntable and fixture (JJF 2003 Table 1, §6.2), at the parameters *theta*.

        Per segment: the position error (a rotation of the pose about East, North and Up; accuracy and
        repeatability together) and, when the table turns, the rate error of the point. Per calibration:
        the fixture's misalignment (3), the platform tilt (2), the rate-axis perpendicularity (2 per
        axis) and the systematic rate error. Each with the standard uncertainty of its
        :class:`~plansim.config.scenario.ErrorDistribution` and the sensitivity of the segment means by
        central differences of the kernel's physics. A pose placed by hand has no table position error: its
        tilt is a parameter of the fit (*tilts*). *turn_angles* = (turns, u): turns fitted by an angle the table
        gave, with its standard uncertainty at each rest (:meth:`_turn_angle_sources`); with u > 0 those turns carry
        the table's angle errors in place of the rate error of the point.
        """
        S = self.n_segments
        sources: list[InputSource] = []
        u_position = turntable.position_uncertainty
        if u_position > 0:
            for axis, name in enumerate("ENU"):
                d = self.segment_sensitivity(theta, SEG_POSITION_ACCURACY + 2 * axis, tilts)
                for s in range(S):
                    if np.any(d[:, s]) and not self.placed[s]:
                        sources.append(self._source(f"position error about {name}, segment {s}", "table",
                                                    u_position, d, s))
        u_point = turntable.rate_error_per_point.standard_uncertainty
        turns, u_angle = turn_angles
        by_angle = {turn[0] for turn in turns} if u_angle > 0 else set()
        by_rate = [s for s in np.flatnonzero(self.rotating) if s not in by_angle] if u_point > 0 else []
        angle_sources = []  # appended last
        if by_rate or by_angle:
            d = self.segment_sensitivity(theta, SEG_RATE_ERROR, tilts)  # (ANGLES, S, 6) per relative rate error
            for s in by_rate:
                sources.append(self._source(f"rate error of the point, segment {s}", "table", u_point, d, s))
            angle_sources = self._turn_angle_sources(d, turns, u_angle) if by_angle else []
        per_calibration = [
            ("fixture misalignment about x", FIXTURE.start, turntable.fixture_perpendicularity, ANGLE_STEP),
            ("fixture misalignment about y", FIXTURE.start + 1, turntable.fixture_perpendicularity, ANGLE_STEP),
            ("fixture misalignment about z", FIXTURE.start + 2, turntable.fixture_perpendicularity, ANGLE_STEP),
            ("platform tilt about East", TILT.start, turntable.platform_tilt, ANGLE_STEP),
            ("platform tilt about North", TILT.start + 1, turntable.platform_tilt, ANGLE_STEP),
            ("systematic rate error", RATE_SYSTEMATIC, turntable.rate_error_systematic, RATE_STEP),
        ] + [(f"perpendicularity of the {'xyz'[k // 2]} rate axis ({k % 2})", PERPENDICULARITY.start + k,
              turntable.axis_perpendicularity, ANGLE_STEP) for k in range(6)]
        for name, column, distribution, step in per_calibration:
            u = distribution.standard_uncertainty
            if u > 0 and column not in self.nuisance_columns:  # a hand-turned axis is a parameter of the fit
                d = self._central(theta, [column], step, tilts=tilts)
                if np.any(d):
                    sources.append(self._source(name, "table", u, d))
        return sources + angle_sources

    def _turn_angle_sources(self, d: np.ndarray, turns, u: float) -> list[InputSource]:
        """Type B inputs of the angles of turns fitted by their angle, where the table gave it (its encoder's
        column, or the angle it was set to turn between two poses).

        A turn by *angle* over T seconds is fitted through its mean rate angle/T (docs/fitting.md, "Turns known by
        their angle"). The table's angle at each rest is off by e_r (its position accuracy and repeatability, of
        standard uncertainty *u*, rad), so a turn from rest a to rest b is off by e_b − e_a: a relative rate error
        (e_b − e_a)/angle. One input per rest: the turns on either side of one rest share its e_r (over a run of
        turns the errors telescope, and the angle turned in all is off by the first and last rests' alone).

        *d*: the segment means' sensitivity to each segment's relative rate error (:meth:`segment_sensitivity`,
        ``SEG_RATE_ERROR``); *turns*: (segment index, the rest it starts from, the rest it ends at, angle in rad)
        per turn.
        """
        by_rest: dict[int, np.ndarray] = {}
        for s, start, end, angle in turns:
            for rest, sign in ((start, -1.0), (end, 1.0)):
                at = by_rest.setdefault(rest, np.zeros_like(d))
                at[:, s] += sign * d[:, s] / angle
        return [self._source(f"the table's angle at rest {rest}", "table", u, at) for rest, at in by_rest.items()]

    def site_sources(self, theta: np.ndarray, u_gravity: float, u_earth_enu, tilts=None) -> list[InputSource]:
        """Type B inputs of an unknown site: gravity and the Earth rate's components."""
        sources = []
        if u_gravity > 0:
            d = self._central(theta, None, 1.0, gravity_step=GRAVITY_STEP, tilts=tilts) * (1.0 / GRAVITY_STEP)
            sources.append(self._source("local gravity (site not known)", "site", float(u_gravity), d))
        for axis, name in enumerate(("East", "North", "Up")):
            u = float(np.asarray(u_earth_enu)[axis])
            if u > 0:
                step = np.zeros(3)
                step[axis] = EARTH_RATE_STEP
                d = self._central(theta, None, 1.0, earth_step=step, tilts=tilts) * (1.0 / EARTH_RATE_STEP)
                sources.append(self._source(f"Earth rate, {name} component (site not known)", "site", u, d))
        return sources
