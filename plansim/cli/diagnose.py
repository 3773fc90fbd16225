"""``plansim diagnose``: from a recording's residual to the effect the model lacks (docs/closing-the-loop.md)."""

from __future__ import annotations

import json
import os

from plansim.cli.common import COMMANDS
from plansim.cli.measured import add_site_and_scenario_options, recording_site_and_scenario
from plansim.io.files import OutputSet, check_output_path
from plansim.report.plot import FIGURE_SUFFIXES


def _cmd_diagnose(args) -> int:
    from plansim.diagnose.procedure import diagnose, diagnosis_json, scenario_diagnose_options
    from plansim.report.diagnose import diagnose_report

    if not 0 < args.alpha < 1:
        raise ValueError(f"--alpha {args.alpha}: must be between 0 and 1")
    if args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.null_draws < 19:
        raise ValueError(f"--null-draws {args.null_draws}: must be >= 19")
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    if args.learned is not None:
        check_output_path(args.learned, "--learned", (".toml",))
    recording, site, scenario = recording_site_and_scenario(args)
    options = scenario_diagnose_options(scenario)
    result = diagnose(recording, site, alpha=args.alpha, seed=args.seed, null_draws=args.null_draws, **options)
    with OutputSet() as outputs:
        if args.plot is not None:
            from plansim.report.plot import diagnosis_figure

            diagnosis_figure(result, outputs.stage(args.plot, "--plot", FIGURE_SUFFIXES),
                             format=os.path.splitext(args.plot)[1].lstrip("."))
        if args.learned is not None:
            _write_learned(result, recording, args, outputs.stage(args.learned, "--learned", (".toml",)))
        outputs.commit()
    if args.json:
        print(json.dumps(diagnosis_json(result), indent=2))
    else:
        print(diagnose_report(result))
    return 0


def _write_learned(result, recording, args, path) -> None:
    """The learned scenario (plansim.diagnose.learned), parsed back before it is written: a document the scenario
    reader refuses is never left behind."""
    import tomli_w

    from plansim.config.scenario import parse_scenario
    from plansim.diagnose.learned import learned_document
    from plansim.io.scenario_file import load_scenario

    base = load_scenario(args.scenario if args.scenario is not None else "jjf2003")
    document = learned_document(result, base, recording_name=os.path.basename(args.recording),
                                temperatures=[s.temperature for s in recording.schedule.segments])
    parse_scenario(document, source=str(args.learned))
    with open(path, "wb") as fh:
        fh.write(tomli_w.dumps(document).encode())


def add_commands(sub) -> None:
    p = sub.add_parser(
        "diagnose", help=COMMANDS["diagnose"],
        description="Fit a recording, test its residual for the effects of a catalogue (identifiability first; "
                    "likelihood-ratio tests with the family-wise false-alarm rate held at alpha by a null simulated "
                    "from the fitted model), add the significant ones by closed testing, and report what remains and "
                    "the error before and after (docs/closing-the-loop.md). With --scenario, the segment means are "
                    "also tested against the slow noise it states for the unit")
    p.add_argument("recording", help="recording file (.nc, or the samples .csv beside its .segments.csv)")
    add_site_and_scenario_options(p)
    p.add_argument("--alpha", type=float, default=0.05, help="family-wise false-alarm rate (default 0.05)")
    p.add_argument("--seed", type=int, default=0, help="seed of the simulated nulls (default 0)")
    p.add_argument("--null-draws", type=int, default=2000, help="simulated null draws per test (default 2000)")
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of the report")
    p.add_argument("--plot", default=None,
                   help="write the residuals before and after, against each channel's reading and time "
                        "(.png, .pdf or .svg)")
    p.add_argument("--learned", default=None, metavar="FILE.toml",
                   help="write the world the data showed as a scenario: the fitted parameters (truth, spread = u), "
                        "the noise from the data, the site and the effects found, on top of --scenario (default "
                        "jjf2003) for the turntable, acquisition and schedule")
    p.set_defaults(func=_cmd_diagnose)
