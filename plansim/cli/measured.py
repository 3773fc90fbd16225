"""``plansim import`` and ``plansim fit``: measured data in (docs/measured-data.md, docs/fitting.md)."""

from __future__ import annotations

import json
import os

from plansim.cli.common import COMMANDS
from plansim.io.files import OutputSet, check_output_path
from plansim.report.plot import FIGURE_SUFFIXES


def _cmd_import(args) -> int:
    from plansim.io.log_import import import_log
    from plansim.io.recording import write_recording
    from plansim.io.recording_csv import segment_table_path
    from plansim.report.import_summary import format_summary

    target = check_output_path(args.out, "--out", (".nc", ".csv"))
    outputs = [target]
    if args.plot is not None:
        outputs.append(check_output_path(args.plot, "--plot", FIGURE_SUFFIXES))
    if target.suffix.lower() == ".csv":  # the segment table is written beside the samples
        outputs.append(check_output_path(segment_table_path(target), "--out's segment table"))
    for log in (args.log, args.accel_log):
        if log is not None and any(os.path.exists(log) and os.path.exists(out) and os.path.samefile(log, out)
                                   for out in outputs):
            raise ValueError(f"--out {args.out!r} would overwrite the log {log!r}; write the recording elsewhere")
    columns = None if args.columns is None else tuple(name.strip() for name in args.columns.split(","))
    options = {name: getattr(args, name) for name in ("window", "min_static", "rest_variance")
               if getattr(args, name) is not None}
    result = import_log(args.log, columns=columns, time_column=args.time, time_unit=args.time_unit,
                        units=args.units, scale=args.scale, offset=args.offset, sample_rate=args.sample_rate,
                        temperature_column=args.temperature_column, temperature=args.temperature,
                        latitude=args.latitude, height=args.height, full_scale=args.full_scale,
                        accel_log=args.accel_log, table_rate_column=args.table_rate_column,
                        table_rate_unit=args.table_rate_unit, table_angle_column=args.table_angle_column,
                        table_angle_unit=args.table_angle_unit, poses=args.poses, **options)
    with OutputSet() as staged:
        if args.plot is not None:  # drawn before the recording is written; committed once it is
            from plansim.report.plot import recording_figure

            recording_figure(result.recording, staged.stage(args.plot, "--plot", FIGURE_SUFFIXES),
                             format=os.path.splitext(args.plot)[1].lstrip("."))
        write_recording(result.recording, args.out)  # whole or not at all
        staged.commit()
    print(format_summary(result))
    print(f"\nwrote recording: {args.out} (review its segment table: docs/measured-data.md)")
    if args.plot is not None:
        print(f"wrote figure: {args.plot} (the samples against time, the segments shaded and numbered)")
    return 0


