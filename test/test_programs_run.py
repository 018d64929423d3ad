"""Every shipped test program runs to its end on the rig (``bearing-rig run PROGRAM --no-realtime``),
and its summary says what the paper's method found (docs/method.md):

* every program: a row for every segment of its file (read here as plain YAML), in order, and the
  simulator's true slip for every segment that turns;
* validation: every speed is held until stable (the rows of docs/paper.md section 9 are the
  settled slips of a bearing at 100 N; a segment's 10 s is many times the seconds the twin's slip
  takes to settle after a 1 s step, so "timeout" would be a slip that never settles);
* acceleration: every run-up ends stable, with its time to stable (the twin's run-up slip is the
  steady slip of the speed it passes plus 0.01 pp, docs/paper.md "The acceleration effect", so
  it has settled within the 3 s hold at 1500 rpm);
* load_sweep: under the table, a line per spindle speed. What each line concludes (stable from
  which load, or why not) is the paper's method on the sweep's slips, tested against hand
  calculations in test_analysis_stability.py (load_sweep_verdict) and on bench-like pulses in
  test_monitoring_bench.py; here only what the program guarantees is asserted.

And the live summary, ``analyze`` of the recorded bag and the recorded statuses agree on every
verdict: the segment verdicts and times to stable (validation, acceleration) and the load-sweep
verdict of each speed (load_sweep; its holds' states are interim verdicts of the sweep so far).

Each session waits for its own end (its exit), never for a duration, bounded by what is left of
the test's :data:`TIMEOUT_S`.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path
from typing import Any

import pytest
import yaml

pytest.importorskip("rclpy")

from bearing_rig_sim.config import config_path
from bearing_rig_sim.monitoring.load_sweep import sweep_key
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.offline.report import state_name
from conftest import start_run, summary_rows, the_bag, time_left

TIMEOUT_S = 600
"""Each program's limit, s: the load sweep is 147.5 s of simulated time, run without real time at
a real-time factor of 2-5 (1-2 on a loaded host), then its bag analysed."""

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.timeout(TIMEOUT_S)]

SEGMENT, SPEED, TRUTH_SLIP, VERDICT, T_STABLE = 1, 2, 7, 8, 9
"""Columns of a summary row split on whitespace."""


def run_program(ros_graph: Any, tmp_path: Path, name: str) -> tuple[int, str, Path]:
    session = start_run(ros_graph, config_path("programs", f"{name}.yaml"), tmp_path, "--quiet")
    try:
        out, err = session.communicate(timeout=time_left())
    except subprocess.TimeoutExpired:
        session.kill()
        out, err = session.communicate()
        pytest.fail(f"{name} did not end within the test's {TIMEOUT_S} s:\n{(out + err)[-3000:]}")
    return session.returncode, out + err, the_bag(tmp_path)


def segment_names(name: str) -> list[str]:
    """The segments of a shipped program, read as plain YAML."""
    return [segment["name"] for segment in yaml.safe_load(config_path("programs", f"{name}.yaml").read_text(encoding="utf-8"))["segments"]]


def sweep_lines(text: str) -> dict[int, str]:
    """The summary's load-sweep verdicts: rpm -> text."""
    found = {}
    for line in text.splitlines():
        match = re.match(r"^  (\d+) rpm: (.*)$", line)
        if match:
            found[int(match.group(1))] = match.group(2)
    return found


@pytest.mark.parametrize("name", ["validation", "load_sweep", "acceleration"])
def test_each_shipped_program_runs_to_its_end_and_its_verdicts_agree(ros_graph: Any, tmp_path: Path, name: str) -> None:
    code, text, bag = run_program(ros_graph, tmp_path, name)
    assert code == 0, text[-3000:]
    rows = summary_rows(text)
    result = analyse_bag(bag)
    assert [r[SEGMENT] for r in rows] == segment_names(name), text[-3000:]
    assert len(result.segments) == len(rows)
    turning = [r for r in rows if float(r[SPEED]) > 0.0]
    without_truth = [r[SEGMENT] for r in turning if not re.fullmatch(r"-?\d+\.\d{3}", r[TRUTH_SLIP])]
    assert turning and not without_truth, (f"no truth slip in {without_truth}", text[-3000:])
    if name == "validation":
        assert [r[VERDICT] for r in rows[1:]] == ["stable"] * (len(rows) - 1), text[-3000:]
    if name == "acceleration":
        run_ups = [r for r in rows if r[SEGMENT].startswith("accel_")]
        assert len(run_ups) == 4 and all(r[VERDICT] == "stable" and re.fullmatch(r"\d+\.\d\d", r[T_STABLE]) for r in run_ups), text
        # the live summary, analyze and the recorded statuses give the same time to stable
        for row, segment in zip(rows, result.segments):
            if row[SEGMENT].startswith("accel_"):
                assert segment.recorded_time_to_stable is not None
                assert float(row[T_STABLE]) == pytest.approx(segment.recorded_time_to_stable, abs=0.006)
    if name == "load_sweep":
        # what the program guarantees: a verdict line for every speed it swept, the same text as
        # the recorded statuses (the live summary is read off them), and analyze's replay of the
        # bag sweeping the same speeds. Which verdict each line gives is the method's, covered by
        # its own tests (module docstring).
        live = sweep_lines(text)
        assert sorted(live) == [1000, 3000, 5000, 7000, 9000], text[-3000:]
        assert all(live.values()), live
        assert live == result.recorded_sweeps
        assert sorted(sweep_key(v.inner_ring_speed) for v in result.sweeps) == sorted(live)
        return  # a load hold's state is the interim verdict of its speed's sweep so far, timed by
        # when the load cell's samples reach each reader: the sweep's lines above are its verdicts
    # every segment's verdict: the live summary and the recorded statuses agree (the same stream),
    # and analyze's replay of the pulses ends each segment in the same state; a time to stable
    # the replay finds is the recorded one. A segment that ends at rest is the exception for the
    # replay: once the pulses stop, the monitor node checks at its own estimate of the rig time
    # on a wall-clock timer, the replay on its status ticks, so each finds the stop (state
    # unknown) at another moment of the silence
    for row, segment in zip(rows, result.segments):
        recorded = state_name(segment.final_recorded_state) if segment.final_recorded_state >= 0 else "unknown"
        if segment.final_recorded_state >= 0 and segment.target_speed > 0.0:
            assert state_name(segment.final_state) == recorded, segment.name
        if row[VERDICT] == "stable" and row[T_STABLE] != "-" or row[VERDICT] == "timeout":
            assert (row[T_STABLE] != "-") == (segment.recorded_time_to_stable is not None), segment.name
            if row[T_STABLE] != "-":
                assert float(row[T_STABLE]) == pytest.approx(segment.recorded_time_to_stable, abs=0.006), segment.name
            if segment.time_to_stable is not None and segment.recorded_time_to_stable is not None:
                assert segment.time_to_stable == pytest.approx(segment.recorded_time_to_stable, abs=0.25), segment.name
        else:
            assert row[VERDICT] == recorded, segment.name
