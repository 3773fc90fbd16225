"""Scenarios: the whole simulated world and procedure, as configuration objects with their checks.

:func:`parse_scenario` builds a :class:`Scenario` from a parsed document (a dict, as TOML gives it);
reading and writing files is :mod:`plansim.io.scenario_file`.

A scenario file has the sections ``[monte_carlo]``, ``[environment]``, ``[mimu]`` (with
``[mimu.truth]``, ``[mimu.truth_spread]``, ``[mimu.noise]``, ``[mimu.effects]``),
``[acquisition]``, ``[turntable]``, ``[schedule]`` and ``[reduction]``; docs/scenario-file.md
explains every field. Quantities are strings ``"<number> <unit>"``; parsing is strict: an unknown
key, a wrong unit, a NaN, a non-positive dwell, fewer than two distinct rate points, a repeated rate
point, a rank-deficient position set or a rate that drives an output beyond its range
(:mod:`plansim.config.saturation`) raise ``ValueError``/``TypeError`` naming the field, the value and
what is allowed. Inside, everything is SI.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field, fields

import numpy as np

from plansim.config.saturation import check_saturation
from plansim.estimate.jjf2003 import check_design
from plansim.model.environment import earth_rate_enu, normal_gravity
from plansim.model.parameters import N_PARAMETERS, PARAMETER_NAMES, PARAMETERS
from plansim.schedule import Schedule, Segment, jjf2003
from plansim.units import STANDARD_GRAVITY, parse_matrix, parse_quantity, parse_vector

# ----------------------------------------------------------------------------- configuration objects


@dataclass(frozen=True)
class ErrorDistribution:
    """A table or fixture error: a ± limit is uniform, a stated uncertainty is normal (GUM 4.3.7, 4.3.3)."""

    kind: str  # "uniform" | "normal"
    scale: float  # half-width (uniform) or standard deviation (normal), SI

    @property
    def standard_uncertainty(self) -> float:
        return self.scale / math.sqrt(3.0) if self.kind == "uniform" else self.scale

    @property
    def code(self) -> int:
        return 0 if self.kind == "uniform" else 1


@dataclass(frozen=True)
class Environment:
    latitude: float = math.radians(39.9)  # rad
    height: float = 50.0  # m
    earth_rate: bool = True

    @property
    def gravity(self) -> float:
        """Local normal gravity, m/s²."""
        return normal_gravity(self.latitude, self.height)

    @property
    def earth_rate_vector(self) -> np.ndarray:
        """Earth rate in ENU, rad/s (zero when switched off)."""
        return earth_rate_enu(self.latitude) if self.earth_rate else np.zeros(3)


@dataclass(frozen=True)
class Noise:
    """IEEE Std 952 Allan-variance coefficients per axis (SI), and optional Gauss–Markov drift."""

    gyro_angle_random_walk: np.ndarray  # N, rad/√s
    gyro_bias_instability: np.ndarray  # B, rad/s
    gyro_rate_random_walk: np.ndarray  # K, rad/s/√s
    accel_velocity_random_walk: np.ndarray  # m/s/√s
    accel_bias_instability: np.ndarray  # m/s²
    accel_acceleration_random_walk: np.ndarray  # m/s²/√s
    bias_instability_correlation_time: float  # s
    gyro_markov_sigma: np.ndarray  # rad/s
    accel_markov_sigma: np.ndarray  # m/s²
    markov_correlation_time: float  # s
    drift_update_interval: float  # s: drift states are advanced (exactly) this often and held between


@dataclass(frozen=True)
class Effects:
    """Effects beyond eq. (1)/(2); all zero (off) unless a scenario sets them."""

    gyro_nonlinearity_quadratic: np.ndarray  # 1/(rad/s)
    gyro_nonlinearity_cubic: np.ndarray  # 1/(rad/s)²
    gyro_asymmetry: np.ndarray  # (K+ − K−)/K
    gyro_g2_sensitivity: np.ndarray  # 3×3, rad/s per (m/s²)²
    accel_second_order: np.ndarray  # K2, 1/(m/s²)
    gyro_bias_temperature_coefficient: np.ndarray  # rad/s/°C
    gyro_scale_temperature_coefficient: np.ndarray  # 1/°C
    accel_bias_temperature_coefficient: np.ndarray  # m/s²/°C
    accel_scale_temperature_coefficient: np.ndarray  # 1/°C
    reference_temperature: float  # °C
    accel_lever_arm: np.ndarray  # 3×3, row i = position of accelerometer i from the table axis, m
    gyro_output_range: float  # rad/s; inf = no saturation
    accel_output_range: float  # m/s²
    # the effects JJF 1535-2015 measures (7.2.6, 7.2.7, 7.2.9, 7.2.11); applied to the segment means of the JJF 1535
    # Monte Carlo only (plansim.simulate.jjf1535_effects); the JJF 2003 kernels refuse a scenario that sets one
    gyro_dead_zone: np.ndarray = field(default_factory=lambda: np.zeros(3))  # rad/s: |w_i| below it -> no output
    gyro_resolution: np.ndarray = field(default_factory=lambda: np.zeros(3))  # rad/s: input steps of this size
    gyro_warm_up_amplitude: np.ndarray = field(default_factory=lambda: np.zeros(3))  # rad/s of output at power-on
    gyro_warm_up_time_constant: np.ndarray = field(default_factory=lambda: np.zeros(3))  # s
    gyro_turn_on_bias: np.ndarray = field(default_factory=lambda: np.zeros(3))  # rad/s: σ per power cycle

    def jjf1535_effects_set(self) -> tuple[str, ...]:
        """The names of :data:`JJF1535_EFFECTS` this unit sets (non-zero), in that order."""
        return tuple(name for name in JJF1535_EFFECTS if np.any(np.asarray(getattr(self, name)) != 0))


#: the effects of :class:`Effects` that only the JJF 1535 Monte Carlo simulates (on segment means, in closed form)
JJF1535_EFFECTS = tuple(f.name for f in fields(Effects) if f.name.startswith(("gyro_dead_zone", "gyro_resolution",
                                                                                "gyro_warm_up", "gyro_turn_on")))


@dataclass(frozen=True)
class Acquisition:
    """Data acquisition (JJF 2003 Appendix A eq. (A.3)): N bits over ±full scale, δ = 1/2^N."""

    bits: int  # 0 = no quantisation
    gyro_full_scale: float  # rad/s
    accel_full_scale: float  # m/s²
    #: the schedule may drive outputs beyond the range or full scale on purpose (they are clipped);
    #: without it such a scenario is refused when it loads (plansim.config.saturation)
    allow_saturation: bool = False

    @property
    def gyro_step(self) -> float:
        """Quantisation step 2·FS/2^N (so the half-step is δ·FS), rad/s; 0 when off."""
        return 2.0 * self.gyro_full_scale / 2**self.bits if self.bits else 0.0

    @property
    def accel_step(self) -> float:
        return 2.0 * self.accel_full_scale / 2**self.bits if self.bits else 0.0


@dataclass(frozen=True)
class Turntable:
    """Turntable and fixture errors (JJF 2003 Table 1, §6.2). Angles in rad, rate errors relative."""

    position_accuracy: ErrorDistribution  # per position
    position_repeatability: ErrorDistribution  # per position
    axis_perpendicularity: ErrorDistribution  # per calibration, per rate-test axis
    platform_tilt: ErrorDistribution  # per calibration
    fixture_perpendicularity: ErrorDistribution  # per calibration
    rate_error_systematic: ErrorDistribution  # per calibration
    rate_error_per_point: ErrorDistribution  # per rate point
    rate_smoothness: float  # relative standard deviation of the rate, per sample

    @property
    def position_uncertainty(self) -> float:
        """Standard uncertainty of one position's angle about each axis, rad: accuracy and repeatability, both
        drawn per position, combined."""
        return math.hypot(self.position_accuracy.standard_uncertainty,
                          self.position_repeatability.standard_uncertainty)


#: the parameter groups a scenario's ``[reduction]`` may give its data sheet's u for (``data_sheet_<group>``), and
#: the kind of quantity of each (its parameters')
DATA_SHEET_KEYS = {p.group: p.kind for p in PARAMETERS}


@dataclass(frozen=True)
class Reduction:
    """Choices a lab makes when it reduces the data with the specification's formulas."""

    reference_gravity: float  # m/s²: the value of "1 g" in the matrix A of eq. (6)-(11)
    reference_gravity_label: str  # "local", "standard" or the stated value
    omega_squared_sign: str  # "model": p = (U8 − U7)/ω², consistent with eq. (2); "as_printed": eq. (12)
    #: the Type B standard uncertainties a fit of measured data gives what it holds at nominal (plansim fit
    #: --scenario): a gyro scale factor or cross-coupling, the accelerometers' shear (dimensionless), a g-sensitivity
    #: (rad/s per m/s²); None where the scenario does not say (the fit's data-sheet default)
    held_gyro: float | None = None
    held_accel_cross: float | None = None
    held_g_sensitivity: float | None = None
    #: (group, u) pairs, SI: the unit's data sheet, beyond which a fitted parameter's u says no more than it does and
    #: which the fit carries as a prior where the data leave a direction to it (``data_sheet_kg`` … ``data_sheet_p``;
    #: plansim.fit.identify.HeldPriors.data_sheet); empty where the scenario does not say (a consumer MEMS unit's)
    data_sheet: tuple = ()


