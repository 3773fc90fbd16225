"""Numba options, set in one place for every kernel.

``cache=True`` keeps compiled kernels on disk (cold start once per install); ``fastmath`` stays
off so that results do not depend on the instruction set or reassociation; ``nogil`` lets the
engine run kernels on several threads side by side (slices of trials; see
:func:`plansim.simulate.engine.iterate_chunks`), which compiles far faster than ``parallel=True``.
"""

import numba

JIT_OPTIONS = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")

jit = numba.njit(**JIT_OPTIONS)

#: for small helpers called per sample with array arguments: inlined at numba's IR level, so the
#: call does not pay a reference-count round trip per array argument
inline_jit = numba.njit(inline="always", **JIT_OPTIONS)

