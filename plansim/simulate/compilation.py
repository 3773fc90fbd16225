"""Compiling the kernels of a run before it starts, on every core.

The first run after an install compiles the kernels of its simulation path; numba keeps them in
its on-disk cache (:mod:`plansim.kernels.options`) and every later run loads them in a fraction of a second.
Compiling is slow — numba's compiler is Python code, and the segment path's kernels take several
seconds each — so :func:`compile_kernels` shortens the cold start in two ways:

- **Two processes.** The segment-statistics path has two entry kernels that share no compiled
  code (:mod:`plansim.kernels.segment_path`). When neither is cached and the machine has a
  second core, a second Python process compiles the first into the cache while this process
  compiles the second; this process then loads the first from the cache. Which process compiled
  a kernel changes nothing in it: numba builds the same code from the same source and types.
- **No garbage collection while compiling.** numba's compiler allocates millions of short-lived
  objects, and the cyclic collector's passes over them cost about a sixth of the compile time;
  the collector is paused while compiling and restored after.

If the second process cannot start, fails or hangs (:data:`SECOND_PROCESS_TIMEOUT`), or the
cache cannot be written, this process compiles the kernel itself (with a :class:`RuntimeWarning`
in the first three cases): the run goes on either way.
If this process is interrupted (``KeyboardInterrupt``, or the command line's SIGTERM) or fails
while compiling or waiting, the second process is killed and reaped before the exception goes on:
no compile process outlives the run.

Whether a kernel is already cached is asked of numba's cache with the lookup
``Dispatcher.compile`` itself makes first (``dispatcher._cache.load_overload``). It is not a
public API; should it change, every kernel counts as not cached, which costs time, never
correctness.
"""

from __future__ import annotations

import base64
import contextlib
import gc
import importlib
import inspect
import os
import pickle
import subprocess
import sys
import warnings

import numba

from plansim.kernels.options import COMPILE_IN_SECOND_PROCESS, SECOND_PROCESS_TIMEOUT


def bound_call(dispatcher, *args, **kwargs) -> tuple[object, tuple]:
    """``(dispatcher, positional arguments)`` of the call ``dispatcher(*args, **kwargs)``."""
    # under NUMBA_DISABLE_JIT=1 (the coverage run) a kernel is its plain Python function
    bound = inspect.signature(getattr(dispatcher, "py_func", dispatcher)).bind(*args, **kwargs)
    return dispatcher, tuple(bound.args)


def argument_types(arguments: tuple) -> tuple:
    """The numba types a call with *arguments* from Python compiles for."""
    return tuple(numba.typeof(value) for value in arguments)


def is_compiled_or_cached(dispatcher, types: tuple) -> bool:
    """True if *dispatcher* needs no compiling for *types*: compiled in this process or in numba's cache."""
    if types in dispatcher.overloads:
        return True
    try:
        return dispatcher._cache.load_overload(types, dispatcher.targetctx) is not None
    except Exception:  # see the module docstring: assume not cached
        return False


@contextlib.contextmanager
def collector_paused():
    """Pause Python's cyclic garbage collector (numba's compiler makes it busy for nothing)."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def compile_kernels(calls: list[tuple[object, tuple]], parallel: bool = COMPILE_IN_SECOND_PROCESS) -> None:
    """Compile (or load from the cache) each kernel of *calls* for the types of its arguments.

    Parameters
    ----------
    calls : list of (dispatcher, arguments)
        Entry kernels with arguments of the types the run will pass (values do not matter); see
        :func:`bound_call`. Kernels must not call one another.
    parallel : bool
        Let a second process compile the first kernel when two or more need compiling and the
        machine has two or more cores.
    """
    if numba.config.DISABLE_JIT:  # nothing to compile: the kernels run as Python (coverage run)
        return
    pending = [(dispatcher, argument_types(arguments)) for dispatcher, arguments in calls]
    pending = [(dispatcher, types) for dispatcher, types in pending if not is_compiled_or_cached(dispatcher, types)]
    if not pending:
        return
    offloaded, child = [], None
    if parallel and len(pending) >= 2 and (os.cpu_count() or 1) >= 2:
        offloaded, pending = pending[:1], pending[1:]
        try:
            child = _start_compiling_elsewhere(offloaded)
        except OSError as error:  # no usable interpreter to start (an embedded Python, say)
            warnings.warn(f"could not start a second process to compile ({error}); compiling here",
                          RuntimeWarning, stacklevel=2)
            offloaded, pending = [], offloaded + pending
    try:
        with collector_paused():
            for dispatcher, types in pending:
                dispatcher.compile(types)
        if child is None:
            return
        try:
            _, errors = child.communicate(timeout=SECOND_PROCESS_TIMEOUT)
        except subprocess.TimeoutExpired:
            child.kill()
            _, errors = child.communicate()
            errors += f"(no answer after {SECOND_PROCESS_TIMEOUT} s)".encode()
    except BaseException:  # interrupted (Ctrl-C, SIGTERM) or failed here: the second process ends with this one
        if child is not None:
            child.kill()
            child.wait()
            child.stderr.close()
        raise
    if child.returncode != 0:
        warnings.warn(f"the second process compiling {offloaded[0][0].__name__} failed (exit {child.returncode}); "
                      f"compiling it here instead:\n{errors.decode(errors='replace')[-2000:]}", RuntimeWarning,
                      stacklevel=2)
    with collector_paused():
        for dispatcher, types in offloaded:
            dispatcher.compile(types)  # from the cache the other process filled (or compiled here if it failed)


def _start_compiling_elsewhere(requests: list[tuple[object, tuple]]) -> subprocess.Popen:
    """Start ``python -m plansim.simulate.compilation REQUESTS`` compiling *requests* into numba's cache
    (REQUESTS: the pickled ``(module, function, types)`` list, base64, a few kB)."""
    payload = pickle.dumps([(d.py_func.__module__, d.py_func.__name__, types) for d, types in requests])
    return subprocess.Popen([sys.executable, "-m", "plansim.simulate.compilation",
                             base64.b64encode(payload).decode("ascii")],
                            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)


def _compile_requests(encoded: str) -> None:
    """The second process: compile each ``(module, function, types)`` of *encoded* (pickled by the parent)."""
    requests = pickle.loads(base64.b64decode(encoded))
    gc.disable()  # this process only compiles
    for module, name, types in requests:
        getattr(importlib.import_module(module), name).compile(types)


if __name__ == "__main__":
    _compile_requests(sys.argv[1])