@dataclass(frozen=True)
class Scenario:
    """The whole simulated world and procedure, SI inside; built by :func:`parse_scenario`.

    ``name`` is what reports and results call the scenario; ``source`` says where it came from
    (``"built-in scenario 'jjf2003'"``, ``"file 'lab.toml'"``, ``"file 'lab.toml', copied from built-in
    scenario 'jjf2003'"``; empty for a document not read from a file).
    """

    name: str
    description: str
    trials: int
    seed: int
    environment: Environment
    mimu_description: str
    truth_nominal: np.ndarray  # (39,) SI
    truth_spread: np.ndarray  # (39,) SI standard deviations
    noise: Noise
    effects: Effects
    acquisition: Acquisition
    turntable: Turntable
    schedule: Schedule
    reduction: Reduction
    document: dict = field(repr=False, default_factory=dict)  # the parsed TOML, for provenance and saving
    source: str = ""
    overrides: tuple[str, ...] = ()  # the KEY=VALUE overrides set in the document (plansim run --set)


# ----------------------------------------------------------------------------- parsing helpers

_ZERO3 = ["0 1"] * 3


class _Section:
    """Reads one TOML table, remembering which keys were used so that unknown keys are errors."""

    def __init__(self, document: dict, path: str):
        self.path = path
        node = document
        for part in path.split("."):
            node = node.get(part, {}) if isinstance(node, dict) else {}
        if not isinstance(node, dict):
            raise TypeError(f"[{path}] must be a table, got {type(node).__name__}")
        self.data = node
        self.used: set[str] = set()

    def where(self, key: str) -> str:
        return f"{self.path}.{key}"

    def get(self, key, default=None):
        self.used.add(key)
        return self.data.get(key, default)

    def quantity(self, key, kind, default):
        return parse_quantity(self.get(key, default), kind, self.where(key))

    def vector(self, key, kind, default="0"):
        raw = self.get(key, None)
        if raw is None:
            return np.zeros(3) if default == "0" else parse_vector(default, kind, self.where(key))
        return parse_vector(raw, kind, self.where(key))

    def matrix(self, key, kind):
        raw = self.get(key, None)
        return np.zeros((3, 3)) if raw is None else parse_matrix(raw, kind, self.where(key))

    def boolean(self, key, default):
        value = self.get(key, default)
        if not isinstance(value, bool):
            raise TypeError(f"{self.where(key)} = {value!r}: expected true or false")
        return value

    def integer(self, key, default, minimum=None):
        value = self.get(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise TypeError(f"{self.where(key)} = {value!r}: expected a whole number")
        if minimum is not None and value < minimum:
            raise ValueError(f"{self.where(key)} = {value!r}: must be >= {minimum}")
        return value

    def string(self, key, default, allowed=None):
        value = self.get(key, default)
        if not isinstance(value, str):
            raise TypeError(f"{self.where(key)} = {value!r}: expected a string")
        if allowed is not None and value not in allowed:
            raise ValueError(f"{self.where(key)} = {value!r}; allowed: {', '.join(map(repr, allowed))}")
        return value

    def error(self, key, kind):
        raw = self.get(key, None)
        where = self.where(key)
        if raw is None:
            return ErrorDistribution("uniform", 0.0)
        if isinstance(raw, dict):
            keys = set(raw)
            if keys == {"limit"}:
                limit = parse_quantity(raw["limit"], kind, where + ".limit")
                return ErrorDistribution("uniform", _nonneg(limit, where))
            if keys == {"standard_uncertainty"}:
                u = parse_quantity(raw["standard_uncertainty"], kind, where)
                return ErrorDistribution("normal", _nonneg(u, where))
            if keys == {"expanded_uncertainty", "k"}:
                k = raw["k"]
                if isinstance(k, bool) or not isinstance(k, (int, float)) or not k > 0:
                    raise ValueError(f"{where}.k = {k!r}: the coverage factor must be a number > 0")
                u = parse_quantity(raw["expanded_uncertainty"], kind, where + ".expanded_uncertainty")
                return ErrorDistribution("normal", _nonneg(u / k, where))
            raise ValueError(f"{where} = {raw!r}: give {{limit = ...}} (uniform ± limit), "
                             "{standard_uncertainty = ...} or {expanded_uncertainty = ..., k = ...} (normal)")
        return ErrorDistribution("uniform", _nonneg(parse_quantity(raw, kind, where), where))

    def check_unknown(self, subtables=()):
        unknown = set(self.data) - self.used - set(subtables)
        if unknown:
            raise ValueError(f"[{self.path}] has unknown key(s) {', '.join(sorted(map(repr, unknown)))}; "
                             f"allowed: {', '.join(sorted(self.used | set(subtables)))}")


def _missing(where: str, what: str):
    raise ValueError(f"{where} is required: {what}")


def _nonnegative_vector(section: _Section, key: str, kind: str, what: str) -> np.ndarray:
    """A per-axis vector of *kind* whose every component is >= 0 (*what* says what it is, for the message)."""
    value = section.vector(key, kind)
    if np.any(value < 0):
        raise ValueError(f"{section.where(key)} = {section.data.get(key)!r}: {what} must be >= 0 on every axis; "
                         "allowed: values >= 0 (0 = off)")
    return value


def _nonneg(value: float, where: str) -> float:
    if value < 0:
        raise ValueError(f"{where} = {value!r}: an error limit or uncertainty must be >= 0")
    return value


_TOP_LEVEL = {"name", "description", "monte_carlo", "environment", "mimu", "acquisition", "turntable",
              "schedule", "reduction"}


def _parse_truth(section: _Section, default_zero: bool) -> np.ndarray:
    out = np.zeros(N_PARAMETERS)
    for k, p in enumerate(PARAMETERS):
        raw = section.get(p.name)
        if raw is None:
            if not default_zero and p.group in ("Kg", "Ka") and p.row == p.col:
                out[k] = 1.0
            continue
        out[k] = parse_quantity(raw, p.kind, section.where(p.name))
    unknown = set(section.data) - set(PARAMETER_NAMES)
    if unknown:
        raise ValueError(f"[{section.path}] has unknown parameter(s) {', '.join(sorted(map(repr, unknown)))}; "
                         f"parameters are named by the JJF 2003 symbols: {', '.join(PARAMETER_NAMES)}")
    return out


def _same_rate(a: float, b: float) -> bool:
    """Two rates the same rate point (written in different units, they may differ in the last bit)."""
    return math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-15)


