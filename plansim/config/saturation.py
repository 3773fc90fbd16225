"""Outputs beyond the range: which segments of a schedule drive a channel past its limit.

A channel's *limit* is the smaller of the sensor's output range (``mimu.gyro_range`` /
``mimu.accel_range``; 0 or absent = none) and, when the acquisition quantises (``acquisition.bits``
> 0), its full scale (``acquisition.gyro_full_scale`` / ``accel_full_scale``): the simulation clips
every sample there (:func:`plansim.kernels.quantiser.quantise`). A clipped rate point flattens the
line fit of JJF 2003 eq. (5), so Kg comes out wrong without any other sign; :func:`check_saturation`
refuses such a scenario when it loads, unless ``acquisition.allow_saturation = true``.

The bound on each channel's output in a segment is the model of JJF 2003 eq. (1) and (2) with every
coefficient at ``|nominal| + 3 × its unit-to-unit spread`` and every input at its magnitude:

- gyro *i*:  ``Σ_j K̂g_ij·(|ω_j| + Ω_E) + |B̂g_i| + Σ_j Ĝ_ij·g·|u_j|``
- accelerometer *i*:  ``Σ_j K̂a_ij·(g·|u_j| + ω²·|r_i|) + |B̂a_i| + Σ_j P̂_ij·(|ω_j| + Ω_E)²``

where ω is the table rate on the segment's rate axis (body frame), Ω_E the Earth rate (0 when off),
u the body axis pointing up, g the local gravity and r_i accelerometer *i*'s lever arm. Noise, drift,
table errors and the effects beyond eq. (1)/(2) are left out: they move a channel near its limit by
far less than a rate point does. All SI.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import unpack
from plansim.schedule.segments import Segment, axis_vector
from plansim.units import KINDS

if TYPE_CHECKING:
    from plansim.config.scenario import Scenario

#: each coefficient of the bound is |nominal| + SPREAD_SIGMAS × its unit-to-unit standard deviation
SPREAD_SIGMAS = 3.0

#: the fields that set each channel's limit: (sensor range, acquisition full scale), gyros then accelerometers
LIMIT_FIELDS = (("mimu.gyro_range", "acquisition.gyro_full_scale"),) * 3 + \
    (("mimu.accel_range", "acquisition.accel_full_scale"),) * 3
_KIND = ("angular_rate",) * 3 + ("acceleration",) * 3
_DEFAULT_UNIT = ("deg/s",) * 3 + ("g",) * 3
_SENSOR = ("gyro",) * 3 + ("accelerometer",) * 3


def output_bounds(truth_nominal: np.ndarray, truth_spread: np.ndarray, segments: tuple[Segment, ...] | list[Segment],
                  gravity: float, earth_rate: float, lever_arm: np.ndarray) -> np.ndarray:
    """Bound on |output| of every channel in every segment, (S, 6) SI (the rule of the module docstring).

    Parameters
    ----------
    truth_nominal, truth_spread : (39,) array
        Nominal true parameters and their unit-to-unit standard deviations, SI.
    segments : sequence of Segment
        The schedule's segments.
    gravity : float
        Local gravity, m/s².
    earth_rate : float
        Magnitude of the Earth rate the gyros sense, rad/s (0 when off).
    lever_arm : (3, 3) array
        Row *i*: position of accelerometer *i* from the table axes, m.
    """
    m = unpack(np.abs(np.asarray(truth_nominal, float)) + SPREAD_SIGMAS * np.abs(np.asarray(truth_spread, float)))
    radius = np.linalg.norm(np.asarray(lever_arm, float), axis=1)
    out = np.empty((len(segments), 6))
    for k, segment in enumerate(segments):
        rate = abs(segment.rate)
        w = rate * np.abs(axis_vector(segment.rate_axis)) + earth_rate
        f_gravity = gravity * np.abs(axis_vector(segment.up))
        out[k, :3] = m["Kg"] @ w + m["Bg"] + m["G"] @ f_gravity
        f = f_gravity[None, :] + (rate * rate * radius)[:, None]  # row i: what accelerometer i senses, bounded
        out[k, 3:] = np.einsum("ij,ij->i", m["Ka"], f) + m["Ba"] + m["P"] @ (w * w)
    return out


def output_limits(gyro_range: float, accel_range: float, bits: int, gyro_full_scale: float,
                  accel_full_scale: float) -> tuple[np.ndarray, tuple[str, ...]]:
    """``(limits, fields)``: each channel's clipping level (SI, inf = none) and the field that sets it.

    The full scale clips only when the acquisition quantises (``bits > 0``); where the range and the
    full scale are equal, the sensor's range is named (it clips first).
    """
    limits, fields = np.full(6, math.inf), ["", "", "", "", "", ""]
    for c in range(6):
        gyro = c < 3
        candidates = [(gyro_range if gyro else accel_range, LIMIT_FIELDS[c][0])]
        if bits:
            candidates.append((gyro_full_scale if gyro else accel_full_scale, LIMIT_FIELDS[c][1]))
        for value, name in candidates:
            if value < limits[c]:
                limits[c], fields[c] = value, name
    return limits, tuple(fields)


def scenario_bounds(scenario: Scenario) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """``(bounds (S, 6), limits (6,), limit fields)`` of a scenario, SI."""
    e, a = scenario.effects, scenario.acquisition
    bounds = output_bounds(scenario.truth_nominal, scenario.truth_spread, scenario.schedule.segments,
                           scenario.environment.gravity,
                           float(np.linalg.norm(scenario.environment.earth_rate_vector)), e.accel_lever_arm)
    limits, fields = output_limits(e.gyro_output_range, e.accel_output_range, a.bits, a.gyro_full_scale,
                                   a.accel_full_scale)
    return bounds, limits, fields


def unit_of(raw: object, kind: str, default: str) -> str:
    """The unit a user wrote in ``"<number> <unit>"`` if it is one of *kind*, else *default*."""
    if isinstance(raw, str):
        parts = raw.strip().split(None, 1)
        if len(parts) == 2 and parts[1].strip() in KINDS[kind] and parts[1].strip():
            return parts[1].strip()
    return default


def _text(value: float, unit: str, kind: str, versus: float | None = None) -> str:
    """*value* (SI) in *unit*, with enough digits to differ from *versus* (SI) when it does."""
    x = value / KINDS[kind][unit]
    y = None if versus is None else versus / KINDS[kind][unit]
    for digits in range(4, 11):
        text = f"{x:.{digits}g}"
        if y is None or x == y or text != f"{y:.{digits}g}":
            return text
    return repr(x)


def _document_value(document: dict, dotted: str) -> object:
    node: object = document
    for part in dotted.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    return node


def saturation_report(scenario: Scenario) -> list[str]:
    """Human-readable lines, one per channel whose output the schedule drives beyond its limit.

    Each line names the channel, the bound on its output, the limit and the field that sets it, by
    how much the output is clipped (absolute and per cent of the limit) and in which segments. The
    bound is the module's rule; an empty list means no channel saturates. A scenario loads with such
    channels only when ``acquisition.allow_saturation = true``; the console should then print these
    lines, since the estimates of the clipped segments' parameters (Kg above all) are biased.
    """
    bounds, limits, fields = scenario_bounds(scenario)
    segments = scenario.schedule.segments
    lines = []
    for c in range(6):
        over = np.flatnonzero(bounds[:, c] > limits[c])
        if not over.size:
            continue
        unit = unit_of(_document_value(scenario.document, fields[c]), _KIND[c], _DEFAULT_UNIT[c])
        worst = float(bounds[over, c].max())
        labels = [segments[k].label for k in over[:4]] + (["…"] if over.size > 4 else [])
        lines.append(f"{CHANNELS[c]}: output up to {_text(worst, unit, _KIND[c], limits[c])} {unit} against the limit "
                     f"{_text(limits[c], unit, _KIND[c])} {unit} ({fields[c]}): clipped by up to "
                     f"{_text(worst - limits[c], unit, _KIND[c])} {unit} "
                     f"({100 * (worst - limits[c]) / limits[c]:.3g} % over) in {over.size} of {len(segments)} segments "
                     f"({', '.join(labels)})")
    return lines


def check_saturation(scenario: Scenario, origins: list[tuple[str, object] | None],
                     raw_limits: dict[str, object]) -> None:
    """Refuse a schedule that drives a channel beyond its limit (unless the scenario allows saturation).

    Parameters
    ----------
    scenario : Scenario
        The parsed scenario.
    origins : list
        Per segment: ``(field, value as written)`` of the rate that set it (e.g.
        ``("schedule.rate_points[8]", "400 deg/s")``), or ``None`` for a segment at rest.
    raw_limits : dict
        The limit fields (:data:`LIMIT_FIELDS`) as the user wrote them.

    Raises
    ------
    ValueError
        Naming the rate field and its value (or, at rest, the limit field), the bound in the user's
        units, the limit and its field, and, for a gyro on a rate point, the largest rate within it.
    """
    if scenario.acquisition.allow_saturation:
        return
    bounds, limits, fields = scenario_bounds(scenario)
    over = bounds > limits[None, :]
    if not over.any():
        return
    k, c = (int(i) for i in np.argwhere(over)[0])
    segment = scenario.schedule.segments[k]
    origin = origins[k]
    limit_field = fields[c]
    limit_raw = raw_limits.get(limit_field)
    kind = _KIND[c]
    limit_unit = unit_of(limit_raw, kind, _DEFAULT_UNIT[c])
    if origin is not None and kind == "angular_rate":
        unit = unit_of(origin[1], kind, limit_unit)
    else:
        unit = limit_unit
    converted = "" if unit == limit_unit else f" ({_text(limits[c], unit, kind)} {unit})"
    where = f"in segment {segment.label!r}" if origin is not None else f"at rest in segment {segment.label!r}"
    subject = f"{origin[0]} = {origin[1]!r}" if origin is not None else f"{limit_field} = {limit_raw!r}"
    beyond = f"{limit_field} = {limit_raw!r}{converted}" if origin is not None else "that limit"
    message = (f"{subject}: {_SENSOR[c]} {CHANNELS[c]} would output up to {_text(bounds[k, c], unit, kind, limits[c])} "
               f"{unit} {where}, beyond {beyond}, where the simulation clips it "
               f"(bound: JJF 2003 eq. (1)/(2) with each coefficient at |nominal| + {SPREAD_SIGMAS:g}σ of its unit "
               "spread, plus gravity and the Earth rate)")
    if origin is not None and c < 3:
        # the gyro bound is a·|ω| + b in the table rate: the largest rate inside the limit
        at_rest = output_bounds(scenario.truth_nominal, scenario.truth_spread,
                                [_at_rest(segment)], scenario.environment.gravity,
                                float(np.linalg.norm(scenario.environment.earth_rate_vector)),
                                scenario.effects.accel_lever_arm)[0, c]
        slope = (bounds[k, c] - at_rest) / abs(segment.rate)
        if slope > 0 and limits[c] > at_rest:
            message += (f"; the largest rate within the limit there is "
                        f"{_text((limits[c] - at_rest) / slope, unit, kind)} {unit}")
    others = int(over.any(axis=1).sum()) - 1
    if others:
        message += f"; {others} more segment(s) exceed a limit too"
    remedy = "Lower the rate or widen the range" if origin is not None else "Widen the range"
    raise ValueError(f"{message}. {remedy}, or set acquisition.allow_saturation = true to simulate the clipping on "
                     "purpose (docs/scenario-file.md)")


def _at_rest(segment: Segment) -> Segment:
    return replace(segment, rate=0.0)
