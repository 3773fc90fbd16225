"""The JJF 1535-2015 procedure as schedule data (plansim.schedule.jjf1535)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from plansim.schedule import body_to_level
from plansim.schedule.jjf1535 import jjf1535_procedure, r5_rate_points
from plansim.units import DEG


def test_r5_points_up_to_the_range():
    """GB/T 321 R5 from 1 °/s: 1, 1.6, 2.5, 4, 6.3, 10, 16, 25, 40, 63, 100, then the 125 °/s maximum: 12 points."""
    assert np.allclose(np.array(r5_rate_points(125 * DEG)) / DEG,
                       [1, 1.6, 2.5, 4, 6.3, 10, 16, 25, 40, 63, 100, 125])
    # a maximum on the series is not repeated
    assert np.allclose(np.array(r5_rate_points(100 * DEG, 0.1 * DEG)) / DEG,
                       [0.1, 0.16, 0.25, 0.4, 0.63, 1, 1.6, 2.5, 4, 6.3, 10, 16, 25, 40, 63, 100])


def test_r5_thinning_keeps_the_ends_and_refuses_too_few():
    """From 0.1 to 125 °/s: 16 R5 values (0.1 … 100) plus the maximum, 17 candidates; thinned to 11 by index
    round(k·16/10), the smallest and the maximum stay and the list stays increasing."""
    full = r5_rate_points(125 * DEG, 0.1 * DEG)
    thin = r5_rate_points(125 * DEG, 0.1 * DEG, points=11)
    assert len(full) == 17 and len(thin) == 11
    assert thin[0] == full[0] and thin[-1] == full[-1] and set(thin) <= set(full)
    assert all(b > a for a, b in zip(thin, thin[1:]))
    with pytest.raises(ValueError, match="at least 11"):
        r5_rate_points(50 * DEG)  # 1 … 40, then 50: 10 points
    with pytest.raises(ValueError, match="points = 10"):
        r5_rate_points(125 * DEG, points=10)
    with pytest.raises(ValueError, match="points = 20"):
        r5_rate_points(125 * DEG, points=20)
    with pytest.raises(TypeError, match="maximum"):
        r5_rate_points("125 deg/s")


def test_procedure_layout():
    p = jjf1535_procedure(125 * DEG, repeats=3, bias_periods=6, allan_duration=600.0)
    segs = p.schedule.segments
    assert p.schedule.procedure == "jjf1535" and p.axis == 0
    assert len(p.room_runs) == 3 and len(p.room_bias) == 3 and len(p.temperature_runs) == 2
    for run in p.room_runs + p.temperature_runs:
        rates = np.array([segs[k].rate for k in run.points])
        # ≥ 11 points in each direction including ± the maximum
        assert np.sum(rates > 0) >= 11 and np.sum(rates < 0) >= 11
        assert np.isclose(rates.max(), 125 * DEG) and np.isclose(rates.min(), -125 * DEG)
        for k in run.points:
            s = segs[k]
            assert s.test == "rotation" and s.up == "+x" and s.rate_axis == "+x" and s.temperature == run.temperature
            # 7.2.1.1 c): ≥ 30 samples below 100 °/s, ≥ 5 at or above (1 s sampling period)
            assert s.samples >= (30 if abs(s.rate) < 100 * DEG * (1 - 1e-12) else 5)
            assert s.sample_rate == 1.0
        for k in (run.rest_before, run.rest_after):
            assert segs[k].test == "static" and segs[k].rate == 0.0 and segs[k].up == "+x"
        assert run.rest_before < min(run.points) and run.rest_after > max(run.points)
    # repeats 30 min apart
    assert segs[p.room_runs[1].rest_before].settle == 1800.0
    # bias records: consecutive P-second segments, no settling inside a record
    for record in p.room_bias + p.temperature_bias:
        assert len(record) == 6 and list(record) == list(range(record[0], record[0] + 6))
        assert all(segs[k].dwell == 10.0 and segs[k].up == "+x" for k in record)
        assert all(segs[k].settle == 0.0 for k in record[1:])
    assert p.temperatures == (20.0, 60.0, -20.0)
    assert [segs[r.rest_before].settle for r in p.temperature_runs] == [3600.0, 3600.0]
    assert segs[p.allan].dwell == 600.0 and segs[p.allan].samples == 600


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_g_positions_keep_the_input_axis_off_north(axis):
    """7.2.12: each axis up then down; the gyro under test is vertical (its own axis) or East–West (the others),
    so that the horizontal Earth rate (along North) never enters the up/down difference."""
    p = jjf1535_procedure(125 * DEG, axis=axis)
    gyro = "xyz".index(axis)
    for name, (up, down) in p.g_positions.items():
        su, sd = p.schedule.segments[up], p.schedule.segments[down]
        assert su.up == f"+{name}" and sd.up == f"-{name}"
        for s in (su, sd):
            direction = body_to_level(s.up, s.heading)[:, gyro]  # ENU
            assert abs(direction[1]) < 1e-15  # no North component
            if name == axis:
                assert abs(direction[2]) == 1.0
            else:
                assert abs(direction[0]) == pytest.approx(1.0)


@pytest.mark.parametrize(("kwargs", "error", "match"), [
    ({"axis": "w"}, ValueError, "axis = 'w'"),
    ({"repeats": 1}, ValueError, "repeats = 1"),
    ({"averaging_period": 2.5}, ValueError, "averaging_period = 2.5"),
    ({"upper_temperature": 10.0}, ValueError, "lower < room < upper"),
    ({"soak": -1.0}, ValueError, "soak = -1.0"),
    ({"sample_rate": "1 Hz"}, TypeError, "sample_rate"),
])
def test_bad_input_names_the_field(kwargs, error, match):
    with pytest.raises(error, match=match):
        jjf1535_procedure(125 * DEG, **kwargs)


def test_sample_counts_follow_the_sample_rate():
    p = jjf1535_procedure(125 * DEG, sample_rate=10.0, averaging_period=1.0)
    segs = p.schedule.segments
    slow = [segs[k] for k in p.room_runs[0].points if abs(segs[k].rate) < 90 * DEG]
    fast = [segs[k] for k in p.room_runs[0].points if abs(segs[k].rate) > 110 * DEG]
    assert {s.samples for s in slow} == {30} and {s.samples for s in fast} == {5}
    assert math.isclose(segs[p.room_bias[0][0]].dwell, 1.0)
