"""``plansim run jjf1535``: the JJF 1535-2015 Monte Carlo on a unit scenario; ``plansim validate jjf1535``: the GUM of
its items against an adaptive Monte Carlo (:mod:`plansim.uncertainty.jjf1535_validation`).

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

#: what ``plansim validate jjf1535`` still refuses (exit status 2): a claims file names JJF 2003 parameters and items
VALIDATE_CLAIMS_REFUSAL = (
    "--claims: not available with 'plansim validate jjf1535', which checks the GUM of the items against the "
    "adaptive Monte Carlo; a certificate's claims on JJF 1535 items ([jjf1535.ITEM] U = …) are judged by "
    "'plansim run jjf1535 --claims claims.toml' (docs/jjf1535.md)")


def load_unit(args, procedures=PROCEDURES):
    """The unit scenario of a procedure run (``--unit``, default :data:`DEFAULT_UNIT`, with ``--set``); a name
    among *procedures* is refused (a procedure is not a unit)."""
    from plansim.io.scenario_file import load_scenario

    name = DEFAULT_UNIT if args.unit is None else args.unit
    if name in procedures:
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
    from plansim.io.claims import load_jjf1535_claims
    from plansim.report.jjf1535 import claims_json, claims_table, header, items_json, items_table, not_simulated_json
    from plansim.report.progress import end_progress_line, stderr_progress
    from plansim.runner import jjf1535_angle_random_walk, jjf1535_run
    from plansim.simulate.overrides import jjf1535_settings
    from plansim.uncertainty.jjf1535_claims import judge_jjf1535_claims
    from plansim.uncertainty.jjf1535_monte_carlo import jjf1535_scenario

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
    unit = load_unit(args)
    settings = jjf1535_settings(args.procedure or ())
    procedure = settings.procedure()
    jjf1535_scenario(unit, procedure)  # refuses a unit the procedure would drive past its limits, before any work
    claims = load_jjf1535_claims(args.claims) if args.claims else {}

    options = {} if args.trials is None else {"trials": args.trials}
    progress = None if args.quiet else stderr_progress(f"plansim run jjf1535 --unit {unit.name}")
    start = time.perf_counter()
    result = jjf1535_run(unit, seed=args.seed, procedure=procedure, path=args.path, progress=progress, **options)
    arw = jjf1535_angle_random_walk(unit, seed=result.seed, procedure=procedure)
    elapsed = time.perf_counter() - start
    end_progress_line()
    rows = result.summary()
    judged = judge_jjf1535_claims(result, claims) if claims else []

    if args.json:
        print(json.dumps({
            "procedure": "jjf1535", "unit_scenario": unit.name, "overrides": list(unit.overrides),
            "procedure_settings": list(settings.overrides),
            "trials": result.trials, "seed": result.seed, "path": result.path,
            "plansim_version": _version(), "elapsed_s": elapsed,
            "units": "SI: each item's 'unit'; budget_U and the *_relative figures are relative (Appendix A reads "
                     "both budgets relative)",
            "items": items_json(rows),
            "angle_random_walk": {"clause": "7.2.13", "trial": 0, "unit": "rad/s^0.5", "reported": arw[0],
                                  "simulated": arw[1]},
            "not_simulated": not_simulated_json(),
            "claims": claims_json(judged) if claims else None,
        }, indent=2))
    else:
        print(header(result, unit, procedure, elapsed))
        if settings.overrides:
            print(f"Procedure settings (--procedure): {'; '.join(settings.overrides)}")
        print()
        print(items_table(rows, arw))
        if judged:
            print()
            print(claims_table(judged, args.claims))
    return 0


def _version() -> str:
    from plansim.io.recording import plansim_version

    return plansim_version()


def validate_jjf1535_command(args) -> int:
    """``plansim validate jjf1535``: every check first, then the GUM and the adaptive Monte Carlo, then the report.

    Parameters
    ----------
    args : argparse.Namespace
        The options of ``plansim validate`` (``--unit``, ``--seed``, ``--json``, ``--digits``,
        ``--trials-per-block``, ``--max-trials``, ``--path``, ``--summary``, ``--quiet``; not ``--claims``).
    """
    from plansim.report.progress import end_progress_line
    from plansim.report.validation import format_jjf1535_report, jjf1535_json, validate_progress
    from plansim.simulate.overrides import jjf1535_settings
    from plansim.uncertainty.jjf1535_validation import validate_jjf1535

    if args.claims:
        raise ValueError(VALIDATE_CLAIMS_REFUSAL)
    unit = load_unit(args)
    settings = jjf1535_settings(args.procedure or ())
    progress = validate_progress(f"plansim validate jjf1535 --unit {unit.name}", args.quiet or args.json)
    report = validate_jjf1535(unit, settings.procedure(), digits=args.digits, trials_per_block=args.trials_per_block,
                              max_trials=args.max_trials, seed=args.seed, path=args.path, progress=progress)
    end_progress_line()
    if args.json:
        print(json.dumps({**jjf1535_json(report), "overrides": list(unit.overrides),
                          "procedure_settings": list(settings.overrides), "plansim_version": _version()}, indent=2))
    else:
        if unit.overrides:
            print(f"Overrides (--set): {'; '.join(unit.overrides)}")
        if settings.overrides:
            print(f"Procedure settings (--procedure): {'; '.join(settings.overrides)}")
        print(format_jjf1535_report(report, details=not args.summary))
    return 0
