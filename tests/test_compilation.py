"""plansim.simulate.compilation: what happens around the compile, with throwaway kernels.

The real parallel cold start (one segment kernel compiled by a second process) is checked in
tests/test_kernels.py from an empty cache; here the second process is replaced, to check that a
failure there costs time, not the run, and that nothing starts when nothing needs compiling.
"""

from __future__ import annotations

import subprocess
import sys

import numba
import numpy as np
import pytest

from plansim.simulate import compilation


def _kernels():
    """Two fresh uncached kernels (new dispatchers each call, so nothing is compiled yet)."""
    @numba.njit(cache=False)
    def scale(values, factor, out):
        for i in range(values.shape[0]):
            out[i] = factor * values[i]

    @numba.njit(cache=False)
    def shift(values, offset, out):
        for i in range(values.shape[0]):
            out[i] = values[i] + offset

    values, out = np.arange(3.0), np.empty(3)
    return [compilation.bound_call(scale, values, 2.0, out=out),
            compilation.bound_call(shift, values, offset=1, out=out)]


def test_bound_call_puts_keyword_arguments_in_place():
    (scale, scale_args), (shift, shift_args) = _kernels()
    assert len(scale_args) == 3 and scale_args[1] == 2.0
    assert shift_args[1] == 1 and shift_args[2] is scale_args[2]
    assert compilation.argument_types(shift_args) == (numba.typeof(np.arange(3.0)), numba.int64,
                                                      numba.typeof(np.empty(3)))


def _child_that_exits_3(requests):
    assert len(requests) == 1  # the first kernel was handed over
    return subprocess.Popen([sys.executable, "-c", "import sys; sys.stderr.write('no compiler'); sys.exit(3)"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _child_that_cannot_start(requests):
    raise FileNotFoundError("no such interpreter")


def _child_that_hangs(requests):
    return subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


@pytest.mark.parametrize("start_child, message", [
    (_child_that_exits_3, r"(?s)failed \(exit 3\).*no compiler"),
    (_child_that_cannot_start, "could not start a second process"),
    (_child_that_hangs, "no answer after 1 s"),
])
def test_a_failed_second_process_costs_time_not_the_run(monkeypatch, start_child, message):
    """Whatever goes wrong in the second process, a warning says so and the kernel is compiled here."""
    monkeypatch.setattr(compilation, "_start_compiling_elsewhere", start_child)
    monkeypatch.setattr(compilation, "SECOND_PROCESS_TIMEOUT", 1)
    monkeypatch.setattr(compilation.os, "cpu_count", lambda: 2)
    calls = _kernels()
    with pytest.warns(RuntimeWarning, match=message):
        compilation.compile_kernels(calls)
    for dispatcher, arguments in calls:
        assert len(dispatcher.signatures) == 1  # compiled here after all
        dispatcher(*arguments)
    assert np.array_equal(calls[1][1][2], [1.0, 2.0, 3.0])


def test_nothing_starts_when_everything_is_compiled(monkeypatch):
    calls = _kernels()
    compilation.compile_kernels(calls, parallel=False)

    def no_child(requests):
        raise AssertionError("a second process was started for compiled kernels")

    monkeypatch.setattr(compilation, "_start_compiling_elsewhere", no_child)
    compilation.compile_kernels(calls)


def test_one_kernel_is_compiled_here_without_a_second_process(monkeypatch):
    def no_child(requests):
        raise AssertionError("a second process was started for a single kernel")

    monkeypatch.setattr(compilation, "_start_compiling_elsewhere", no_child)
    (dispatcher, arguments), _ = _kernels()
    compilation.compile_kernels([(dispatcher, arguments)])
    assert dispatcher.signatures == [compilation.argument_types(arguments)]


def test_the_collector_is_restored_after_compiling():
    import gc

    assert gc.isenabled()
    with compilation.collector_paused():
        assert not gc.isenabled()
    assert gc.isenabled()
    gc.disable()
    try:
        with compilation.collector_paused():
            pass
        assert not gc.isenabled()  # it was off before: it stays off
    finally:
        gc.enable()
