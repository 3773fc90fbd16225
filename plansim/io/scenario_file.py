"""Scenario files: the built-in scenarios, and reading and writing scenario TOML.

Parsing is strict (:func:`plansim.config.parse_scenario`): an unknown key, a wrong unit, a NaN, a
non-positive dwell, fewer than two distinct rate points, a repeated rate point, a rank-deficient
position set or a rate beyond the range raise ``ValueError``/``TypeError`` naming the field and what
is allowed; a file that is not UTF-8 TOML (binary, UTF-16, empty) is a ``ValueError`` naming the
file. docs/scenario-file.md explains every field.
"""

from __future__ import annotations

import copy
import dataclasses
import os
import tomllib
from importlib import resources
from pathlib import Path

import tomli_w

from plansim.config import Scenario, parse_scenario
from plansim.io.files import atomic_write_bytes
from plansim.schedule import Schedule


def builtin_scenarios() -> dict[str, Path]:
    """Name -> path of the scenarios shipped in ``scenarios/``."""
    root = resources.files("plansim.scenarios")
    return {Path(p.name).stem: Path(str(p)) for p in sorted(root.iterdir(), key=lambda p: p.name)
            if p.name.endswith(".toml")}


def parse_override(text: str) -> tuple[tuple[str, ...], object]:
    """``"schedule.dwell=60 s"`` -> (("schedule", "dwell"), "60 s"): a dotted key and a value.

    The value is read as a TOML value where it is one (``6``, ``true``, ``["5 deg/s", "10 deg/s"]``,
    ``"60 s"`` with its quotes) and as text otherwise (``60 s``: the quotes a shell takes away).

    Raises
    ------
    ValueError
        No ``=``, an empty key or a key part that is empty.
    """
    if not isinstance(text, str):
        raise TypeError(f"override {text!r}: expected text KEY=VALUE, got {type(text).__name__}")
    key, sep, raw = text.partition("=")
    key = key.strip()
    parts = tuple(part.strip() for part in key.split("."))
    if not sep or not key or any(not part for part in parts):
        raise ValueError(f"override {text!r}: expected KEY=VALUE with a dotted scenario key, e.g. "
                         "schedule.dwell=\"60 s\" or schedule.positions=6")
    raw = raw.strip()
    try:
        value = tomllib.loads(f"value = {raw}")["value"]
    except tomllib.TOMLDecodeError:
        value = raw
    return parts, value


def apply_overrides(document: dict, overrides) -> dict:
    """A copy of a scenario *document* with each override (``KEY=VALUE``, :func:`parse_override`) set.

    Tables on the way are created where the document has none (``mimu.effects`` in a scenario without
    effects); the result is checked by :func:`plansim.config.parse_scenario` exactly as a file is, so an
    unknown key or a bad value is refused with the field named.

    Raises
    ------
    ValueError
        An override that is not KEY=VALUE, or whose key runs through a value that is not a table
        (``schedule.dwell.x``) or replaces a whole table with a value (``schedule=6``).
    """
    document = copy.deepcopy(document)
    for text in overrides:
        parts, value = parse_override(text)
        table = document
        for depth, part in enumerate(parts[:-1]):
            child = table.setdefault(part, {})
            if not isinstance(child, dict):
                raise ValueError(f"override {text!r}: {'.'.join(parts[:depth + 1])} is a value "
                                 f"({child!r}), not a table with keys")
            table = child
        if isinstance(table.get(parts[-1]), dict) and not isinstance(value, dict):
            raise ValueError(f"override {text!r}: {'.'.join(parts)} is a table; set one of its keys "
                             f"({', '.join(sorted(table[parts[-1]]))})")
        table[parts[-1]] = value
    return document


