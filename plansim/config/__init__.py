"""Configuration: the scenario dataclasses (the simulated world and procedure, SI inside) and their checks."""

from plansim.config.saturation import saturation_report
from plansim.config.scenario import (
                                     Acquisition,
                                     Effects,
                                     Environment,
                                     ErrorDistribution,
                                     Noise,
                                     Reduction,
                                     Scenario,
                                     Turntable,
                                     parse_scenario,
)

__all__ = ["Acquisition", "Effects", "Environment", "ErrorDistribution", "Noise", "Reduction", "Scenario",
           "Turntable", "parse_scenario", "saturation_report"]
