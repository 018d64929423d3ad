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

With ``--live`` (``case: "live"``), the node itself, across processes: the bench run is written
as a bag, the shadow node runs as its own process (the session's domain isolation and transport
profile) and ``bearing-rig replay`` feeds it the bag at ``--rate`` times the bench's pace. A probe
in the benchmark's process takes the cage pulses and ``/twin/residual`` with their reception
times (the middleware's ``received_timestamp``). Per rate: ``windows_received`` against
``windows_expected`` (the offline run over the same bag), ``latency_p50_ms`` / ``latency_p99_ms``
/ ``latency_max_ms`` from the reception of a window's closing cage pulse to that of its residual
(the engine's half-revolution wait included; windows given up without a prediction, such as the
last one of the bag, which the engine never passes, are not counted), ``drain_ms`` from the last
pulse to the last residual; the node keeps up at that rate when every window arrives and the latency does not grow.

Taken on a quiet machine for the records; the machine's load changes every figure.
"""

from __future__ import annotations

import argparse
import bisect
import math
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from bearing_rig_sim.benchmarks import percentile, rig_graph
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.shadow import ResidualWindow, ShadowSettings, ShadowTwin
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.synthetic.twin_bench import BenchRun, Hold, twin_bench_run, write_bench_bag

CHECK_PERIOD_S = 0.1
"""Bench time between the twin's periodic checks (the node's 10 Hz timer)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench shadow``."""
    parser.add_argument("--rpm", type=float, nargs="+", default=[900.0, 2700.0], help="spindle speeds of the bench runs (rpm)")
    parser.add_argument("--bench-seconds", type=float, default=5.0, help="bench time per run (s), after a 0.5 s ramp from rest")
    parser.add_argument("--repeats", type=int, default=3, help="runs per case; medians are reported")
    parser.add_argument("--recalibrate", choices=["off", "on", "both"], default="both", help="online re-calibration in the cases")
    parser.add_argument("--live", action="store_true", help="also run the node across processes, fed by bearing-rig replay")
    parser.add_argument("--rate", type=float, nargs="+", default=[1.0, 2.0], help="live: replay rates (bench seconds per wall second)")


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
                    rows: list[ResidualWindow]
                    if kind == "force":
                        twin.add_force(t, float(payload))  # type: ignore[arg-type]  # a decoded float64 field
                        rows = []
                    elif kind == "temperature":
                        twin.add_temperature(t, float(payload))  # type: ignore[arg-type]  # a decoded float64 field
                        rows = []
                    elif kind == "torque":
                        twin.add_torque(t, float(payload))  # type: ignore[arg-type]  # a decoded float64 field
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
                "message_p50_ms": round(1e3 * percentile(per_message, 0.5), 4),
                "message_p99_ms": round(1e3 * percentile(per_message, 0.99), 4),
                "message_max_ms": round(1e3 * max(per_message), 3),
                "residual_wait_p50_ms": round(1e3 * percentile(waits, 0.5), 3),
                "residual_wait_p99_ms": round(1e3 * percentile(waits, 0.99), 3),
                "residual_latency_p99_ms": round(1e3 * percentile(latencies, 0.99), 3),
            }
        if args.live:
            for rate in args.rate:
                yield _live(bench, rpm, rate)


def _take(sub: Any, msgtype: type) -> list[tuple[int, bytes]]:
    """Everything queued on a raw subscription: (reception time ns, bytes)."""
    from bearing_rig_sim.nodes.common import drain

    return [(int(info.get("received_timestamp") or time.time_ns()), raw) for raw, info in drain(sub, msgtype)]


def _live(bench: BenchRun, rpm: float, rate: float) -> dict:
    """One live case (see the module docstring)."""
    from rclpy.node import Node
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    from bearing_rig_msgs.msg import FibreOpticPulse, ShadowResidual
    from bearing_rig_sim.interfaces import CAGE_PULSES, TWIN_RESIDUAL
    from bearing_rig_sim.session.processes import NodeProcess, NodeSpec, node_command, stop_all
    from bearing_rig_sim.session.recorder import header_stamp_ns
    from bearing_rig_sim.shadow.offline import shadow_bag

    work = Path(tempfile.mkdtemp(prefix="bearing-rig-bench-shadow-"))
    bag = write_bench_bag(bench, work / "bench")
    expected = shadow_bag(bag, None).counts["windows"]
    shadow = NodeProcess("shadow", [*node_command(NodeSpec("shadow", "bearing-rig-shadow")), "--autostart"], work / "shadow.log")
    replay = NodeProcess(
        "replay",
        [sys.executable, "-m", "bearing_rig_sim.cli", "replay", str(bag), "--rate", str(rate), "--wait-for-subscribers", "--delay", "30", "--quiet"],
        work / "replay.log",
    )
    pulses: list[tuple[int, bytes]] = []
    residuals: list[tuple[int, bytes]] = []
    with rig_graph(work) as graph:
        try:
            shadow.start(graph.env)
            probe = graph.join(lambda context: Node("bench_shadow_probe", context=context))
            deep = QoSProfile(depth=10000, reliability=ReliabilityPolicy.BEST_EFFORT)
            reliable = QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
            cage_sub = probe.create_subscription(FibreOpticPulse, CAGE_PULSES.name, lambda _m: None, deep, raw=True)
            residual_sub = probe.create_subscription(ShadowResidual, TWIN_RESIDUAL.name, lambda _m: None, reliable, raw=True)

            def pump(seconds: float) -> None:
                until = time.monotonic() + seconds
                while time.monotonic() < until:
                    if shadow.poll() is not None:
                        raise RigError(f"bench shadow: {shadow.describe_exit()}")
                    pulses.extend(_take(cage_sub, FibreOpticPulse))
                    residuals.extend(_take(residual_sub, ShadowResidual))
                    time.sleep(0.002)

            deadline = time.monotonic() + 60.0
            while probe.count_publishers(TWIN_RESIDUAL.name) == 0:
                if time.monotonic() > deadline:
                    raise RigError(f"bench shadow: the shadow node did not come up within 60 s; log {shadow.log_path}")
                pump(0.1)
            replay.start(graph.env)
            while replay.poll() is None:
                pump(0.05)
            pump(2.0)
            probe.destroy_node()
        finally:
            stop_all([shadow, replay])
    from rclpy.serialization import deserialize_message

    arrivals = sorted((stamp, at) for at, raw in pulses if (stamp := header_stamp_ns(raw)) is not None)
    stamps = [s for s, _ in arrivals]
    latencies = []
    for at, raw in residuals:
        stamp = header_stamp_ns(raw)
        if stamp is None or math.isnan(deserialize_message(raw, ShadowResidual).predicted_slip):
            continue  # a window given up (no prediction) is not a residual that came late
        k = bisect.bisect_left(stamps, stamp - 2000)
        if k < len(stamps) and abs(stamps[k] - stamp) <= 2000:
            latencies.append((at - arrivals[k][1]) * 1e-6)
    return {
        "bench": "shadow",
        "case": "live",
        "rpm": rpm,
        "rate": rate,
        "windows_expected": expected,
        "windows_received": len(residuals),
        "latency_p50_ms": round(percentile(latencies, 0.5), 3),
        "latency_p99_ms": round(percentile(latencies, 0.99), 3),
        "latency_max_ms": round(max(latencies), 3) if latencies else None,
        "drain_ms": round((residuals[-1][0] - max(at for _s, at in arrivals)) * 1e-6, 3) if residuals and arrivals else None,
    }