def _add_import_command(sub) -> None:
    from plansim.estimate.segmentation import FULL_SCALE_MARGIN

    p = sub.add_parser(
        "import", help=COMMANDS["import"],
        description="Read a plain CSV log (six channels; a time column or a sample rate) and write a recording "
                    "whose segment table (static poses, rotations, moves) is found from the data, for you to "
                    "review (docs/measured-data.md)")
    p.add_argument("log", help="the CSV log: a header line of column names (lines of a logger's own before it are "
                               "skipped and reported), or none, then one row per sample; values separated by "
                               "commas, semicolons, tabs or spaces")
    p.add_argument("--out", required=True, help="recording file (.nc, or .csv plus <stem>.segments.csv)")
    p.add_argument("--accel-log", default=None, metavar="LOG2",
                   help="the accelerometers' log, where they were logged in a file of their own (imu_tk, phyphox, "
                        "phone sensor loggers): LOG then holds the gyros, --columns names LOG's three then LOG2's "
                        "three, and --time is in both; each sample of the slower log is paired with the mean of the "
                        "other's samples in its interval (nothing interpolated)")
    p.add_argument("--time", default=None, metavar="COL",
                   help="the time column (default: none; give --sample-rate); in a log with no header line, its "
                        "position (1 for the first column)")
    p.add_argument("--time-unit", default="s", choices=("s", "ms", "us", "ns", "samples"),
                   help="unit of the time column (samples: a sample counter, with --sample-rate); default s")
    p.add_argument("--columns", default=None, metavar="GX,GY,GZ,AX,AY,AZ",
                   help="the six channel columns in this order (default gx,gy,gz,ax,ay,az); other columns are "
                        "then ignored. A log with no header line names them by position, 1 for the first (imu_tk's "
                        "'time ax ay az gx gy gz': --columns 5,6,7,2,3,4 --time 1). A leading '-' reverses a channel "
                        "whose sign the log has the other way (gyr_x,-gyr_y,…)")
    p.add_argument("--units", default=None,
                   help="the channels' units: gyro,accelerometer (e.g. deg/s,m/s^2) or one per channel; with "
                        "--scale, the unit the counts are per; default: the units the log writes for every channel "
                        "(a row of units, or its names' ends: 'X (rad/s)'), else rad/s,m/s^2")
    p.add_argument("--scale", default=None,
                   help="counts per unit, gyro,accelerometer or one per channel (e.g. 16.4,2048 with --units deg/s,g)")
    p.add_argument("--offset", default=None,
                   help="counts at zero input, gyro,accelerometer or one per channel, subtracted before --scale "
                        "divides (e.g. 32768,32768 for an unsigned 16-bit converter)")
    p.add_argument("--sample-rate", type=float, default=None, metavar="HZ",
                   help="sample rate; required without --time (default: from the time column)")
    p.add_argument("--full-scale", default=None, metavar="GYRO,ACCEL",
                   help="the sensor's full scale (the largest magnitude it reads) in --units, gyro,accelerometer or "
                        "one per channel (e.g. 2000,16 with --units deg/s,g): every sample within "
                        f"{FULL_SCALE_MARGIN * 100:g} %% of it is at the rail, a steady turn held there included. "
                        "Default: a rail is looked for in the data")
    p.add_argument("--temperature-column", default=None, metavar="COL", help="a temperature column in degC")
    p.add_argument("--table-rate-column", default=None, metavar="COL",
                   help="a column holding the turntable's rate (its encoder's or controller's): each steady turn's "
                        "rate is its mean over the segment, signed as the gyros measured the turn, so the fit uses "
                        "it without editing the segment table (with --accel-log: a column of LOG)")
    p.add_argument("--table-rate-unit", default="deg/s", metavar="UNIT",
                   help="unit of --table-rate-column (deg/s, rad/s or deg/h; default deg/s)")
    p.add_argument("--table-angle-column", default=None, metavar="COL",
                   help="a column holding the turntable's angle (its encoder's position, wrapping or not): each turn "
                        "between two rests takes the table's change of angle as its reference, whatever the angle, "
                        "and without --table-rate-column its rate gives each steady turn's (with --accel-log: a "
                        "column of LOG)")
    p.add_argument("--table-angle-unit", default="deg", metavar="UNIT",
                   help="unit of --table-angle-column (deg, rad, arcmin or arcsec; default deg)")
    p.add_argument("--poses", default="hand", metavar="{hand,table}",
                   help="how the poses were set: 'hand' (default; each pose's tilt is fitted) or 'table' (a table "
                        "set each pose's up-axis to its grade, JJF 2003's positions, and turned the unit about the "
                        "vertical: those poses and turns are known, their heading not logged, and plansim fit takes "
                        "the table's position errors as Type B and identifies the cross-couplings)")
    p.add_argument("--temperature", type=float, default=None, metavar="DEGC",
                   help="the lab's temperature, for a log without a temperature column (default 20, noted as assumed)")
    p.add_argument("--latitude", type=float, default=None, metavar="DEG", help="site latitude (site_latitude_deg)")
    p.add_argument("--height", type=float, default=None, metavar="M", help="site height (site_height_m)")
    p.add_argument("--window", type=float, default=None, metavar="S",
                   help="window of the rest detector (default 0.5 s)")
    p.add_argument("--min-static", type=float, default=None, metavar="S",
                   help="shortest static pose kept (default 1 s)")
    p.add_argument("--rest-variance", type=float, default=None, metavar="FACTOR",
                   help="how many times the quiet stretch's variance a rest's may reach, per channel (default 4): "
                        "raise it for a log whose poses are noisier than its quietest stretch")
    p.add_argument("--plot", default=None, metavar="FIGURE",
                   help="also draw the samples against time with the segments found shaded and numbered as in the "
                        "segment table (.png, .pdf or .svg), to review it by eye")
    p.set_defaults(func=_cmd_import)


