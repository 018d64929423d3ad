"""The ``bearing-rig`` command line.

Each sub-command is a module ``bearing_rig_sim.commands.<name>`` listed in :data:`COMMANDS`.
Such a module exposes ``register(subparsers) -> None``, which adds its parser and sets
``func`` (``callable(args) -> int``, the exit status) as the parser's default. Errors a user can
cause (:class:`~bearing_rig_sim.errors.RigError`, hence configuration errors) are printed as
one line, ``bearing-rig: error: <message>``, with exit status 2; anything else is a bug and
keeps its traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from bearing_rig_sim import __version__
from bearing_rig_sim.commands import CommandParser
from bearing_rig_sim.errors import RigError

PROG = "bearing-rig"

COMMANDS: tuple[str, ...] = ("bench", "calibrate", "predict", "reproduce", "sweep", "run", "replay", "analyze", "bag", "shadow")
"""Sub-command modules under :mod:`bearing_rig_sim.commands`, in the order ``--help`` lists them."""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command of :data:`COMMANDS` registered."""
    parser = CommandParser(
        prog=PROG,
        description="Digital twin of the H7006C bearing cage-slip test rig.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        module = importlib.import_module(f"bearing_rig_sim.commands.{name}")
        module.register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``bearing-rig`` with ``argv`` (default: ``sys.argv[1:]``); return the exit status.

    argparse itself exits with status 2 on a usage error and 0 on ``--help``/``--version``.
    """
    parser = build_parser()
    args = parser.parse_args(None if argv is None else list(argv))
    try:
        status = args.func(args)
    except RigError as exc:
        print(f"{PROG}: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    return int(status) if status is not None else 0


def _one_line(message: str) -> str:
    """``message`` with its line breaks folded, so the error stays one line."""
    return " ".join(message.split()) or "unspecified error"


if __name__ == "__main__":  # pragma: no cover - ``python -m bearing_rig_sim.cli``
    sys.exit(main())
