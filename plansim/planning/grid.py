"""A sweep's grid: which scenario fields vary, over which values (``grid.toml``; docs/planning.md).

.. code-block:: toml

    [vary]                        # one dimension per field: the cells are every combination
    "schedule.dwell" = ["10 s", "30 s", "60 s"]
    "schedule.positions" = [6, 12]

    [zip]                         # optional: fields that change together, one dimension "zip"
    "schedule.rate_points" = [["-100 deg/s", "0 deg/s", "100 deg/s"],
                              ["-100 deg/s", "-50 deg/s", "0 deg/s", "50 deg/s", "100 deg/s"]]
    "schedule.omega_squared_rate" = ["100 deg/s", "100 deg/s"]

A key is a dotted scenario field, as ``--set`` takes it (quoted, or written as nested tables:
``[vary.schedule] dwell = [...]`` is the same). Each value is written as in the scenario file; a
cell's scenario is the base scenario with one ``KEY=VALUE`` override per field
(:func:`plansim.io.scenario_file.apply_overrides`), checked exactly as the file is.

Each cell's seed comes from the base seed and the cell's overrides (:func:`cell_seed`), so a cell's
numbers do not depend on the order, the executor or the number of workers that computed them.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plansim.io.scenario_file import parse_override

#: the dimension of the ``[zip]`` fields
ZIP_DIMENSION = "zip"


def toml_value(value) -> str:
    """*value* (str, int, float, bool or a list of them, as TOML reads them) written back as a TOML value."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf")
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # a TOML basic string is JSON's, for what TOML reads back
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TypeError(f"grid value {value!r}: expected text, a number, true/false or a list of them, "
                    f"got {type(value).__name__}")


@dataclass(frozen=True)
class Dimension:
    """One dimension of the grid: its name, the fields it sets and, per field, the values along it."""

    name: str
    fields: tuple[str, ...]
    values: tuple[tuple, ...]  # values[f][i]: field f's value at index i

    def __len__(self) -> int:
        return len(self.values[0])

    def overrides(self, index: int) -> list[str]:
        return [f"{field}={toml_value(self.values[f][index])}" for f, field in enumerate(self.fields)]

    def labels(self, field_index: int = 0) -> list:
        """The coordinate values of a field: numbers and text as written, a list as its TOML text."""
        out = [v if isinstance(v, (int, float, str)) and not isinstance(v, bool) else toml_value(v)
               for v in self.values[field_index]]
        kinds = {type(v) for v in out}
        return out if len(kinds) == 1 or kinds <= {int, float} else [toml_value(v) for v in self.values[field_index]]


@dataclass(frozen=True)
class Grid:
    """The dimensions of a sweep (``[vary]`` fields in file order, then ``[zip]``) and where they came from."""

    dimensions: tuple[Dimension, ...]
    source: str = ""

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(d) for d in self.dimensions)

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    def cells(self):
        """Yield ``(index tuple, overrides)`` of every cell, in C order."""
        for index in itertools.product(*(range(n) for n in self.shape)):
            yield index, [o for d, i in zip(self.dimensions, index) for o in d.overrides(i)]


def cell_seed(base_seed: int, overrides) -> int:
    """A cell's seed: numpy's SeedSequence over the base seed and the UTF-8 bytes of the cell's overrides
    (as JSON), its first 64-bit word halved to a non-negative 63-bit integer. Independent of where the cell
    sits in the grid and of who computes it (the seeding plansim's runs already use)."""
    text = json.dumps(list(overrides), ensure_ascii=False)
    state = np.random.SeedSequence([int(base_seed), *text.encode("utf-8")]).generate_state(1, np.uint64)
    return int(state[0] >> np.uint64(1))


def _flatten(table: dict, where: str, prefix: tuple[str, ...] = ()) -> dict[str, list]:
    out: dict[str, list] = {}
    for key, value in table.items():
        path = prefix + tuple(part.strip() for part in str(key).split("."))
        if isinstance(value, dict):
            out.update(_flatten(value, where, path))
            continue
        name = ".".join(path)
        if not isinstance(value, list) or not value:
            raise ValueError(f"{where}.{name} = {value!r}: expected a non-empty list of the values the field takes")
        parse_override(f"{name}={toml_value(value[0])}")  # the key is a dotted field
        out[name] = value
    return out


def parse_grid(document: dict, source: str = "") -> Grid:
    """The :class:`Grid` of a grid document (``tomllib`` output of ``grid.toml``).

    Raises
    ------
    ValueError
        Unknown tables; a field that is not a non-empty list; ``[zip]`` lists of different lengths; a
        field both in ``[vary]`` and ``[zip]`` or listing one value twice; no field at all.
    TypeError
        *document* is not a table.
    """
    if not isinstance(document, dict):
        raise TypeError(f"grid: expected a TOML table, got {type(document).__name__}")
    unknown = sorted(set(document) - {"vary", "zip"})
    if unknown:
        raise ValueError(f"grid {source}: unknown table(s) {unknown}; allowed: [vary], [zip]")
    vary = _flatten(document.get("vary", {}), "vary")
    zipped = _flatten(document.get("zip", {}), "zip")
    both = sorted(set(vary) & set(zipped))
    if both:
        raise ValueError(f"grid {source}: {both} both in [vary] and [zip]; a field varies along one dimension")
    if not vary and not zipped:
        raise ValueError(f"grid {source}: no field varies; give a [vary] table of field = [values]")
    lengths = {name: len(values) for name, values in zipped.items()}
    if len(set(lengths.values())) > 1:
        raise ValueError(f"grid {source}: the [zip] lists must have one length, got {lengths}")
    dims = []
    for name, values in vary.items():
        texts = [toml_value(v) for v in values]
        if len(set(texts)) < len(texts):
            raise ValueError(f"vary.{name} = {values!r}: a value is listed twice")
        dims.append(Dimension(name, (name,), (tuple(values),)))
    if zipped:
        texts = [tuple(toml_value(zipped[name][i]) for name in zipped) for i in range(next(iter(lengths.values())))]
        if len(set(texts)) < len(texts):
            raise ValueError(f"grid {source}: two [zip] entries are the same")
        dims.append(Dimension(ZIP_DIMENSION, tuple(zipped), tuple(tuple(v) for v in zipped.values())))
    return Grid(tuple(dims), source)


def load_grid(path: str | os.PathLike) -> Grid:
    """Read and check a ``grid.toml`` (:func:`parse_grid`); errors name the file."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            document = tomllib.load(fh)
    except FileNotFoundError:
        raise ValueError(f"--grid {str(path)!r}: no such file") from None
    except IsADirectoryError:
        raise ValueError(f"--grid {str(path)!r}: is a folder, not a grid file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise ValueError(f"--grid {str(path)!r}: not valid TOML ({error})") from None
    try:
        return parse_grid(document, source=str(path))
    except (ValueError, TypeError) as error:
        raise type(error)(f"{error} (grid file {str(path)!r})") from None
