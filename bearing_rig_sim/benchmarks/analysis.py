"""Benchmark of the slip analysis: cost of a Gaussian fit and latency of the online monitor.

``run`` yields one JSON-ready dict per case:

* ``case: "fit"``: a full multi-start fit (:func:`select_gaussian_fit`) of ``n_points`` synthetic
  points with up to ``max_terms`` terms; ``fit_ms`` is the median and ``fit_ms_max`` the slowest
  of ``--repeats`` runs, wall-clock milliseconds;
* ``case: "streaming"``: the monitor's verdict (:class:`~bearing_rig_sim.analysis.streaming.TrailingSlope`,
  built by :class:`~bearing_rig_sim.monitoring.SlipMonitor` from the shipped ``config/monitor.yaml``
  with the case's criterion) fed ``n_points`` points one by one with a verdict asked after each,
  as the monitor does; ``add_ms_p50`` / ``add_ms_p99`` / ``add_ms_max`` and ``verdict_ms_p50`` /
  ``verdict_ms_p99`` are latency percentiles (ms).

Data: slip against time from the paper's Table 7 (20 rad/s^2) sampled at ``--rate`` Hz, and slip
against load from its Table 5 (1000 rpm) every 5 N, both with 0.005 % Gaussian noise (seed 0).
Single-threaded; run on an otherwise idle core.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Iterator

import numpy as np

from bearing_rig_sim.analysis.gaussian import gaussian_sum, select_gaussian_fit
from bearing_rig_sim.analysis.streaming import TrailingSlope
from bearing_rig_sim.monitoring import MonitorSettings, SlipMonitor, shipped_parameters

TABLE7_20 = np.array([[3.5, -1.52, 1.29]])
"""Slip (%) against time (s) at 20 rad/s^2, paper Table 7."""
TABLE5_1000 = np.array([[5.18, -4.14, 214.0], [2.05, 530.0, 469.0]])
"""Slip (%) against axial load (N) at 1000 rpm, paper Table 5 (docs/paper.md section 10)."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Options of ``bearing-rig bench analysis``."""
    parser.add_argument("--rate", type=float, default=100.0, help="sample rate of the slip-against-time series (Hz)")
    parser.add_argument("--seconds", type=float, default=10.0, help="length of the streamed time series (s)")
    parser.add_argument("--repeats", type=int, default=5, help="runs per fit case; the median is reported")


def _series(criterion: str, n: int, rate: float) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    if criterion == "time":
        x: np.ndarray = np.arange(1, n + 1) / rate
        params = TABLE7_20
    else:
        x = 50.0 + 5.0 * np.arange(n)
        params = TABLE5_1000
    return x, np.asarray(gaussian_sum(x, params)) + rng.normal(0.0, 0.005, n)


def monitor_verdict(criterion: str) -> TrailingSlope:
    """The monitor's verdict on the shipped settings with ``criterion``, built as the monitor
    builds it."""
    settings = MonitorSettings.from_values({**shipped_parameters(), "criterion": criterion})
    return SlipMonitor(settings.kinematics(), settings).slope


def run(args: argparse.Namespace) -> Iterator[dict]:
    """Time the fits, then the streaming monitor."""
    rate = float(args.rate)
    for criterion, max_terms, n in (("time", 1, 150), ("time", 1, 1000), ("axial_load", 2, 14), ("axial_load", 2, 131)):
        x, y = _series(criterion, n, rate)
        times = []
        for _ in range(max(1, args.repeats)):
            start = time.perf_counter()
            select_gaussian_fit(x, y, max_terms)
            times.append(time.perf_counter() - start)
        yield {
            "bench": "analysis",
            "case": "fit",
            "criterion": criterion,
            "max_terms": max_terms,
            "n_points": n,
            "fit_ms": round(1e3 * statistics.median(times), 3),
            "fit_ms_max": round(1e3 * max(times), 3),
        }

    for criterion, n in (("time", int(round(args.seconds * rate))), ("axial_load", 131)):
        x, y = _series(criterion, n, rate)
        monitor = monitor_verdict(criterion)
        add_s, verdict_s = [], []
        for xi, yi in zip(x.tolist(), y.tolist()):
            start = time.perf_counter()
            monitor.add(xi, yi)
            mid = time.perf_counter()
            monitor.verdict()
            end = time.perf_counter()
            add_s.append(mid - start)
            verdict_s.append(end - mid)
        add_ms, verdict_ms = 1e3 * np.array(add_s), 1e3 * np.array(verdict_s)
        yield {
            "bench": "analysis",
            "case": "streaming",
            "criterion": criterion,
            "n_points": n,
            "add_ms_p50": round(float(np.percentile(add_ms, 50)), 4),
            "add_ms_p99": round(float(np.percentile(add_ms, 99)), 3),
            "add_ms_max": round(float(add_ms.max()), 3),
            "verdict_ms_p50": round(float(np.percentile(verdict_ms, 50)), 4),
            "verdict_ms_p99": round(float(np.percentile(verdict_ms, 99)), 3),
            "final_state": monitor.verdict().state.label,
        }
