"""``plansim run``, ``validate``, ``scenarios`` and ``record``: the simulator's commands."""

from __future__ import annotations

import json
import os
import time

from plansim.cli.chapter import PROCEDURES as CHAPTER_PROCEDURES
from plansim.cli.chapter import run_chapter
from plansim.cli.common import COMMANDS, add_procedure_option, add_set_option
from plansim.cli.jjf1535 import DEFAULT_UNIT, run_jjf1535, validate_jjf1535_command
from plansim.cli.jjf1535 import PROCEDURES as JJF1535_PROCEDURES
from plansim.cli.jjf1537 import DYNAMIC_TESTS, run_jjf1537_command
from plansim.cli.vibration import EXPERIMENTS as VIBRATION_EXPERIMENTS
from plansim.cli.vibration import run_vibration
from plansim.io.files import OutputSet, check_output_path
from plansim.report.plot import FIGURE_SUFFIXES
from plansim.report.progress import end_progress_line

#: ``plansim run --chunk-size``'s default
DEFAULT_CHUNK_SIZE = 4096
#: the built-in experiments (``plansim run NAME [--set KEY=VALUE]``), listed last by ``plansim scenarios``
EXPERIMENTS = {**DYNAMIC_TESTS, **VIBRATION_EXPERIMENTS}
#: the built-in procedures run on a unit scenario (``plansim run NAME --unit SCENARIO``)
PROCEDURES = {**JJF1535_PROCEDURES, **CHAPTER_PROCEDURES}


def _cmd_run(args) -> int:
    from plansim.config import saturation_report
    from plansim.io.results import write_results
    from plansim.io.scenario_file import load_scenario
    from plansim.report.progress import stderr_progress
    from plansim.report.summary import appendix_a_comparisons
    from plansim.report.table import appendix_a_table, header, parameter_summary, parameter_table
    from plansim.runner import run, run_summary
    from plansim.uncertainty import compare_with_appendix_a

    if args.scenario in CHAPTER_PROCEDURES:  # the chapter's tests and JJF 2003 on the same units
        return run_chapter(args, DEFAULT_CHUNK_SIZE, PROCEDURES)
    if args.scenario in JJF1535_PROCEDURES:  # a built-in procedure run on a unit scenario, not a scenario file
        return run_jjf1535(args, DEFAULT_CHUNK_SIZE)
    for option, value in (("--procedure", args.procedure), ("--claims", args.claims)):
        if value:
            raise ValueError(f"{option}: only with the procedure jjf1535 (plansim run jjf1535 {option} …); "
                             f"{args.scenario!r} takes its settings with --set")
    if args.scenario in DYNAMIC_TESTS:  # a built-in dynamic test, a Monte Carlo with its own settings (--set)
        return run_jjf1537_command(args, DEFAULT_CHUNK_SIZE)
    if args.scenario in VIBRATION_EXPERIMENTS:  # a built-in experiment with its own settings (--set)
        return run_vibration(args, DEFAULT_CHUNK_SIZE)
    if args.unit is not None:
        raise ValueError(f"--unit {args.unit!r}: only with a procedure ({', '.join(PROCEDURES)}: plansim run "
                         f"jjf1535 --unit SCENARIO); the scenario {args.scenario!r} is its own unit")
    # every check before any work: the outputs, the scenario, the numbers
    if args.out is not None:
        check_output_path(args.out, "--out", (".nc",))
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    scenario = load_scenario(args.scenario, args.set)
    saturation = saturation_report(scenario)  # empty unless acquisition.allow_saturation let it load
    trials = scenario.trials if args.trials is None else args.trials
    if trials < 1:
        raise ValueError(f"--trials {trials}: must be >= 1")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.plot is not None and trials < 2:
        raise ValueError(f"--plot {args.plot!r}: the error histograms need at least 2 trials (trials = {trials})")

    # the outputs are staged beside their targets and committed together at the end, or not at all
    with OutputSet() as outputs:
        out = outputs.stage(args.out, "--out", (".nc",)) if args.out is not None else None
        plot = outputs.stage(args.plot, "--plot", FIGURE_SUFFIXES) if args.plot is not None else None
        progress = None if args.quiet else stderr_progress(f"plansim run {scenario.name}")
        start = time.perf_counter()
        if plot is not None:  # the histograms need every trial's error: keep the trials (run checks the memory)
            results = run(scenario, trials=trials, seed=args.seed, chunk_size=args.chunk_size, progress=progress,
                          path=args.path)
            elapsed = time.perf_counter() - start
            comparisons = compare_with_appendix_a(results["truth"].values, results["estimate"].values, scenario)
            if out is not None:
                write_results(results, out)
            from plansim.report.plot import appendix_a_histograms

            appendix_a_histograms(results, scenario, comparisons, plot,
                                  format=os.path.splitext(args.plot)[1].lstrip("."))
        else:  # only the statistics, streamed; --out streams every trial to the file
            results = run_summary(scenario, trials=trials, seed=args.seed, chunk_size=args.chunk_size,
                                  progress=progress, path=args.path, out=out)
            elapsed = time.perf_counter() - start
            comparisons = appendix_a_comparisons(results, scenario)
        outputs.commit()

    if args.json:
        print(json.dumps({
            "scenario": scenario.name, "overrides": list(scenario.overrides), "seed": results.attrs["seed"],
            "trials": trials,
            "plansim_version": results.attrs["plansim_version"], "elapsed_s": elapsed,
            "parameters": [{k: r[k] for k in ("name", "unit", "mean_error", "std_error")}
                           for r in parameter_summary(results)],
            "appendix_a": [c.as_dict() for c in comparisons],
            "saturation": saturation,
        }, indent=2))
    else:
        print(header(results, elapsed))
        print()
        if saturation:
            print("Saturation (acquisition.allow_saturation = true): these outputs clip, and the estimates that "
                  "use them are biased")
            print("\n".join(f"  {line}" for line in saturation))
            print()
        print(parameter_table(results))
        if comparisons:
            print()
            print(appendix_a_table(comparisons))
        for label, path in (("results", args.out), ("figure", args.plot)):
            if path:
                print(f"\nwrote {label}: {path}")
    return 0


