"""plansim — Monte Carlo calibration planning for MEMS inertial measurement units (JJF 2003-2022).

>>> import plansim
>>> results = plansim.run("ideal", trials=10, seed=1)        # doctest: +SKIP
>>> float(abs(results.error).max())                          # doctest: +SKIP

The public names are imported on first use (PEP 562): ``import plansim.kernels…`` alone, as the
process that compiles kernels in parallel does (:mod:`plansim.simulate.compilation`), does not
pay for xarray and the rest of the orchestrator.
"""

from importlib import import_module
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("plansim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "unknown"

_PUBLIC = {"run": "plansim.runner", "Scenario": "plansim.config", "parse_scenario": "plansim.config",
           "builtin_scenarios": "plansim.io.scenario_file", "load_scenario": "plansim.io.scenario_file",
           "save_scenario": "plansim.io.scenario_file", "simulate_and_record": "plansim.runner",
           "predict": "plansim.planning.predict", "plan": "plansim.planning.plan",
           "optimal_design": "plansim.design.schedule_design"}

__all__ = ["Scenario", "builtin_scenarios", "load_scenario", "optimal_design", "parse_scenario", "plan", "predict",
           "run", "save_scenario", "simulate_and_record", "__version__"]


def __getattr__(name: str):
    if name in _PUBLIC:
        value = getattr(import_module(_PUBLIC[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'plansim' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_PUBLIC))
