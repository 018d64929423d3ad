"""Benchmark of ``bearing-rig replay``: how late, on this host, do replayed messages leave?

A bench-like bag (both pulse streams, 4 strips, 2 % slip; no ``/clock``, so the replay makes one
at 100 Hz of bag time) is written once and replayed, as its own process (the session's domain
isolation and transport profile), at each ``--rate`` and ``--repeats`` times. A probe in the
benchmark's process takes every pulse and ``/clock`` with the middleware's timestamps. The
replay's schedule starts when its first ``/clock`` has been published (``w0``; see
:mod:`bearing_rig_sim.replay.player`), so a message of bag offset ``d`` is due at
``w0 + d / rate`` and its lateness is its ``source_timestamp`` minus that, ``w0`` taken as the
first ``/clock``'s ``source_timestamp`` (it precedes ``w0`` by that publish's own time, so the
figures include it). One row per rate, medians over the repeats:

* ``late_p50_ms``, ``late_p90_ms``, ``late_p99_ms``, ``late_max_ms``: lateness of the pulses as
  published (``late_max_ms`` the largest of the repeats);
* ``transit_p50_ms``, ``transit_p99_ms``: reception minus publication (the middleware's
  ``received_timestamp - source_timestamp``, loopback);
* ``early_ms``: the most any pulse left before its time, 0 when none did (the replay's
  contract; the system and monotonic clocks may part by their slewing, well under 1 ms);
* ``received``, ``published``: pulses taken against the bag's.

The figures are the host's, at its load: a busy host holds the player back now and then and the
replay then catches up (absolute deadlines), which shows in the tail, not in the median.
"""

from __future__ import annotations

import argparse
import math
import shutil
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from bearing_rig_sim.bags.cdr import header_stamp_ns
from bearing_rig_sim.benchmarks import percentile, rig_graph
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.errors import RigError


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench replay``."""
    parser.add_argument("--rate", type=float, nargs="+", default=[1.0, 2.0], help="replay rates (bag seconds per wall second)")
    parser.add_argument("--seconds", type=float, default=10.0, help="length of the bag (s of bench time)")
    parser.add_argument("--rpm", type=float, default=2700.0, help="spindle speed of the bag (rpm)")
    parser.add_argument("--repeats", type=int, default=3, help="replays per rate; medians are reported")


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Measure each rate (see the module docstring).

    Raises:
        RigError: an option out of its range (named), a replay that failed or reached the probe
            without its first ``/clock``.
    """
    for name, value in (("--seconds", args.seconds), ("--rpm", args.rpm), *(("--rate", r) for r in args.rate)):
        if not (math.isfinite(value) and value > 0.0):
            raise RigError(f"bench replay: {name} must be a finite number > 0, got {value!r}")
    if args.repeats < 1:
        raise RigError(f"bench replay: --repeats must be >= 1, got {args.repeats}")
    work = Path(tempfile.mkdtemp(prefix="bearing-rig-bench-replay-"))
    try:
        yield from _rows(args, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def _rows(args: argparse.Namespace, work: Path) -> Iterator[dict]:
    from bearing_rig_sim.synthetic.bench import BenchScenario, write_bench_bag

    speed = rpm_to_rad_s(args.rpm)
    scenario = BenchScenario(args.seconds, lambda t: t * 0.0 + speed, lambda t: t * 0.0 + 2.0)
    bag = write_bench_bag(work / "bench", scenario)
    for rate in args.rate:
        runs = [_replay(bag, rate, work) for _ in range(args.repeats)]
        row: dict[str, Any] = {"bench": "replay", "rate": rate, "seconds": args.seconds, "rpm": args.rpm}
        for key in ("late_p50_ms", "late_p90_ms", "late_p99_ms", "transit_p50_ms", "transit_p99_ms"):
            row[key] = round(statistics.median(r[key] for r in runs), 3)
        row["late_max_ms"] = round(max(r["late_max_ms"] for r in runs), 3)
        row["early_ms"] = round(max(r["early_ms"] for r in runs), 3)
        row["received"] = min(r["received"] for r in runs)
        row["published"] = runs[0]["published"]
        yield row


def _replay(bag: Path, rate: float, work: Path) -> dict[str, Any]:
    """One replay at ``rate``, measured by a probe (see the module docstring)."""
    from rclpy.node import Node
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    from bearing_rig_msgs.msg import FibreOpticPulse
    from bearing_rig_sim.bags import open_bag
    from bearing_rig_sim.interfaces import CAGE_PULSES, CLOCK, SPINDLE_PULSES
    from bearing_rig_sim.nodes.common import drain
    from bearing_rig_sim.session.processes import NodeProcess, stop_all

    with open_bag(bag) as reader:
        first_ns = reader.start_ns
        published = sum(reader.topics[t.name].message_count for t in (SPINDLE_PULSES, CAGE_PULSES))
    replay = NodeProcess(
        "replay",
        [sys.executable, "-m", "bearing_rig_sim.cli", "replay", str(bag), "--rate", str(rate), "--wait-for-subscribers", "--delay", "30", "--quiet"],
        work / "replay.log",
    )
    pulses: list[tuple[int, int, bytes]] = []
    clocks: list[tuple[int, int | None]] = []  # (sent, the /clock's time: the message's leading Time)
    with rig_graph(work) as graph:
        try:
            probe = graph.join(lambda context: Node("bench_replay_probe", context=context))
            deep = QoSProfile(depth=100000, reliability=ReliabilityPolicy.BEST_EFFORT)
            subs = [probe.create_subscription(FibreOpticPulse, topic.name, lambda _m: None, deep, raw=True) for topic in (SPINDLE_PULSES, CAGE_PULSES)]
            clock_sub = probe.create_subscription(
                Clock, CLOCK.name, lambda _m: None, QoSProfile(depth=100000, reliability=ReliabilityPolicy.RELIABLE), raw=True
            )

            def take() -> None:
                for sub in subs:
                    pulses.extend((int(info["source_timestamp"]), int(info["received_timestamp"]), raw) for raw, info in drain(sub, FibreOpticPulse))
                clocks.extend((int(info["source_timestamp"]), header_stamp_ns(raw)) for raw, info in drain(clock_sub, Clock))

            replay.start(graph.env)
            while replay.poll() is None:
                take()
                time.sleep(0.01)
            take()
            probe.destroy_node()
            if replay.poll() != 0:
                raise RigError(f"bench replay: {replay.describe_exit()}")
        finally:
            stop_all([replay])
    start = [sent for sent, value in clocks if value == first_ns]
    if not start:
        raise RigError(f"bench replay: the replay's first {CLOCK.name} did not reach the probe (discovery); run again")
    late, transit = [], []
    for sent, received, raw in pulses:
        stamp = header_stamp_ns(raw)
        if stamp is None:
            continue
        late.append((sent - start[0] - (stamp - first_ns) / rate) * 1e-6)
        transit.append((received - sent) * 1e-6)
    if not late:
        raise RigError("bench replay: no pulse reached the probe")
    return {
        "late_p50_ms": percentile(late, 0.5),
        "late_p90_ms": percentile(late, 0.9),
        "late_p99_ms": percentile(late, 0.99),
        "late_max_ms": max(late),
        "early_ms": max(0.0, -min(late)),
        "transit_p50_ms": percentile(transit, 0.5),
        "transit_p99_ms": percentile(transit, 0.99),
        "received": len(late),
        "published": published,
    }
