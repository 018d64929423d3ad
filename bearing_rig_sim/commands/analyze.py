"""``bearing-rig analyze BAG``: the slip and stability report of a recorded bag (markdown, PNG
plots, CSV series), from the monitor run offline over its pulses.

What is written and which bags: docs/guide.md, section ``bearing-rig analyze``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from bearing_rig_sim.commands import describe, output_folder


def register(subparsers: Any) -> None:
    """Add ``analyze`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("analyze", help="slip and stability report of a bag (markdown, PNG, CSV)", description=describe(__doc__, "analyze"))
    p.add_argument("bag", type=Path, metavar="BAG", help="bag directory (or a single .mcap file)")
    p.add_argument("--out", type=Path, default=None, metavar="DIR", help="output folder (default: out/analyze/<bag name>)")
    p.add_argument(
        "--monitor-params",
        type=Path,
        default=None,
        metavar="FILE",
        help="monitor parameter file (default: the one recorded in the bag, else config/monitor.yaml)",
    )
    p.add_argument("--max-points", type=int, default=2000, metavar="N", help="points per plotted series (default 2000)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Analyse the bag and write the report."""
    from bearing_rig_sim.commands.bag import bag_warnings_as_lines
    from bearing_rig_sim.monitoring import MonitorSettings, SlipState
    from bearing_rig_sim.offline.analysis import analyse_bag
    from bearing_rig_sim.offline.report import state_name, write_report

    out = args.out if args.out is not None else Path("out") / "analyze" / args.bag.resolve().name
    settings = MonitorSettings.from_yaml(args.monitor_params) if args.monitor_params is not None else None
    output_folder(out, "--out")  # before the analysis, not after it
    with bag_warnings_as_lines():
        result = analyse_bag(args.bag, settings=settings, csv_dir=out, max_points=args.max_points)
        files = write_report(result, out)
    final = result.final_status
    verdict = state_name(int(final.state)) if final is not None else "none"
    stable = sum(s.final_state == SlipState.STABLE for s in result.segments)
    print(
        f"{args.bag}: {result.windows} slip windows, final verdict {verdict}; "
        f"{len(result.segments)} segment(s), {stable} stable{'' if result.complete else '; INCOMPLETE bag, partial results'}"
    )
    print(f"report: {files.report} ({len(files.plots)} plots, {len(files.csv)} CSV files)")
    return 0
