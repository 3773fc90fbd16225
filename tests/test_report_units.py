"""`plansim run` and `plansim validate` print the same quantities in the same units.

Both print, per parameter, the mean and the standard deviation of the error estimate − truth over
the Monte Carlo trials; `run` did so in display units (°/h, µg, …) with a unit column and `validate`
in SI without one, under other names (MCM y, MCM u), so the same number looked different.
"""

from __future__ import annotations

import re

import pytest

from plansim.cli import main
from plansim.model.parameters import PARAMETER_NAMES, parameter


def _rows(text: str, header_start: str) -> dict[str, list[str]]:
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header_start))
    rows = {}
    for line in lines[start + 1:]:
        fields = line.split()
        if not fields or fields[0] not in PARAMETER_NAMES:
            break
        rows[fields[0]] = fields
    return rows


@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    import contextlib
    import io

    out = {}
    for command in (["run", "linear_gaussian", "--trials", "4000", "--seed", "5", "--quiet"],
                    ["validate", "linear_gaussian", "--trials-per-block", "2000", "--max-trials", "4000",
                     "--seed", "5", "--quiet", "--summary"]):
        buffer = io.StringIO()
        with contextlib.redirect_stdout(buffer):
            assert main(command) == 0
        out[command[0]] = buffer.getvalue()
    return out


def test_validate_names_the_run_table_quantities_and_their_units(printed):
    header = next(line for line in printed["validate"].splitlines() if line.startswith("name"))
    assert re.search(r"\bunit\b", header) and "mean error" in header and "std error" in header
    rows = _rows(printed["validate"], "name")
    assert set(rows) == set(PARAMETER_NAMES)
    for name, fields in rows.items():
        assert fields[1] == parameter(name).display_unit, (name, fields[1])


def test_run_and_validate_print_the_same_error_statistics_in_the_same_units(printed):
    """Same scenario and trial count (validate: 2 blocks of 2000 trials, seeded from the root seed block
    by block, so not the same trials as run's 4000): the units agree and the two std errors agree within
    0.8-1.25 (each has a relative standard error of 1/sqrt(2·4000) ≈ 1.1 %; a unit mix-up is a factor of
    10³ or more)."""
    run_rows = _rows(printed["run"], "name")
    validate_rows = _rows(printed["validate"], "name")
    for name in PARAMETER_NAMES:
        assert run_rows[name][1] == validate_rows[name][1] == parameter(name).display_unit
        run_std = float(run_rows[name][4])  # name, unit, truth (mean), mean error, std error
        validate_std = float(validate_rows[name][3])  # name, unit, mean error, std error, …
        assert 0.8 < validate_std / run_std < 1.25, (name, run_std, validate_std)
