"""``plansim diagnose``: (being written)."""

from __future__ import annotations


def add_commands(sub) -> None:
    """No command yet."""
