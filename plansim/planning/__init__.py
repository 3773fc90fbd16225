"""Choosing a schedule: sweeps of scenario variants and the planner (docs/planning.md).

A layer above ``checks`` and ``runner`` (it runs Monte Carlo through the runner) and below ``bench`` and ``cli``.
"""
