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
"""

from __future__ import annotations

import argparse
import multiprocessing
import resource
import shutil
import statistics
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Iterator

from bearing_rig_sim.recording import BagWriter, open_bag
from bearing_rig_sim.recording.synthetic import RIG_TRAFFIC_TOPICS, SPEEDS_TOPIC, rig_traffic

TARGET_MSGS_PER_S = 20_000
"""Recorder throughput required by issue 6 (messages/s)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench bags``."""
    parser.add_argument("--quick", action="store_true", help="read-back bags of 4 and 1 minutes instead of 60 and 15")
    parser.add_argument("--minutes", type=float, default=None, help="length of the long read-back bag (simulated minutes)")
    parser.add_argument("--messages", type=int, default=200_000, help="messages per recorder throughput run")
    parser.add_argument("--repeats", type=int, default=3, help="recorder throughput runs; the median is reported")
    parser.add_argument("--workdir", type=Path, default=None, help="where to write the bags (default: a temporary folder, removed)")


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


def _current_rss_mb() -> float:
    with open("/proc/self/statm", encoding="ascii") as statm:
        pages = int(statm.read().split()[1])
    return pages * resource.getpagesize() / 2**20


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
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return {"read_s": elapsed, "messages_read": count, "peak_rss_mb": peak, "baseline_rss_mb": baseline}


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Measure recorder throughput, then read-back time and memory for two bag lengths."""
    long_minutes = args.minutes if args.minutes is not None else (4.0 if args.quick else 60.0)
    workdir = Path(tempfile.mkdtemp(prefix="bench-bags-")) if args.workdir is None else args.workdir
    workdir.mkdir(parents=True, exist_ok=True)
    try:
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
        context = multiprocessing.get_context("spawn")
        for minutes in (long_minutes / 4, long_minutes):
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
