"""The ``bearing-rig`` command line.

Each sub-command is a module ``bearing_rig_sim.commands.<name>`` listed in :data:`COMMANDS`.
Such a module exposes ``register(subparsers) -> None``, which adds its parser and sets
``func`` (``callable(args) -> int``, the exit status) as the parser's default. Errors a user can
cause (:class:`~bearing_rig_sim.errors.RigError`, hence configuration errors) are printed as
one line, ``bearing-rig: error: <message>``, with exit status 2; anything else is a bug and
keeps its traceback.

Only the chosen sub-command's module is imported (all of them for ``--help`` or no command):
some import the dynamics engine and numba (about 100 MB), which ``analyze``, ``replay`` or
``bag`` do not need.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from bearing_rig_sim import __version__
from bearing_rig_sim.commands import CommandParser
from bearing_rig_sim.errors import RigError

PROG = "bearing-rig"

COMMANDS: tuple[str, ...] = ("bench", "calibrate", "predict", "reproduce", "sweep", "run", "replay", "analyze", "bag", "shadow")
"""Sub-command modules under :mod:`bearing_rig_sim.commands`, in the order ``--help`` lists them."""


def build_parser(commands: Sequence[str] = COMMANDS) -> argparse.ArgumentParser:
    """The argument parser with the sub-commands ``commands`` (default: every one of
    :data:`COMMANDS`) registered, in that order."""
    parser = CommandParser(
        prog=PROG,
        description="Digital twin of the H7006C bearing cage-slip test rig.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in commands:
        module = importlib.import_module(f"bearing_rig_sim.commands.{name}")
        module.register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``bearing-rig`` with ``argv`` (default: ``sys.argv[1:]``); return the exit status.

    argparse itself exits with status 2 on a usage error and 0 on ``--help``/``--version``.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    chosen = chosen_command(argv)
    parser = build_parser(COMMANDS if chosen is None else (chosen,))
    args = parser.parse_args(argv)
    try:
        status = args.func(args)
    except RigError as exc:
        print(f"{PROG}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    return int(status) if status is not None else 0


def chosen_command(argv: Sequence[str]) -> str | None:
    """The sub-command ``argv`` names (its first argument not an option, when that is one of
    :data:`COMMANDS`), or None (no command, ``--help``, ``--version`` or an unknown name, which
    the full parser then answers)."""
    for arg in argv:
        if arg.startswith("-"):
            if arg in ("-h", "--help", "--version"):
                return None
            continue
        return arg if arg in COMMANDS else None
    return None


def _one_line(message: str) -> str:
    """``message`` with its line breaks folded, so the error stays one line."""
    return " ".join(message.split()) or "unspecified error"


if __name__ == "__main__":  # pragma: no cover - ``python -m bearing_rig_sim.cli``
    sys.exit(main())
