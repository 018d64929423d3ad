"""Sub-commands of ``bearing-rig``.

One module per sub-command, listed in :data:`bearing_rig_sim.cli.COMMANDS`. Each module exposes::

    def register(subparsers: argparse._SubParsersAction) -> None:
        parser = subparsers.add_parser("name", help="...", description=describe(__doc__, "name"))
        ...
        parser.set_defaults(func=run)      # run(args: argparse.Namespace) -> int

and keeps its heavy imports inside ``run`` so that ``bearing-rig --help`` stays fast. Its
``--help`` is the first paragraph of the module's documentation (:func:`describe`: a line or two)
and its options; the long explanation is its section of docs/guide.md's "Command reference",
which the help links (test_cli checks both).
"""

from __future__ import annotations

import argparse
import os
import re
import textwrap
from pathlib import Path
from typing import Any

from bearing_rig_sim.errors import RigError

__all__ = ["GUIDE", "CommandParser", "HelpFormatter", "describe", "output_file", "output_folder", "rig_limit_text"]

GUIDE = "docs/guide.md"
"""Where each sub-command is explained in full (its section "Command reference")."""


class HelpFormatter(argparse.HelpFormatter):
    """argparse's help layout, with lines broken only at spaces: a name such as ``bearing-rig``
    or a link such as ``docs/guide.md#bearing-rig-run`` stays whole."""

    def _fill_text(self, text: str, width: int, indent: str) -> str:
        return textwrap.fill(" ".join(text.split()), width, initial_indent=indent, subsequent_indent=indent, break_on_hyphens=False, break_long_words=False)

    def _split_lines(self, text: str, width: int) -> list[str]:
        return textwrap.wrap(" ".join(text.split()), width, break_on_hyphens=False, break_long_words=False)


class CommandParser(argparse.ArgumentParser):
    """The parser of ``bearing-rig`` and of each sub-command: :class:`HelpFormatter` unless told
    otherwise (argparse makes sub-command parsers of their parent's class)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)


def rig_limit_text(rig_key: str, *, unit_in_si: float = 1.0, unit: str = "") -> str:
    """An option's bound as its help states it: ``at most 1000 N (loading_chain.max_setpoint_n
    in rig.yaml)``, read from the shipped rig file that the option is checked against ("" where
    the file cannot be read: the check then names the problem)."""
    from bearing_rig_sim.config import ConfigError, shipped_rig_file
    from bearing_rig_sim.settings_model import rig_file_value

    rig = shipped_rig_file()
    try:
        limit = rig_file_value(rig, rig_key) / unit_in_si
    except ConfigError:
        return ""
    return f"at most {limit:.6g}{unit} ({rig_key} in {rig.name})"


def describe(doc: str | None, command: str) -> str:
    """What ``bearing-rig COMMAND --help`` shows between the usage and the options: the first
    paragraph of the command module's documentation (its syntax, one or more ````...```` joined
    by commas, "and" or "or", left to the usage line) and
    where the command is explained in full (``docs/guide.md#bearing-rig-<command>``)."""
    first = " ".join((doc or "").split("\n\n")[0].split())
    first = re.sub(r"^``[^`]*``(\s*(,|and|or)\s*``[^`]*``)*[:.]?\s*", "", first).replace("``", "")
    first = first[:1].upper() + first[1:]
    return f"{first} Details: {GUIDE}#bearing-rig-{command.replace(' ', '-')}"


def output_folder(path: Path, option: str) -> Path:
    """Create ``path`` (with its parents) as an output folder and check it can be written, before
    any long work starts.

    Raises:
        RigError: one line naming ``option``, the path and why (a file in the way, no permission).
    """
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RigError(f"{option} {path}: cannot create the folder ({exc.strerror or exc})") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise RigError(f"{option} {path}: the folder is not writable")
    return path


def output_file(path: Path, option: str, *, overwrite: bool) -> Path:
    """Check that ``path`` can be written as an output file: its folder made and writable, and
    an existing file replaced only with ``overwrite``.

    Raises:
        RigError: one line naming ``option``, the path and why.
    """
    if path.is_dir():
        raise RigError(f"{option} {path}: is a folder, not a file")
    if path.exists() and not overwrite:
        raise RigError(f"{option} {path}: exists; give --force to replace it, or another --out")
    output_folder(path.parent, option)
    return path
