"""``plansim diagnose-check``: the diagnosis validated blind by simulation (docs/closing-the-loop.md)."""

from __future__ import annotations

import json
import sys

from plansim.cli.common import COMMANDS
from plansim.io.files import OutputSet, check_output_path


def _cmd_diagnose_check(args) -> int:
    from plansim.checks.diagnose_check import check_json, run_diagnose_check
    from plansim.io.scenario_file import load_scenario
    from plansim.report.progress import end_progress_line, stderr_progress

    if args.out is not None:
        check_output_path(args.out, "--out", (".json",))
    try:
        sizes = tuple(float(x) for x in args.sizes.split(","))
    except ValueError as exc:
        raise ValueError(f"--sizes {args.sizes!r}: expected numbers separated by commas, e.g. 2,5,10") from exc
    scenario = load_scenario(args.scenario)
    effects = None if args.effects is None else tuple(e.strip() for e in args.effects.split(",") if e.strip())

    progress = None if args.quiet else stderr_progress(f"plansim diagnose-check {scenario.name}", unit="recordings")
    report = run_diagnose_check(scenario, null=args.null, per_effect=args.per_effect, sizes=sizes, alpha=args.alpha,
                                seed=args.seed, null_draws=args.null_draws, progress=progress, effects=effects)
    end_progress_line()
    data = check_json(report)
    with OutputSet() as outputs:
        if args.out is not None:
            with open(outputs.stage(args.out, "--out", (".json",)), "w") as fh:
                json.dump(data, fh, indent=2)
        outputs.commit()
    if args.json:
        print(json.dumps(data, indent=2))
    else:
        n = data["null"]
        print(f"null: {n['false_alarms']} false alarms in {n['recordings']} recordings ({n['rate']:.3f}; selections "
              f"{n['selection_rate']:.3f}; binomial 99 % bound at alpha: {n['binomial_99_upper_count']})")
        fired = ", ".join(f"{k} {v}" for k, v in n["by_family"].items())
        wrong = ", ".join(f"{k} {v}" for k, v in n["falsely_selected"].items()) or "none"
        print(f"  by family (a recording may fire several): {fired}; selected: {wrong}")
        groups = "; ".join(f"{g} {v['rms_z']:.2f}, {v['coverage_95']:.3f}" for g, v in n["by_group"].items())
        print(f"  parameters of the base fit against the truth, r.m.s. z and 95 % coverage: all {n['rms_z']:.2f}, "
              f"{n['coverage_95']:.3f}; {groups}")
        for e in data["effects"]:
            k = "" if e["times_noise_equivalent"] is None else f" x{e['times_noise_equivalent']:g}"
            print(f"{e['effect']}[{e['component']}]{k}: detection {e['detection']:.2f}, attribution "
                  f"{e['attribution']:.2f}, selected {e['confusion']}")
        for e in data["out_of_catalogue"]:
            nes = "" if e["noncentrality"] is None else (
                f", non-centrality {e['noncentrality']:.3g}; {e['in_natural_units']:.3g}x {e['natural_unit']}")
            print(f"{e['effect']} x{e['times']:g} ({e['scale']}{nes}): flagged {e['flagged_unexplained']:.2f}, named "
                  f"after a candidate {e['named_after_a_candidate']:.2f}")
        for f in data["failures"]:
            print(f"FAILED: {f['case']} recording {f['index']} (seed {f['seed']}): {f['error']}")
        if args.out:
            print(f"\nwrote: {args.out}")
    if data["failures"]:
        # the figures above count the recordings that ran; a failure is a fault to fix, so the exit code says so
        print(f"plansim diagnose-check: {len(data['failures'])} recording(s) failed (listed with their seeds); the "
              "figures count the others", file=sys.stderr)
        return 1
    return 0


def add_commands(sub) -> None:
    p = sub.add_parser(
        "diagnose-check", help=COMMANDS["diagnose-check"],
        description="Simulate recordings with no effect, with each catalogue effect at multiples of its "
                    "noise-equivalent size, and with effects outside the catalogue; run plansim diagnose on each "
                    "blind; report false alarms, detection, attribution and the error before and after "
                    "(docs/closing-the-loop.md)")
    p.add_argument("scenario", nargs="?", default="jjf2003")
    p.add_argument("--null", type=int, default=100, help="null recordings (default 100)")
    p.add_argument("--per-effect", type=int, default=10, help="recordings per effect and size (default 10)")
    p.add_argument("--sizes", default="2,5,10", help="multiples of the noise-equivalent size (default 2,5,10)")
    p.add_argument("--effects", default=None, metavar="E1,E2",
                   help="the injected effects to run, comma-separated (default all: gyro_scale_asymmetry, "
                        "gyro_scale_nonlinearity, gyro_g2_sensitivity, accel_quadratic, bias_drift, lever_arm, "
                        "bias_step, clock_fast, noise_burst, scale_change, segment_offset); the nulls always run")
    p.add_argument("--alpha", type=float, default=0.05)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--null-draws", type=int, default=500, help="simulated null draws per test (default 500)")
    p.add_argument("--json", action="store_true")
    p.add_argument("--out", default=None, help="write the figures as JSON (.json)")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(func=_cmd_diagnose_check)
