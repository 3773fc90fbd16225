"""Scenario files: the built-in scenarios, and reading and writing scenario TOML.

Parsing is strict (:func:`plansim.config.parse_scenario`): an unknown key, a wrong unit, a NaN, a
non-positive dwell, fewer than two distinct rate points or a rank-deficient position set raise
``ValueError``/``TypeError`` naming the field and what is allowed. docs/scenario-file.md explains
every field.
"""

from __future__ import annotations

import copy
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


def load_scenario(name_or_path: str | os.PathLike = "jjf2003") -> Scenario:
    """Load a built-in scenario by name, or a TOML file by path."""
    text_name = str(name_or_path)
    builtin = builtin_scenarios()
    if text_name in builtin:
        path = builtin[text_name]
    else:
        path = Path(text_name)
        if not path.is_file():
            raise ValueError(f"scenario {text_name!r}: no such file and no built-in scenario of that name; "
                             f"built-in: {', '.join(builtin)}")
    try:
        with open(path, "rb") as fh:
            document = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"scenario file {str(path)!r} is not valid TOML: {exc}") from None
    return parse_scenario(document, name=path.stem)


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
