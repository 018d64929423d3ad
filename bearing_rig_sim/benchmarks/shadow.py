"""Benchmark of shadow mode: does the twin keep up with a 1 kHz bench, and how late is a residual?

A bench run is recorded first from the twin itself (:func:`~bearing_rig_sim.synthetic.twin_bench.
twin_bench_run`: both pulse streams and the load cell at 1 kHz), then fed message by message, as
fast as possible, into a :class:`~bearing_rig_sim.shadow.ShadowTwin`, with its checks every
0.1 s of bench time as the node runs them. One row per case (speed, re-calibration off or on):

* ``rtf``: bench seconds per wall second over the whole run (>= 1: keeps up with the bench);
  ``rtf_min``: the lowest over the ``--repeats`` runs;
* ``message_p50_ms``, ``message_p99_ms``, ``message_max_ms``: wall time to take one message (the
  engine advances on spindle pulses, so those carry the cost);
* ``residual_wait_p50_ms``, ``residual_wait_p99_ms``: bench time from a window's end (its closing
  cage pulse) to the message that releases its residual: the engine runs half a spindle
  revolution behind the latest pulse (speed points are whole-revolution midpoints), plus the
  pulses' own spacing;
* ``residual_latency_p99_ms``: that wait plus the wall time of the releasing message, i.e. how
  long after the window's end a node that keeps up publishes its residual;
* ``windows``, ``messages``, ``bench_s``.

Taken on a quiet machine for the records; the machine's load changes every figure.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Iterator

from bearing_rig_sim.rig.fibre_optic import Pulse
from bearing_rig_sim.shadow import ShadowSettings, ShadowTwin
from bearing_rig_sim.synthetic.twin_bench import Hold, twin_bench_run

CHECK_PERIOD_S = 0.1
"""Bench time between the twin's periodic checks (the node's 10 Hz timer)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench shadow``."""
    parser.add_argument("--rpm", type=float, nargs="+", default=[900.0, 2700.0], help="spindle speeds of the bench runs (rpm)")
    parser.add_argument("--bench-seconds", type=float, default=5.0, help="bench time per run (s), after a 0.5 s ramp from rest")
    parser.add_argument("--repeats", type=int, default=3, help="runs per case; medians are reported")
    parser.add_argument("--recalibrate", choices=["off", "on", "both"], default="both", help="online re-calibration in the cases")


def _percentile(values: list[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Measure each case (see the module docstring)."""
    settings = ShadowSettings.from_yaml()
    modes = {"off": [False], "on": [True], "both": [False, True]}[args.recalibrate]
    warm = ShadowTwin(settings)  # compile (or load) the engine's kernels outside the timing
    warm.drive.engine.advance(10 * warm.drive.engine.time_step)
    for rpm in args.rpm:
        bench = twin_bench_run([Hold(rpm, args.bench_seconds + 0.5)], clock_offset_s=1.7e9)
        events = bench.events()
        span = events[-1][0] - events[0][0]
        for recalibrate in modes:
            rtfs: list[float] = []
            per_message: list[float] = []
            waits: list[float] = []
            latencies: list[float] = []
            windows = 0
            for _ in range(max(1, args.repeats)):
                twin = ShadowTwin(settings.replace(recalibrate=recalibrate))
                per_message.clear()
                waits.clear()
                latencies.clear()
                tick = events[0][0]
                start = time.perf_counter()
                for t, kind, payload in events:
                    while t >= tick:
                        twin.check(tick)
                        tick += CHECK_PERIOD_S
                    t0 = time.perf_counter()
                    if kind == "force":
                        twin.add_force(t, float(payload))  # type: ignore[arg-type]
                        rows = []
                    else:
                        assert isinstance(payload, Pulse)
                        rows = twin.add_pulse(kind, payload)
                    cost = time.perf_counter() - t0
                    per_message.append(cost)
                    for row in rows:
                        wait = t - row.time
                        waits.append(wait)
                        latencies.append(wait + cost)
                wall = time.perf_counter() - start
                rtfs.append(span / wall)
                windows = twin.counts["windows"]
            yield {
                "bench": "shadow",
                "rpm": rpm,
                "recalibrate": recalibrate,
                "bench_s": round(span, 3),
                "messages": len(events),
                "windows": windows,
                "rtf": round(statistics.median(rtfs), 3),
                "rtf_min": round(min(rtfs), 3),
                "message_p50_ms": round(1e3 * _percentile(per_message, 0.5), 4),
                "message_p99_ms": round(1e3 * _percentile(per_message, 0.99), 4),
                "message_max_ms": round(1e3 * max(per_message), 3),
                "residual_wait_p50_ms": round(1e3 * _percentile(waits, 0.5), 3),
                "residual_wait_p99_ms": round(1e3 * _percentile(waits, 0.99), 3),
                "residual_latency_p99_ms": round(1e3 * _percentile(latencies, 0.99), 3),
            }
