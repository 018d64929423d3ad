"""Benchmark of the recorder and the bag reader.

``bearing-rig bench bags --json`` (or ``python -m bearing_rig_sim.benchmarks.bags --json``)
prints one JSON object per line:

* ``case: "record"``: recorder throughput for speeds-sized messages (``sensor_msgs/JointState``,
  2 joints, raw CDR bytes with the Fast-CDR padding a raw subscription delivers, so the padding
  trim is included), zstd chunks, ``--messages`` per run, median of ``--repeats`` runs, closing
  the bag included: ``msgs_per_s`` (median), ``msgs_per_s_min``, ``target_msgs_per_s`` (20000),
  ``bytes_per_msg`` on disk.
* ``case: "read"``, one per bag length: a bag of the rig's steady traffic (speeds 1 kHz, both
  pulse trains, truth 100 Hz) is recorded (``write_s``), then read back in full, every message
  decoded, in a fresh process: ``read_s``, ``read_msgs_per_s``, ``peak_rss_mb`` (peak resident
  memory of that process) and ``baseline_rss_mb`` (after imports and opening the bag, before
  reading). The long bag is one hour (``--quick``: 4 minutes); the short one a quarter of it:
  equal peaks show that memory does not grow with the bag's length.
* ``case: "analyse"``, one per bag length (each analysis ``--repeats`` times, medians): a bag at the rig's rates (speeds 1 kHz, truth 100 Hz
  (:func:`rig_traffic`, steady content), fibre-optic pulses of 4 strips per shaft with 1 us
  jitter and slip status at 10 Hz (:func:`program_traffic`: the validation program's speeds,
  900-2700 rpm, held ``HOLD_S`` each with 1 s STEP ramps and a decaying slip transient after
  each step, over and over) is analysed offline as ``bearing-rig analyze`` does, in a fresh
  process: ``analyse_s`` (the monitor run over every pulse, the series and CSV files), of it
  ``monitor_s`` (inside the monitor's own ``add_pulse``, ``check`` and ``status``: its slip
  windows, trailing slopes and verdicts; null when the pulse path runs compiled, where no timer
  reaches inside it), ``compiled`` and ``compiled_reason`` (:func:`bearing_rig_sim.compiled.status`:
  whether the pulse path ran compiled, and why), ``report_s`` (plots and markdown), ``cpu_s`` (the
  process's CPU time over both: the figure to trust on a busy machine), ``target_s`` (10 for an
  hour, pro rata), ``peak_rss_mb`` (target 200), ``baseline_rss_mb``, and the counts (pulses,
  windows, status rows). With ``--workdir`` the bags are kept there and a complete one of the
  same length is analysed again rather than recorded anew (``bag_reused``; the hour takes some
  minutes to generate): remove the folder after changing the traffic's generators.
"""

from __future__ import annotations

import argparse
import heapq
import math
import multiprocessing
import random
import resource
import shutil
import statistics
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from collections.abc import Iterator
from typing import Any

import psutil

from bearing_rig_sim.interfaces import SLIP_STATUS
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.bags import BagError, BagWriter, open_bag, rig_typestore
from bearing_rig_sim.synthetic.traffic import (
    CAGE_PULSES_TOPIC,
    RIG_TRAFFIC_TOPICS,
    SPEEDS_TOPIC,
    SPINDLE_PULSES_TOPIC,
    rig_traffic,
)

TARGET_MSGS_PER_S = 20_000
"""Recorder throughput required by issue 6 (messages/s)."""

TARGET_ANALYSE_S_PER_HOUR = 10.0
"""Offline analysis of a one-hour bag required by issue 36 (s; issue 12 asked for 30, issue 6 for 60)."""
TARGET_ANALYSE_PEAK_MB = 200.0
"""Peak resident memory of the analysis of a one-hour bag, report included, required by issue 36 (MB)."""

