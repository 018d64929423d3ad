"""Every shipped test program runs to its end on the rig (``bearing-rig run PROGRAM --no-realtime``),
and its summary says what the paper's method found (docs/method.md):

* validation: every speed segment ends stable or timed out;
* load_sweep: under the table, a line per spindle speed with "stable from N" or the reason there
  is none ("no stable state: ...");
* acceleration: a time to stable for every run-up.

And the live summary, ``analyze`` of the recorded bag and the recorded statuses agree on every
verdict: the segment verdicts and times to stable (validation, acceleration) and the load-sweep
verdict of each speed (load_sweep; its holds' states are interim verdicts of the sweep so far).

Each session waits for its own end (its exit), never for a duration.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy")

from bearing_rig_sim.config import config_path
from bearing_rig_sim.monitoring.load_sweep import sweep_key
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.offline.report import state_name
from conftest import start_run, summary_rows, the_bag

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SESSION_TIMEOUT_S = 1800.0
"""Longest wait for a whole program (the load sweep is 165 s of sim time), s: a hang guard only."""

SEGMENT, VERDICT, T_STABLE = 1, 8, 9
"""Columns of a summary row split on whitespace."""


def run_program(ros_graph: Any, tmp_path: Path, name: str) -> tuple[int, str, Path]:
    session = start_run(ros_graph, config_path("programs", f"{name}.yaml"), tmp_path, "--quiet")
    out, err = session.communicate(timeout=SESSION_TIMEOUT_S)
    return session.returncode, out + err, the_bag(tmp_path)


def sweep_lines(text: str) -> dict[int, str]:
    """The summary's load-sweep verdicts: rpm -> text."""
    found = {}
    for line in text.splitlines():
        match = re.match(r"^  (\d+) rpm: (.*)$", line)
        if match:
            found[int(match.group(1))] = match.group(2)
    return found


def verdict_of(text: str) -> str:
    """ "stable from 500 N" or "no stable state" of a load-sweep verdict's text."""
    return text.split(" (")[0] if text.startswith("stable from") else "no stable state"


@pytest.mark.parametrize("name", ["validation", "load_sweep", "acceleration"])
def test_each_shipped_program_runs_to_its_end_and_its_verdicts_agree(ros_graph: Any, tmp_path: Path, name: str) -> None:
    code, text, bag = run_program(ros_graph, tmp_path, name)
    assert code == 0, text[-3000:]
    rows = summary_rows(text)
    result = analyse_bag(bag)
    assert len(result.segments) == len(rows)
    if name == "validation":
        assert all(r[VERDICT] in ("stable", "timeout") for r in rows[1:])
    if name == "acceleration":
        run_ups = [r for r in rows if r[SEGMENT].startswith("accel_")]
        assert len(run_ups) == 4 and all(re.fullmatch(r"\d+\.\d\d", r[T_STABLE]) for r in run_ups), text
        # the live summary, analyze and the recorded statuses give the same time to stable
        for row, segment in zip(rows, result.segments):
            if row[SEGMENT].startswith("accel_"):
                assert segment.recorded_time_to_stable is not None
                assert float(row[T_STABLE]) == pytest.approx(segment.recorded_time_to_stable, abs=0.006)
    if name == "load_sweep":
        live = sweep_lines(text)
        assert sorted(live) == [1000, 3000, 5000, 7000, 9000], text[-3000:]
        assert all(v.startswith(("stable from ", "no stable state: ")) for v in live.values())
        offline = {sweep_key(v.inner_ring_speed): v.describe() for v in result.sweeps}
        # the live summary is read off the statuses: the same text as recorded
        assert live == result.recorded_sweeps
        # analyze replays the pulses and the load cell as recorded; the node may have missed a
        # few of the 1 kHz load-cell samples (sensor-data QoS), which moves the fit's figures in
        # their last digits: the verdict itself, "stable from N" or none, is the same
        assert {k: verdict_of(v) for k, v in live.items()} == {k: verdict_of(v) for k, v in offline.items()}, (live, offline)
    if name == "load_sweep":
        return  # a load hold's state is the interim verdict of its speed's sweep so far, timed by
        # when the load cell's samples reach each reader: the sweep verdicts above are the verdicts
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
