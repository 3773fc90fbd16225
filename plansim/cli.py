"""Command line: ``plansim run``, ``plansim scenarios``, ``plansim record``.

Errors in the user's input end with ``plansim: error: …`` and exit status 2, before anything is
written; output files are written whole or not at all.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

from plansim.report.plot import FIGURE_SUFFIXES


def _check_output(path: str | None, suffixes: tuple[str, ...], option: str) -> None:
    """Fail before the (long) run if an output could not be written."""
    if path is None:
        return
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise ValueError(f"{option} {path!r}: the file name must end in {' or '.join(suffixes)}")
    folder = p.parent if str(p.parent) else Path(".")
    if not folder.is_dir():
        raise ValueError(f"{option} {path!r}: the folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK):
        raise ValueError(f"{option} {path!r}: the folder {str(folder)!r} is not writable")


def _cmd_run(args) -> int:
    from plansim.io.results import write_results
    from plansim.io.scenario_file import load_scenario
    from plansim.report.progress import stderr_progress
    from plansim.report.summary import appendix_a_comparisons
    from plansim.report.table import appendix_a_table, header, parameter_summary, parameter_table
    from plansim.runner import run, run_summary
    from plansim.uncertainty import compare_with_appendix_a

    _check_output(args.out, (".nc",), "--out")
    _check_output(args.plot, FIGURE_SUFFIXES, "--plot")
    scenario = load_scenario(args.scenario)
    trials = scenario.trials if args.trials is None else args.trials
    if trials < 1:
        raise ValueError(f"--trials {trials}: must be >= 1")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    progress = None if args.quiet else stderr_progress(f"plansim run {scenario.name}")
    start = time.perf_counter()
    if args.plot:  # the histograms need every trial's error: keep the trials (run checks the memory)
        results = run(scenario, trials=trials, seed=args.seed, chunk_size=args.chunk_size, progress=progress,
                      path=args.path)
        elapsed = time.perf_counter() - start
        comparisons = compare_with_appendix_a(results["truth"].values, results["estimate"].values, scenario) \
            if trials >= 2 else []
        if args.out:
            write_results(results, args.out)
    else:  # only the statistics, streamed; --out streams every trial to the file
        results = run_summary(scenario, trials=trials, seed=args.seed, chunk_size=args.chunk_size,
                              progress=progress, path=args.path, out=args.out)
        elapsed = time.perf_counter() - start
        comparisons = appendix_a_comparisons(results, scenario)
    if args.plot:
        if not comparisons:
            raise ValueError("--plot needs at least 2 trials")
        from plansim.report.plot import appendix_a_histograms

        appendix_a_histograms(results, scenario, comparisons, args.plot)
    if args.json:
        print(json.dumps({
            "scenario": scenario.name, "seed": results.attrs["seed"], "trials": trials,
            "plansim_version": results.attrs["plansim_version"], "elapsed_s": elapsed,
            "parameters": [{k: r[k] for k in ("name", "unit", "mean_error", "std_error")}
                           for r in parameter_summary(results)],
            "appendix_a": [c.as_dict() for c in comparisons],
        }, indent=2))
    else:
        print(header(results, elapsed))
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

    for name, path in builtin_scenarios().items():
        with open(path, "rb") as fh:
            description = tomllib.load(fh).get("description", "")
        print(f"{name:14s} {description}")
    return 0


def _cmd_record(args) -> int:
    from plansim.io.recording import write_recording
    from plansim.io.scenario_file import load_scenario
    from plansim.runner import simulate_and_record

    _check_output(args.out, (".nc", ".csv"), "--out")
    scenario = load_scenario(args.scenario)
    seed = scenario.seed if args.seed is None else args.seed
    rec = simulate_and_record(scenario, seed=seed, trial=args.trial)
    write_recording(rec, args.out)
    print(f"wrote recording of trial {args.trial} of {scenario.name!r} (seed {seed}): "
          f"{rec.samples.shape[0]} samples in {len(rec.schedule)} segments -> {args.out}")
    return 0


def _cmd_validate(args) -> int:
    from plansim.io.claims import load_claims
    from plansim.io.scenario_file import load_scenario
    from plansim.report.validation import format_report, stderr_block_progress, validation_json
    from plansim.runner import validate

    scenario = load_scenario(args.scenario)
    claims = load_claims(args.claims, scenario) if args.claims else None
    for option, value, minimum in (("--trials-per-block", args.trials_per_block, 2),
                                   ("--max-trials", args.max_trials, 1), ("--digits", args.digits, 1)):
        if value < minimum:
            raise ValueError(f"{option} {value}: must be >= {minimum}")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    progress = None if (args.quiet or args.json) else stderr_block_progress(f"plansim validate {scenario.name}")
    report = validate(scenario, claims, digits=args.digits, trials_per_block=args.trials_per_block,
                      max_trials=args.max_trials, seed=args.seed, path=args.path, progress=progress)
    if progress is not None:
        sys.stderr.write("\n")
    if args.json:
        print(json.dumps(validation_json(report), indent=2))
    else:
        print(format_report(report, details=not args.summary))
    return 0


def _add_validate_command(sub) -> None:
    from plansim.uncertainty.metrology.monte_carlo import DEFAULT_DIGITS, DEFAULT_TRIALS_PER_BLOCK
    from plansim.uncertainty.validation import DEFAULT_MAX_TRIALS

    p = sub.add_parser(
        "validate", help="GUM budget from the schedule, validated by adaptive Monte Carlo (JCGM 101/102); "
                         "checks a claimed budget (default: JJF 2003 Appendix A)")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name (see 'plansim scenarios') or a TOML path; default jjf2003")
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


def _cmd_bench(args) -> int:
    import numba

    from plansim.bench import main as bench_main

    if args.threads is not None:
        if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
            raise ValueError(f"--threads {args.threads}: allowed 1 to {numba.config.NUMBA_NUM_THREADS}")
        numba.set_num_threads(args.threads)
    return bench_main(json_output=args.json, quick=args.quick)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="plansim", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("run", help="Monte Carlo of a scenario's calibration, compared with JJF 2003 Appendix A")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name (see 'plansim scenarios') or a TOML path; default jjf2003")
    p.add_argument("--trials", type=int, default=None, help="number of simulated calibrations (default: the scenario's)")
    p.add_argument("--seed", type=int, default=None, help="random seed (default: the scenario's)")
    p.add_argument("--out", default=None, help="write the results Dataset to this NetCDF file (.nc)")
    p.add_argument("--plot", default=None, help="write the Appendix A error histograms (.png, .pdf or .svg)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the tables")
    p.add_argument("--chunk-size", type=int, default=4096,
                   help="trials per kernel call (results do not depend on it; memory grows with it)")
    p.add_argument("--path", choices=("auto", "sample", "segment"), default="auto",
                   help="simulation path: auto takes the segment-statistics path only where it is exact")
    p.add_argument("--quiet", action="store_true", help="no progress line on stderr")
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("scenarios", help="list the built-in scenarios")
    p.set_defaults(func=_cmd_scenarios)

    p = sub.add_parser("record", help="write one simulated trial's raw samples as a recording (NetCDF or CSV)")
    p.add_argument("scenario", nargs="?", default="jjf2003")
    p.add_argument("--out", required=True, help="recording file (.nc, or .csv plus <stem>.segments.csv)")
    p.add_argument("--seed", type=int, default=None)
    p.add_argument("--trial", type=int, default=0, help="which trial of the seed's Monte Carlo to record")
    p.set_defaults(func=_cmd_record)

    p = sub.add_parser("bench", help="measure speed and memory on this machine (takes a few minutes)")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    p.add_argument("--quick", action="store_true", help="small sizes (seconds): checks the method, not the speed")
    p.add_argument("--threads", type=int, default=None, help="pin the kernel thread count (default: all cores)")
    p.set_defaults(func=_cmd_bench)
    _add_validate_command(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "chunk_size", 1) < 1:
        parser.error(f"--chunk-size {args.chunk_size}: must be >= 1")
    try:
        return args.func(args)
    except (ValueError, TypeError, FileNotFoundError) as exc:
        print(f"plansim: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
