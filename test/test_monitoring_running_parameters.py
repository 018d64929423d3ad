"""The time to stable is judged at the running monitor's ``stable_confidence``, in the session
summary and in ``analyze`` alike (issue: an override that changed the monitor's live verdicts but
not the time to stable, which used the shipped constant).

The monitor publishes its running parameter values on its ``/diagnostics`` status; the session's
runner takes them from there, ``analyze`` from the recorded ``/diagnostics``. The test sets
``stable_confidence`` on the monitor of two sessions of the same program and shows that the
summary's time to stable and analyze's (from its own rerun of the monitor and from the recorded
statuses) change with it, and agree with each other in each run.

Why the value must matter here: with the critical slope k2 set to 0 and a slip held steady (the
twin at 900 rpm / 100 N after its ramp), the slope's estimate scatters about zero, so P(slope >=
k) hovers about 1/2 from one trailing window to the next. At a confidence of 0.5 a STABLE needs
only slope >= 0, which an independent window gives with P = 1/2: over 12 s of one-second windows
it fails to come with P < 0.5^12 = 2.4e-4. At 0.999 a STABLE needs the slope 3.1 standard errors
above zero (P = 1e-3 per window), and it must then also come at the very same status to give the
same time. Both without it (equal "none"): P < 2.4e-4.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy")

from conftest import start_run, summary_rows, the_bag, time_left

from bearing_rig_sim.offline.analysis import analyse_bag

pytestmark = [pytest.mark.ros, pytest.mark.slow]

PROGRAM = """
name: held_after_a_ramp
description: 900 rpm held 12 s after its ramp, the time criterion judging the slip
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 100, dwell_s: 0.3}
  - {name: n0900, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 100, dwell_s: 12.0}
"""

T_STABLE = 9
"""Column of the time to stable in a summary row split on whitespace."""


def run_with_confidence(ros_graph: Any, run_dir: Path, confidence: float) -> tuple[float | None, Any]:
    """One session with ``stable_confidence`` (and k2 = 0) set on its monitor: the summary's time
    to stable of the held segment (None for "-") and the held segment of analyze's result."""
    run_dir.mkdir()
    program = run_dir / "program.yaml"
    program.write_text(PROGRAM, encoding="utf-8")
    params = run_dir / "monitor.yaml"
    params.write_text(f"monitor:\n  ros__parameters:\n    critical_slope_pct_per_s: 0.0\n    stable_confidence: {confidence}\n", encoding="utf-8")
    session = start_run(ros_graph, program, run_dir, "--params-file", str(params))
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    (row,) = [r for r in summary_rows(out) if r[1] == "n0900"]
    summary = None if row[T_STABLE] == "-" else float(row[T_STABLE])
    result = analyse_bag(the_bag(run_dir))
    assert result.stable_confidence == confidence, result.settings_source
    assert "published on /diagnostics" in result.settings_source
    (segment,) = [s for s in result.segments if s.name == "n0900"]
    return summary, segment


def same_time(summary: float | None, analysed: float | None) -> bool:
    """The summary prints the time to stable to 0.01 s."""
    if summary is None or analysed is None:
        return summary is None and analysed is None
    return math.isclose(summary, analysed, abs_tol=0.006)


def test_the_time_to_stable_follows_the_running_monitors_stable_confidence(ros_graph: Any, tmp_path: Path) -> None:
    times = {}
    for confidence in (0.5, 0.999):
        summary, segment = run_with_confidence(ros_graph, tmp_path / f"c{confidence}", confidence)
        # analyze agrees with the summary, by its own rerun of the monitor and on the recorded statuses
        assert same_time(summary, segment.time_to_stable), (confidence, summary, segment)
        assert same_time(summary, segment.recorded_time_to_stable), (confidence, summary, segment)
        times[confidence] = summary
    assert times[0.5] is not None, times  # a STABLE at slope >= 0 comes within the hold
    assert not same_time(times[0.5], times[0.999]), times  # and the confidence changed the time to stable
