"""Simulation: numba kernels (plain SI arrays) and the engine that feeds them from a scenario."""
