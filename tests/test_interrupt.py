"""Interrupting the command line: Ctrl-C (SIGINT), SIGTERM and a reader that stops reading.

The commands run in their own process here, as a user runs them, and get the signal once they are
working (their progress line is on stderr, or their output file is being written). Each must end with
one line on stderr (``plansim: interrupted`` / ``plansim: terminated``), the exit status 128 + the
signal's number (130, 143), no traceback, and no file left behind: neither the outputs nor their
hidden temporary files (``.NAME.XXXX.part``). A compile process started on a cold start is ended
with its parent. ``plansim … | head`` ends quietly with the exit status 141 (128 + SIGPIPE), as the
standard tools do.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time

import numba
import numpy as np
import pytest

from plansim.io.scenario_file import builtin_scenarios
from plansim.simulate import compilation

MESSAGES = {signal.SIGINT: ("plansim: interrupted", 130), signal.SIGTERM: ("plansim: terminated", 143)}
#: seconds to wait for a command to start working (a cold start compiles the kernels: 10-20 s)
START_TIMEOUT = 180


def _as_at_a_terminal() -> None:
    """In the child, before plansim starts: SIGINT at its default, as at a terminal where Ctrl-C reaches it. A
    shell without job control starts a background job (``pytest … &``, ``nohup``) with SIGINT ignored, the child
    inherits that, and Python then installs no KeyboardInterrupt handler: the test would measure how it was
    launched, not plansim."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(argv, cwd, logs, env=None) -> tuple[subprocess.Popen, object]:
    out, err = open(logs / "stdout", "wb"), open(logs / "stderr", "wb")
    process = subprocess.Popen([sys.executable, "-m", "plansim.cli", *argv], cwd=cwd, stdout=out, stderr=err,
                               stdin=subprocess.DEVNULL, env=env, preexec_fn=_as_at_a_terminal)
    out.close()
    err.close()
    return process, logs / "stderr"


def _wait_until(process, ready, what: str, stderr_path) -> None:
    deadline = time.monotonic() + START_TIMEOUT
    while not ready():
        if process.poll() is not None:
            pytest.fail(f"the command ended (exit {process.returncode}) before {what}:\n"
                        f"{stderr_path.read_text(errors='replace')[-3000:]}")
        if time.monotonic() > deadline:
            process.kill()
            process.wait()
            pytest.fail(f"no sign of {what} after {START_TIMEOUT} s")
        time.sleep(0.05)


def _stderr_shows(stderr_path, pattern: str):
    return lambda: re.search(pattern, stderr_path.read_text(errors="replace")) is not None


def _end_with(process, signum, stderr_path) -> str:
    process.send_signal(signum)
    try:
        process.wait(timeout=60)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        pytest.fail(f"still running 60 s after {signal.Signals(signum).name}")
    return stderr_path.read_text(errors="replace")


def _assert_ended_by(process, signum, err: str) -> None:
    message, status = MESSAGES[signum]
    assert process.returncode == status, err[-3000:]
    assert "Traceback" not in err and "Exception ignored" not in err, err[-3000:]
    # the one line, on a line of its own (after the progress line, which has no line end of its own)
    assert err.endswith("\n" + message + "\n") or err == message + "\n", err[-500:]
    assert err.count(message) == 1


@pytest.fixture
def folders(tmp_path):
    """(work folder, log folder): the command runs in the first, its stdout/stderr go to the second."""
    work, logs = tmp_path / "work", tmp_path / "logs"
    work.mkdir()
    logs.mkdir()
    return work, logs


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_run_ends_cleanly_on_a_signal_and_leaves_no_file(folders, signum):
    work, logs = folders
    process, stderr_path = _start(["run", "linear_gaussian", "--trials", "2000000", "--out", "X.nc"], work, logs)
    _wait_until(process, _stderr_shows(stderr_path, r"\d+/2000000 trials"), "the progress line", stderr_path)
    err = _end_with(process, signum, stderr_path)
    _assert_ended_by(process, signum, err)
    assert sorted(os.listdir(work)) == []
    assert (logs / "stdout").read_text() == ""


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_run_with_a_figure_ends_cleanly_on_a_signal(folders, signum):
    """The trials kept for the figure (plansim.runner.run): both outputs are staged, neither is left."""
    work, logs = folders
    process, stderr_path = _start(["run", "linear_gaussian", "--trials", "2000000", "--out", "X.nc", "--plot",
                                   "X.png"], work, logs)
    _wait_until(process, _stderr_shows(stderr_path, r"\d+/2000000 trials"), "the progress line", stderr_path)
    err = _end_with(process, signum, stderr_path)
    _assert_ended_by(process, signum, err)
    assert sorted(os.listdir(work)) == []


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_validate_ends_cleanly_on_a_signal(folders, signum):
    work, logs = folders
    process, stderr_path = _start(["validate", "linear_gaussian", "--digits", "4", "--max-trials", "100000000"],
                                  work, logs)
    _wait_until(process, _stderr_shows(stderr_path, r"\d+ blocks, \d+ trials"), "the progress line", stderr_path)
    err = _end_with(process, signum, stderr_path)
    _assert_ended_by(process, signum, err)
    assert sorted(os.listdir(work)) == []


