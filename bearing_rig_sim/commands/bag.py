"""``bearing-rig bag info BAG`` and ``bearing-rig bag repair BAG [BAG ...]``: what a bag holds
(topics, counts, duration, run context, problems), and the index of a killed recording restored."""

from __future__ import annotations

import argparse
import contextlib
import sys
import warnings
from pathlib import Path
from typing import Any, TextIO
from collections.abc import Iterator

from bearing_rig_sim.commands import describe

PROG = "bearing-rig"


@contextlib.contextmanager
def bag_warnings_as_lines(out: TextIO | None = None) -> Iterator[list[str]]:
    """Print each bag warning (damage, unknown types) as one line ``bearing-rig: warning: ...``
    on stderr, once, instead of Python's warning format; yields the list of them."""
    from bearing_rig_sim.bags.errors import BagWarning

    seen: list[str] = []
    stream = out if out is not None else sys.stderr
    previous = warnings.showwarning

    def show(message: Warning | str, category: type[Warning], filename: str, lineno: int, file: TextIO | None = None, line: str | None = None) -> None:
        if not issubclass(category, BagWarning):
            previous(message, category, filename, lineno, file, line)
            return
        text = " ".join(str(message).split())
        if text not in seen:
            seen.append(text)
            print(f"{PROG}: warning: {text}", file=stream)

    with warnings.catch_warnings():
        warnings.simplefilter("always", BagWarning)
        warnings.showwarning = show
        try:
            yield seen
        finally:
            warnings.showwarning = previous


def register(subparsers: Any) -> None:
    """Add ``bag`` (``info``, ``repair``) to the ``bearing-rig`` parser."""
    parser = subparsers.add_parser("bag", help="inspect or repair a recorded bag", description=describe(__doc__, "bag"))
    actions = parser.add_subparsers(dest="action", metavar="ACTION", required=True)
    info_help = "topics, counts, duration, run context and problems of a bag"
    info = actions.add_parser("info", help=info_help, description=describe(f"{info_help}.", "bag"))
    info.add_argument("bag", type=Path, metavar="BAG", help="bag directory (or a single .mcap file)")
    info.add_argument("--metadata", action="store_true", help="print every run-context value in full")
    info.add_argument(
        "--index-only",
        action="store_true",
        help="read the index only: skip decompressing every chunk (checksums, unreadable messages, log-time outliers)",
    )
    info.set_defaults(action_func=run_info)
    repair_help = "restore the index of bags whose recording was interrupted (originals kept as *.orig)"
    repair = actions.add_parser("repair", help=repair_help, description=describe(f"{repair_help}.", "bag"))
    repair.add_argument("bags", type=Path, nargs="+", metavar="BAG", help="bag directory")
    repair.set_defaults(action_func=run_repair)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the chosen action (``info`` or ``repair``)."""
    return int(args.action_func(args))


def _duration(seconds: float) -> str:
    minutes, sec = divmod(seconds, 60.0)
    return f"{seconds:.3f} s" if minutes < 1 else f"{int(minutes)} min {sec:.3f} s ({seconds:.3f} s)"


def _qos(spec: Any) -> str:
    if spec is None:
        return "-"
    return f"{spec.reliability}, {spec.durability}, {spec.history} {spec.depth}"


def print_info(path: Path, out: TextIO, *, full_metadata: bool = False, index_only: bool = False) -> None:
    """Print a bag's summary to ``out`` (see the module documentation).

    Raises:
        BagError: not a bag.
    """
    from bearing_rig_sim.bags import open_bag

    with open_bag(path) as bag:
        topics = bag.topics
        found = [] if index_only else bag.verify()
        out.write(f"bag:        {bag.path}\n")
        out.write(f"files:      {', '.join(f.name for f in bag.files) or 'none'}\n")
        state = "complete" if bag.complete and not found else "DAMAGED or unfinished (see problems)"
        out.write(f"state:      {state}{' (index only; chunks not checked)' if index_only else ''}\n")
        out.write(f"messages:   {bag.message_count}\n")
        out.write(f"duration:   {_duration(bag.duration_ns * 1e-9)}\n")
        out.write(f"start, end: {bag.start_ns * 1e-9:.9f} s, {bag.end_ns * 1e-9:.9f} s (log time)\n")
        out.write(f"topics:     {len(topics)}\n")
        width = max((len(n) for n in topics), default=5)
        type_width = max((len(t.msgtype) for t in topics.values()), default=4)
        for name in sorted(topics):
            t = topics[name]
            unknown = "" if t.decodable else "  (type unknown: not decodable)"
            out.write(f"  {name:<{width}}  {t.msgtype:<{type_width}}  {t.message_count:>10}  {_qos(t.qos)}{unknown}\n")
        metadata = bag.run_metadata
        out.write(f"run context: {len(metadata)} entries\n")
        for key in sorted(metadata):
            value = metadata[key]
            lines = value.splitlines()
            if full_metadata:
                out.write(f"  {key}:\n" + "".join(f"    {line}\n" for line in lines))
            elif len(lines) <= 1 and len(value) <= 100:
                out.write(f"  {key}: {value}\n")
            else:
                out.write(f"  {key}: {len(lines)} lines (--metadata shows them)\n")
        problems = bag.problems + found
        out.write(f"problems:   {len(problems) or 'none'}\n")
        for problem in problems:
            out.write(f"  {problem}\n")


def run_info(args: argparse.Namespace) -> int:
    """``bag info``."""
    with warnings.catch_warnings():
        from bearing_rig_sim.bags.errors import BagWarning

        warnings.simplefilter("ignore", BagWarning)  # the problems are listed in the output
        print_info(args.bag, sys.stdout, full_metadata=args.metadata, index_only=args.index_only)
    return 0


def run_repair(args: argparse.Namespace) -> int:
    """``bag repair``: each bag in turn; exit status 2 if one could not be repaired."""
    from bearing_rig_sim.bags import BagError, repair_bag

    status = 0
    for path in args.bags:
        try:
            print(repair_bag(path).summary())
        except BagError as exc:
            print(f"{PROG}: error: {' '.join(str(exc).split())}", file=sys.stderr)
            status = 2
    return status
