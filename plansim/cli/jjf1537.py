"""``plansim run jjf1537``: JJF 1537-2015's amplitude/phase-frequency test on an angular vibration table, and its
items 7.2.4–7.2.7 (amplitude nonlinearity, output change under vibration, bias change across vibration and
shock), simulated as a Monte Carlo and reduced (docs/dynamic.md).

Like ``vibration_g2`` it is built in, not a scenario file: its settings are
:class:`plansim.simulate.vibration_table.Jjf1537Experiment`, changed with ``--set KEY=VALUE``
(:data:`plansim.simulate.vibration_table.FIELDS`).
"""

from __future__ import annotations

#: the built-in dynamic tests (``plansim run NAME``), with a description
DYNAMIC_TESTS = {
    "jjf1537": "JJF 1537-2015 7.2.1 on an angular vibration table: sine fits at >= 7 frequencies x 7 repeats, "
               "amplitude/phase response and -3 dB bandwidth, Monte Carlo bias and scatter against the truth and "
               "the GUM; 7.2.4-7.2.7 at one frequency: amplitude nonlinearity, output change in vibration, bias "
               "change across vibration and shock",
}


def run_jjf1537_command(args, default_chunk_size: int) -> int:
    """``plansim run jjf1537``: every check first, then the Monte Carlo and the report."""
    from plansim.cli.common import checked_trials, run_experiment
    from plansim.report.jjf1537 import bode_figure, jjf1537_json, jjf1537_text
    from plansim.report.progress import stderr_progress
    from plansim.simulate.jjf1537 import run_jjf1537
    from plansim.simulate.vibration_table import DEFAULT_SEED, DEFAULT_TRIALS, Jjf1537Experiment, with_overrides

    for option, value in (("--out", args.out), ("--unit", args.unit)):
        if value is not None:
            raise ValueError(f"{option} {value!r}: not available with the test jjf1537 (its settings change with "
                             "--set KEY=VALUE)")
    if args.path != "auto":
        raise ValueError(f"--path {args.path}: not available with the test jjf1537 (it has one simulation path of "
                         "its own, plansim/simulate/jjf1537.py)")
    if args.chunk_size != default_chunk_size:
        raise ValueError(f"--chunk-size {args.chunk_size}: not available with the test jjf1537 (the results do "
                         "not depend on its chunks)")
    trials = checked_trials(args, DEFAULT_TRIALS)
    settings = with_overrides(Jjf1537Experiment(), args.set)
    seed = DEFAULT_SEED if args.seed is None else args.seed

    progress = None if args.quiet else stderr_progress("plansim run jjf1537")
    return run_experiment(args, lambda: run_jjf1537(settings, trials=trials, seed=seed, progress=progress),
                          bode_figure, jjf1537_json, jjf1537_text)
