"""Sub-commands of ``bearing-rig``.

One module per sub-command, listed in :data:`bearing_rig_sim.cli.COMMANDS`. Each module exposes::

    def register(subparsers: argparse._SubParsersAction) -> None:
        parser = subparsers.add_parser("name", help="...")
        ...
        parser.set_defaults(func=run)      # run(args: argparse.Namespace) -> int

and keeps its heavy imports inside ``run`` so that ``bearing-rig --help`` stays fast.
"""

from __future__ import annotations

import os
from pathlib import Path

from bearing_rig_sim.errors import RigError

__all__ = ["output_file", "output_folder"]


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
