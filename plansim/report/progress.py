"""Progress lines on stderr for long runs.

On a terminal a progress line is redrawn in place (``\\r``) and ends with a line break only when the work is
done. Whatever else is written to stderr while one is open (an error, ``plansim: interrupted``) must start on
a new line: :func:`end_progress_line` writes the line break if a progress line is open. Where stderr is not a
terminal (a file, a pipe, a CI log) each report is a whole line, written at the first report, at most once per
:data:`LOG_INTERVAL` seconds after it, and at the end: redrawn lines would pile up there as one line thousands
of characters long.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable

ProgressCallback = Callable[[int, int], None]

#: seconds between two progress lines where stderr is not a terminal
LOG_INTERVAL = 10.0

_line_open = False


def mark_progress_line(open_: bool = True) -> None:
    """Record that a progress line without its line break is (``True``) or is no longer (``False``) on stderr.

    For progress lines drawn elsewhere (``plansim validate``'s block progress)."""
    global _line_open
    _line_open = bool(open_)


def progress_line_open() -> bool:
    """True while a progress line without its line break is on stderr."""
    return _line_open


def end_progress_line() -> None:
    """End an open progress line with its line break (nothing if none is open)."""
    if _line_open:
        sys.stderr.write("\n")
        sys.stderr.flush()
        mark_progress_line(False)


def progress_writer() -> Callable[..., None]:
    """``write(text, finished=False)``: one progress report on stderr. On a terminal *text* is redrawn in place
    and the line kept open (:func:`mark_progress_line`) until *finished*; elsewhere each report is a whole line, the
    first, then at most one per :data:`LOG_INTERVAL` seconds, and the *finished* one (module docstring)."""
    terminal = _is_terminal(sys.stderr)
    last = [-math.inf]  # when the last whole line was written (not on a terminal)

    def write(text: str, finished: bool = False) -> None:
        if not terminal:
            now = time.perf_counter()
            if finished or now - last[0] >= LOG_INTERVAL:
                last[0] = now
                sys.stderr.write(text + "\n")
                sys.stderr.flush()
            return
        # the line is marked open before it is written: a signal between the write and the mark would otherwise
        # find it closed, and its message would follow the progress line on the same line
        mark_progress_line(True)
        sys.stderr.write(f"\r{text}   " + ("\n" if finished else ""))
        sys.stderr.flush()
        mark_progress_line(not finished)

    return write


def stderr_progress(label: str = "simulating", unit: str = "trials") -> ProgressCallback:
    """A progress line on stderr (:func:`progress_writer`): *unit* (trials, cells) done / total, rate, time left;
    with a total of None (a search that does not know its length) done, rate and time so far."""
    start = time.perf_counter()
    write = progress_writer()

    def report(done: int, total: int | None) -> None:
        elapsed = time.perf_counter() - start
        rate = done / elapsed if elapsed > 0 else float("nan")
        shown = f"{rate:,.0f}" if rate >= 10 else f"{rate:.1f}"
        if total is None:  # a search: how much is done, not how much is left
            write(f"{label}: {done} {unit} ({shown}/s, {elapsed:4.0f} s)")
            return
        left = (total - done) / rate if rate > 0 else float("nan")
        write(f"{label}: {done}/{total} {unit} ({shown}/s, {left:4.0f} s left)", finished=done >= total)

    return report


def _is_terminal(stream) -> bool:
    """Whether *stream* is a terminal (a stream without ``isatty`` is taken for none)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False