def _cmd_scenarios(args) -> int:
    import tomllib

    from plansim.io.scenario_file import builtin_scenarios

    descriptions = {}
    for name, path in builtin_scenarios().items():
        with open(path, "rb") as fh:
            descriptions[name] = tomllib.load(fh).get("description", "")
    width = max(map(len, [*descriptions, *PROCEDURES, *EXPERIMENTS]), default=0)
    for name, description in descriptions.items():
        print(f"{name:{width}s}  {description}".rstrip())
    for name, description in PROCEDURES.items():  # one line each too, marked: not scenario files
        print(f"{name:{width}s}  [procedure, not a scenario file: plansim run {name} --unit SCENARIO] {description}")
    for name, description in EXPERIMENTS.items():
        print(f"{name:{width}s}  [experiment, not a scenario file: plansim run {name} [--set KEY=VALUE]] {description}")
    return 0


def _cmd_record(args) -> int:
    from plansim.io.recording import write_recording
    from plansim.io.recording_csv import segment_table_path
    from plansim.io.scenario_file import load_scenario
    from plansim.runner import simulate_and_record

    target = check_output_path(args.out, "--out", (".nc", ".csv"))
    if target.suffix.lower() == ".csv":  # the segment table is written beside the samples
        check_output_path(segment_table_path(target), "--out's segment table")
    scenario = load_scenario(args.scenario, args.set)
    seed = scenario.seed if args.seed is None else args.seed
    rec = simulate_and_record(scenario, seed=seed, trial=args.trial)
    write_recording(rec, args.out)
    print(f"wrote recording of trial {args.trial} of {scenario.name!r} (seed {seed}): "
          f"{rec.samples.shape[0]} samples in {len(rec.schedule)} segments -> {args.out}")
    return 0