def _parse_schedule(document: dict) -> tuple[Schedule, list[tuple[str, object] | None]]:
    """The schedule, and per segment ``(field, value as written)`` of the rate that set it (``None`` at rest)."""
    s = _Section(document, "schedule")
    procedure = s.string("procedure", "jjf2003", allowed=("jjf2003", "custom"))
    if procedure == "custom":
        raw_segments = s.get("segments")
        if not isinstance(raw_segments, list) or not raw_segments:
            raise ValueError("schedule.segments: a custom schedule needs a non-empty list of [[schedule.segments]]")
        segments = []
        for i, raw in enumerate(raw_segments):
            if not isinstance(raw, dict):
                raise TypeError(f"schedule.segments[{i}] = {raw!r}: each segment must be a table "
                                "([[schedule.segments]] with label, test, group, up, ...)")
            seg = _Section({"seg": raw}, "seg")
            seg.path = f"schedule.segments[{i}]"
            segments.append(Segment(
                label=seg.string("label", f"segment {i}"),
                test=seg.string("test", "multi_position"),
                group=seg.integer("group", 0),
                up=seg.string("up", None) if "up" in raw else _missing(f"schedule.segments[{i}].up",
                                                                        "the body axis pointing up, e.g. '+z'"),
                heading=seg.quantity("heading", "angle", "0 deg"),
                rate=seg.quantity("rate", "angular_rate", "0 deg/s"),
                rate_axis=seg.string("rate_axis", "+x"),
                dwell=seg.quantity("dwell", "time", "30 s"),
                settle=seg.quantity("settle", "time", "10 s"),
                sample_rate=seg.quantity("sample_rate", "frequency", "100 Hz"),
                temperature=seg.quantity("temperature", "temperature", "20 degC"),
            ))
            seg.check_unknown()
        s.check_unknown()
        schedule = Schedule(tuple(segments), procedure="custom")
        origins = [(f"schedule.segments[{i}].rate", raw.get("rate")) if segment.is_rotating else None
                   for i, (segment, raw) in enumerate(zip(segments, raw_segments))]
        check_design(schedule)  # the estimators say what they need
        _check_repeated_rate_segments(schedule, raw_segments)
    else:
        rate_points = s.get("rate_points", ["-100 deg/s", "-50 deg/s", "-20 deg/s", "-5 deg/s", "0 deg/s",
                                            "5 deg/s", "20 deg/s", "50 deg/s", "100 deg/s"])
        if not isinstance(rate_points, list):
            raise TypeError(f"schedule.rate_points = {rate_points!r}: expected a list of rates")
        rates = [parse_quantity(r, "angular_rate", f"schedule.rate_points[{i}]") for i, r in enumerate(rate_points)]
        omega_squared_raw = s.get("omega_squared_rate", "100 deg/s")
        schedule = jjf2003(
            rate_points=rates,
            omega_squared_rate=s.quantity("omega_squared_rate", "angular_rate", "100 deg/s"),
            positions=s.integer("positions", 12),
            dwell=s.quantity("dwell", "time", "30 s"),
            settle=s.quantity("settle", "time", "10 s"),
            sample_rate=s.quantity("sample_rate", "frequency", "100 Hz"),
            temperature_start=s.quantity("temperature_start", "temperature", "20 degC"),
            temperature_end=(None if s.get("temperature_end") is None
                             else s.quantity("temperature_end", "temperature", None)),
        )
        s.check_unknown()
        check_design(schedule)  # the estimators say what they need
        for i, rate in enumerate(rates):
            for j in range(i):
                if _same_rate(rate, rates[j]):
                    raise ValueError(f"schedule.rate_points[{i}] = {rate_points[i]!r} repeats "
                                     f"schedule.rate_points[{j}] = {rate_points[j]!r}: each rate point is recorded "
                                     "once per axis; JJF 2003 §7.2.1.1 c) asks for 7 to 11 distinct rate points, "
                                     "including the maximum input rate. Remove the repeat")
        origins = []
        for segment in schedule.segments:
            if not segment.is_rotating:
                origins.append(None)
            elif segment.test == "rate":
                i = next(i for i, rate in enumerate(rates) if _same_rate(rate, segment.rate))
                origins.append((f"schedule.rate_points[{i}]", rate_points[i]))
            else:
                origins.append(("schedule.omega_squared_rate", omega_squared_raw))
    return schedule, origins


