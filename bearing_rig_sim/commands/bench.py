"""``bearing-rig bench NAME [--json] [options]``: run one benchmark and print its results.

A benchmark is a module named in :data:`BENCHMARKS` that exposes::

    def add_arguments(parser: argparse.ArgumentParser) -> None: ...   # its own options
    def run(args: argparse.Namespace) -> Iterator[dict]: ...          # one dict per result row

With ``--json`` every row is printed as it arrives, one JSON object per line (the form kept
in benchmark records); otherwise the rows are printed at the end as an aligned table. Timing
belongs in benchmarks, never in tests.
"""

from __future__ import annotations

import argparse
import importlib
import json
import numbers
import sys
from types import ModuleType
from typing import Any, TextIO
from collections.abc import Iterable

from bearing_rig_sim.commands import CommandParser, describe
from bearing_rig_sim.errors import RigError

BENCHMARKS: dict[str, str] = {
    "analysis": "bearing_rig_sim.benchmarks.analysis",
    "bags": "bearing_rig_sim.benchmarks.bags",
    "dynamics": "bearing_rig_sim.benchmarks.dynamics",
    "rig": "bearing_rig_sim.benchmarks.rig",
    "sweep": "bearing_rig_sim.benchmarks.sweep",
    "replay": "bearing_rig_sim.benchmarks.replay",
    "shadow": "bearing_rig_sim.benchmarks.shadow",
    "thermal": "bearing_rig_sim.benchmarks.thermal",
}
"""Benchmark name -> module path (``bearing_rig_sim.benchmarks.<name>``)."""


def register(subparsers: Any) -> None:
    """Add the ``bench`` sub-command to the ``bearing-rig`` parser."""
    parser = subparsers.add_parser(
        "bench",
        help="run a benchmark (JSON lines with --json)",
        description=describe(__doc__, "bench"),
        epilog=f"benchmarks: {known_names()}. `bearing-rig bench NAME --help` lists NAME's options.",
    )
    parser.add_argument("--json", action="store_true", help="print one JSON object per line")
    parser.add_argument("name", metavar="NAME", help="which benchmark to run")
    parser.add_argument("options", nargs=argparse.REMAINDER, help="options of that benchmark")
    parser.set_defaults(func=run)


def known_names() -> str:
    """The registered benchmark names, for messages."""
    return ", ".join(sorted(BENCHMARKS)) if BENCHMARKS else "none registered yet"


def load_benchmark(name: str) -> ModuleType:
    """The benchmark module registered as ``name``.

    Raises:
        RigError: ``name`` is not in :data:`BENCHMARKS` (the message lists the known names).
    """
    if name not in BENCHMARKS:
        raise RigError(f"unknown benchmark {name!r}; known benchmarks: {known_names()}")
    module = importlib.import_module(BENCHMARKS[name])
    for attribute in ("add_arguments", "run"):
        if not callable(getattr(module, attribute, None)):
            raise TypeError(f"benchmark module {module.__name__} has no {attribute}() function")
    return module


def run(args: argparse.Namespace) -> int:
    """Parse the benchmark's own options, run it and print its rows; return the exit status."""
    module = load_benchmark(args.name)
    parser = CommandParser(prog=f"bearing-rig bench {args.name}", description=describe(module.__doc__, "bench"))
    parser.add_argument("--json", action="store_true", help="print one JSON object per line")
    module.add_arguments(parser)
    options = parser.parse_args(args.options)
    options.json = bool(options.json or args.json)
    rows = module.run(options)
    if options.json:
        print_json_lines(rows, sys.stdout)
    else:
        print_table(list(rows), sys.stdout)
    return 0


def _json_default(value: Any) -> Any:
    """numpy scalars and arrays (and anything with ``tolist``/``item``) as plain JSON values."""
    for method in ("tolist", "item"):
        if callable(getattr(value, method, None)):
            return getattr(value, method)()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def print_json_lines(rows: Iterable[dict[str, Any]], out: TextIO) -> None:
    """Print each row as one JSON object per line, flushing after each."""
    for row in rows:
        out.write(json.dumps(row, default=_json_default, allow_nan=True) + "\n")
        out.flush()


def _cell(value: Any) -> str:
    """A table cell: floats to 6 significant digits, anything else as ``str``."""
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def print_table(rows: list[dict[str, Any]], out: TextIO) -> None:
    """Print rows as an aligned table; the columns are the keys in order of first appearance."""
    if not rows:
        out.write("(no results)\n")
        return
    columns: list[str] = []
    for row in rows:
        columns.extend(key for key in row if key not in columns)
    cells = [[_cell(row.get(col, "")) for col in columns] for row in rows]
    numeric = [all(isinstance(row[col], numbers.Real) and not isinstance(row[col], bool) for row in rows if col in row) for col in columns]
    widths = [max(len(col), *(len(line[i]) for line in cells)) for i, col in enumerate(columns)]

    def fmt(values: list[str]) -> str:
        return "  ".join(v.rjust(w) if num else v.ljust(w) for v, w, num in zip(values, widths, numeric)).rstrip()

    out.write(fmt(columns) + "\n")
    out.write("  ".join("-" * w for w in widths) + "\n")
    for line in cells:
        out.write(fmt(line) + "\n")
