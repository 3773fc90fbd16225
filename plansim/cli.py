"""Command line: ``plansim run``, ``validate``, ``scenarios``, ``record``, ``import``, ``fit``, ``bench``.

Errors in the user's input end with ``plansim: error: …`` and exit status 2, before any work starts:
output paths are checked first (:func:`plansim.io.files.check_output_path`). The output files of one
command are written to temporary files beside their targets and renamed onto them together at the end,
or not at all (:class:`plansim.io.files.OutputSet`).

Ctrl-C (SIGINT) and SIGTERM end a command with one line on stderr (``plansim: interrupted``,
``plansim: terminated``) and the exit status 128 + the signal's number (130, 143), after removing its
temporary files and any compile process. When the reader of the standard output goes away
(``plansim run | head``), the command ends quietly with the exit status 141 (128 + SIGPIPE), as the
standard tools killed by SIGPIPE do.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import sys
import threading
import time

import plansim
from plansim.io.files import OutputSet, check_output_path
from plansim.report.plot import FIGURE_SUFFIXES
from plansim.report.progress import end_progress_line

#: exit statuses (besides 0 and 1): bad input, then 128 + the signal's number
EXIT_BAD_INPUT = 2
EXIT_BROKEN_PIPE = 128 + signal.SIGPIPE
#: the signals that end a command cleanly, and the word it says
SIGNAL_WORDS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}


class Interrupted(KeyboardInterrupt):
    """Raised in the main thread when SIGINT or SIGTERM arrives, so that every ``finally`` and ``except
    BaseException`` on the way out runs (temporary files removed, a compile process killed).

    A subclass of KeyboardInterrupt: code that lets Ctrl-C through lets SIGTERM through too.
    """

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)


def _raise_interrupted(signum, frame):
    raise Interrupted(signum)


@contextlib.contextmanager
def signals_as_exceptions():
    """While a command runs, SIGINT and SIGTERM raise :class:`Interrupted` in the main thread.

    A signal the caller ignores (``nohup``, a background job without job control) stays ignored; the
    previous handlers are restored at the end. Outside the main thread nothing changes (Python runs
    signal handlers there only).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {}
    try:
        for signum in SIGNAL_WORDS:
            if signal.getsignal(signum) is not signal.SIG_IGN:
                previous[signum] = signal.signal(signum, _raise_interrupted)
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _silence_stdout() -> None:
    """The reader of stdout is gone: send what is still buffered, and anything later, to /dev/null (so the
    interpreter's last flush at exit does not fail again)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor (captured, say)
        pass


def _cmd_run(args) -> int:
    from plansim.config import saturation_report
    from plansim.io.results import write_results
    from plansim.io.scenario_file import load_scenario
    from plansim.report.progress import stderr_progress
    from plansim.report.summary import appendix_a_comparisons
    from plansim.report.table import appendix_a_table, header, parameter_summary, parameter_table
    from plansim.runner import run, run_summary
    from plansim.uncertainty import compare_with_appendix_a

    # every check before any work: the outputs, the scenario, the numbers
    if args.out is not None:
        check_output_path(args.out, "--out", (".nc",))
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    scenario = load_scenario(args.scenario)
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
            "scenario": scenario.name, "seed": results.attrs["seed"], "trials": trials,
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
    width = max(map(len, descriptions), default=0)
    for name, description in descriptions.items():
        print(f"{name:{width}s}  {description}".rstrip())
    return 0


def _cmd_record(args) -> int:
    from plansim.io.recording import write_recording
    from plansim.io.recording_csv import segment_table_path
    from plansim.io.scenario_file import load_scenario
    from plansim.runner import simulate_and_record

    target = check_output_path(args.out, "--out", (".nc", ".csv"))
    if target.suffix.lower() == ".csv":  # the segment table is written beside the samples
        check_output_path(segment_table_path(target), "--out's segment table")
    scenario = load_scenario(args.scenario)
    seed = scenario.seed if args.seed is None else args.seed
    rec = simulate_and_record(scenario, seed=seed, trial=args.trial)
    write_recording(rec, args.out)
    print(f"wrote recording of trial {args.trial} of {scenario.name!r} (seed {seed}): "
          f"{rec.samples.shape[0]} samples in {len(rec.schedule)} segments -> {args.out}")
    return 0


def _cmd_import(args) -> int:
    from plansim.io.log_import import format_summary, import_log
    from plansim.io.recording import write_recording
    from plansim.io.recording_csv import segment_table_path

    target = check_output_path(args.out, "--out", (".nc", ".csv"))
    outputs = [target]
    if target.suffix.lower() == ".csv":  # the segment table is written beside the samples
        outputs.append(check_output_path(segment_table_path(target), "--out's segment table"))
    if any(os.path.exists(args.log) and os.path.exists(out) and os.path.samefile(args.log, out) for out in outputs):
        raise ValueError(f"--out {args.out!r} would overwrite the log {args.log!r}; write the recording elsewhere")
    columns = None if args.columns is None else tuple(name.strip() for name in args.columns.split(","))
    options = {name: getattr(args, name) for name in ("window", "min_static") if getattr(args, name) is not None}
    result = import_log(args.log, columns=columns, time_column=args.time, time_unit=args.time_unit,
                        units=args.units, scale=args.scale, sample_rate=args.sample_rate,
                        temperature_column=args.temperature_column, temperature=args.temperature,
                        latitude=args.latitude, height=args.height, **options)
    write_recording(result.recording, args.out)  # whole or not at all
    print(format_summary(result))
    print(f"\nwrote recording: {args.out} (review its segment table: docs/measured-data.md)")
    return 0


def _add_import_command(sub) -> None:
    p = sub.add_parser(
        "import", help=COMMANDS["import"],
        description="Read a plain CSV log (six channels; a time column or a sample rate) and write a recording "
                    "whose segment table (static poses, rotations, moves) is found from the data, for you to "
                    "review (docs/measured-data.md)")
    p.add_argument("log", help="the CSV log: a header line of column names, one row per sample")
    p.add_argument("--out", required=True, help="recording file (.nc, or .csv plus <stem>.segments.csv)")
    p.add_argument("--time", default=None, metavar="COL", help="the time column (default: none; give --sample-rate)")
    p.add_argument("--time-unit", default="s", choices=("s", "ms", "us", "ns", "samples"),
                   help="unit of the time column (samples: a sample counter, with --sample-rate); default s")
    p.add_argument("--columns", default=None, metavar="GX,GY,GZ,AX,AY,AZ",
                   help="the six channel columns in this order (default gx,gy,gz,ax,ay,az); other columns are "
                        "then ignored")
    p.add_argument("--units", default=None,
                   help="the channels' units: gyro,accelerometer (e.g. deg/s,m/s^2) or one per channel; with "
                        "--scale, the unit the counts are per; default rad/s,m/s^2")
    p.add_argument("--scale", default=None,
                   help="counts per unit, gyro,accelerometer or one per channel (e.g. 16.4,2048 with --units deg/s,g)")
    p.add_argument("--sample-rate", type=float, default=None, metavar="HZ",
                   help="sample rate; required without --time (default: from the time column)")
    p.add_argument("--temperature-column", default=None, metavar="COL", help="a temperature column in degC")
    p.add_argument("--temperature", type=float, default=None, metavar="DEGC",
                   help="the lab's temperature, for a log without a temperature column (default 20, noted as assumed)")
    p.add_argument("--latitude", type=float, default=None, metavar="DEG", help="site latitude (site_latitude_deg)")
    p.add_argument("--height", type=float, default=None, metavar="M", help="site height (site_height_m)")
    p.add_argument("--window", type=float, default=None, metavar="S",
                   help="window of the rest detector (default 0.5 s)")
    p.add_argument("--min-static", type=float, default=None, metavar="S",
                   help="shortest static pose kept (default 1 s)")
    p.set_defaults(func=_cmd_import)


def _cmd_fit(args) -> int:
    from plansim.fit import fit_recording, resolve_site
    from plansim.fit.result import fit_dataset, fit_json
    from plansim.io.recording import read_recording
    from plansim.io.scenario_file import load_scenario
    from plansim.report.fit import fit_report

    if args.out is not None:
        check_output_path(args.out, "--out", (".nc",))
    scenario = load_scenario(args.scenario) if args.scenario is not None else None
    recording = read_recording(args.recording)
    site = resolve_site(args.latitude, args.height, recording.attrs, scenario)
    options = {}
    if scenario is not None:
        options = dict(turntable=scenario.turntable, turntable_source=f"scenario {scenario.name!r}, [turntable]",
                       reference_gravity=scenario.reduction.reference_gravity,
                       omega_squared_sign=scenario.reduction.omega_squared_sign)
    result = fit_recording(recording, site, **options)
    with OutputSet() as outputs:
        if args.out is not None:
            fit_dataset(result).to_netcdf(outputs.stage(args.out, "--out", (".nc",)), engine="h5netcdf")
        outputs.commit()
    if args.json:
        print(json.dumps(fit_json(result), indent=2))
    else:
        print(fit_report(result, residuals=not args.no_residuals))
        if args.out is not None:
            print(f"\nwrote fit: {args.out}")
    return 0


def _add_fit_command(sub) -> None:
    p = sub.add_parser(
        "fit", help=COMMANDS["fit"],
        description="Fit a recording: which of the 39 JJF 2003 parameters its segments identify, their estimates by "
                    "the specification's estimators (where the procedure is complete) and by one joint weighted "
                    "least squares, the noise from the data (Allan deviation), and each parameter's standard "
                    "uncertainty (docs/fitting.md)")
    p.add_argument("recording", help="recording file (.nc, or the samples .csv beside its .segments.csv)")
    p.add_argument("--latitude", type=float, default=None, metavar="DEG",
                   help="site latitude (default: the recording's site_latitude_deg, else the scenario's)")
    p.add_argument("--height", type=float, default=None, metavar="M", help="site height, with --latitude")
    p.add_argument("--scenario", default=None,
                   help="the lab's scenario (name or TOML path): its site, turntable/fixture grade and reduction "
                        "(default: JJF 2003 Table 1 and the recording's attributes)")
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of the report")
    p.add_argument("--out", default=None, help="write the fit as a NetCDF file (.nc)")
    p.add_argument("--no-residuals", action="store_true", help="leave the per-segment residual table out of the report")
    p.set_defaults(func=_cmd_fit)


def _cmd_validate(args) -> int:
    from plansim.io.claims import load_claims
    from plansim.io.scenario_file import load_scenario
    from plansim.report.progress import mark_progress_line
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
    progress = None
    if not (args.quiet or args.json):
        block_progress = stderr_block_progress(f"plansim validate {scenario.name}")

        def progress(*state) -> None:  # the block progress line is open until the report starts
            block_progress(*state)
            mark_progress_line(True)

    report = validate(scenario, claims, digits=args.digits, trials_per_block=args.trials_per_block,
                      max_trials=args.max_trials, seed=args.seed, path=args.path, progress=progress)
    end_progress_line()
    if args.json:
        print(json.dumps(validation_json(report), indent=2))
    else:
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


#: one line per command in ``plansim --help`` (at most 52 characters: one line in an 80-column terminal)
COMMANDS = {
    "run": "Monte Carlo of a calibration vs JJF 2003 Appendix A",
    "validate": "GUM budgets validated by adaptive Monte Carlo",
    "scenarios": "list the built-in scenarios",
    "record": "write one simulated trial's raw samples",
    "import": "a plain CSV log to a recording with segments",
    "fit": "fit a recording: parameters, noise, uncertainty",
    "bench": "measure speed and memory on this machine",
}

EPILOG = """exit status: 0 done; 1 failed; 2 bad input (plansim: error: ...); 130 interrupted (Ctrl-C);
143 terminated (SIGTERM); 141 the reader of the output went away (plansim run | head).
'plansim COMMAND --help' describes a command's options."""


