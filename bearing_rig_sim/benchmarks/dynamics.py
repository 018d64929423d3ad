"""Benchmark of the dynamics engine: real-time factor per operating point and model.

``bearing-rig bench dynamics --json`` prints one JSON object per line and operating point with
keys ``rpm``, ``axial_load_n``, ``radial_load_n``, ``model``, ``dt_s``, ``sim_s``, ``wall_s``, ``rtf`` (simulated
seconds per wall-clock second, median of ``--repeats`` runs, compile time excluded),
``rtf_min``, ``compile_s`` (first-call JIT compilation or cache load) and ``cage_speed_rad_s``.
Model ``exudyn`` is the reference: Exudyn's rigid 6-DOF ball bearing
(:mod:`.exudyn_bearing`) at :data:`EXUDYN_POINT`, whose row adds ``reduced_over_exudyn``, the
reduced engine's rtf at that point over Exudyn's, both measured in the same run.
Run on one core: the engine is single-threaded.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Iterator

from bearing_rig_sim.benchmarks.exudyn_bearing import run_exudyn
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.config import BEARING_MODELS
from bearing_rig_sim.dynamics.models import model_parameters
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters

POINTS: tuple[tuple[float, float], ...] = ((900, 100), (2700, 100), (5000, 300), (9000, 700), (9000, 50))
"""Operating points (rpm, N) required by issue 3."""
RADIAL_POINTS: tuple[tuple[float, float, float], ...] = ((900, 163, 500), (5000, 300, 300))
"""Operating points (rpm, axial N, radial N) under combined load (reduced model only: each
ball's loads from the ring's radial balance every step)."""
EXUDYN_POINT: tuple[float, float] = (900, 100)
"""Operating point (rpm, axial N) of the Exudyn comparison."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench dynamics``."""
    parser.add_argument("--sim-seconds", type=float, default=1.0, help="simulated time per run of the reduced model (s)")
    parser.add_argument("--stiff-sim-seconds", type=float, default=0.02, help="simulated time per run of the stiff reference (s)")
    parser.add_argument("--exudyn-sim-seconds", type=float, default=0.02, help="simulated time per run of Exudyn's bearing (s)")
    parser.add_argument("--repeats", type=int, default=3, help="runs per point; the median is reported")
    parser.add_argument("--models", nargs="+", default=["reduced", "stiff", "exudyn"], choices=["reduced", "stiff", "exudyn"])
    parser.add_argument("--uncalibrated", action="store_true", help="use the clean bearing data instead of the bench calibration")
    parser.add_argument("--bearing-model", choices=BEARING_MODELS, default="bench", help="the named bearing model (default bench; paper: the paper's own)")


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Measure the real-time factor of each model at each operating point."""
    params = model_parameters(args.bearing_model, calibrated=not args.uncalibrated)
    reduced_rtf: float | None = None
    for model in args.models:
        if model == "exudyn":
            yield _exudyn_row(params, args, reduced_rtf)
            continue
        sim_s = args.sim_seconds if model == "reduced" else args.stiff_sim_seconds
        t0 = time.perf_counter()
        warm = BearingDynamics(params, model=model)
        warm.advance(10 * warm.time_step)
        compile_s = time.perf_counter() - t0
        points = [(rpm, load, 0.0) for rpm, load in POINTS]
        if model == "reduced":
            points += list(RADIAL_POINTS)
        for rpm, load, radial in points:
            engine = BearingDynamics(params, model=model)
            rtfs = []
            for _ in range(max(1, args.repeats)):
                engine.initialise(rpm_to_rad_s(rpm), load, radial_load=radial)
                start = time.perf_counter()
                avg = engine.advance(sim_s)
                wall = time.perf_counter() - start
                rtfs.append(avg.duration / wall)
            rtf = statistics.median(rtfs)
            if model == "reduced" and (rpm, load, radial) == (*EXUDYN_POINT, 0.0):
                reduced_rtf = rtf
            yield {
                "bench": "dynamics",
                "rpm": rpm,
                "axial_load_n": load,
                "radial_load_n": radial,
                "model": model,
                "dt_s": engine.time_step,
                "sim_s": sim_s,
                "wall_s": round(sim_s / rtf, 6),
                "rtf": round(rtf, 3),
                "rtf_min": round(min(rtfs), 3),
                "compile_s": round(compile_s, 3),
                "cage_speed_rad_s": round(avg.cage_speed, 6),
            }


def _exudyn_row(params: BearingParameters, args: argparse.Namespace, reduced_rtf: float | None) -> dict:
    """Time Exudyn's rigid ball bearing at :data:`EXUDYN_POINT` (median of ``--repeats`` runs)."""
    rpm, load = EXUDYN_POINT
    runs = [run_exudyn(params, rpm_to_rad_s(rpm), load, args.exudyn_sim_seconds) for _ in range(max(1, args.repeats))]
    rtf = statistics.median(r.rtf for r in runs)
    row = {
        "bench": "dynamics",
        "rpm": rpm,
        "axial_load_n": load,
        "radial_load_n": 0.0,
        "model": "exudyn",
        "sim_s": args.exudyn_sim_seconds,
        "wall_s": round(args.exudyn_sim_seconds / rtf, 6),
        "rtf": round(rtf, 5),
        "rtf_min": round(min(r.rtf for r in runs), 5),
        "cage_speed_rad_s": round(runs[-1].cage_speed_rad_s, 6),
    }
    if reduced_rtf is not None:
        row["reduced_over_exudyn"] = round(reduced_rtf / rtf, 1)
    return row


def main() -> None:  # pragma: no cover - convenience entry point
    """``python -m bearing_rig_sim.benchmarks.dynamics``: print JSON lines."""
    import json

    parser = argparse.ArgumentParser(description=__doc__)
    add_arguments(parser)
    parser.add_argument("--json", action="store_true")
    for row in run(parser.parse_args()):
        print(json.dumps(row))


if __name__ == "__main__":  # pragma: no cover
    main()
