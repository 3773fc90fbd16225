"""Shared fixture: the ``ideal`` scenario (scenarios/ideal.toml) as a fresh TOML document."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

IDEAL_TOML = Path(__file__).resolve().parent.parent / "scenarios" / "ideal.toml"

with open(IDEAL_TOML, "rb") as _fh:
    _IDEAL_DOCUMENT = tomllib.load(_fh)


@pytest.fixture
def ideal_document() -> dict:
    """A fresh, independently mutable copy of scenarios/ideal.toml as parsed by tomllib."""
    return copy.deepcopy(_IDEAL_DOCUMENT)
