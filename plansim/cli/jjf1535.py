"""``plansim run jjf1535``: the JJF 1535-2015 Monte Carlo on a unit scenario; ``plansim validate jjf1535`` refused.

``jjf1535`` is a built-in *procedure*, not a scenario file: a scenario file describes JJF 2003 procedures only, so
the JJF 1535 session replaces a loaded unit scenario's schedule, turntable and acquisition
(:func:`plansim.uncertainty.jjf1535_monte_carlo.jjf1535_scenario`; docs/jjf1535.md).
"""

from __future__ import annotations

import json
import time

#: the built-in procedures run on a unit scenario (``plansim run PROCEDURE --unit SCENARIO``), with a description
PROCEDURES = {
    "jjf1535": "JJF 1535-2015 single-axis MEMS gyro calibration of the unit's x gyro: its items against the "
               "truth, the scale factor and bias against its Appendix A",
}
#: the unit scenario of ``plansim run jjf1535`` without ``--unit``
DEFAULT_UNIT = "jjf2003"

#: why ``plansim validate jjf1535`` is refused (exit status 2)
VALIDATE_REFUSAL = (
    "validate jjf1535: not available. 'plansim validate' checks a GUM budget propagated through the schedule's "
    "reduction against an adaptive Monte Carlo (JCGM 101) for the 39 JJF 2003 parameters; for JJF 1535 it would "
    "need the GUM of the JJF 1535 items (the sensitivity of each to the segment means and the table's errors), "
    "which is not built. The Appendix A budgets of JJF 1535 against the Monte Carlo (the coverage of K and B0) "
    "are in 'plansim run jjf1535 [--unit SCENARIO]'")


def _load_unit(args):
    from plansim.io.scenario_file import load_scenario

    name = DEFAULT_UNIT if args.unit is None else args.unit
    if name in PROCEDURES:
        raise ValueError(f"--unit {name!r}: {name} is a procedure, not a unit scenario; allowed: a built-in "
                         "scenario name (see 'plansim scenarios') or a TOML path")
    try:
        return load_scenario(name, args.set)
    except FileNotFoundError as exc:
        raise ValueError(f"--unit {name!r}: {exc}") from None
    except ValueError as exc:
        if args.set:  # the message names the --set override at fault
            raise
        raise ValueError(f"--unit {name!r}: {exc}") from None


def run_jjf1535(args, default_chunk_size: int) -> int:
    """``plansim run jjf1535``: every check first, then the Monte Carlo, then the report (text or ``--json``).

    Parameters
    ----------
    args : argparse.Namespace
        The options of ``plansim run``.
    default_chunk_size : int
        ``--chunk-size``'s default: any other value is refused (the JJF 1535 Monte Carlo uses its own chunks).
    """
    from plansim.report.jjf1535 import header, items_json, items_table, not_simulated_json
    from plansim.report.progress import end_progress_line, stderr_progress
    from plansim.runner import jjf1535_angle_random_walk, jjf1535_run
    from plansim.schedule.jjf1535 import jjf1535_procedure
    from plansim.uncertainty.jjf1535_monte_carlo import DEFAULT_MAXIMUM_RATE, jjf1535_scenario

    # every check before any work: the options that do not apply, the numbers, the unit
    for option, value in (("--out", args.out), ("--plot", args.plot)):
        if value is not None:
            raise ValueError(f"{option} {value!r}: not available with the procedure jjf1535 (it writes no file); "
                             "allowed with a scenario file: plansim run SCENARIO " + option)
    if args.chunk_size != default_chunk_size:
        raise ValueError(f"--chunk-size {args.chunk_size}: not available with the procedure jjf1535 "
                         "(its Monte Carlo uses its own chunks; results do not depend on them)")
    if args.trials is not None and args.trials < 2:
        raise ValueError(f"--trials {args.trials}: must be >= 2 (the standard deviations need two trials)")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    unit = _load_unit(args)
    procedure = jjf1535_procedure(DEFAULT_MAXIMUM_RATE)
    jjf1535_scenario(unit, procedure)  # refuses a unit the procedure would drive past its limits, before any work

    options = {} if args.trials is None else {"trials": args.trials}
    progress = None if args.quiet else stderr_progress(f"plansim run jjf1535 --unit {unit.name}")
    start = time.perf_counter()
    result = jjf1535_run(unit, seed=args.seed, procedure=procedure, path=args.path, progress=progress, **options)
    arw = jjf1535_angle_random_walk(unit, seed=result.seed, procedure=procedure)
    elapsed = time.perf_counter() - start
    end_progress_line()
    rows = result.summary()

    if args.json:
        print(json.dumps({
            "procedure": "jjf1535", "unit_scenario": unit.name, "overrides": list(unit.overrides),
            "trials": result.trials, "seed": result.seed, "path": result.path,
            "plansim_version": _version(), "elapsed_s": elapsed,
            "units": "SI: each item's 'unit'; budget_U and the *_relative figures are relative (Appendix A reads "
                     "both budgets relative)",
            "items": items_json(rows),
            "angle_random_walk": {"clause": "7.2.13", "trial": 0, "unit": "rad/s^0.5", "reported": arw[0],
                                  "simulated": arw[1]},
            "not_simulated": not_simulated_json(),
        }, indent=2))
    else:
        print(header(result, unit, procedure, elapsed))
        print()
        print(items_table(rows, arw))
    return 0


def _version() -> str:
    from plansim.io.recording import plansim_version

    return plansim_version()
