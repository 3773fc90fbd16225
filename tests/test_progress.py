"""Progress lines on stderr (plansim.report.progress): redrawn in place on a terminal; whole lines, at most one per
LOG_INTERVAL seconds plus the last, where stderr is a file or a pipe (a real hand session's fit, its stderr sent to
a file, had its search's progress written as one line of 18 redraws)."""

from __future__ import annotations

import io

import pytest

from plansim.report import progress


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture
def clock(monkeypatch):
    """A clock the test moves by hand (seconds)."""
    now = [100.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: now[0])
    return now


def test_on_a_terminal_the_line_is_redrawn_and_ends_when_done(monkeypatch, clock):
    stream = _Terminal()
    monkeypatch.setattr(progress.sys, "stderr", stream)
    report = progress.stderr_progress("plansim run x", unit="trials")
    for done in (1, 2, 3):
        clock[0] += 1.0
        report(done, 3)
    text = stream.getvalue()
    assert text.count("\r") == 3 and text.endswith("\n") and text.count("\n") == 1
    assert "3/3 trials" in text and not progress.progress_line_open()
    report = progress.stderr_progress("search", unit="starts")
    report(1, None)
    assert progress.progress_line_open()  # a search's line stays open until ended
    progress.end_progress_line()
    assert stream.getvalue().endswith("\n") and not progress.progress_line_open()


def test_elsewhere_each_report_is_a_whole_line_at_most_every_interval(monkeypatch, clock):
    stream = io.StringIO()
    monkeypatch.setattr(progress.sys, "stderr", stream)
    report = progress.stderr_progress("plansim diagnose-check jjf2003", unit="recordings")
    steps = 100
    for done in range(1, steps + 1):
        clock[0] += 1.0  # one second a recording: 100 s in all
        report(done, steps)
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue() and stream.getvalue().endswith("\n")
    # the first report, one every LOG_INTERVAL seconds after it, and the last
    expected = 1 + int((steps - 1) // progress.LOG_INTERVAL) + 1
    assert len(lines) == expected, lines
    assert lines[0].startswith("plansim diagnose-check jjf2003: 1/100 recordings")
    assert lines[-1].startswith("plansim diagnose-check jjf2003: 100/100 recordings")
    assert not progress.progress_line_open()  # nothing for end_progress_line to end
    progress.end_progress_line()
    assert stream.getvalue().count("\n") == expected


def test_validates_block_progress_and_diagnose_checks_use_the_same_lines(monkeypatch, clock, capsys):
    """``plansim validate``'s block progress and ``plansim diagnose-check``'s progress wrote their own carriage-return
    redraws; they now go through the one writer (progress_writer): off a terminal, whole lines, none left open."""
    from plansim.report.validation import stderr_block_progress

    stream = io.StringIO()
    monkeypatch.setattr(progress.sys, "stderr", stream)
    report = stderr_block_progress("plansim validate x")
    for blocks in (1, 2, 3):
        clock[0] += 6.0
        report(1000 * blocks, blocks, 2.0 / blocks)
    text = stream.getvalue()
    assert "\r" not in text and text.count("\n") == 2  # the first report, and one 12 s later (LOG_INTERVAL 10 s)
    assert text.startswith("plansim validate x: 1 blocks, 1000 trials, max 2s/δ = 2")
    assert not progress.progress_line_open()
    terminal = _Terminal()
    monkeypatch.setattr(progress.sys, "stderr", terminal)
    stderr_block_progress("plansim validate x")(1000, 1, 2.0)
    assert terminal.getvalue().startswith("\rplansim validate x") and progress.progress_line_open()
    progress.end_progress_line()
