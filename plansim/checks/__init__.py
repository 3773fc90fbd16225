"""Checks of plansim's own methods by simulation: ``plansim diagnose-check`` (docs/closing-the-loop.md).

A layer above ``runner`` (it simulates recordings through it) and below ``cli``.
"""
