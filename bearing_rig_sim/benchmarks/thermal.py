"""Benchmark of the thermal coupling's cost: the reduced engine in 1 ms chunks with the
bearing's thermal network attached (:class:`~bearing_rig_sim.thermal.coupling.ThermalCoupling`).

``bearing-rig bench thermal --json`` prints one JSON object per operating point with
``engine_s`` and ``thermal_s`` (wall time in the engine's chunks and in the coupling's calls over
``--sim-seconds`` of simulated time, the run with the least engine time of ``--repeats``),
``rtf`` (simulated seconds per wall-clock second of both) and ``thermal_cost_pct`` =
100 thermal_s / engine_s, the share of a step's time the thermal coupling adds, split into
``network_cost_pct`` (the thermal state: the network's steps, the heat split, the retuned
resistances) and ``table_build_pct`` (the slices of the traction tables the grid builds ahead of
the lubricant's temperature, :class:`~bearing_rig_sim.thermal.coupling.TractionTableGrid`: a
cost only while a table is being built, which each run here is from its start). Both are timed
inside the same run, so other processes on a shared machine load them alike.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Iterator

from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters
from bearing_rig_sim.thermal.bearing import ThermalConfig, heat_sources
from bearing_rig_sim.thermal.coupling import ThermalCoupling

POINTS: tuple[tuple[float, float], ...] = ((900, 100), (2700, 100), (9000, 700))
CHUNK_S = 1e-3
"""The simulator's chunk, s."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench thermal``."""
    parser.add_argument("--sim-seconds", type=float, default=2.0, help="simulated time per run (s)")
    parser.add_argument("--repeats", type=int, default=3, help="runs per point; the least disturbed is reported")


def _times(engine: BearingDynamics, coupling: ThermalCoupling, sim_s: float) -> tuple[float, float, float]:
    """Wall time (s) in the engine, in the coupling, and in the coupling's table building."""
    n = int(round(sim_s / CHUNK_S))
    t_engine = t_thermal = 0.0
    clock = time.perf_counter
    building = [0.0]
    grid = coupling.grid
    if grid is not None:
        work = grid.work

        def timed_work() -> bool:
            t = clock()
            done = work()
            building[0] += clock() - t
            return done

        grid.work = timed_work  # type: ignore[method-assign]  # the bench times the grid's slices in place
    for _ in range(n):
        t0 = clock()
        engine.advance(CHUNK_S)
        t1 = clock()
        coupling.advance(CHUNK_S)
        t_engine += t1 - t0
        t_thermal += clock() - t1
    return t_engine, t_thermal, building[0]


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Engine and thermal time at each operating point."""
    params = BearingParameters.calibrated()
    cfg = ThermalConfig.from_yaml()
    warm = BearingDynamics(params)
    warm.advance(10 * warm.time_step)
    ThermalCoupling(warm, cfg, interval=warm.time_step).advance(warm.time_step)
    heat_sources(warm)  # compile the heat split (the coupling skips it at rest; else the first run pays 30-40 ms)
    for rpm, load in POINTS:
        engine = BearingDynamics(params)
        runs = []
        for _ in range(max(1, args.repeats)):
            engine.initialise(rpm_to_rad_s(rpm), load)
            runs.append(_times(engine, ThermalCoupling(engine, cfg), args.sim_seconds))
        t_engine, t_thermal, t_tables = min(runs)
        yield {
            "bench": "thermal",
            "rpm": rpm,
            "axial_load_n": load,
            "sim_s": args.sim_seconds,
            "engine_s": round(t_engine, 4),
            "thermal_s": round(t_thermal, 5),
            "rtf": round(args.sim_seconds / (t_engine + t_thermal), 3),
            "thermal_cost_pct": round(100.0 * t_thermal / t_engine, 2),
            "network_cost_pct": round(100.0 * (t_thermal - t_tables) / t_engine, 2),
            "table_build_pct": round(100.0 * t_tables / t_engine, 2),
        }