def load_scenario(name_or_path: str | os.PathLike = "jjf2003", overrides=()) -> Scenario:
    """Load a built-in scenario by name, or a TOML file by path.

    The scenario's name: a built-in one's is its own; a file's is the document's ``name`` key, else
    the file name without ``.toml`` — except that a ``name`` still saying a built-in scenario's name
    in a file that is not that built-in (a copy a user edits: ``jjf2003.toml`` copied to ``lab.toml``)
    gives way to the file name, so that the run of ``lab.toml`` does not report itself as
    ``jjf2003``. :attr:`Scenario.source` keeps where it came from (``"file 'lab.toml', copied from
    built-in scenario 'jjf2003'"``).

    Raises
    ------
    ValueError
        No such file or built-in; the file is a folder, cannot be read, is not UTF-8 text (binary
        data, UTF-16), is empty or holds only comments, is not valid TOML, or fails
        :func:`plansim.config.parse_scenario`. The message names the file.

    *overrides* (``KEY=VALUE`` texts, as ``--set`` gives them: :func:`apply_overrides`) are set in the
    document before it is parsed; :attr:`Scenario.overrides` and :attr:`Scenario.source` say so.
    """
    overrides = (overrides,) if isinstance(overrides, str) else tuple(overrides)
    if not overrides:
        return _load_scenario(name_or_path, overrides)
    said = ", ".join(overrides)
    try:
        scenario = _load_scenario(name_or_path, overrides)
    except (ValueError, TypeError) as error:
        if str(error).startswith("override "):
            raise
        raise type(error)(f"{error} (scenario {str(name_or_path)!r} with {said})") from error
    return dataclasses.replace(scenario, overrides=overrides, source=f"{scenario.source}, with {said}")


def _load_scenario(name_or_path, overrides) -> Scenario:
    text_name = str(name_or_path)
    builtin = builtin_scenarios()
    if text_name in builtin:
        document = apply_overrides(_read_document(builtin[text_name]), overrides)
        return parse_scenario(document, name=text_name, source=f"built-in scenario {text_name!r}")
    path = Path(text_name)
    if path.is_dir():
        raise ValueError(f"scenario file {text_name!r} is a folder, not a TOML file")
    if not path.is_file():
        raise ValueError(f"scenario {text_name!r}: no such file and no built-in scenario of that name; "
                         f"built-in: {', '.join(builtin)}")
    document = apply_overrides(_read_document(path), overrides)
    source = f"file {str(path)!r}"
    named = document.get("name")
    if isinstance(named, str) and named in builtin and not _same_file(path, builtin[named]):
        # a copy of a built-in whose name key was never changed: the file is the user's, not the built-in
        return parse_scenario(document, name=path.stem, source=f"{source}, copied from built-in scenario {named!r}")
    return parse_scenario(document, name=None if named is not None else path.stem, source=source)


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.samefile(b)
    except OSError:
        return False


def _read_document(path: Path) -> dict:
    """The TOML document of *path*; every way a file can fail to be one is a ValueError naming it."""
    where = f"scenario file {str(path)!r}"
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ValueError(f"{where} cannot be read: {exc.strerror or exc}") from None
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise ValueError(f"{where} is UTF-16 text; TOML is UTF-8: save it as UTF-8")
    try:
        text = data.decode("utf-8-sig")  # a UTF-8 byte-order mark, as some editors write it, is accepted
    except UnicodeDecodeError as exc:
        raise ValueError(f"{where} is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}): binary "
                         "data, such as an image or a NetCDF file, is not a scenario; a scenario file is TOML "
                         "(docs/scenario-file.md)") from None
    try:
        document = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{where} is not valid TOML: {exc}") from None
    if not document:
        raise ValueError(f"{where} is empty (no key, only comments or nothing): a file cut short or never written? "
                         "To run the default world on purpose, write at least one key, e.g. a name = \"...\" line")
    return document


def schedule_to_document(schedule: Schedule) -> dict:
    """The ``[schedule]`` table of a custom schedule listing every segment, in SI units written with
    ``repr`` (rad, rad/s, s, Hz, degC) so that saving and loading round-trips exactly."""
    segments = []
    for s in schedule.segments:
        segments.append({
            "label": s.label, "test": s.test, "group": int(s.group), "up": s.up,
            # SI units and repr: the round trip is exact
            "heading": f"{s.heading!r} rad", "rate": f"{s.rate!r} rad/s",
            "rate_axis": s.rate_axis, "dwell": f"{s.dwell!r} s", "settle": f"{s.settle!r} s",
            "sample_rate": f"{s.sample_rate!r} Hz", "temperature": f"{s.temperature!r} degC",
        })
    return {"procedure": "custom", "segments": segments}


def save_scenario(scenario: Scenario, path: str | os.PathLike, expand_schedule: bool = True) -> None:
    """Write *scenario* as TOML (atomically). With *expand_schedule* the schedule is written segment by segment."""
    document = copy.deepcopy(scenario.document)
    document["name"] = scenario.name
    if expand_schedule:
        document["schedule"] = schedule_to_document(scenario.schedule)
    atomic_write_bytes(path, tomli_w.dumps(document).encode())
