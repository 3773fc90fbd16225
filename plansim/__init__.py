"""plansim — Monte Carlo calibration planning for MEMS inertial measurement units (JJF 2003-2022).

>>> import plansim
>>> results = plansim.run("ideal", trials=10, seed=1)        # doctest: +SKIP
>>> float(abs(results.error).max())                          # doctest: +SKIP
"""

from plansim.runner import package_version, run
from plansim.scenario import Scenario, builtin_scenarios, load_scenario, save_scenario

__version__ = package_version()

__all__ = ["Scenario", "builtin_scenarios", "load_scenario", "run", "save_scenario", "__version__"]
