"""``bearing-rig sweep SPEC.yaml``: run a sweep of operating points on Dask, writing a Parquet
table and, for a steady sweep, the operating map.

Where the points run and what is written: docs/guide.md, section ``bearing-rig sweep``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


from bearing_rig_sim.commands import describe


def register(subparsers: Any) -> None:
    """Add ``sweep`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("sweep", help="run a sweep of operating points on Dask (Parquet results, operating map)", description=describe(__doc__, "sweep"))
    p.add_argument("spec", type=Path, help="sweep spec (YAML), e.g. config/sweeps/paper_load_grid.yaml")
    p.add_argument("--out", type=Path, default=None, help="result folder (default: sweeps/<spec name>)")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--scheduler", default=None, metavar="ADDRESS", help="an existing Dask scheduler, e.g. tcp://127.0.0.1:8786")
    where.add_argument("--workers", type=int, default=None, metavar="N", help="LocalCluster worker processes (default: one per core)")
    p.add_argument("--integrate", action="store_true", help="integrate every steady point in time (the reference) instead of solving")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print the outcome as one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run the sweep, write the table and the map, print a summary."""
    import pyarrow.parquet as pq

    from bearing_rig_sim.commands import output_folder
    from bearing_rig_sim.errors import RigError
    from bearing_rig_sim.sweep.operating_map import boundaries, plot_operating_map
    from bearing_rig_sim.sweep.points import INTEGRATE, SOLVE
    from bearing_rig_sim.sweep.runner import run_sweep
    from bearing_rig_sim.sweep.spec import load_spec

    if args.workers is not None and args.workers < 1:
        raise RigError(f"--workers must be >= 1, got {args.workers}")
    spec = load_spec(args.spec)
    out = output_folder(args.out or Path("sweeps") / spec.name, "--out")  # before the points run
    outcome = run_sweep(spec, out, scheduler=args.scheduler, workers=args.workers, method=INTEGRATE if args.integrate else SOLVE, progress=not args.no_progress)
    table = pq.read_table(outcome.path)
    figure = None
    found: dict[str, dict[float, float | None]] = {}
    if not spec.transient and table.num_rows:
        figure = plot_operating_map(table, out / "operating_map.png", spec.skid_slip_pct, spec.minimum_load_factor_kn, spec.name)
        found = boundaries(table, spec.skid_slip_pct)
    summary = {
        "results": str(outcome.path),
        "points": outcome.points,
        "computed": outcome.computed,
        "errors": outcome.errors,
        "seconds": round(outcome.seconds, 3),
        "workers": outcome.workers,
        "figure": None if figure is None else str(figure),
        "skid_boundary_n": {b: {f"{k:g}": v for k, v in rows.items()} for b, rows in found.items()},
    }
    if args.json:
        print(json.dumps(summary))
        return 0
    print(
        f"{outcome.points} points in {outcome.path} ({outcome.computed} computed now in {outcome.seconds:.1f} s on {outcome.workers} workers, {outcome.errors} failed)"
    )
    for branch, rows in found.items():
        text = ", ".join(f"{k:g} rpm: {'-' if v is None else f'{v:g} N'}" for k, v in rows.items())
        print(f"skid boundary ({branch}, slip < {spec.skid_slip_pct:g} % from this load up): {text}")
    if figure is not None:
        print(f"operating map: {figure}")
    return 0 if outcome.errors == 0 else 1