def _check_repeated_rate_segments(schedule: Schedule, raw_segments: list[dict]) -> None:
    """Two rate-test segments about the same axis at the same rate are a repeat (a typo, or a weight the
    line fit of eq. (5) was not meant to have): refused, naming both."""
    seen: dict[int, list[int]] = {}
    for k, segment in enumerate(schedule.segments):
        if segment.test != "rate":
            continue
        for j in seen.setdefault(segment.group, []):
            if _same_rate(segment.rate, schedule.segments[j].rate):
                raise ValueError(
                    f"schedule.segments[{k}] ({segment.label!r}): rate {raw_segments[k].get('rate', '0 deg/s')!r} "
                    f"repeats schedule.segments[{j}] ({schedule.segments[j].label!r}) of the rate test about "
                    f"{'xyz'[segment.group]}: each rate point is recorded once per axis; JJF 2003 §7.2.1.1 c) asks "
                    "for 7 to 11 distinct rate points. Remove the repeat")
        seen[segment.group].append(k)


def parse_scenario(document: dict, name: str | None = None, source: str = "") -> Scenario:
    """Build a :class:`Scenario` from a parsed TOML document, validating every field.

    Parameters
    ----------
    document : dict
        The scenario as TOML gives it (docs/scenario-file.md).
    name : str, optional
        The scenario's name; when given it wins over the document's ``name`` key. Without it: the
        document's ``name``, else ``"unnamed"``.
    source : str
        Where the document came from, kept in :attr:`Scenario.source` (``load_scenario`` sets it).

    Raises
    ------
    ValueError, TypeError
        A field is unknown, of the wrong kind or unit, out of range, or the schedule cannot give every
        parameter, repeats a rate point, or drives an output beyond its range; the message names the
        field, the value and what is allowed.
    """
    if not isinstance(document, dict):
        raise TypeError(f"scenario: expected a TOML table, got {type(document).__name__}")
    unknown = set(document) - _TOP_LEVEL
    if unknown:
        raise ValueError(f"scenario has unknown section(s) or key(s) {', '.join(sorted(map(repr, unknown)))}; "
                         f"allowed: {', '.join(sorted(_TOP_LEVEL))}")
    mc = _Section(document, "monte_carlo")
    trials = mc.integer("trials", 2000, minimum=1)
    seed = mc.integer("seed", 1, minimum=0)
    mc.check_unknown()

    env = _Section(document, "environment")
    latitude = env.quantity("latitude", "angle", "39.9 deg")
    if abs(latitude) > math.pi / 2:
        raise ValueError(f"environment.latitude = {env.data.get('latitude')!r}: must lie within ±90 deg")
    environment = Environment(latitude=latitude, height=env.quantity("height", "length", "50 m"),
                              earth_rate=env.boolean("earth_rate", True))
    env.check_unknown()

    mimu = _Section(document, "mimu")
    mimu_description = mimu.string("description", "")
    # output ranges (saturation): 0 or absent = no saturation
    gyro_range = _nonneg(mimu.quantity("gyro_range", "angular_rate", "0 deg/s"), "mimu.gyro_range") or math.inf
    accel_range = _nonneg(mimu.quantity("accel_range", "acceleration", "0 g"), "mimu.accel_range") or math.inf
    mimu.check_unknown(subtables=("truth", "truth_spread", "noise", "effects"))
    truth_nominal = _parse_truth(_Section(document, "mimu.truth"), default_zero=False)
    truth_spread = _parse_truth(_Section(document, "mimu.truth_spread"), default_zero=True)
    if np.any(truth_spread < 0):
        bad = PARAMETER_NAMES[int(np.argmax(truth_spread < 0))]
        raise ValueError(f"mimu.truth_spread.{bad}: a standard deviation must be >= 0")

    n = _Section(document, "mimu.noise")
    noise = Noise(
        gyro_angle_random_walk=n.vector("gyro_angle_random_walk", "angle_random_walk"),
        gyro_bias_instability=n.vector("gyro_bias_instability", "angular_rate"),
        gyro_rate_random_walk=n.vector("gyro_rate_random_walk", "rate_random_walk"),
        accel_velocity_random_walk=n.vector("accel_velocity_random_walk", "velocity_random_walk"),
        accel_bias_instability=n.vector("accel_bias_instability", "acceleration"),
        accel_acceleration_random_walk=n.vector("accel_acceleration_random_walk", "acceleration_random_walk"),
        bias_instability_correlation_time=n.quantity("bias_instability_correlation_time", "time", "100 s"),
        gyro_markov_sigma=n.vector("gyro_markov_sigma", "angular_rate"),
        accel_markov_sigma=n.vector("accel_markov_sigma", "acceleration"),
        markov_correlation_time=n.quantity("markov_correlation_time", "time", "300 s"),
        drift_update_interval=n.quantity("drift_update_interval", "time", "0.1 s"),
    )
    n.check_unknown()
    for key in ("bias_instability_correlation_time", "markov_correlation_time", "drift_update_interval"):
        if not getattr(noise, key) > 0:
            raise ValueError(f"mimu.noise.{key}: must be > 0 s")
    for key, value in vars(noise).items():
        if isinstance(value, np.ndarray) and np.any(value < 0):
            raise ValueError(f"mimu.noise.{key}: noise coefficients must be >= 0")

    e = _Section(document, "mimu.effects")
    effects = Effects(
        gyro_nonlinearity_quadratic=e.vector("gyro_nonlinearity_quadratic", "per_rate"),
        gyro_nonlinearity_cubic=e.vector("gyro_nonlinearity_cubic", "per_rate_squared"),
        gyro_asymmetry=e.vector("gyro_asymmetry", "dimensionless"),
        gyro_g2_sensitivity=e.matrix("gyro_g2_sensitivity", "rate_per_acceleration_squared"),
        accel_second_order=e.vector("accel_second_order", "per_acceleration"),
        gyro_bias_temperature_coefficient=e.vector("gyro_bias_temperature_coefficient", "angular_rate_per_temperature"),
        gyro_scale_temperature_coefficient=e.vector("gyro_scale_temperature_coefficient", "per_temperature"),
        accel_bias_temperature_coefficient=e.vector("accel_bias_temperature_coefficient",
                                                    "acceleration_per_temperature"),
        accel_scale_temperature_coefficient=e.vector("accel_scale_temperature_coefficient", "per_temperature"),
        reference_temperature=e.quantity("reference_temperature", "temperature", "20 degC"),
        accel_lever_arm=e.matrix("accel_lever_arm", "length"),
        gyro_output_range=gyro_range,
        accel_output_range=accel_range,
        gyro_dead_zone=_nonnegative_vector(e, "gyro_dead_zone", "angular_rate", "a dead zone"),
        gyro_resolution=_nonnegative_vector(e, "gyro_resolution", "angular_rate", "a resolution"),
        gyro_warm_up_amplitude=e.vector("gyro_warm_up_amplitude", "angular_rate"),
        gyro_warm_up_time_constant=_nonnegative_vector(e, "gyro_warm_up_time_constant", "time", "a time constant"),
        gyro_turn_on_bias=_nonnegative_vector(e, "gyro_turn_on_bias", "angular_rate", "a standard deviation"),
    )
    e.check_unknown()
    missing = (effects.gyro_warm_up_amplitude != 0) & ~(effects.gyro_warm_up_time_constant > 0)
    if np.any(missing):
        i = int(np.argmax(missing))
        raise ValueError(f"mimu.effects.gyro_warm_up_time_constant = {e.data.get('gyro_warm_up_time_constant')!r}: "
                         f"gyro {'xyz'[i]} has a warm-up amplitude "
                         f"({e.data.get('gyro_warm_up_amplitude')!r}), so its time constant must be > 0 s; allowed: "
                         "a time constant > 0 wherever the amplitude is set")

    a = _Section(document, "acquisition")
    bits = a.integer("bits", 0, minimum=0)
    if bits > 52:
        raise ValueError(f"acquisition.bits = {bits}: must be 0 (no quantisation) to 52")
    acquisition = Acquisition(bits=bits,
                              gyro_full_scale=a.quantity("gyro_full_scale", "angular_rate", "125 deg/s"),
                              accel_full_scale=a.quantity("accel_full_scale", "acceleration", "8 g"),
                              allow_saturation=a.boolean("allow_saturation", False))
    a.check_unknown()
    if bits and not (acquisition.gyro_full_scale > 0 and acquisition.accel_full_scale > 0):
        raise ValueError("acquisition: gyro_full_scale and accel_full_scale must be > 0 when bits > 0")

    t = _Section(document, "turntable")
    turntable = Turntable(
        position_accuracy=t.error("position_accuracy", "angle"),
        position_repeatability=t.error("position_repeatability", "angle"),
        axis_perpendicularity=t.error("axis_perpendicularity", "angle"),
        platform_tilt=t.error("platform_tilt", "angle"),
        fixture_perpendicularity=t.error("fixture_perpendicularity", "angle"),
        rate_error_systematic=t.error("rate_error_systematic", "dimensionless"),
        rate_error_per_point=t.error("rate_error_per_point", "dimensionless"),
        rate_smoothness=_nonneg(t.quantity("rate_smoothness", "dimensionless", 0), "turntable.rate_smoothness"),
    )
    t.check_unknown()

    schedule, origins = _parse_schedule(document)

    r = _Section(document, "reduction")
    raw_g = r.get("reference_gravity", "local")
    if raw_g == "local":
        g_ref, g_label = environment.gravity, "local"
    elif raw_g == "standard":
        g_ref, g_label = STANDARD_GRAVITY, "standard"
    else:
        try:
            g_ref = parse_quantity(raw_g, "acceleration", "reduction.reference_gravity")
        except (ValueError, TypeError) as exc:
            raise ValueError(f"{exc}; or use 'local' or 'standard'") from None
        g_label = str(raw_g)
        if not g_ref > 0:
            raise ValueError(f"reduction.reference_gravity = {raw_g!r}: must be > 0")
    held = {}
    for key, kind in (("held_gyro", "dimensionless"), ("held_accel_cross", "dimensionless"),
                      ("held_g_sensitivity", "rate_per_acceleration")):
        if r.get(key) is not None:
            held[key] = _nonneg(r.quantity(key, kind, None), r.where(key))
    data_sheet = []
    for group, kind in DATA_SHEET_KEYS.items():
        key = f"data_sheet_{group.lower()}"
        if r.get(key) is not None:
            value = r.quantity(key, kind, None)
            if not value > 0:
                raise ValueError(f"{r.where(key)} = {r.get(key)!r}: a data sheet's standard uncertainty must be > 0")
            data_sheet.append((group, value))
    reduction = Reduction(reference_gravity=g_ref, reference_gravity_label=g_label,
                          omega_squared_sign=r.string("omega_squared_sign", "model", allowed=("model", "as_printed")),
                          data_sheet=tuple(data_sheet), **held)
    r.check_unknown()

    description = document.get("description", "")
    for key, value in (("name", document.get("name", "unnamed")), ("name", name), ("description", description)):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{key} = {value!r}: expected a string")
    scenario_name = name if name is not None else document.get("name", "unnamed")
    if not scenario_name.strip():
        raise ValueError(f"name = {scenario_name!r}: expected a non-empty name")
    if not isinstance(source, str):
        raise TypeError(f"source = {source!r}: expected a string")
    scenario = Scenario(name=scenario_name, description=description, trials=trials, seed=seed,
                        environment=environment, mimu_description=mimu_description,
                        truth_nominal=truth_nominal, truth_spread=truth_spread, noise=noise, effects=effects,
                        acquisition=acquisition, turntable=turntable, schedule=schedule, reduction=reduction,
                        document=copy.deepcopy(document), source=source)
    check_saturation(scenario, origins, {
        "mimu.gyro_range": mimu.data.get("gyro_range", "0 deg/s"),
        "mimu.accel_range": mimu.data.get("accel_range", "0 g"),
        "acquisition.gyro_full_scale": a.data.get("gyro_full_scale", "125 deg/s"),
        "acquisition.accel_full_scale": a.data.get("accel_full_scale", "8 g"),
    })
    return scenario