class _TopLevelHelp(argparse.RawDescriptionHelpFormatter):
    """``plansim --help``: the commands' help in one column wide enough for the longest command name."""

    def __init__(self, prog: str) -> None:
        super().__init__(prog)
        # argparse measures the commands with the indent of the group, not their own (two more columns)
        self._action_max_length = 4 + max(map(len, COMMANDS))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="plansim", formatter_class=_TopLevelHelp, epilog=EPILOG,
        description="Monte Carlo calibration planning for MEMS IMUs under JJF 2003-2022.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {plansim.__version__}")
    sub = parser.add_subparsers(dest="command", required=True, title="commands", metavar="COMMAND")

    p = sub.add_parser("run", help=COMMANDS["run"],
                       description="Monte Carlo of a scenario's calibration, compared with JJF 2003 Appendix A")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name (see 'plansim scenarios') or a TOML path; default jjf2003")
    p.add_argument("--trials", type=int, default=None,
                   help="number of simulated calibrations (default: the scenario's)")
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

    _add_validate_command(sub)

    p = sub.add_parser("scenarios", help=COMMANDS["scenarios"], description="List the built-in scenarios "
                       "(the folder scenarios/, installed as plansim.scenarios) with their descriptions.")
    p.set_defaults(func=_cmd_scenarios)

    p = sub.add_parser("record", help=COMMANDS["record"],
                       description="Write one simulated trial's raw samples as a recording (NetCDF or CSV)")
    p.add_argument("scenario", nargs="?", default="jjf2003")
    p.add_argument("--out", required=True, help="recording file (.nc, or .csv plus <stem>.segments.csv)")
    p.add_argument("--seed", type=int, default=None)
    p.add_argument("--trial", type=int, default=0, help="which trial of the seed's Monte Carlo to record")
    p.set_defaults(func=_cmd_record)

    _add_import_command(sub)
    _add_fit_command(sub)

    p = sub.add_parser("bench", help=COMMANDS["bench"],
                       description="Measure speed and memory on this machine (takes a few minutes)")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    p.add_argument("--quick", action="store_true", help="small sizes (seconds): checks the method, not the speed")
    p.add_argument("--threads", type=int, default=None, help="pin the kernel thread count (default: all cores)")
    p.set_defaults(func=_cmd_bench)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command of *argv* (default: ``sys.argv[1:]``); return its exit status (see :data:`EPILOG`)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "chunk_size", 1) < 1:
        parser.error(f"--chunk-size {args.chunk_size}: must be >= 1")
    try:
        with signals_as_exceptions():
            code = args.func(args)
            sys.stdout.flush()  # a reader gone away is found here, not in the interpreter's last flush
        return code
    except (ValueError, TypeError, FileNotFoundError) as exc:
        end_progress_line()
        print(f"plansim: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM as Interrupted
        signum = getattr(exc, "signum", signal.SIGINT)
        end_progress_line()
        print(f"plansim: {SIGNAL_WORDS[signum]}", file=sys.stderr)
        return 128 + signum
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE


if __name__ == "__main__":
    sys.exit(main())
