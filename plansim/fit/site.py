"""What a fit takes as known: the site (local gravity, Earth rate) and the turntable's grade.

The site comes, in this order, from the command line (``--latitude/--height``), the recording's
attributes (``site_latitude_deg``, ``site_height_m``, docs/recording.md) or the lab's scenario
(``[environment]``). Without any of them the site is unknown, and gravity and the Earth rate become
Type B inputs that cover every place a laboratory can be (:func:`unknown_site_inputs`).

The turntable's grade (its position, rate and fixture errors) comes from the lab's scenario
(``[turntable]``) or, without one, from JJF 2003-2022 Table 1 (:data:`TABLE_1_TURNTABLE`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.config.scenario import ErrorDistribution, Turntable
from plansim.model.environment import EARTH_RATE, earth_rate_enu, normal_gravity

ARCSEC = math.pi / (180.0 * 3600.0)

#: JJF 2003-2022 Table 1 (three-axis turntable) and §6.2 (fixture): each figure a ± limit, so a uniform
#: distribution (GUM 4.3.7): position accuracy ±10″, position repeatability ±5″, axis perpendicularity
#: ±10″, platform flatness 0.02 mm over the ~400 mm platform (±10″ of tilt), fixture perpendicularity
#: ±10″, rate error 1e-5 (relative, systematic and per rate point), rate smoothness 0.05 %. The built-in
#: scenario ``jjf2003`` uses the same figures (a test holds the two equal).
TABLE_1_TURNTABLE = Turntable(
    position_accuracy=ErrorDistribution("uniform", 10.0 * ARCSEC),
    position_repeatability=ErrorDistribution("uniform", 5.0 * ARCSEC),
    axis_perpendicularity=ErrorDistribution("uniform", 10.0 * ARCSEC),
    platform_tilt=ErrorDistribution("uniform", 10.0 * ARCSEC),
    fixture_perpendicularity=ErrorDistribution("uniform", 10.0 * ARCSEC),
    rate_error_systematic=ErrorDistribution("uniform", 1e-5),
    rate_error_per_point=ErrorDistribution("uniform", 1e-5),
    rate_smoothness=5e-4,
)

#: heights a laboratory of unknown site is taken to lie between, m (sea level to 2 000 m)
UNKNOWN_SITE_HEIGHTS = (0.0, 2000.0)


@dataclass(frozen=True)
class Site:
    """Where the unit was: geodetic latitude (rad) and ellipsoidal height (m), or not known.

    Parameters
    ----------
    latitude : float
        rad, within ±π/2; NaN when the site is not known.
    height : float
        m; NaN when not known.
    earth_rate : bool
        Whether the Earth rate acts on the gyros (always in a real lab; a simulated scenario may switch
        it off, ``[environment] earth_rate = false``).
    source : str
        Where the site came from (``"--latitude/--height"``, ``"recording attributes"``, ``"scenario 'x'"``,
        ``"not known"``).
    """

    latitude: float = math.nan
    height: float = math.nan
    earth_rate: bool = True
    source: str = "not known"

    def __post_init__(self):
        for name in ("latitude", "height"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeError(f"site {name} = {value!r}: expected a number (NaN: not known)")
        if math.isnan(self.latitude) != math.isnan(self.height):
            raise ValueError(f"site: latitude {self.latitude!r} rad and height {self.height!r} m must be both known "
                             "or both NaN (give --height with --latitude)")
        if not math.isnan(self.latitude) and not abs(self.latitude) <= math.pi / 2:
            raise ValueError(f"site latitude = {math.degrees(self.latitude)!r} deg: must lie within ±90 deg")
        if not math.isnan(self.height) and not -11000.0 <= self.height <= 9000.0:
            raise ValueError(f"site height = {self.height!r} m: must lie within -11000 to 9000 m")

    @property
    def known(self) -> bool:
        return not math.isnan(self.latitude)

    @property
    def gravity(self) -> float:
        """Local normal gravity, m/s² (:func:`plansim.model.environment.normal_gravity`); NaN when not known."""
        return normal_gravity(self.latitude, self.height) if self.known else math.nan

    @property
    def earth_rate_vector(self) -> np.ndarray:
        """Earth rate in East-North-Up, rad/s (zero when switched off; NaN when the site is not known)."""
        if not self.earth_rate:
            return np.zeros(3)
        return earth_rate_enu(self.latitude) if self.known else np.full(3, math.nan)

    def describe(self) -> str:
        if not self.known:
            return "site not known: gravity and the Earth rate enter as Type B inputs over every latitude"
        earth = "" if self.earth_rate else ", Earth rate off"
        return (f"latitude {math.degrees(self.latitude):.6g} deg, height {self.height:.6g} m "
                f"(g = {self.gravity:.8g} m/s^2{earth}; from {self.source})")


def unknown_site_inputs(earth_rate: bool = True) -> tuple[float, float, np.ndarray, np.ndarray]:
    """Gravity and Earth rate as Type B inputs when the site is not known.

    The latitude φ is taken uniform over ±90° and the height uniform over :data:`UNKNOWN_SITE_HEIGHTS`.
    Gravity: the midpoint of the range of :func:`~plansim.model.environment.normal_gravity` over those
    sites, uniform over it (u = half-range/√3). Earth rate (ENU): Ω·(0, cos φ, sin φ), so
    E[Ω_N] = 2Ω/π with u(Ω_N) = Ω·√(1/2 − 4/π²), and E[Ω_U] = 0 with u(Ω_U) = Ω/√2 (uncorrelated: the
    range of φ is symmetric).

    Returns
    -------
    gravity : float
        m/s².
    u_gravity : float
        m/s².
    earth_enu : (3,) array
        rad/s.
    u_earth_enu : (3,) array
        rad/s (East 0: the Earth rate has no East component anywhere).
    """
    low = normal_gravity(0.0, UNKNOWN_SITE_HEIGHTS[1])
    high = normal_gravity(math.pi / 2, UNKNOWN_SITE_HEIGHTS[0])
    gravity, u_gravity = 0.5 * (low + high), 0.5 * (high - low) / math.sqrt(3.0)
    if not earth_rate:
        return gravity, u_gravity, np.zeros(3), np.zeros(3)
    earth = np.array([0.0, 2.0 * EARTH_RATE / math.pi, 0.0])
    u_earth = np.array([0.0, EARTH_RATE * math.sqrt(0.5 - 4.0 / math.pi**2), EARTH_RATE / math.sqrt(2.0)])
    return gravity, u_gravity, earth, u_earth


def resolve_site(latitude_deg=None, height_m=None, attrs=None, scenario=None) -> Site:
    """The site of a fit: the command line's, else the recording's attributes, else the scenario's.

    Parameters
    ----------
    latitude_deg, height_m : float or None
        ``--latitude`` (deg) and ``--height`` (m); give both or neither.
    attrs : dict or None
        The recording's attributes (``site_latitude_deg``, ``site_height_m``).
    scenario : plansim.config.Scenario or None
        The lab's scenario (its ``environment``; ``earth_rate = false`` switches the Earth rate off).

    Raises
    ------
    ValueError
        One of ``--latitude``/``--height`` without the other, or a value out of range.
    """
    earth_rate = True if scenario is None else bool(scenario.environment.earth_rate)
    if (latitude_deg is None) != (height_m is None):
        given, missing = ("--latitude", "--height") if height_m is None else ("--height", "--latitude")
        raise ValueError(f"{given} was given without {missing}: give both (the site's latitude in deg and height "
                         "in m) or neither")
    if latitude_deg is not None:
        for name, value in (("--latitude", latitude_deg), ("--height", height_m)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{name} {value!r}: expected a finite number")
        if not abs(latitude_deg) <= 90.0:
            raise ValueError(f"--latitude {latitude_deg!r}: must lie within -90 to 90 deg")
        return Site(math.radians(latitude_deg), float(height_m), earth_rate, "--latitude/--height")
    attrs = attrs or {}
    if "site_latitude_deg" in attrs or "site_height_m" in attrs:
        latitude = attrs.get("site_latitude_deg")
        height = attrs.get("site_height_m", 0.0)
        if latitude is None:
            raise ValueError("recording attribute site_height_m is given without site_latitude_deg")
        return Site(math.radians(float(latitude)), float(height), earth_rate, "recording attributes")
    if scenario is not None:
        env = scenario.environment
        return Site(float(env.latitude), float(env.height), earth_rate, f"scenario {scenario.name!r}")
    return Site(earth_rate=earth_rate)


def scenario_fit_options(scenario) -> dict:
    """The fit's options a lab's scenario gives (:func:`plansim.fit.fit_recording` keywords), one helper for every
    caller (``plansim fit``, ``plansim diagnose``, ``plansim diagnose-check``):

    - ``turntable`` and ``turntable_source``: its ``[turntable]`` grade (the Type B per-setting errors);
    - ``reference_gravity`` and ``omega_squared_sign``: its ``[reduction]``;
    - ``lever_arm``: the fixture's known lever arms (``[mimu.effects] accel_lever_arm``), where any is set — a model
      input, not absorbed by P;
    - ``stated_white``: the sensor's stated white noise (``[mimu.noise]``,
      :func:`plansim.fit.noise.stated_white_noise`), where any is stated — the prior of the noise an undithered
      quantiser hides;
    - ``held``: the Type B standard uncertainties of what the fit holds at nominal (``[reduction]`` ``held_gyro``,
      ``held_accel_cross``, ``held_g_sensitivity``) and the unit's data sheet (``data_sheet_kg`` …
      ``data_sheet_p``; :class:`plansim.fit.identify.HeldPriors`), where any is stated;
    - ``stated_step``: the acquisition's quantisation steps (``[acquisition]``, :func:`plansim.fit.noise.stated_steps`)
      where it quantises — for a channel that reads one code in every pose, whose step the data cannot show.

    *scenario* None gives no options (JJF 2003 Table 1 and the recording's attributes).
    """
    from plansim.config import Scenario
    from plansim.fit.identify import HeldPriors
    from plansim.fit.noise import stated_steps, stated_white_noise

    if scenario is None:
        return {}
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario or None, got {type(scenario).__name__}")
    options = dict(turntable=scenario.turntable, turntable_source=f"scenario {scenario.name!r}, [turntable]",
                   reference_gravity=scenario.reduction.reference_gravity,
                   omega_squared_sign=scenario.reduction.omega_squared_sign)
    stated_priors = {name: getattr(scenario.reduction, f"held_{name}") for name in ("gyro", "accel_cross",
                                                                                      "g_sensitivity")}
    if any(value is not None for value in stated_priors.values()) or scenario.reduction.data_sheet:
        options["held"] = HeldPriors(**{k: v for k, v in stated_priors.items() if v is not None},
                                     source=f"scenario {scenario.name!r}, [reduction]",
                                     data_sheet=dict(scenario.reduction.data_sheet))
    if scenario.effects.accel_lever_arm.any():
        options["lever_arm"] = scenario.effects.accel_lever_arm
    stated = stated_white_noise(scenario)
    if np.any(np.isfinite(stated)):
        options["stated_white"] = stated
    steps = stated_steps(scenario)
    if np.any(steps > 0):
        options["stated_step"] = steps
    return options
