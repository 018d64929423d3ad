"""Benchmark of sweeps: the cost of a steady point, integrated and solved, and cluster scaling.

``bearing-rig bench sweep --json`` prints one JSON object per line:

* ``case: integrated``: points per core-second of the reference (integration from the rolling
  start for 0.15 s, averaged over 0.05 s), in this process on one core;
* ``case: steady_rolling_start``: the direct solver from the rolling start (the same states);
* ``case: steady_continuation``: the direct solver along each load row from the previous point
  (the branch a live load sweep follows);
* ``case: cluster``: the same sweep (``--cluster-method``) on a ``LocalCluster`` of 1 and then
  2 worker processes, wall time from submission to the merged table (cluster start and the
  workers' warm-up excluded) and the 2-worker speed-up.

Points: the paper's grid (1000-9000 rpm) at ``--load-step`` N from 50 to 700 N. Medians of
``--repeats`` runs. Machine load from other processes lowers every figure, the speed-up most.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path
from collections.abc import Callable, Iterator

from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.steady import SteadySolver

SPEEDS_RPM = (1000.0, 3000.0, 5000.0, 7000.0, 9000.0)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench sweep``."""
    parser.add_argument("--load-step", type=float, default=10.0, help="load step of the grid, N (10: the 330-point paper grid)")
    parser.add_argument("--repeats", type=int, default=3, help="runs per case; the median is reported")
    parser.add_argument("--cluster-method", choices=["integrate", "solve"], default="integrate", help="how the cluster case computes its points")
    parser.add_argument("--no-cluster", action="store_true", help="skip the LocalCluster speed-up")


def _loads(step: float) -> list[float]:
    n = int(round(650.0 / step))
    return [50.0 + i * step for i in range(n + 1)]


def _median_wall(run: Callable[[], object], repeats: int) -> float:
    walls = []
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        run()
        walls.append(time.perf_counter() - start)
    return statistics.median(walls)


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Measure the cases (see the module docstring)."""
    params = BearingParameters.calibrated()
    loads = _loads(args.load_step)
    points = [(rpm_to_rad_s(n), f) for n in SPEEDS_RPM for f in loads]
    solver = SteadySolver(params)
    solver.solve(points[0][0], points[0][1])  # compile or load the kernels
    solver.integrate(points[0][0], points[0][1])

    def integrate_all() -> None:
        for w, f in points:
            solver.integrate(w, f)

    def solve_all() -> None:
        for w, f in points:
            solver.solve(w, f)

    def continue_all() -> None:
        for n in SPEEDS_RPM:
            solver.sweep_load(rpm_to_rad_s(n), loads)

    base = None
    for case, job in (("integrated", integrate_all), ("steady_rolling_start", solve_all), ("steady_continuation", continue_all)):
        wall = _median_wall(job, args.repeats)
        rate = len(points) / wall
        base = base or rate
        yield {
            "bench": "sweep",
            "case": case,
            "points": len(points),
            "wall_s": round(wall, 4),
            "points_per_core_s": round(rate, 2),
            "ms_per_point": round(1e3 / rate, 3),
            "speedup_vs_integrated": round(rate / base, 2),
        }
    if not args.no_cluster:
        yield from _cluster_rows(loads, args.cluster_method, args.repeats)


def _cluster_rows(loads: list[float], method: str, repeats: int) -> Iterator[dict]:
    from bearing_rig_sim.sweep.points import INTEGRATE, SOLVE
    from bearing_rig_sim.executors import open_client
    from bearing_rig_sim.sweep.runner import run_sweep
    from bearing_rig_sim.sweep.spec import spec_from_mapping

    doc = {
        "sweep": {"name": "bench", "continuation": False},
        "grid": {"inner_ring_speed_rpm": list(SPEEDS_RPM), "axial_load_n": loads},
    }
    spec = spec_from_mapping(doc, "<bench sweep>")
    warm_doc = {"sweep": {"name": "bench-warm-up"}, "grid": {"inner_ring_speed_rpm": [1000.0, 9000.0], "axial_load_n": [100.0]}}
    warm = spec_from_mapping(warm_doc, "<bench sweep warm-up>")
    chosen = INTEGRATE if method == "integrate" else SOLVE
    walls: dict[int, float] = {}
    for workers in (1, 2):
        client, cluster = open_client(None, workers)
        try:
            with tempfile.TemporaryDirectory() as tmp:
                run_sweep(warm, Path(tmp) / "warm", client=client, method=chosen, progress=False)  # workers up, kernels loaded
                runs = []
                for i in range(max(1, repeats)):
                    outcome = run_sweep(spec, Path(tmp) / f"run{i}", client=client, method=chosen, progress=False)
                    runs.append(outcome.seconds)
                walls[workers] = statistics.median(runs)
        finally:
            client.close()
            cluster.close()
        yield {
            "bench": "sweep",
            "case": "cluster",
            "method": method,
            "workers": workers,
            "points": len(spec.points()),
            "wall_s": round(walls[workers], 4),
            "points_per_s": round(len(spec.points()) / walls[workers], 2),
            "speedup_vs_1_worker": round(walls[1] / walls[workers], 3),
        }
