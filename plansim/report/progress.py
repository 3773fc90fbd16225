"""Progress lines on stderr for long runs.

A progress line is redrawn in place (``\\r``) and ends with a line break only when the work is done.
Whatever else is written to stderr while one is open (an error, ``plansim: interrupted``) must start on
a new line: :func:`end_progress_line` writes the line break if a progress line is open.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

ProgressCallback = Callable[[int, int], None]

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


def stderr_progress(label: str = "simulating", unit: str = "trials") -> ProgressCallback:
    """A progress line on stderr, redrawn in place: *unit* (trials, cells) done / total, rate, time left; with a
    total of None (a search that does not know its length) done, rate and time so far."""
    start = time.perf_counter()

    def report(done: int, total: int | None) -> None:
        elapsed = time.perf_counter() - start
        rate = done / elapsed if elapsed > 0 else float("nan")
        shown = f"{rate:,.0f}" if rate >= 10 else f"{rate:.1f}"
        # the line is marked open before it is written: a signal between the write and the mark would otherwise
        # find it closed, and its message would follow the progress line on the same line
        mark_progress_line(True)
        if total is None:  # a search: how much is done, not how much is left
            sys.stderr.write(f"\r{label}: {done} {unit} ({shown}/s, {elapsed:4.0f} s)   ")
            sys.stderr.flush()
            return
        left = (total - done) / rate if rate > 0 else float("nan")
        end = "\n" if done >= total else ""
        sys.stderr.write(f"\r{label}: {done}/{total} {unit} ({shown}/s, {left:4.0f} s left)   {end}")
        sys.stderr.flush()
        mark_progress_line(done < total)

    return report
