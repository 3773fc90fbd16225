"""``plansim sweep`` (one scenario, a grid of schedules, compared) and ``plansim plan`` (the shortest schedule that
meets a lab's targets); docs/planning.md."""

from __future__ import annotations

import json
import os
import time

from plansim.cli.common import COMMANDS, add_procedure_option, add_set_option
from plansim.io.files import OutputSet, check_output_path
from plansim.report.plot import FIGURE_SUFFIXES


def _cmd_sweep_jjf1535(args) -> int:
    """``plansim sweep jjf1535``: the JJF 1535 Monte Carlo over a grid of its settings and the unit's fields."""
    from plansim.planning.grid import load_grid
    from plansim.planning.jjf1535_sweep import cheapest_cell, jjf1535_cells, sweep_jjf1535
    from plansim.report.jjf1535 import parse_targets, sweep_jjf1535_json, sweep_jjf1535_table
    from plansim.report.progress import end_progress_line, stderr_progress

    # every check before any work: options that do not apply, the outputs, the grid, the targets, every cell
    for option, value in (("--predict-only", args.predict_only), ("--executor", args.executor != "serial"),
                          ("--workers", args.workers is not None), ("--scheduler", args.scheduler is not None)):
        if value:
            raise ValueError(f"{option}: not available with the procedure jjf1535 (its cells are a Monte Carlo, "
                             "run one after another)")
    if args.out is not None:
        check_output_path(args.out, "--out", (".nc",))
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.trials is not None and args.trials < 2:
        raise ValueError(f"--trials {args.trials}: must be >= 2 (the standard deviations need two trials)")
    unit = args.unit or "jjf2003"
    grid = load_grid(args.grid)
    targets = parse_targets(args.target)
    jjf1535_cells(unit, grid, args.set, args.procedure)
    trials = 1000 if args.trials is None else args.trials
    with OutputSet() as outputs:
        out = outputs.stage(args.out, "--out", (".nc",)) if args.out is not None else None
        plot = outputs.stage(args.plot, "--plot", FIGURE_SUFFIXES) if args.plot is not None else None
        progress = None if (args.quiet or args.json) else stderr_progress("plansim sweep jjf1535", unit="cells")
        start = time.perf_counter()
        result = sweep_jjf1535(unit, grid, unit_overrides=args.set, procedure_overrides=args.procedure,
                               trials=trials, seed=args.seed, path=args.path, progress=progress)
        elapsed = time.perf_counter() - start
        end_progress_line()
        best = cheapest_cell(result, targets) if targets else None
        if out is not None:
            result.to_netcdf(out, engine="h5netcdf")
        if plot is not None:
            from plansim.report.plot import sweep_jjf1535_figure

            sweep_jjf1535_figure(result, plot, list(targets) or None, targets,
                                 format=os.path.splitext(args.plot)[1].lstrip("."))
        outputs.commit()
    if args.json:
        print(json.dumps({**sweep_jjf1535_json(result, targets, best), "elapsed_s": elapsed}, indent=2,
                         allow_nan=False))
    else:
        print(f"plansim sweep jjf1535 --unit {unit}: {grid.size} cells, {trials} trials per cell, seed "
              f"{result.attrs['seed']}, {elapsed:.1f} s")
        for label, items in (("Overrides (--set) on every cell", args.set),
                             ("Procedure settings (--procedure) on every cell", args.procedure)):
            if items:
                print(f"{label}: {'; '.join(items)}")
        print()
        print(sweep_jjf1535_table(result, targets, best))
        for label, path in (("sweep", args.out), ("figure", args.plot)):
            if path:
                print(f"\nwrote {label}: {path}")
    return 0