def _long_recording_scenario(folder) -> str:
    """The ideal scenario sampled at 1 kHz: about 1.3 million samples, a CSV file written for seconds."""
    from pathlib import Path

    text = (Path(__file__).resolve().parent.parent / "scenarios" / "ideal.toml").read_text()
    text = text.replace('name = "ideal"', 'name = "long_recording"').replace('sample_rate = "100 Hz"',
                                                                             'sample_rate = "1000 Hz"')
    assert "1000 Hz" in text
    path = folder / "long_recording.toml"
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_record_ends_cleanly_while_writing_and_leaves_no_file(folders, signum):
    work, logs = folders
    scenario = _long_recording_scenario(logs)
    process, stderr_path = _start(["record", scenario, "--out", "rec.csv"], work, logs)

    def writing() -> bool:
        return any(name.endswith(".part") for name in os.listdir(work))

    _wait_until(process, writing, "a temporary file being written", stderr_path)
    err = _end_with(process, signum, stderr_path)
    _assert_ended_by(process, signum, err)
    assert sorted(os.listdir(work)) == []


@pytest.mark.parametrize("argv", [["scenarios"], ["run", "ideal", "--trials", "3", "--quiet"],
                                  ["run", "ideal", "--trials", "3", "--quiet", "--json"]])
def test_a_reader_that_stops_reading_ends_the_command_quietly(tmp_path, argv):
    """`plansim run | head`: no BrokenPipeError traceback; the exit status is 141 (128 + SIGPIPE)."""
    process = subprocess.Popen([sys.executable, "-m", "plansim.cli", *argv], cwd=tmp_path, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
    process.stdout.close()  # the reader is gone before the first line
    with process:
        err = process.stderr.read().decode(errors="replace")
        process.wait(timeout=120)
    assert process.returncode == 141, err
    assert err == ""


def test_a_reader_that_takes_the_first_lines_gets_them(tmp_path):
    """`plansim scenarios | head -1`, with the shell: the first line arrives whole and nothing is said."""
    done = subprocess.run(f"{sys.executable} -m plansim.cli scenarios | head -n 1", shell=True, cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stderr == ""
    first = min(builtin_scenarios())  # plansim scenarios lists them by name
    assert len(done.stdout.splitlines()) == 1 and done.stdout.split()[0] == first


# ----------------------------------------------------------------------------- the compile process

class _Kernel:
    """A stand-in for a numba dispatcher that is neither compiled nor cached; compiling it runs *action*."""

    def __init__(self, name: str, action=None):
        self.__name__ = name
        self.overloads = {}
        self._action = action

    def compile(self, types):
        if self._action is not None:
            self._action()


def _raise_keyboard_interrupt():
    raise KeyboardInterrupt


@pytest.mark.parametrize("when", ["while compiling here", "while waiting for the second process"])
def test_an_interrupted_compile_ends_the_second_process(monkeypatch, when):
    """A signal in the parent, while it compiles or waits, must not leave the compile process running."""
    if numba.config.DISABLE_JIT:
        pytest.skip("nothing is compiled under NUMBA_DISABLE_JIT")
    children = []

    def start_child(requests):
        child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)"], stdin=subprocess.DEVNULL,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        children.append(child)
        return child

    monkeypatch.setattr(compilation, "_start_compiling_elsewhere", start_child)
    monkeypatch.setattr(compilation.os, "cpu_count", lambda: 2)
    arguments = (np.zeros(2),)
    if when == "while compiling here":
        calls = [(_Kernel("first"), arguments), (_Kernel("second", _raise_keyboard_interrupt), arguments)]
        previous = None
    else:  # the parent has compiled its kernel and waits for the child; the alarm stands for Ctrl-C
        calls = [(_Kernel("first"), arguments), (_Kernel("second"), arguments)]
        previous = signal.signal(signal.SIGALRM, lambda signum, frame: _raise_keyboard_interrupt())
        signal.setitimer(signal.ITIMER_REAL, 0.5)
    try:
        with pytest.raises(KeyboardInterrupt):
            compilation.compile_kernels(calls, parallel=True)
        assert len(children) == 1
        assert children[0].poll() is not None, "the compile process is still running"
        assert children[0].returncode == -signal.SIGKILL
    finally:
        if previous is not None:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous)
        for child in children:
            if child.poll() is None:
                child.kill()
                child.wait()


