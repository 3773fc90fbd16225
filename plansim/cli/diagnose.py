"""``plansim diagnose``: from a recording's residual to the effect the model lacks (docs/closing-the-loop.md)."""

from __future__ import annotations

import json

from plansim.cli.common import COMMANDS
from plansim.cli.measured import add_site_and_scenario_options, recording_and_fit_options


def _cmd_diagnose(args) -> int:
    from plansim.diagnose.procedure import diagnose, diagnosis_json
    from plansim.report.diagnose import diagnose_report

    if not 0 < args.alpha < 1:
        raise ValueError(f"--alpha {args.alpha}: must be between 0 and 1")
    if args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.null_draws < 19:
        raise ValueError(f"--null-draws {args.null_draws}: must be >= 19")
    recording, site, options = recording_and_fit_options(args)
    result = diagnose(recording, site, alpha=args.alpha, seed=args.seed, null_draws=args.null_draws, **options)
    if args.json:
        print(json.dumps(diagnosis_json(result), indent=2))
    else:
        print(diagnose_report(result))
    return 0


def add_commands(sub) -> None:
    p = sub.add_parser(
        "diagnose", help=COMMANDS["diagnose"],
        description="Fit a recording, test its residual for the effects of a catalogue (identifiability first; "
                    "score tests with the family-wise false-alarm rate held at alpha by a null simulated from the "
                    "fitted model), add the significant ones by closed testing, and report what remains and the "
                    "error before and after (docs/closing-the-loop.md)")
    p.add_argument("recording", help="recording file (.nc, or the samples .csv beside its .segments.csv)")
    add_site_and_scenario_options(p)
    p.add_argument("--alpha", type=float, default=0.05, help="family-wise false-alarm rate (default 0.05)")
    p.add_argument("--seed", type=int, default=0, help="seed of the simulated nulls (default 0)")
    p.add_argument("--null-draws", type=int, default=2000, help="simulated null draws per test (default 2000)")
    p.add_argument("--json", action="store_true", help="print one JSON object (SI) instead of the report")
    p.set_defaults(func=_cmd_diagnose)