def _cmd_sweep(args) -> int:
    from plansim.io.scenario_file import load_scenario
    from plansim.planning.grid import load_grid
    from plansim.planning.sweep import sweep
    from plansim.report.progress import end_progress_line, stderr_progress
    from plansim.report.sweep import sweep_json, sweep_table

    if args.scenario == "jjf1535":
        return _cmd_sweep_jjf1535(args)
    for option, value in (("--unit", args.unit), ("--procedure", args.procedure), ("--target", args.target)):
        if value:
            raise ValueError(f"{option}: only with the procedure jjf1535 (plansim sweep jjf1535 --grid GRID "
                             f"{option} …); the scenario {args.scenario!r} is its own unit")
    # every check before any work: the outputs, the grid, the scenario and every cell
    if args.out is not None:
        check_output_path(args.out, "--out", (".nc",))
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers {args.workers}: must be >= 1")
    if args.scheduler is not None and args.executor != "dask":
        raise ValueError(f"--scheduler {args.scheduler!r}: only with --executor dask")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    grid = load_grid(args.grid)
    base = load_scenario(args.scenario, args.set)
    trials = 0 if args.predict_only else (base.trials if args.trials is None else args.trials)
    if args.trials is not None and args.trials < 1:
        raise ValueError(f"--trials {args.trials}: must be >= 1 (--predict-only for none)")

    with OutputSet() as outputs:
        out = outputs.stage(args.out, "--out", (".nc",)) if args.out is not None else None
        plot = outputs.stage(args.plot, "--plot", FIGURE_SUFFIXES) if args.plot is not None else None
        progress = None
        if not (args.quiet or args.json):
            progress = stderr_progress(f"plansim sweep {base.name}", unit="cells")
        start = time.perf_counter()
        result = sweep(args.scenario, grid, overrides=args.set, trials=trials, seed=args.seed,
                       executor=args.executor, workers=args.workers, scheduler=args.scheduler, path=args.path,
                       progress=progress)
        elapsed = time.perf_counter() - start
        end_progress_line()
        if out is not None:
            result.to_netcdf(out, engine="h5netcdf")
        if plot is not None:
            from plansim.report.plot import sweep_figure

            sweep_figure(result, plot, format=os.path.splitext(args.plot)[1].lstrip("."))
        outputs.commit()

    if args.json:
        print(json.dumps({**sweep_json(result), "elapsed_s": elapsed}, indent=2, allow_nan=False))
    else:
        cells = grid.size
        what = f"{trials} trials per cell" if trials else "the prediction only (--predict-only)"
        print(f"plansim sweep {base.name}: {cells} cells, {what}, seed {result.attrs['seed']}, "
              f"{elapsed:.1f} s ({args.executor})")
        if base.overrides:
            print(f"Overrides (--set) on every cell: {'; '.join(base.overrides)}")
        print()
        print(sweep_table(result))
        for label, path in (("sweep", args.out), ("figure", args.plot)):
            if path:
                print(f"\nwrote {label}: {path}")
    return 0


def _cmd_plan(args) -> int:
    import tomllib

    from plansim.config import parse_scenario
    from plansim.io.scenario_file import load_scenario, save_scenario
    from plansim.planning.plan import load_targets, plan
    from plansim.report.plan import plan_json, plan_report
    from plansim.report.progress import end_progress_line, stderr_progress

    if args.out is not None:
        check_output_path(args.out, "--out", (".toml",))
    if args.trials is not None and args.trials != 0 and args.trials < 2:
        raise ValueError(f"--trials {args.trials}: must be 0 (no Monte Carlo) or >= 2")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    base = load_scenario(args.scenario, args.set)
    targets = load_targets(args.targets, base)
    trials = base.trials if args.trials is None else args.trials
    with OutputSet() as outputs:
        out = outputs.stage(args.out, "--out", (".toml",)) if args.out is not None else None
        progress = None
        if not (args.quiet or args.json):
            progress = stderr_progress(f"plansim plan {base.name}", unit="predictions")
        start = time.perf_counter()
        result = plan(base, targets, compliant=args.jjf2003_compliant, trials=trials, seed=args.seed,
                      path=args.path, progress=progress)
        elapsed = time.perf_counter() - start
        end_progress_line()
        if out is not None:
            save_scenario(result.scenario, out, expand_schedule=True)
            with open(out, "rb") as f:  # what plansim run will read: parsed back before it is committed
                parse_scenario(tomllib.load(f), source=str(args.out))
        outputs.commit()
    if args.json:
        print(json.dumps({**plan_json(result), "elapsed_s": elapsed}, indent=2, allow_nan=False))
    else:
        print(f"plansim plan {base.name}: {len(targets)} targets from {args.targets}, {elapsed:.1f} s")
        if base.overrides:
            print(f"Overrides (--set): {'; '.join(base.overrides)}")
        print()
        print(plan_report(result, default_time=base.schedule.duration))
        if args.out:
            print(f"\nwrote plan: {args.out} (plansim run {args.out})")
    return 0