PROGRAM_RPM = (900.0, 1200.0, 1500.0, 1800.0, 2100.0, 2400.0, 2700.0)
"""Inner-ring speeds of :func:`program_traffic`: the validation program's (rpm)."""
HOLD_S = 30.0
"""Time each speed is held in :func:`program_traffic` (s)."""
STRIPS = 4
"""Reflective strips per shaft (config/rig.yaml)."""
STATUS_TOPIC = SLIP_STATUS.name
CASES = ("record", "read", "analyse")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench bags``."""
    parser.add_argument("--quick", action="store_true", help="read-back bags of 4 and 1 minutes instead of 60 and 15")
    parser.add_argument("--minutes", type=float, default=None, help="length of the long read-back bag (simulated minutes)")
    parser.add_argument("--messages", type=int, default=200_000, help="messages per recorder throughput run")
    parser.add_argument("--repeats", type=int, default=3, help="recorder throughput runs and analyses of each bag; medians are reported")
    parser.add_argument(
        "--workdir", type=Path, default=None, help="where to write the bags (default: a temporary folder, removed); analysis bags are kept there and reused"
    )
    parser.add_argument("--cases", nargs="+", choices=CASES, default=list(CASES), help="cases to run (default: all)")


def _record_speeds(folder: Path, count: int) -> tuple[float, int]:
    """Seconds to record ``count`` speeds messages (close included) and the bag's bytes."""
    samples = [data for topic, _t, data in rig_traffic(1.0) if topic == SPEEDS_TOPIC]
    start = time.perf_counter()
    with BagWriter(folder) as bag:
        bag.add_topic(SPEEDS_TOPIC, *RIG_TRAFFIC_TOPICS[SPEEDS_TOPIC])
        write = bag.write
        for index in range(count):
            write(SPEEDS_TOPIC, index * 1_000_000, samples[index % len(samples)])
    elapsed = time.perf_counter() - start
    return elapsed, sum(f.stat().st_size for f in folder.iterdir())


def _record_traffic(folder: Path, minutes: float) -> tuple[float, int, int]:
    """Seconds to generate and record ``minutes`` of rig traffic, messages and bytes."""
    start = time.perf_counter()
    with BagWriter(folder, metadata={"test_program": f"steady run, {minutes} min (benchmark)"}) as bag:
        for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
            bag.add_topic(topic, msgtype, qos)
        write = bag.write
        for topic, time_ns, data in rig_traffic(minutes * 60.0):
            write(topic, time_ns, data)
        count = bag.message_count
    elapsed = time.perf_counter() - start
    return elapsed, count, sum(f.stat().st_size for f in folder.iterdir())


