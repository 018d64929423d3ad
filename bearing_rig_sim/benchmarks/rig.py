"""Benchmark of the running rig: the three nodes as a session runs them, in real time on loopback.

``bearing-rig bench rig [--seconds 60] [--speed-rpm 1500] [--load-n 100] [--warmup 5]`` starts the
simulator, load controller and monitor as separate processes (private domain, the session's
transport profile and niceness: :mod:`bearing_rig_sim.session.processes`), commands the speed and
load, waits ``--warmup`` s (ramp, first slip windows), then measures for ``--seconds`` of wall
time from a probe in the benchmark's own process. Rows (one JSON object each):

* ``case: "simulator"``: achieved real-time factor ``rtf_median`` / ``rtf_min`` over 1 s wall
  windows, from ``/clock`` (sim time advanced per window / 1 s, the clock's sim time at each edge
  being the stamp of the last ``/clock`` received before it); ``overruns`` counted by the
  simulator during the window (from ``/rig/truth``); its own reported factor ``truth_rtf_median``.
* ``case: "speeds"``: ``/rig/speeds`` messages received whose stamps lie in the window's sim-time
  span, against the number the configured rate gives for that span (``speeds_rate_hz``, at most
  one per chunk); ``loss_pct``; ``rate_hz`` received per wall second.
* ``case: "latency"``: pulse-to-status latency of the monitor. Definition: a slip window ends at
  a cage pulse (the monitor stamps the window's status with it) and can be computed once that
  cage pulse and the first spindle pulse at or after it have arrived; the latency is the arrival
  of the first status carrying the window's stamp minus the arrival of the later of those two
  pulses. Arrivals are the middleware's reception times (``received_timestamp`` of the message
  info, system clock, ns) in the probe's process, so the probe's own scheduling does not count.
  Re-publications of a window's status by the monitor's timer are not counted again.
  ``p50_ms``, ``p99_ms``, ``max_ms`` over all windows; ``on_change_*`` over those whose state
  differs from the previous status's. Target: p99 <= 5 ms.
* ``case: "cpu"``, one row per process (``node``): user + system CPU time over the window from
  psutil (the probe's from ``os.times``), as ``cpu_pct`` of one core; and
  ``node: "nodes_total"``, the three nodes together, against ``target_pct`` 100 (the rig within
  one core at 1 kHz).

The nodes start with ``--autostart`` (each configures and activates itself, as the session's
lifecycle manager would have them), so the window measures the running rig only.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from bisect import bisect_left, bisect_right
from collections import OrderedDict
from pathlib import Path
from typing import Any
from collections.abc import Iterator

import numpy as np

from bearing_rig_sim.benchmarks import rig_graph
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import (
    AXIAL_LOAD_SETPOINT,
    AXIAL_LOAD_STATE,
    CAGE_PULSES,
    CLOCK,
    SLIP_STATUS,
    SPEEDS,
    SPINDLE_COMMAND,
    SPINDLE_PULSES,
    TRUTH,
)
from bearing_rig_sim.session.processes import (
    NODES,
    NodeProcess,
    node_command,
    stop_all,
)
from bearing_rig_sim.session.readiness import not_ready
from bearing_rig_sim.session.recorder import header_stamp_ns

PULSES_KEPT = 20000
"""Cage pulse arrivals kept for matching statuses (minutes of pulses)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench rig``."""
    parser.add_argument("--seconds", type=float, default=60.0, help="measured wall time, s (default 60)")
    parser.add_argument("--speed-rpm", type=float, default=1500.0, help="inner-ring speed held during the run (default 1500)")
    parser.add_argument("--load-n", type=float, default=100.0, help="axial load held during the run, N (default 100)")
    parser.add_argument("--warmup", type=float, default=5.0, help="wall time between the commands and the measurement, s (default 5)")
    parser.add_argument("--startup-timeout", type=float, default=60.0, help="longest wait for the nodes to come up, s")


class _Probe:
    """The benchmark's ROS side: commands, and queues of the measured topics taken with their
    reception times (a node that is not spun; its queues are taken by :meth:`take`)."""

    def __init__(self, context: Any) -> None:
        from bearing_rig_msgs.msg import AxialLoadState, FibreOpticPulse, SimulatorTruth, SlipStatus, SpindleCommand
        from rclpy.node import Node
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        from rosgraph_msgs.msg import Clock
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64

        from bearing_rig_sim.nodes.common import RELIABLE_QOS, STATUS_QOS

        self.node = Node("bench_rig_probe", context=context)
        self.tap = Node("bench_rig_probe_queues", context=context)
        best = QoSProfile(depth=5000, reliability=ReliabilityPolicy.BEST_EFFORT)
        reliable = QoSProfile(depth=5000, reliability=ReliabilityPolicy.RELIABLE)
        latched = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.types = {
            CLOCK.name: Clock,
            SPEEDS.name: JointState,
            CAGE_PULSES.name: FibreOpticPulse,
            SPINDLE_PULSES.name: FibreOpticPulse,
            SLIP_STATUS.name: SlipStatus,
            TRUTH.name: SimulatorTruth,
            AXIAL_LOAD_STATE.name: AxialLoadState,
        }
        qos = {CLOCK.name: reliable, SLIP_STATUS.name: latched, AXIAL_LOAD_STATE.name: reliable}
        self.subs = {name: self.tap.create_subscription(msgtype, name, lambda _m: None, qos.get(name, best), raw=True) for name, msgtype in self.types.items()}
        self.spindle = self.node.create_publisher(SpindleCommand, SPINDLE_COMMAND.name, STATUS_QOS)
        self.setpoint = self.node.create_publisher(Float64, AXIAL_LOAD_SETPOINT.name, RELIABLE_QOS)
        self._command_types = (SpindleCommand, Float64)

    def take(self) -> dict[str, list[tuple[int, bytes]]]:
        """Everything queued: (reception time ns, serialized message) per topic."""
        from bearing_rig_sim.nodes.common import drain

        taken: dict[str, list[tuple[int, bytes]]] = {}
        for name, sub in self.subs.items():
            items = taken.setdefault(name, [])
            for raw, info in drain(sub, self.types[name]):
                items.append((int(info.get("received_timestamp") or time.time_ns()), raw))
        return taken

    def missing(self, seen: dict[str, int]) -> dict[str, str]:
        """Which node is not up yet, by the session's rule
        (:func:`~bearing_rig_sim.session.readiness.not_ready`)."""
        return not_ready(
            clock_seen=bool(seen.get(CLOCK.name)),
            load_state_seen=bool(seen.get(AXIAL_LOAD_STATE.name)),
            subscribers=lambda topic: self.node.count_subscribers(topic) - (1 if topic in self.subs else 0),
            publishers=self.node.count_publishers,
        )

    def command(self, speed_rad_s: float, load_n: float) -> None:
        spindle_type, float_type = self._command_types
        command = spindle_type()
        command.target_speed = speed_rad_s
        command.ramp_time = 1.0
        self.spindle.publish(command)
        self.setpoint.publish(float_type(data=load_n))

    def close(self) -> None:
        self.tap.destroy_node()
        self.node.destroy_node()


class _Series:
    """What the probe collected, with reception times (ns, system clock)."""

    def __init__(self) -> None:
        self.clock: list[tuple[int, int]] = []
        """(received, stamp) of /clock."""
        self.speeds: list[tuple[int, int]] = []
        self.pulses: OrderedDict[int, int] = OrderedDict()
        """cage pulse stamp -> received."""
        self.spindle: list[tuple[int, int]] = []
        """(stamp, received) of spindle pulses, in arrival order."""
        self.statuses: list[tuple[int, int, int]] = []
        """(received, stamp, state)."""
        self.truth: list[tuple[int, float, int]] = []
        """(received, real-time factor, overruns)."""
        self.seen: dict[str, int] = {}

    def add(self, taken: dict[str, list[tuple[int, bytes]]], types: dict[str, type]) -> None:
        from rclpy.serialization import deserialize_message

        for name, items in taken.items():
            self.seen[name] = self.seen.get(name, 0) + len(items)
            for received, raw in items:
                if name == CLOCK.name:
                    self.clock.append((received, header_stamp_ns(raw) or 0))
                elif name == SPEEDS.name:
                    self.speeds.append((received, header_stamp_ns(raw) or 0))
                elif name == SPINDLE_PULSES.name:
                    self.spindle.append((header_stamp_ns(raw) or 0, received))
                elif name == CAGE_PULSES.name:
                    self.pulses[header_stamp_ns(raw) or 0] = received
                    while len(self.pulses) > PULSES_KEPT:
                        self.pulses.popitem(last=False)
                elif name == SLIP_STATUS.name:
                    msg = deserialize_message(raw, types[name])
                    self.statuses.append((received, header_stamp_ns(raw) or 0, int(msg.state)))
                elif name == TRUTH.name:
                    msg = deserialize_message(raw, types[name])
                    self.truth.append((received, float(msg.real_time_factor), int(msg.overruns)))


def _sim_at(clock: list[tuple[int, int]], wall_ns: int) -> int | None:
    """Sim time (ns) of the last /clock received at or before ``wall_ns``."""
    index = bisect_right([r for r, _ in clock], wall_ns) - 1
    return clock[index][1] if index >= 0 else None


def _percentile(values: list[float], q: float) -> float | None:
    return round(float(np.percentile(values, q)), 3) if values else None


def _configured_speed_rate() -> float:
    """The simulator's configured /rig/speeds rate, Hz of sim time (at most one per chunk)."""
    from bearing_rig_sim.simulation.settings import shipped_parameters

    params = shipped_parameters()
    return min(float(params["speeds_rate_hz"]), 1.0 / float(params["chunk_s"]))


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Start the nodes, measure, stop them; yield the rows of the module documentation."""
    if not args.seconds > 0 or not args.warmup >= 0:
        raise RigError(f"bench rig: --seconds must be > 0 and --warmup >= 0, got {args.seconds}, {args.warmup}")
    logs = Path(tempfile.mkdtemp(prefix="bearing-rig-bench-rig-"))
    children = [NodeProcess(name, node_command(spec) + ["--autostart"], logs / f"{name}.log") for name, spec in NODES.items()]
    probe = None
    series = _Series()
    with rig_graph(logs) as graph:
        try:
            for child in children:
                child.start(graph.env)
            probe = graph.join(_Probe)

            def pump(until: float) -> None:
                while time.monotonic() < until:
                    for child in children:
                        if child.poll() is not None:
                            raise RigError(f"bench rig: {child.describe_exit()}")
                    series.add(probe.take(), probe.types)
                    time.sleep(0.01)

            deadline = time.monotonic() + args.startup_timeout
            while missing := probe.missing(series.seen):
                if time.monotonic() > deadline:
                    name, what = next(iter(missing.items()))
                    raise RigError(f"bench rig: the {name} node did not come up within {args.startup_timeout:g} s ({what}); log {logs / (name + '.log')}")
                pump(time.monotonic() + 0.1)
            probe.command(rpm_to_rad_s(args.speed_rpm), args.load_n)
            pump(time.monotonic() + args.warmup)
            cpu_start = {c.name: c.cpu_seconds() for c in children}
            own_start = os.times()
            wall_start, mono_start = time.time_ns(), time.monotonic()
            pump(mono_start + args.seconds)
            wall_end, mono_end = time.time_ns(), time.monotonic()
            own_end = os.times()
            cpu_end = {c.name: c.cpu_seconds() for c in children}
            series.add(probe.take(), probe.types)
        finally:
            if probe is not None:
                probe.close()
            stop_all(children)
    duration = mono_end - mono_start
    yield from _rows(args, series, wall_start, wall_end, duration)
    total: float | None = 0.0
    for name in NODES:
        start, end = cpu_start[name], cpu_end[name]
        used = None if start is None or end is None else end - start
        total = None if used is None or total is None else total + used
        yield {"bench": "rig", "case": "cpu", "node": name, "cpu_pct": None if used is None else round(100.0 * used / duration, 1)}
    yield {
        "bench": "rig",
        "case": "cpu",
        "node": "nodes_total",
        "cpu_pct": None if total is None else round(100.0 * total / duration, 1),
        "target_pct": 100.0,
    }
    own = (own_end.user + own_end.system) - (own_start.user + own_start.system)
    yield {"bench": "rig", "case": "cpu", "node": "bench_probe", "cpu_pct": round(100.0 * own / duration, 1)}


def _rows(args: argparse.Namespace, series: _Series, wall_start: int, wall_end: int, duration: float) -> Iterator[dict]:
    """The simulator, speeds and latency rows."""
    clock = sorted(series.clock)
    edges = list(range(wall_start, wall_end + 1, 1_000_000_000))
    rtf = []
    for a, b in zip(edges, edges[1:]):
        s0, s1 = _sim_at(clock, a), _sim_at(clock, b)
        if s0 is not None and s1 is not None:
            rtf.append((s1 - s0) / (b - a))
    truth = [t for t in series.truth if wall_start <= t[0] <= wall_end]
    yield {
        "bench": "rig",
        "case": "simulator",
        "seconds": round(duration, 2),
        "speed_rpm": args.speed_rpm,
        "load_n": args.load_n,
        "rtf_median": round(statistics.median(rtf), 4) if rtf else None,
        "rtf_min": round(min(rtf), 4) if rtf else None,
        "rtf_windows": len(rtf),
        "overruns": (truth[-1][2] - truth[0][2]) if len(truth) > 1 else None,
        "truth_rtf_median": round(statistics.median(t[1] for t in truth), 4) if truth else None,
    }

    sim_start, sim_end = _sim_at(clock, wall_start), _sim_at(clock, wall_end)
    rate = _configured_speed_rate()
    if sim_start is None or sim_end is None or sim_end <= sim_start:
        yield {"bench": "rig", "case": "speeds", "error": f"no {CLOCK.name} during the window"}
    else:
        stamps = {s for _, s in series.speeds if sim_start < s <= sim_end}
        expected = int(round((sim_end - sim_start) * 1e-9 * rate))
        yield {
            "bench": "rig",
            "case": "speeds",
            "configured_rate_hz": rate,
            "expected": expected,
            "received": len(stamps),
            "loss_pct": round(100.0 * max(0, expected - len(stamps)) / expected, 3) if expected else None,
            "rate_hz": round(len(stamps) / duration, 1),
        }

    latencies, on_change = [], []
    previous_state = None
    seen_stamps: set[int] = set()
    spindle = sorted(series.spindle)
    spindle_stamps = [s for s, _ in spindle]
    for received, stamp, state in sorted(series.statuses):
        changed = previous_state is not None and state != previous_state
        previous_state = state
        if stamp in seen_stamps:
            continue  # a timer re-publication of a window already reported
        seen_stamps.add(stamp)
        if not wall_start <= received <= wall_end:
            continue
        cage = series.pulses.get(stamp)
        k = bisect_left(spindle_stamps, stamp)
        if cage is None or k >= len(spindle):
            continue
        # The window closes when both its closing cage pulse and the next spindle pulse are in.
        completed = max(cage, spindle[k][1])
        latency = (received - completed) * 1e-6
        latencies.append(latency)
        if changed:
            on_change.append(latency)
    in_window = sum(1 for r, _, _ in series.statuses if wall_start <= r <= wall_end)
    yield {
        "bench": "rig",
        "case": "latency",
        "statuses": in_window,
        "matched": len(latencies),
        "p50_ms": _percentile(latencies, 50),
        "p99_ms": _percentile(latencies, 99),
        "max_ms": round(max(latencies), 3) if latencies else None,
        "on_change": len(on_change),
        "on_change_p50_ms": _percentile(on_change, 50),
        "on_change_p99_ms": _percentile(on_change, 99),
        "target_p99_ms": 5.0,
    }
