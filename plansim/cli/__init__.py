"""Command line: ``plansim run``, ``validate``, ``scenarios``, ``record``, ``import``, ``fit``, ``diagnose``,
``diagnose-check``, ``sweep``, ``bench``.

Errors in the user's input end with ``plansim: error: …`` and exit status 2, before any work starts:
output paths are checked first (:func:`plansim.io.files.check_output_path`). The output files of one
command are written to temporary files beside their targets and renamed onto them together at the end,
or not at all (:class:`plansim.io.files.OutputSet`).

Ctrl-C (SIGINT) and SIGTERM end a command with one line on stderr (``plansim: interrupted``,
``plansim: terminated``) and the exit status 128 + the signal's number (130, 143), after removing its
temporary files and any compile process. When the reader of the standard output goes away
(``plansim run | head``), the command ends quietly with the exit status 141 (128 + SIGPIPE), as the
standard tools killed by SIGPIPE do.
"""

from __future__ import annotations

import argparse
import signal
import sys

import plansim
from plansim.cli import bench_command, checks, diagnose, measured, planning, simulation
from plansim.cli.common import (
    COMMANDS,
    EXIT_BAD_INPUT,
    EXIT_BROKEN_PIPE,
    SIGNAL_WORDS,
    Interrupted,
    _silence_stdout,
    signals_as_exceptions,
)
from plansim.report.progress import end_progress_line

__all__ = ["COMMANDS", "EXIT_BAD_INPUT", "EXIT_BROKEN_PIPE", "Interrupted", "build_parser", "main"]

EPILOG = """exit status: 0 done; 1 failed; 2 bad input (plansim: error: ...); 130 interrupted (Ctrl-C);
143 terminated (SIGTERM); 141 the reader of the output went away (plansim run | head).
'plansim COMMAND --help' describes a command's options."""


class _TopLevelHelp(argparse.RawDescriptionHelpFormatter):
    """``plansim --help``: the commands' help in one column wide enough for the longest command name."""

    def __init__(self, prog: str) -> None:
        super().__init__(prog)
        # argparse measures the commands with the indent of the group, not their own (two more columns)
        self._action_max_length = 4 + max(map(len, COMMANDS))


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="plansim", formatter_class=_TopLevelHelp, epilog=EPILOG,
        description="Monte Carlo calibration planning for MEMS IMUs under JJF 2003-2022.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {plansim.__version__}")
    sub = parser.add_subparsers(dest="command", required=True, title="commands", metavar="COMMAND")
    for module in (simulation, measured, diagnose, checks, planning, bench_command):
        module.add_commands(sub)
    return parser


#: options whose value is a comma-separated list of numbers that may start with a minus sign
SIGNED_LIST_OPTIONS = ("--scale", "--offset")
#: options whose value is a comma-separated list of column names, each of which a leading minus sign reverses
SIGNED_NAME_OPTIONS = ("--columns",)


def _signed_value(option: str, value: str) -> bool:
    """Whether *value*, after *option*, is that option's list starting with a minus sign, not another option."""
    if value[:1] != "-" or value[:2] == "--":
        return False
    if option in SIGNED_LIST_OPTIONS:
        return value[1:2].isdigit() or value[1:2] == "."
    return option in SIGNED_NAME_OPTIONS and "," in value


def _join_signed_lists(argv: list[str]) -> list[str]:
    """``--scale -16.4,-2048`` as ``--scale=-16.4,-2048``, ``--columns -gyr_x,gyr_y,…`` as ``--columns=-gyr_x,…``:
    argparse takes a value that starts with "-" and is not one plain negative number for an option, and says only
    "expected one argument"."""
    out: list[str] = []
    k = 0
    while k < len(argv):
        value = argv[k + 1] if k + 1 < len(argv) else ""
        if _signed_value(argv[k], value):
            out.append(f"{argv[k]}={value}")
            k += 2
            continue
        out.append(argv[k])
        k += 1
    return out


def main(argv: list[str] | None = None) -> int:
    """Run the command of *argv* (default: ``sys.argv[1:]``); return its exit status (see :data:`EPILOG`)."""
    parser = build_parser()
    args = parser.parse_args(_join_signed_lists(sys.argv[1:] if argv is None else list(argv)))
    if getattr(args, "chunk_size", 1) < 1:
        parser.error(f"--chunk-size {args.chunk_size}: must be >= 1")
    try:
        with signals_as_exceptions():
            code = args.func(args)
            sys.stdout.flush()  # a reader gone away is found here, not in the interpreter's last flush
        return code
    except (ValueError, TypeError, FileNotFoundError) as exc:
        end_progress_line()
        print(f"plansim: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt as exc:  # Ctrl-C, or SIGTERM as Interrupted
        signum = getattr(exc, "signum", signal.SIGINT)
        end_progress_line()
        print(f"plansim: {SIGNAL_WORDS[signum]}", file=sys.stderr)
        return 128 + signum
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
