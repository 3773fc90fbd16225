"""numba kernels on plain SI arrays: random streams, physics, drift, quantiser, the two simulation paths.

They import only numpy, numba and math (and :mod:`plansim.kernels.options`, which sets every numba
option); the layouts of the arrays they share with their callers are named in
:mod:`plansim.kernels.layout`.
"""