def program_traffic(duration_s: float, seed: int = 0, transient_pct: float = 2.0) -> Iterator[tuple[str, int, bytes]]:
    """Fibre-optic pulses and slip status of a speed program, in time order: (topic, time in ns,
    CDR bytes); see the module documentation. The cage turns at the epicyclic speed of H7006C
    (0.4283 n_i) less a slip of 1-1.5 % plus 2 % decaying with a 2 s time constant after each
    speed change."""
    from bearing_rig_sim.rig.speed_profile import step_ramp

    store = rig_typestore()
    types = store.types
    rng = random.Random(seed)
    period = HOLD_S + 1.0
    speeds = [rpm_to_rad_s(rpm) for rpm in PROGRAM_RPM]

    def state(t: float) -> tuple[float, float]:
        k = int(t // period)
        t0 = k * period
        before, after = speeds[(k - 1) % len(speeds)] if k else speeds[0], speeds[k % len(speeds)]
        inner = step_ramp(t, t0, before, t0 + 1.0, after)
        slip = 1.0 + 0.5 * after / speeds[-1] + transient_pct * math.exp(-max(t - t0 - 1.0, 0.0) / 2.0)
        return inner, inner * 0.4283 * (1.0 - slip / 100.0)

    def stamp(time_ns: int) -> Any:
        return types["builtin_interfaces/msg/Time"](sec=time_ns // 10**9, nanosec=time_ns % 10**9)

    def pulse(time_ns: int, shaft: str, index: int) -> bytes:
        header = types["std_msgs/msg/Header"](stamp=stamp(time_ns), frame_id="rig")
        message = types["bearing_rig_msgs/msg/FibreOpticPulse"](
            header=header, sensor_id=shaft, strip_id=index % STRIPS, strip_count=STRIPS, revolution=index // STRIPS, pulse_index=index
        )
        return bytes(store.serialize_cdr(message, "bearing_rig_msgs/msg/FibreOpticPulse"))

    spacing = 2 * math.pi / STRIPS
    angles = {SPINDLE_PULSES_TOPIC: 0.0, CAGE_PULSES_TOPIC: 0.0}
    counts = {SPINDLE_PULSES_TOPIC: 0, CAGE_PULSES_TOPIC: 0}
    shafts = {SPINDLE_PULSES_TOPIC: "spindle", CAGE_PULSES_TOPIC: "cage"}
    status: Any = store.types["bearing_rig_msgs/msg/SlipStatus"](
        header=types["std_msgs/msg/Header"](stamp=stamp(0), frame_id="bearing"),
        inner_ring_speed=0.0,
        cage_speed=0.0,
        theoretical_cage_speed=0.0,
        slip_rate=0.0,
        fitted_slope=0.0,
        critical_slope=-0.03,
        state=2,
        criterion="time",
        confidence=0.9,
        window_revolutions=1,
        detail="slope -0.001 +- 0.002 over 7 points (0.953) clearly >= k = -0.03; P(slope >= k) 1.000",
        axial_load=100.0,
        kinematic_slip_rate=0.0,
        loaded_contact_angle=0.2845,
        sweep_speed=104.72,
        sweep_stable_from=300.0,
        sweep_verdict="stable from 300 N (2-term Gaussian, R^2 0.9991, RMSE 0.012 %, 8 loads)",
    )
    dt = 1e-3
    for step in range(int(round(duration_s / dt))):
        t = step * dt
        inner, cage = state(t + 0.5 * dt)
        out = []
        for topic, speed in ((SPINDLE_PULSES_TOPIC, inner), (CAGE_PULSES_TOPIC, cage)):
            start, end = angles[topic], angles[topic] + speed * dt
            while (counts[topic] + 1) * spacing <= end:
                crossing = t + ((counts[topic] + 1) * spacing - start) / (end - start) * dt
                counts[topic] += 1
                time_ns = int(round((crossing + max(-4e-6, min(4e-6, rng.gauss(0.0, 1e-6)))) * 1e9))
                out.append((max(time_ns, step * 1_000_000), topic, counts[topic]))
            angles[topic] = end
        for time_ns, topic, index in sorted(out):
            yield topic, time_ns, pulse(time_ns, shafts[topic], index)
        if step % 100 == 0:
            status.header.stamp = stamp(step * 1_000_000)
            status.inner_ring_speed, status.cage_speed = inner, cage
            yield STATUS_TOPIC, step * 1_000_000, bytes(store.serialize_cdr(status, "bearing_rig_msgs/msg/SlipStatus"))


def _rig_bag_program(minutes: float) -> str:
    """The test program the analysis bag of ``minutes`` records (what tells a kept one)."""
    return f"validation speeds over and over, {minutes} min (benchmark)"


def _kept_rig_bag(folder: Path, minutes: float) -> tuple[float, int, int] | None:
    """A complete analysis bag of ``minutes`` left in ``folder`` by an earlier run with the same
    ``--workdir``, as (0 s, messages, bytes); None when there is none."""
    if not (folder / "metadata.yaml").is_file():
        return None
    try:
        with open_bag(folder) as bag:
            if not bag.complete or bag.run_metadata.get("test_program") != _rig_bag_program(minutes):
                return None
            count = bag.message_count
    except BagError:
        return None
    return 0.0, count, sum(f.stat().st_size for f in folder.iterdir())


def _record_rig_bag(folder: Path, minutes: float) -> tuple[float, int, int]:
    """Seconds to generate and record ``minutes`` of the rig's traffic for the analysis (see the
    module documentation), messages and bytes."""
    start = time.perf_counter()
    steady = ((topic, t, data) for topic, t, data in rig_traffic(minutes * 60.0) if topic not in (SPINDLE_PULSES_TOPIC, CAGE_PULSES_TOPIC))
    shutil.rmtree(folder, ignore_errors=True)  # an incomplete one left by an interrupted run
    with BagWriter(folder, metadata={"test_program": _rig_bag_program(minutes)}) as bag:
        for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
            bag.add_topic(topic, msgtype, qos)
        bag.add_topic(STATUS_TOPIC, "bearing_rig_msgs/msg/SlipStatus", "transient_local")
        write = bag.write
        for topic, time_ns, data in heapq.merge(steady, program_traffic(minutes * 60.0), key=lambda m: m[1]):
            write(topic, time_ns, data)
        count = bag.message_count
    return time.perf_counter() - start, count, sum(f.stat().st_size for f in folder.iterdir())


def measure_analysis(path: str, out: str) -> dict:
    """``bearing-rig analyze`` of a bag (CSV, plots and report into ``out``); runs in a fresh
    process. Returns seconds of each part, counts, peak and baseline resident memory (MB)."""
    import matplotlib.pyplot  # noqa: F401 - imported before the baseline, as analyse_bag's modules

    from bearing_rig_sim import compiled
    from bearing_rig_sim.monitoring import SlipMonitor
    from bearing_rig_sim.offline.analysis import analyse_bag
    from bearing_rig_sim.offline.report import write_report

    spent = [0.0]

    def timed(method):
        def wrapper(*args, **kwargs):
            begin = time.perf_counter()
            try:
                return method(*args, **kwargs)
            finally:
                spent[0] += time.perf_counter() - begin

        return wrapper

    running = compiled.status()
    if not running.active:  # a compiled class takes no wrapper, and compiled callers would bypass one
        for name in ("add_pulse", "check", "status"):
            setattr(SlipMonitor, name, timed(getattr(SlipMonitor, name)))
    baseline = _current_rss_mb()
    start = time.perf_counter()
    cpu = time.process_time()
    result = analyse_bag(path, csv_dir=out)
    analysed = time.perf_counter()
    write_report(result, out)
    done = time.perf_counter()
    cpu = time.process_time() - cpu
    peak = _peak_rss_mb()
    return {
        "analyse_s": analysed - start,
        "cpu_s": cpu,
        "monitor_s": None if running.active else spent[0],
        "report_s": done - analysed,
        "pulses": sum(result.pulses.values()),
        "windows": result.windows,
        "status_rows": result.status_rows,
        "segments": len(result.segments),
        "complete": result.complete,
        "peak_rss_mb": peak,
        "baseline_rss_mb": baseline,
        "compiled": running.active,
        "compiled_reason": running.reason,
    }


def _current_rss_mb() -> float:
    return float(psutil.Process().memory_info().rss) / 2**20


def _peak_rss_mb() -> float:
    """Peak resident memory of this process's program, MB: Linux's ``VmHWM``, which starts
    afresh at ``exec``. ``ru_maxrss`` does not: a process started by ``spawn`` (a fork, then an
    exec) keeps the peak of the fork's copy of its parent, here the benchmark's command with
    everything it imported, and would report that instead of the analysis'."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def measure_read(path: str) -> dict:
    """Read every message of a bag, decoded; runs in a fresh process. Returns seconds, count,
    peak and baseline resident memory (MB)."""
    with open_bag(path) as bag:
        baseline = _current_rss_mb()
        start = time.perf_counter()
        count = 0
        for _message in bag.messages():
            count += 1
        elapsed = time.perf_counter() - start
    peak = _peak_rss_mb()
    return {"read_s": elapsed, "messages_read": count, "peak_rss_mb": peak, "baseline_rss_mb": baseline}


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Measure recorder throughput, then read-back and analysis time and memory for two bag
    lengths (the cases of ``--cases``)."""
    long_minutes = args.minutes if args.minutes is not None else (4.0 if args.quick else 60.0)
    workdir = Path(tempfile.mkdtemp(prefix="bench-bags-")) if args.workdir is None else args.workdir
    workdir.mkdir(parents=True, exist_ok=True)
    context = multiprocessing.get_context("spawn")
    try:
        if "record" in args.cases:
            runs = [_record_speeds(workdir / f"record-{i}", args.messages) for i in range(max(1, args.repeats))]
            rates = [args.messages / elapsed for elapsed, _size in runs]
            median = statistics.median(rates)
            yield {
                "bench": "bags",
                "case": "record",
                "messages": args.messages,
                "msgs_per_s": round(median),
                "msgs_per_s_min": round(min(rates)),
                "target_msgs_per_s": TARGET_MSGS_PER_S,
                "meets_target": median >= TARGET_MSGS_PER_S,
                "bytes_per_msg": round(runs[0][1] / args.messages, 1),
                "compression": "zstd",
            }
        for minutes in (long_minutes / 4, long_minutes) if "read" in args.cases else ():
            folder = workdir / f"traffic-{minutes:g}min"
            write_s, count, size = _record_traffic(folder, minutes)
            with ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
                read = pool.submit(measure_read, str(folder)).result()
            yield {
                "bench": "bags",
                "case": "read",
                "sim_minutes": minutes,
                "messages": count,
                "bag_mb": round(size / 2**20, 1),
                "write_s": round(write_s, 2),
                "read_s": round(read["read_s"], 2),
                "read_msgs_per_s": round(read["messages_read"] / read["read_s"]),
                "all_read": read["messages_read"] == count,
                "peak_rss_mb": round(read["peak_rss_mb"], 1),
                "baseline_rss_mb": round(read["baseline_rss_mb"], 1),
            }
            shutil.rmtree(folder)
        for minutes in (long_minutes / 4, long_minutes) if "analyse" in args.cases else ():
            folder = workdir / f"rig-{minutes:g}min"
            kept = _kept_rig_bag(folder, minutes) if args.workdir is not None else None
            write_s, count, size = kept if kept is not None else _record_rig_bag(folder, minutes)
            analyses: list[dict[str, Any]] = []
            for _ in range(max(1, args.repeats)):  # each in a fresh process; medians of time, the largest peak
                with ProcessPoolExecutor(max_workers=1, mp_context=context) as pool:
                    analyses.append(pool.submit(measure_analysis, str(folder), str(workdir / f"report-{minutes:g}min")).result())
            analysis = {
                **analyses[0],
                **{key: statistics.median(r[key] for r in analyses) for key in ("analyse_s", "report_s", "cpu_s", "baseline_rss_mb")},
                "monitor_s": None if analyses[0]["monitor_s"] is None else statistics.median(r["monitor_s"] for r in analyses),
                "peak_rss_mb": max(r["peak_rss_mb"] for r in analyses),
            }
            target = TARGET_ANALYSE_S_PER_HOUR * minutes / 60.0
            yield {
                "bench": "bags",
                "case": "analyse",
                "sim_minutes": minutes,
                "messages": count,
                "bag_mb": round(size / 2**20, 1),
                "write_s": round(write_s, 2),
                "bag_reused": kept is not None,
                "analyse_s": round(analysis["analyse_s"], 2),
                "monitor_s": None if analysis["monitor_s"] is None else round(analysis["monitor_s"], 2),
                "compiled": analysis["compiled"],
                "compiled_reason": analysis["compiled_reason"],
                "report_s": round(analysis["report_s"], 2),
                "cpu_s": round(analysis["cpu_s"], 2),
                "target_s": round(target, 2),
                "meets_target": analysis["analyse_s"] + analysis["report_s"] <= target and analysis["peak_rss_mb"] <= TARGET_ANALYSE_PEAK_MB,
                "pulses": analysis["pulses"],
                "windows": analysis["windows"],
                "status_rows": analysis["status_rows"],
                "segments": analysis["segments"],
                "peak_rss_mb": round(analysis["peak_rss_mb"], 1),
                "baseline_rss_mb": round(analysis["baseline_rss_mb"], 1),
            }
            if args.workdir is None:
                shutil.rmtree(folder)
            shutil.rmtree(workdir / f"report-{minutes:g}min", ignore_errors=True)
    finally:
        if args.workdir is None:
            shutil.rmtree(workdir, ignore_errors=True)


def main() -> None:  # pragma: no cover - convenience entry point
    """``python -m bearing_rig_sim.benchmarks.bags``: print JSON lines."""
    import json

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object per line (the only output format)")
    for row in run(parser.parse_args()):
        print(json.dumps(row), flush=True)


if __name__ == "__main__":  # pragma: no cover
    main()