def add_commands(sub) -> None:
    p = sub.add_parser(
        "sweep", help=COMMANDS["sweep"],
        description="Predict (GUM) and simulate (Monte Carlo) a scenario over a grid of its fields: "
                    "uncertainty, table time and JJF 2003 compliance per cell (docs/planning.md)")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name (see 'plansim scenarios') or a TOML path; default jjf2003; or the "
                        "procedure jjf1535 (a Monte Carlo per cell of its settings; docs/jjf1535.md)")
    p.add_argument("--grid", required=True,
                   help="grid file (TOML): [vary] field = [values, ...], optional [zip] (docs/planning.md); with "
                        "jjf1535, keys procedure.SETTING or the unit's fields")
    add_set_option(p)
    p.add_argument("--unit", default=None, metavar="SCENARIO",
                   help="with the procedure jjf1535: the unit scenario (default jjf2003)")
    add_procedure_option(p)
    p.add_argument("--target", action="append", default=[], metavar="ITEM=VALUE",
                   help="with the procedure jjf1535: the largest acceptable 95 %% |error| of an item (its spread "
                        "where it has no true value), in the item's unit as the report prints it, e.g. "
                        "--target nonlinearity=100 (ppm); the shortest session meeting every target is named")
    how = p.add_mutually_exclusive_group()
    how.add_argument("--trials", type=int, default=None,
                     help="Monte Carlo trials per cell (default: the scenario's)")
    how.add_argument("--predict-only", action="store_true", help="the prediction (GUM) only, no Monte Carlo")
    p.add_argument("--seed", type=int, default=None,
                   help="base seed (default: the scenario's); each cell's comes from it and the cell's fields")
    p.add_argument("--executor", choices=("serial", "threads", "dask"), default="serial",
                   help="where cells run: serial, threads, or dask (needs plansim[dask]); results do not "
                        "depend on it")
    p.add_argument("--workers", type=int, default=None, help="threads or Dask worker processes (default: cores)")
    p.add_argument("--scheduler", default=None, help="address of a running Dask scheduler (with --executor dask)")
    p.add_argument("--path", choices=("auto", "sample", "segment"), default="auto",
                   help="simulation path, as for plansim run")
    p.add_argument("--out", default=None, help="write the sweep Dataset to this NetCDF file (.nc)")
    p.add_argument("--plot", default=None, help="uncertainty against table time with the Pareto front "
                                                "(.png, .pdf or .svg)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the table")
    p.add_argument("--quiet", action="store_true", help="no progress line on stderr")
    p.set_defaults(func=_cmd_sweep)

    p = sub.add_parser(
        "plan", help=COMMANDS["plan"],
        description="The shortest JJF 2003-structured schedule (table time, settling included) whose expanded "
                    "uncertainty meets every target, searched on the prediction and verified by a Monte Carlo "
                    "(docs/planning.md)")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name or a TOML path (the unit, noise, table, site); default jjf2003")
    p.add_argument("--targets", required=True,
                   help="targets file (TOML): [targets] parameter or group = U (k = 2) with its unit, or "
                        "from_appendix_a = true (docs/planning.md)")
    add_set_option(p)
    p.add_argument("--jjf2003-compliant", action="store_true",
                   help="keep to JJF 2003 §7.2: 12 positions, 7-11 rate points with both maxima, dwell >= 30 s")
    p.add_argument("--trials", type=int, default=None,
                   help="Monte Carlo trials of the calibration and verification (default: the scenario's; 0: none)")
    p.add_argument("--seed", type=int, default=None, help="Monte Carlo seed (default: the scenario's)")
    p.add_argument("--path", choices=("auto", "sample", "segment"), default="auto",
                   help="simulation path, as for plansim run")
    p.add_argument("--out", default=None, help="write the planned scenario (TOML) that plansim run takes")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the report")
    p.add_argument("--quiet", action="store_true", help="no progress line on stderr")
    p.set_defaults(func=_cmd_plan)


__all__ = ["add_commands"]