def _search_progress():
    """A progress line for the moves' search, its clock started at the search's first start (not at the fit's)."""
    from plansim.report.progress import stderr_progress

    line = None

    def report(done, total):
        nonlocal line
        if line is None:
            line = stderr_progress("plansim fit: the moves' search for the gyros' scale factors", unit="starts")
        line(done, total)

    return report


def _cmd_fit(args) -> int:
    from plansim.fit import fit_recording, scenario_fit_options
    from plansim.fit.result import fit_dataset, fit_json
    from plansim.report.fit import fit_report
    from plansim.report.progress import end_progress_line

    if args.out is not None:
        check_output_path(args.out, "--out", (".nc",))
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    recording, site, scenario = recording_site_and_scenario(args)
    options = scenario_fit_options(scenario)
    progress = None if (args.json or args.quiet) else _search_progress()
    result = fit_recording(recording, site, progress=progress, **options)
    end_progress_line()
    with OutputSet() as outputs:
        if args.out is not None:
            fit_dataset(result).to_netcdf(outputs.stage(args.out, "--out", (".nc",)), engine="h5netcdf")
        if args.plot is not None:
            from plansim.report.plot import fit_figure

            fit_figure(result, outputs.stage(args.plot, "--plot", FIGURE_SUFFIXES),
                       format=os.path.splitext(args.plot)[1].lstrip("."))
        outputs.commit()
    if args.json:
        print(json.dumps(fit_json(result), indent=2))
    else:
        print(fit_report(result, residuals=not args.no_residuals))
        if args.out is not None:
            print(f"\nwrote fit: {args.out}")
        if args.plot is not None:
            print(f"wrote figure: {args.plot} (the residuals per channel against the reading and against time)")
    return 0


def recording_site_and_scenario(args):
    """The recording, the site and the lab's scenario (None without --scenario) from a command's RECORDING,
    --latitude/--height and --scenario, as ``plansim fit`` and ``plansim diagnose`` take them; each command
    takes its options from the scenario (:func:`plansim.fit.scenario_fit_options`,
    :func:`plansim.diagnose.procedure.scenario_diagnose_options`)."""
    from plansim.fit import resolve_site
    from plansim.io.recording import read_recording
    from plansim.io.scenario_file import load_scenario

    scenario = load_scenario(args.scenario) if args.scenario is not None else None
    recording = read_recording(args.recording)
    return recording, resolve_site(args.latitude, args.height, recording.attrs, scenario), scenario


def add_site_and_scenario_options(p) -> None:
    """--latitude, --height and --scenario, as ``plansim fit`` and ``plansim diagnose`` take them."""
    p.add_argument("--latitude", type=float, default=None, metavar="DEG",
                   help="site latitude (default: the recording's site_latitude_deg, else the scenario's)")
    p.add_argument("--height", type=float, default=None, metavar="M", help="site height, with --latitude")
    p.add_argument("--scenario", default=None,
                   help="the lab's scenario (name or TOML path): its site, turntable/fixture grade, reduction, stated "
                        "noise and known lever arms (default: JJF 2003 Table 1 and the recording's attributes)")


def _add_fit_command(sub) -> None:
    p = sub.add_parser(
        "fit", help=COMMANDS["fit"],
        description="Fit a recording: which of the 39 JJF 2003 parameters its segments identify, their estimates by "
                    "the specification's estimators (where the procedure is complete) and by one joint weighted "
                    "least squares, the noise from the data (Allan deviation), and each parameter's standard "
                    "uncertainty (docs/fitting.md)")
    p.add_argument("recording", help="recording file (.nc, or the samples .csv beside its .segments.csv)")
    add_site_and_scenario_options(p)
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of the report")
    p.add_argument("--out", default=None, help="write the fit as a NetCDF file (.nc)")
    p.add_argument("--no-residuals", action="store_true", help="leave the per-segment residual table out of the report")
    p.add_argument("--plot", default=None, metavar="FIGURE",
                   help="also draw the residuals per channel, with ±2 sd of each, against the channel's reading and "
                        "against time (.png, .pdf or .svg)")
    p.add_argument("--quiet", action="store_true",
                   help="no progress on stderr (the moves' search; none with --json either)")
    p.set_defaults(func=_cmd_fit)



def add_commands(sub) -> None:
    _add_import_command(sub)
    _add_fit_command(sub)
