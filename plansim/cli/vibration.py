"""``plansim run vibration_g2``: the vibration paper's g² experiment, simulated and reduced (docs/dynamic.md).

Like ``jjf1535`` it is built in, not a scenario file: its settings are
:class:`plansim.simulate.vibration.VibrationExperiment`, changed with ``--set KEY=VALUE``
(:data:`plansim.simulate.vibration.FIELDS`). ``--trials N`` runs it on the records of seeds S … S + N − 1 and
reports their spread (:func:`plansim.simulate.vibration.vibration_monte_carlo`).
"""

from __future__ import annotations

#: the built-in experiments (``plansim run NAME``), with a description
EXPERIMENTS = {
    "vibration_g2": "the vibration paper's experiment: 100 s still, 300 s random vibration (0.04 g^2/Hz, "
                    "6.06 g rms), 100 s still; gyro output shift from g^2, Welch PSD, static vs g^2 compensation",
}
#: ``--seed``'s default (the paper's date)
DEFAULT_SEED = 20200612


def run_vibration(args, default_chunk_size: int) -> int:
    """``plansim run vibration_g2``: every check first, then the record, the reduction and the report."""
    from plansim.cli.common import run_experiment
    from plansim.io.files import check_output_path
    from plansim.report.plot import FIGURE_SUFFIXES
    from plansim.report.vibration import vibration_figure, vibration_json, vibration_text
    from plansim.simulate.vibration import VibrationExperiment, run_vibration_experiment, with_overrides

    for option, value in (("--out", args.out), ("--unit", args.unit)):
        if value is not None:
            raise ValueError(f"{option} {value!r}: not available with the experiment vibration_g2 (its settings "
                             "change with --set KEY=VALUE)")
    if args.trials is not None and args.trials < 2:
        raise ValueError(f"--trials {args.trials}: must be >= 2 (records of seeds S, S+1, …; without --trials, one "
                         "record)")
    if args.path != "auto":
        raise ValueError(f"--path {args.path}: not available with the experiment vibration_g2 (it has one simulation "
                         "path of its own, plansim/simulate/vibration.py)")
    if args.chunk_size != default_chunk_size:
        raise ValueError(f"--chunk-size {args.chunk_size}: not available with the experiment vibration_g2 "
                         "(the record does not depend on its chunks)")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    settings = with_overrides(VibrationExperiment(), args.set)
    seed = DEFAULT_SEED if args.seed is None else args.seed

    if args.trials is not None:  # a Monte Carlo over records: seeds S … S + N − 1
        from plansim.report.progress import end_progress_line, stderr_progress
        from plansim.report.vibration import vibration_mc_figure, vibration_mc_json, vibration_mc_text
        from plansim.simulate.vibration import vibration_monte_carlo

        progress = None if (args.quiet or args.json) else stderr_progress("plansim run vibration_g2", unit="records")

        def monte_carlo():
            result = vibration_monte_carlo(settings, args.trials, seed, progress=progress)
            end_progress_line()
            return result

        return run_experiment(args, monte_carlo, vibration_mc_figure, vibration_mc_json, vibration_mc_text)
    return run_experiment(args, lambda: run_vibration_experiment(settings, seed=seed), vibration_figure,
                          vibration_json, vibration_text)
