"""Progress lines on stderr for long runs."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable

ProgressCallback = Callable[[int, int], None]


def stderr_progress(label: str = "simulating") -> ProgressCallback:
    """A progress line on stderr, redrawn in place: trials done / total, rate, time left."""
    start = time.perf_counter()

    def report(done: int, total: int) -> None:
        elapsed = time.perf_counter() - start
        rate = done / elapsed if elapsed > 0 else float("nan")
        left = (total - done) / rate if rate > 0 else float("nan")
        end = "\n" if done >= total else ""
        sys.stderr.write(f"\r{label}: {done}/{total} trials ({rate:,.0f}/s, {left:4.0f} s left)   {end}")
        sys.stderr.flush()

    return report
