"""``bearing-rig run [PROGRAM]``: a rig session: the three nodes, a test program on the
simulation clock, every rig topic recorded, live progress and a summary per segment.

Processes, bag, exit statuses: docs/guide.md, section ``bearing-rig run``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from bearing_rig_sim.commands import describe
from bearing_rig_sim.config import BEARING_MODELS, check_number, config_path
from bearing_rig_sim.errors import RigError

MAX_STARTUP_TIMEOUT_S = 3600.0
"""Longest ``--startup-timeout`` accepted, s: an hour covers the slowest first start (kernel
compilation on a loaded machine); NaN or infinity would never time out."""

FOXGLOVE_PORT = 8765
"""Default port of ``--foxglove``: the Foxglove app's default."""


def add_foxglove_argument(parser: argparse.ArgumentParser) -> None:
    """``--foxglove [PORT]``: serve the topics live to the Foxglove app (run and replay)."""
    parser.add_argument(
        "--foxglove",
        type=int,
        nargs="?",
        const=FOXGLOVE_PORT,
        default=None,
        metavar="PORT",
        help=f"serve the rig's topics live to the Foxglove app on ws://localhost:PORT (default {FOXGLOVE_PORT}); layout: config/foxglove/rig.json",
    )


DEFAULT_PROGRAM = "validation"
"""The shipped program run by default: the validation program (paper Table 3 conditions)."""


def register(subparsers: Any) -> None:
    """Add the ``run`` sub-command to the ``bearing-rig`` parser."""
    parser = subparsers.add_parser(
        "run",
        help="run a test program on the rig's nodes, recorded (default: the validation program)",
        description=describe(__doc__, "run"),
    )
    parser.add_argument(
        "program",
        metavar="PROGRAM",
        nargs="?",
        type=Path,
        default=None,
        help=f"test program: a YAML file, or the name of a shipped one in config/programs/ (default: {DEFAULT_PROGRAM})",
    )
    parser.add_argument("--no-realtime", action="store_true", help="run the simulator as fast as it goes, not locked to the wall clock")
    parser.add_argument("--bag-dir", type=Path, default=Path("bags"), metavar="DIR", help="folder of the run's bag directory (default: bags)")
    parser.add_argument("--quiet", action="store_true", help="no live progress or event lines; only the summary")
    parser.add_argument(
        "--startup-timeout",
        type=float,
        default=60.0,
        metavar="SECONDS",
        help="longest wait for the nodes to come up (default: 60 s; the simulator's first start compiles its kernels)",
    )
    parser.add_argument(
        "--params-file",
        type=Path,
        default=None,
        metavar="FILE",
        help="ROS 2 parameter file given to every node (a block per node name), over config/<node>.yaml",
    )
    parser.add_argument(
        "--attach",
        action="store_true",
        help="run the program on nodes already running and managed elsewhere (launch/rig.launch.py): start no processes",
    )
    parser.add_argument("--no-record", action="store_true", help="record no bag (where ros2 bag record records)")
    parser.add_argument(
        "--model",
        choices=BEARING_MODELS,
        default=None,
        help="the simulator's bearing model: bench (the bench twin, shipped) or paper (the paper's own model); its bearing_model parameter",
    )
    add_foxglove_argument(parser)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the session; returns its exit status."""
    from bearing_rig_sim.rig.program import PROGRAMS_DIR, program_file
    from bearing_rig_sim.session import SessionOptions, run_session

    program = program_file(args.program) if args.program is not None else config_path(*PROGRAMS_DIR, f"{DEFAULT_PROGRAM}.yaml")
    if args.model is not None and args.attach:
        raise RigError("--model sets the simulator's bearing_model parameter: attached, set it where the nodes are started (-p bearing_model:=...)")
    options = SessionOptions(
        program=program,
        realtime=not args.no_realtime,
        bag_dir=args.bag_dir,
        quiet=args.quiet,
        startup_timeout_s=check_number(args.startup_timeout, "bearing-rig run", "--startup-timeout", gt=0.0, le=MAX_STARTUP_TIMEOUT_S),
        params_file=args.params_file,
        foxglove_port=args.foxglove,
        attach=args.attach,
        record=not args.no_record,
        bearing_model=args.model,
        command_line=["bearing-rig", *sys.argv[1:]],
    )
    return run_session(options)