def _cmd_validate(args) -> int:
    from plansim.io.claims import load_claims
    from plansim.io.scenario_file import load_scenario
    from plansim.report.validation import format_report, validate_progress, validation_json
    from plansim.runner import validate

    for option, value, minimum in (("--trials-per-block", args.trials_per_block, 2),
                                   ("--max-trials", args.max_trials, 1), ("--digits", args.digits, 1)):
        if value < minimum:
            raise ValueError(f"{option} {value}: must be >= {minimum}")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.scenario in CHAPTER_PROCEDURES:
        raise ValueError(f"{args.scenario!r}: 'plansim validate' checks a GUM budget, and the chapter's procedures "
                         "carry none; compare them with JJF 2003 by Monte Carlo: plansim run chapter --unit SCENARIO")
    if args.scenario in JJF1535_PROCEDURES:  # a built-in procedure validated on a unit scenario
        return validate_jjf1535_command(args)
    if args.unit is not None:
        raise ValueError(f"--unit {args.unit!r}: only with a procedure ({', '.join(PROCEDURES)}: plansim validate "
                         f"jjf1535 --unit SCENARIO); the scenario {args.scenario!r} is its own unit")
    scenario = load_scenario(args.scenario, args.set)
    claims = load_claims(args.claims, scenario) if args.claims else None
    progress = validate_progress(f"plansim validate {scenario.name}", args.quiet or args.json)
    report = validate(scenario, claims, digits=args.digits, trials_per_block=args.trials_per_block,
                      max_trials=args.max_trials, seed=args.seed, path=args.path, progress=progress)
    end_progress_line()
    if args.json:
        print(json.dumps({**validation_json(report), "overrides": list(scenario.overrides)}, indent=2))
    else:
        if scenario.overrides:
            print(f"Overrides (--set): {'; '.join(scenario.overrides)}")
        print(format_report(report, details=not args.summary))
    return 0


def _add_validate_command(sub) -> None:
    from plansim.uncertainty.metrology.monte_carlo import DEFAULT_DIGITS, DEFAULT_TRIALS_PER_BLOCK
    from plansim.uncertainty.validation import DEFAULT_MAX_TRIALS

    p = sub.add_parser(
        "validate", help="GUM budgets validated by adaptive Monte Carlo",
        description="GUM budget from the schedule, validated by adaptive Monte Carlo (JCGM 101/102); "
                    "checks a claimed budget (default: JJF 2003 Appendix A)")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name (see 'plansim scenarios') or a TOML path; default jjf2003; or the "
                        "procedure jjf1535 (the GUM of its items against the Monte Carlo)")
    p.add_argument("--unit", default=None, metavar="SCENARIO",
                   help=f"with the procedure jjf1535: the scenario whose unit, noise, effects and laboratory it runs "
                        f"on (built-in name or TOML path; default {DEFAULT_UNIT})")
    add_set_option(p)
    add_procedure_option(p)
    p.add_argument("--claims", default=None,
                   help="TOML file of claimed expanded uncertainties ([items.\"A.2\"] U = ...; [parameters.Bgx] "
                        "U = \"10 deg/h\"; k = 2 by default); default: the Appendix A budgets as printed")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the text report")
    p.add_argument("--trials-per-block", type=int, default=DEFAULT_TRIALS_PER_BLOCK,
                   help=f"M, Monte Carlo trials per block (JCGM 101 7.9.4 b); default {DEFAULT_TRIALS_PER_BLOCK}")
    p.add_argument("--max-trials", type=int, default=DEFAULT_MAX_TRIALS,
                   help=f"stop the adaptive procedure here at the latest (default {DEFAULT_MAX_TRIALS})")
    p.add_argument("--seed", type=int, default=None, help="root seed of the block seeds (default: the scenario's)")
    p.add_argument("--digits", type=int, default=DEFAULT_DIGITS,
                   help="n_dig, significant digits of the numerical tolerance δ "
                        f"(JCGM 101 7.9.2; default {DEFAULT_DIGITS})")
    p.add_argument("--path", choices=("auto", "sample", "segment"), default="auto",
                   help="simulation path: auto takes the segment-statistics path only where it is exact")
    p.add_argument("--summary", action="store_true", help="text report without the per-parameter budgets")
    p.add_argument("--quiet", action="store_true", help="no progress line on stderr")
    p.set_defaults(func=_cmd_validate)