def _children(pid: int) -> list[int]:
    found = []
    try:
        for task in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{task}/children") as fh:
                found += [int(c) for c in fh.read().split()]
    except OSError:
        pass
    return found


def _command_line(pid: int) -> str:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as fh:
            return fh.read().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


@pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="needs Linux /proc to find the compile process")
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_cold_start_interrupted_leaves_no_compile_process(folders, tmp_path, signum):
    """From an empty kernel cache, `plansim run` starts a second process to compile; a signal ends both."""
    if numba.config.DISABLE_JIT:
        pytest.skip("nothing is compiled under NUMBA_DISABLE_JIT")
    work, logs = folders
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba-cache"))
    process, stderr_path = _start(["run", "linear_gaussian", "--trials", "10", "--out", "X.nc"], work, logs, env)
    compiler = []

    def compiling_elsewhere() -> bool:
        compiler[:] = [c for c in _children(process.pid) if "plansim.simulate.compilation" in _command_line(c)]
        return bool(compiler)

    _wait_until(process, compiling_elsewhere, "a second process compiling", stderr_path)
    err = _end_with(process, signum, stderr_path)
    _assert_ended_by(process, signum, err)
    assert not os.path.exists(f"/proc/{compiler[0]}"), "the compile process outlived its parent"
    assert sorted(os.listdir(work)) == []


def test_a_signal_whose_exception_is_swallowed_still_stops_the_commit(tmp_path):
    """A SIGTERM whose handler runs inside a ``__del__`` (or a garbage collector's weakref callback) raises there, and
    Python only reports it as unraisable ("Exception ignored"): the command would run to its end and commit its
    outputs with exit status 0 (seen once in CI, `plansim run` under SIGTERM). The handler remembers the signal, and
    the commit raises it again: nothing is left, nothing is printed for it, and the command ends as terminated."""
    from plansim.cli.common import Interrupted, signals_as_exceptions
    from plansim.io.files import OutputSet

    class Dropped:
        def __del__(self):
            os.kill(os.getpid(), signal.SIGTERM)
            deadline = time.monotonic() + 5.0
            while time.monotonic() < deadline:  # the handler runs here, inside __del__, and its exception is lost
                pass

    unraisable = []
    hook = sys.unraisablehook
    sys.unraisablehook = lambda u: unraisable.append(u.exc_type)  # what Python would print as "Exception ignored"
    target = tmp_path / "out.json"
    swallowed = []
    try:
        with signals_as_exceptions():
            inner = sys.unraisablehook
            sys.unraisablehook = lambda u: (swallowed.append(u.exc_type), inner(u))
            with pytest.raises(Interrupted) as raised:
                with OutputSet() as outputs:
                    with open(outputs.stage(target, "--out", (".json",)), "w") as fh:
                        fh.write("{}")
                    Dropped()  # collected at once: its __del__ runs now
                    outputs.commit()
            sys.unraisablehook = inner
    finally:
        sys.unraisablehook = hook
    assert swallowed == [Interrupted]  # the exception was indeed swallowed on the way ...
    assert unraisable == []  # ... and not printed: the command's one line says what happened
    assert raised.value.signum == signal.SIGTERM
    assert os.listdir(tmp_path) == []
