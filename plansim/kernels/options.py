"""Numba options, set in one place for every kernel: compilation flags, the cache, threads, the compile policy.

``cache=True`` keeps compiled kernels on disk (cold start once per install); ``fastmath`` stays
off so that results do not depend on the instruction set or reassociation; ``nogil`` lets the
engine run kernels on several threads side by side (slices of trials; see
:func:`plansim.simulate.chunks.iterate_chunks`), which compiles far faster than ``parallel=True``.

Numba's cache checks the source file of each cached function, not of the functions it calls in
other files, so an edited kernel helper could be served stale. The cache therefore lives in a
folder named after a hash of every kernel source file (and the numba version), unless the user
chose one with ``NUMBA_CACHE_DIR``.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numba

JIT_OPTIONS = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")


def _kernel_cache_dir() -> Path | None:
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    here = Path(__file__).resolve().parent
    sources = sorted(here.glob("*.py"))  # this module and every kernel module beside it
    source_hash = hashlib.sha256(numba.__version__.encode())
    for path in sources:
        source_hash.update(path.read_bytes())
    root = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    folder = root / "plansim" / f"numba-{source_hash.hexdigest()[:16]}"
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:  # no writable home: numba's default (__pycache__ beside the sources)
        return None
    return folder


_folder = _kernel_cache_dir()
if _folder is not None:
    numba.config.CACHE_DIR = str(_folder)

jit = numba.njit(**JIT_OPTIONS)

#: for small helpers called per sample with array arguments: inlined at numba's IR level, so the
#: call does not pay a reference-count round trip per array argument
inline_jit = numba.njit(inline="always", **JIT_OPTIONS)


def worker_threads() -> int:
    """Threads that run kernels side by side (slices of trials): numba's thread count, which honours
    ``numba.set_num_threads`` and ``NUMBA_NUM_THREADS``. Results do not depend on it."""
    return numba.get_num_threads()


#: compile policy (:mod:`plansim.simulate.compilation`): on a cold start with two or more cores, a
#: second process compiles one entry kernel into the cache while this one compiles the other
COMPILE_IN_SECOND_PROCESS = True
#: seconds to wait for that second process (a compile takes seconds; this only guards against a hang)
SECOND_PROCESS_TIMEOUT = 600