def add_commands(sub) -> None:
    p = sub.add_parser("run", help=COMMANDS["run"],
                       description="Monte Carlo of a scenario's calibration, compared with JJF 2003 Appendix A; "
                                   "'plansim run jjf1535 [--unit SCENARIO]': the JJF 1535-2015 procedure on a unit "
                                   "scenario, compared with its Appendix A; 'plansim run vibration_g2': the vibration "
                                   "paper's g² experiment; 'plansim run jjf1537': the JJF 1537-2015 "
                                   "angular vibration test, a Monte Carlo (docs/dynamic.md); 'plansim run chapter "
                                   "[--unit SCENARIO]': the textbook chapter's procedures against JJF 2003 on the "
                                   "same units (docs/chapter-procedures.md)")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name (see 'plansim scenarios') or a TOML path; default jjf2003; or the "
                        "procedure jjf1535 or chapter, the experiment vibration_g2, or the dynamic test jjf1537")
    p.add_argument("--unit", default=None, metavar="SCENARIO",
                   help=f"with the procedure jjf1535 or chapter: the scenario whose unit, noise, effects and "
                        f"laboratory it runs on (built-in name or TOML path; default {DEFAULT_UNIT})")
    add_set_option(p)
    add_procedure_option(p)
    p.add_argument("--claims", default=None,
                   help="with the procedure jjf1535: a TOML file of a certificate's stated U per item "
                        "([jjf1535.ITEM] U = …, relative, k), judged against the Monte Carlo (docs/jjf1535.md)")
    p.add_argument("--trials", type=int, default=None,
                   help="number of simulated calibrations (default: the scenario's; jjf1535, chapter: 1000; "
                        "jjf1537: 500)")
    p.add_argument("--seed", type=int, default=None, help="random seed (default: the scenario's, or the unit's)")
    p.add_argument("--out", default=None, help="write the results Dataset to this NetCDF file (.nc)")
    p.add_argument("--plot", default=None, help="write the Appendix A error histograms (.png, .pdf or .svg); "
                   "vibration_g2: the PSDs and the compensated output; jjf1537: the Bode diagram; chapter: the rms "
                   "errors by procedure")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the tables")
    p.add_argument("--chunk-size", type=int, default=DEFAULT_CHUNK_SIZE,
                   help="trials per kernel call (results do not depend on it; memory grows with it)")
    p.add_argument("--path", choices=("auto", "sample", "segment"), default="auto",
                   help="simulation path: auto takes the segment-statistics path only where it is exact")
    p.add_argument("--quiet", action="store_true", help="no progress line on stderr")
    p.set_defaults(func=_cmd_run)

    _add_validate_command(sub)

    p = sub.add_parser("scenarios", help=COMMANDS["scenarios"], description="List the built-in scenarios "
                       "(the folder scenarios/, installed as plansim.scenarios) with their descriptions, then the "
                       "built-in procedures, which are not scenario files but run on a unit scenario "
                       "(plansim run jjf1535 --unit SCENARIO).")
    p.set_defaults(func=_cmd_scenarios)

    p = sub.add_parser("record", help=COMMANDS["record"],
                       description="Write one simulated trial's raw samples as a recording (NetCDF or CSV)")
    p.add_argument("scenario", nargs="?", default="jjf2003")
    add_set_option(p)
    p.add_argument("--out", required=True, help="recording file (.nc, or .csv plus <stem>.segments.csv)")
    p.add_argument("--seed", type=int, default=None)
    p.add_argument("--trial", type=int, default=0, help="which trial of the seed's Monte Carlo to record")
    p.set_defaults(func=_cmd_record)

