"""What every command shares: exit statuses, signals as exceptions, the commands' one-line help."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading

from plansim.io.files import forget_signals, note_signal

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
    exc = Interrupted(signum)
    note_signal(exc)  # raised again before any output is committed, should this one be swallowed
    raise exc


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
    forget_signals()
    hook = sys.unraisablehook

    def quiet(unraisable):
        # a signal's exception raised where Python cannot raise it (a __del__, a weakref callback): the handler
        # remembered it (raised again before any output is committed), so it is not printed as "Exception ignored"
        if not isinstance(unraisable.exc_value, Interrupted):
            hook(unraisable)

    sys.unraisablehook = quiet
    try:
        for signum in SIGNAL_WORDS:
            if signal.getsignal(signum) is not signal.SIG_IGN:
                previous[signum] = signal.signal(signum, _raise_interrupted)
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        sys.unraisablehook = hook
        forget_signals()


def _silence_stdout() -> None:
    """The reader of stdout is gone: send what is still buffered, and anything later, to /dev/null (so the
    interpreter's last flush at exit does not fail again)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor (captured, say)
        pass



#: one line per command in ``plansim --help`` (at most 52 characters: one line in an 80-column terminal)
COMMANDS = {
    "run": "Monte Carlo of a calibration vs JJF 2003 Appendix A",
    "validate": "GUM budgets validated by adaptive Monte Carlo",
    "scenarios": "list the built-in scenarios and procedures",
    "record": "write one simulated trial's raw samples",
    "import": "a plain CSV log to a recording with segments",
    "fit": "fit a recording: parameters, noise, uncertainty",
    "diagnose": "find the effect a recording's fit lacks",
    "diagnose-check": "check diagnose blind on simulated recordings",
    "sweep": "compare schedules over a grid of scenario fields",
    "plan": "the shortest schedule that meets your targets",
    "bench": "measure speed and memory on this machine",
}


def add_set_option(p) -> None:
    """``--set KEY=VALUE`` (repeatable): a scenario field overridden, checked exactly as the file is
    (:func:`plansim.io.scenario_file.apply_overrides`)."""
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a scenario field, e.g. --set schedule.dwell=\"60 s\" --set schedule.positions=6 "
                        "(dotted key as in the scenario file; repeatable; checked as the file is)")


def add_procedure_option(p) -> None:
    """``--procedure KEY=VALUE`` (repeatable): a setting of the JJF 1535 procedure
    (:class:`plansim.schedule.jjf1535.Jjf1535Settings`), checked by building it."""
    p.add_argument("--procedure", action="append", default=[], metavar="KEY=VALUE",
                   help="with the procedure jjf1535: one of its settings, e.g. --procedure points=15 --procedure "
                        "repeats=5 --procedure maximum_rate=\"100 deg/s\" (repeatable; docs/jjf1535.md)")


def checked_trials(args, default_trials: int) -> int:
    """``--trials`` (default *default_trials*, >= 2), ``--seed`` (>= 0) and ``--plot`` (a figure suffix) of a built-in
    Monte Carlo, checked before any work; returns the number of trials."""
    from plansim.io.files import check_output_path
    from plansim.report.plot import FIGURE_SUFFIXES

    trials = default_trials if args.trials is None else args.trials
    if trials < 2:
        raise ValueError(f"--trials {trials}: must be >= 2 (the Monte Carlo's scatter needs two trials)")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    if args.plot is not None:
        check_output_path(args.plot, "--plot", FIGURE_SUFFIXES)
    return trials


def run_experiment(args, run, figure, as_json, as_text) -> int:
    """The tail of ``plansim run`` for a built-in experiment (``jjf1537``, ``vibration_g2``), once its options are
    checked: *run* () → result, timed; ``--plot`` written by *figure* (result, path, format) and committed with the
    run or not at all (:class:`plansim.io.files.OutputSet`); then *as_json* (result, elapsed, version) printed as
    JSON with ``--json``, else *as_text* (result, elapsed) and the figure's name."""
    import json
    import time

    from plansim.io.files import OutputSet
    from plansim.io.recording import plansim_version
    from plansim.report.plot import FIGURE_SUFFIXES

    with OutputSet() as outputs:
        plot = outputs.stage(args.plot, "--plot", FIGURE_SUFFIXES) if args.plot is not None else None
        start = time.perf_counter()
        result = run()
        elapsed = time.perf_counter() - start
        if plot is not None:
            figure(result, plot, format=args.plot.rsplit(".", 1)[-1])
        outputs.commit()
    if args.json:
        print(json.dumps(as_json(result, elapsed, plansim_version()), indent=2))
    else:
        print(as_text(result, elapsed))
        if args.plot:
            print(f"\nwrote figure: {args.plot}")
    return 0
