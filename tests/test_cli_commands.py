"""The command line's own face: `plansim --help`, `--version`, `plansim scenarios`."""

from __future__ import annotations

import re

import pytest

import plansim
import plansim.io.scenario_file
from plansim import cli

EVERY_COMMAND = {"run", "validate", "scenarios", "record", "bench"}


def _subcommands(parser) -> dict:
    """{name: one-line help} of the parser's commands."""
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return {action.dest: action.help for action in sub._choices_actions}


def test_help_lists_every_command_on_one_line(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    with pytest.raises(SystemExit) as done:
        cli.main(["--help"])
    assert done.value.code == 0
    text = capsys.readouterr().out
    lines = text.splitlines()
    commands = _subcommands(cli.build_parser())
    assert set(commands) >= EVERY_COMMAND
    for name, help_text in commands.items():
        assert help_text, f"{name} has no help line"
        matches = [k for k, line in enumerate(lines) if line.split()[:1] == [name]]
        assert len(matches) == 1, (name, text)
        line = lines[matches[0]]
        assert line.split(None, 1)[1] == help_text, line  # the whole help on the command's own line
        following = lines[matches[0] + 1] if matches[0] + 1 < len(lines) else ""
        assert not following.strip() or following.split()[0] in commands, \
            f"{name}: its help goes on past its line:\n{text}"
        assert len(line) <= 80


def test_version_prints_the_package_version(capsys):
    with pytest.raises(SystemExit) as done:
        cli.main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out.strip() == f"plansim {plansim.__version__}"


def test_scenarios_are_aligned_whatever_the_length_of_the_names(capsys, monkeypatch, tmp_path):
    builtins = dict(plansim.io.scenario_file.builtin_scenarios())
    long_name = "a_scenario_with_a_name_much_longer_than_fourteen_characters"
    path = tmp_path / f"{long_name}.toml"
    path.write_text('description = "a long name"\n')
    monkeypatch.setattr(plansim.io.scenario_file, "builtin_scenarios", lambda: {**builtins, long_name: path})
    assert cli.main(["scenarios"]) == 0
    lines = capsys.readouterr().out.splitlines()
    # the scenarios, then the procedures (run on a unit scenario) and the experiments, in the same columns
    assert [line.split()[0] for line in lines] == [*builtins, long_name, *cli.simulation.PROCEDURES,
                                                   *cli.simulation.EXPERIMENTS]
    starts = {re.match(r"\S+\s+", line).end() for line in lines}
    assert len(starts) == 1, lines  # every description starts in the same column
    assert starts.pop() == len(long_name) + 2
