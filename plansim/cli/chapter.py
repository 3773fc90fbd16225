"""``plansim run chapter``: the textbook chapter's procedures and JJF 2003 on the same simulated units
(:mod:`plansim.uncertainty.chapter_comparison`; docs/chapter-procedures.md).

Like ``jjf1535`` it is a built-in *procedure* run on a unit scenario (``--unit``): the chapter's ± rate turns,
8-position test and drift positions are appended to the unit's JJF 2003 schedule, and both reductions are
compared with the simulated unit.
"""

from __future__ import annotations

#: the built-in procedure (``plansim run chapter --unit SCENARIO``), with a description
PROCEDURES = {
    "chapter": "the textbook chapter's +/- rate misalignment turns (eq. (6-8)), 8-position accelerometer test "
               "(eq. (6-9)) and gyro drift model D0..D3 with its random drift (eq. (6-6)), against JJF 2003 on "
               "the same units",
}
#: ``--trials``' default
DEFAULT_TRIALS = 1000


def run_chapter(args, default_chunk_size: int, procedures) -> int:
    """``plansim run chapter``: every check first, then the Monte Carlo, then the report (text, ``--json``,
    ``--plot``).

    Parameters
    ----------
    args : argparse.Namespace
        The options of ``plansim run``.
    default_chunk_size : int
        ``--chunk-size``'s default (any other value is passed on: results do not depend on it).
    procedures : dict
        Every built-in procedure's name (refused as ``--unit``).
    """
    from plansim.cli.common import checked_trials, run_experiment
    from plansim.cli.jjf1535 import load_unit
    from plansim.report.chapter import chapter_figure, chapter_json, chapter_text
    from plansim.report.progress import end_progress_line, stderr_progress
    from plansim.runner import compare_chapter_procedures

    for option, value in (("--out", args.out), ("--claims", args.claims)):
        if value is not None:
            raise ValueError(f"{option} {value!r}: not available with the procedure chapter (it writes no data file "
                             "and has no certificate budget to judge)")
    if args.procedure:
        raise ValueError(f"--procedure {args.procedure[0]!r}: only with the procedure jjf1535; the chapter's tests "
                         "take the unit's settings (--set on the unit scenario)")
    trials = checked_trials(args, DEFAULT_TRIALS)
    if args.chunk_size < 1:
        raise ValueError(f"--chunk-size {args.chunk_size}: must be >= 1")
    unit = load_unit(args, procedures)
    progress = None if (args.quiet or args.json) else stderr_progress(f"plansim run chapter --unit {unit.name}")

    def comparison():
        result = compare_chapter_procedures(unit, trials=trials, seed=args.seed, path=args.path,
                                            chunk_size=args.chunk_size, progress=progress)
        end_progress_line()
        return result

    return run_experiment(args, comparison, chapter_figure, chapter_json, chapter_text)
