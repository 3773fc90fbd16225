"""Schedules: what the table does, as data (segments), and builders for the JJF 2003 procedures."""

from plansim.schedule.builders import jjf2003, multi_position, omega_squared_test, rate_test, with_temperature_ramp
from plansim.schedule.segments import Schedule, Segment, axis_vector, body_to_level

__all__ = ["Schedule", "Segment", "axis_vector", "body_to_level", "jjf2003", "multi_position",
           "omega_squared_test", "rate_test", "with_temperature_ramp"]
