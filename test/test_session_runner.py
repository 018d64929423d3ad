"""The program runner without ROS, on a fake clock with fake monitor statuses: dwell counted from
the end of the speed change (STEP ramp and constant acceleration), until-stable (a stable verdict
resting on windows of the ramp or the previous speed does not count), the timeout, the dwell verdict, measured
against true slip over the same window, the mean bearing force, interruption.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.rig.program import RigLimits, TestProgram, load_program
from bearing_rig_sim.session.runner import COMMAND_LEAD_S, ProgramRunner, SlipObservation, StatusState, Verdict

PROGRAM = """
name: short
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 100, dwell_s: 1.0}
  - {name: n0900, speed_rpm: 900, ramp_s: 1.5, axial_load_n: 100, until_stable: true, timeout_s: 4.0}
  - {name: n1200, speed_rpm: 1200, ramp_s: 1.0, axial_load_n: 150, until_stable: true, timeout_s: 3.0}
  - {name: accel, speed_rpm: 1500, acceleration_rad_s2: 20, axial_load_n: 200, dwell_s: 2.0}
"""


@pytest.fixture
def program(tmp_path: Path) -> TestProgram:
    path = tmp_path / "short.yaml"
    path.write_text(PROGRAM, encoding="utf-8")
    return load_program(path)


def status(t: float, state: StatusState, slip: float = 3.0, cage: float = 40.0, revolutions: int = 1, confidence: float = 0.99) -> SlipObservation:
    return SlipObservation(time=t, state=state, slip_rate=slip, inner_ring_speed=94.0, cage_speed=cage, window_revolutions=revolutions, confidence=confidence)


# The shipped monitor's verdict rests on the windows of the last slope_span_s = 1 s, at least 5 of
# them: a status stamped t with one-revolution windows of w seconds speaks for t - max(1 + w, 5 w) on.
W40 = 2.0 * math.pi / 40.0  # window at the default cage speed of 40 rad/s: 0.157 s


def run_until(runner: ProgramRunner, t0: float, t1: float, dt: float = 0.01) -> list:
    """Update every ``dt`` from t0 to t1 (fake clock); the plans started."""
    started = []
    for k in range(int(round((t1 - t0) / dt)) + 1):
        started.extend(runner.update(t0 + k * dt))
    return started


def test_dwell_counts_from_the_end_of_the_speed_change(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    first = runner.start(10.0)
    assert first.segment.name == "load_up" and first.ramp_end == 10.0 and first.deadline == 11.0
    assert runner.update(10.999) == []
    (second,) = runner.update(11.0)
    assert second.segment.name == "n0900" and second.start_time == 11.0
    assert second.profile.start_speed == 0.0 and second.profile.target_speed == pytest.approx(rpm_to_rad_s(900))
    assert second.ramp_end == pytest.approx(12.5) and second.deadline == pytest.approx(16.5)


def test_constant_acceleration_dwell_starts_when_the_target_speed_is_reached(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)  # -> n0900
    runner.update(1.5 + 1.0 + 4.0)  # n0900 times out -> n1200 at 6.5
    (accel,) = runner.update(6.5 + 1.0 + 3.0)  # n1200 times out -> accel at 10.5
    ramp = (rpm_to_rad_s(1500) - rpm_to_rad_s(1200)) / 20.0
    assert accel.ramp_end == pytest.approx(10.5 + ramp)
    assert runner.update(10.5 + ramp + 1.99) == []
    assert runner.update(10.5 + ramp + 2.0) == [] and runner.finished
    assert [o.verdict for o in runner.outcomes] == [Verdict.UNKNOWN, Verdict.TIMEOUT, Verdict.TIMEOUT, Verdict.UNKNOWN]


def test_until_stable_needs_a_stable_verdict_on_windows_after_the_ramp(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    (plan,) = runner.update(1.0)  # n0900: ramp 1.0 .. 2.5
    runner.observe_status(status(2.0, StatusState.STABLE))  # during the ramp: ignored
    runner.observe_status(status(3.3, StatusState.STABLE))  # its windows reach back to 2.14 s: ignored
    assert runner.update(3.3) == []
    first = plan.ramp_end + 1.0 + W40
    runner.observe_status(status(first + 0.01, StatusState.STABLE, confidence=0.55))  # held, not shown now (below STABLE_CONFIDENCE, 0.6)
    runner.observe_status(status(first + 0.05, StatusState.STABLE, slip=3.2))
    (nxt,) = runner.update(first + 0.06)
    outcome = runner.outcomes[-1]
    assert outcome.name == "n0900" and outcome.verdict is Verdict.STABLE
    assert outcome.time_to_stable == pytest.approx(first + 0.05 - plan.ramp_end)
    assert outcome.measured_slip == 3.2
    assert nxt.segment.name == "n1200"


def test_stable_verdict_of_the_previous_speed_does_not_end_the_next_segment(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)
    runner.observe_status(status(2.6, StatusState.SLIPPING))
    runner.observe_status(status(3.7, StatusState.STABLE))  # n0900 (ramp end 2.5) is stable
    (n1200,) = runner.update(3.7)  # ramp 3.7 .. 4.7
    runner.observe_status(status(3.7, StatusState.STABLE))  # stamped at the segment start: the old speed
    runner.observe_status(status(5.0, StatusState.STABLE))  # its windows reach back into the ramp
    assert run_until(runner, 3.7, 7.69) == []  # nothing on windows after the ramp: the timeout
    assert runner.update(7.7) and runner.outcomes[-1].verdict is Verdict.TIMEOUT
    assert runner.outcomes[-1].time_to_stable is None


def test_a_stable_verdict_resting_on_the_ramp_does_not_count(program: TestProgram) -> None:
    """A verdict whose slope still includes windows of the ramp speaks for the ramp, and a stable
    state held by hysteresis (P(slope >= k) below the STABLE test's confidence, 0.6) for older
    points: neither counts."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    (plan,) = runner.update(1.0)  # n0900: ramp 1.0 .. 2.5
    cage = 2.0 * math.pi / 0.1  # 0.1 s windows: a verdict reaches back 1.1 s
    runner.observe_status(status(2.55, StatusState.STABLE, cage=cage))
    runner.observe_status(status(3.5, StatusState.STABLE, cage=cage))  # back to 2.4 s: in the ramp
    runner.observe_status(status(3.62, StatusState.STABLE, cage=cage, confidence=0.55))
    assert runner.update(3.62) == []
    runner.observe_status(status(3.65, StatusState.STABLE, slip=3.3, cage=cage))
    assert runner.update(3.65) and runner.outcomes[-1].time_to_stable == pytest.approx(3.65 - plan.ramp_end)


def test_without_a_speed_change_the_first_stable_verdict_on_windows_after_the_start_counts(tmp_path: Path) -> None:
    path = tmp_path / "load_step.yaml"
    path.write_text(
        "name: load_step\nbearing: bearings/h7006c.yaml\nstability_criterion: axial_load\ninitial_speed_rpm: 900\n"
        "segments:\n  - {name: f200, speed_rpm: 900, axial_load_n: 200, until_stable: true, timeout_s: 5.0}\n",
        encoding="utf-8",
    )
    runner = ProgramRunner(load_program(path))
    plan = runner.start(10.0)
    assert plan.ramp_end == 10.0
    runner.observe_status(status(10.1, StatusState.STABLE, cage=2.0 * math.pi / 0.2))  # back to 8.9 s: before
    runner.observe_status(status(11.3, StatusState.STABLE, cage=2.0 * math.pi / 0.2))  # back to 10.1 s
    runner.update(11.3)
    assert runner.finished and runner.outcomes[-1].verdict is Verdict.STABLE
    assert runner.outcomes[-1].time_to_stable == pytest.approx(1.3)


def test_dwell_verdict_is_the_monitors_last_state_in_the_segment(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.observe_status(status(0.5, StatusState.SLIPPING))
    runner.observe_status(status(0.9, StatusState.FAULT))
    runner.update(1.0)
    assert runner.outcomes[-1].verdict is Verdict.FAULT


def test_measured_and_true_slip_compare_over_the_same_window(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)
    for k in range(400):  # truth at 100 Hz: 3.0 % until 3.0 s, then 3.5 %
        t = k * 0.01
        runner.observe_truth(t, 3.0 if t < 3.0 else 3.5)
    cage = 2.0 * math.pi / 0.5  # one cage revolution takes 0.5 s
    runner.observe_status(status(2.6, StatusState.UNKNOWN))
    runner.observe_status(status(3.45, StatusState.SLIPPING, slip=3.49, cage=cage))
    runner.update(2.5 + 4.0)  # n0900 times out: its last status decides
    outcome = runner.outcomes[-1]
    # window 2.95 .. 3.45 s: 5 samples at 3.0 %, 45 at 3.5 % (samples 2.95 .. 3.45 inclusive)
    inside = [3.0 if k * 0.01 < 3.0 else 3.5 for k in range(295, 346)]
    assert outcome.truth_slip == pytest.approx(sum(inside) / len(inside))
    assert outcome.measured_slip == 3.49


def test_a_window_that_began_in_the_ramp_gives_the_segment_no_slip(program: TestProgram) -> None:
    """A segment that ends on a status whose window began before its ramp's end (a stop: the last
    windows close during the deceleration) shows no slip: that slip is the ramp's. The offline
    analysis leaves such windows out of a segment's means by the same rule."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)  # n0900: ramp 1.0 .. 2.5, dwell to 6.5
    for k in range(1100):  # truth at 100 Hz, 3.0 %
        runner.observe_truth(k * 0.01, 3.0)
    cage = 2.0 * math.pi / 0.5  # 0.5 s windows
    runner.observe_status(status(2.9, StatusState.SLIPPING, slip=2.7, cage=cage))  # began at 2.4 s: in the ramp
    runner.update(6.5)
    outcome = runner.outcomes[-1]
    assert outcome.name == "n0900" and outcome.measured_slip is None and outcome.truth_slip is None
    runner.observe_status(status(7.1, StatusState.SLIPPING, slip=2.8, cage=cage))  # n1200's ramp: 6.5 .. 7.5
    runner.observe_status(status(8.1, StatusState.SLIPPING, slip=3.1, cage=cage))  # began at 7.6 s: after it
    runner.update(7.5 + 3.0)
    outcome = runner.outcomes[-1]
    assert outcome.name == "n1200" and outcome.measured_slip == 3.1 and outcome.truth_slip == pytest.approx(3.0)


def test_a_status_without_a_window_has_no_true_slip_beside_it(program: TestProgram) -> None:
    """A rig found stopped: the last status has cage speed 0 and no slip; the truth's slip at
    that moment (finite near standstill: 1 - cage / (ratio x inner) of vanishing speeds) is not
    shown beside it, whatever its value."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)
    for k in range(400):
        runner.observe_truth(k * 0.01, -67.9)
    runner.observe_status(SlipObservation(time=3.45, state=StatusState.UNKNOWN, slip_rate=math.nan, inner_ring_speed=0.0, cage_speed=0.0, window_revolutions=1))
    runner.update(2.5 + 4.0)
    outcome = runner.outcomes[-1]
    assert outcome.truth_slip is None and outcome.measured_slip is None


def test_mean_bearing_force_counts_after_the_ramp(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)  # n0900 ramp 1.0 .. 2.5
    runner.observe_axial_setpoint(1.0, 100.0)  # the load controller has the segment's set-point
    runner.observe_load(0.5, 1000.0)  # previous segment: not counted
    runner.observe_load(2.0, 50.0)  # during the ramp: not counted
    for t in (2.5, 2.6, 2.7):
        runner.observe_load(t, 100.0 + (t - 2.5) * 10)
    runner.update(6.5)
    assert runner.outcomes[-1].bearing_force == pytest.approx(101.0)


def test_interrupt_ends_the_running_segment(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)
    outcome = runner.interrupt(1.7)
    assert outcome is not None and outcome.verdict is Verdict.INTERRUPTED and outcome.end_time == 1.7
    assert runner.finished and runner.current is None and runner.update(9.0) == []
    with pytest.raises(RuntimeError):
        runner.start(10.0)


# -- conditions: measured beside commanded, disturbances from outside ------------------------------
def test_a_speed_the_spindle_did_not_reach_is_marked(program: TestProgram) -> None:
    """The audit's load sweep: the drive refused 7000 rpm and stayed at 5000; the row said
    "stable". Here n0900 is measured at 600 rpm (62.8 rad/s against 94.2): a STABLE status there
    is not stable at 900 rpm, so the segment runs to its timeout, and the row says why."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)  # n0900: ramp 1.0 .. 2.5, timeout 4 s
    slow = status(3.7, StatusState.UNKNOWN)
    slow = SlipObservation(**{**slow.__dict__, "inner_ring_speed": rpm_to_rad_s(600.0)})
    runner.observe_status(slow)
    runner.observe_status(SlipObservation(**{**slow.__dict__, "time": 3.8, "state": StatusState.STABLE}))  # on windows after the ramp
    runner.update(3.9)
    assert [o.name for o in runner.outcomes] == ["load_up"]  # n0900 goes on
    runner.update(10.0)
    outcome = runner.outcomes[1]
    assert outcome.name == "n0900" and outcome.verdict is Verdict.TIMEOUT
    assert outcome.measured_speed == pytest.approx(rpm_to_rad_s(600.0))
    assert outcome.conditions == ("speed 600 rpm measured, 900 rpm commanded",)
    assert not outcome.conditions_met


def test_speed_within_one_percent_meets_the_conditions(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)
    near = SlipObservation(
        time=3.0, state=StatusState.UNKNOWN, slip_rate=3.0, inner_ring_speed=rpm_to_rad_s(900.0) * 0.995, cage_speed=40.0, window_revolutions=1
    )
    runner.observe_status(near)
    runner.observe_status(SlipObservation(**{**near.__dict__, "time": 3.5, "state": StatusState.STABLE}))
    runner.update(3.6)
    assert runner.outcomes[-1].conditions_met


def test_a_load_off_its_set_point_is_marked_once_settled(program: TestProgram) -> None:
    """The audit's case: 30 N on the bearing against a 100 N set-point, summary "stable"."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.observe_axial_setpoint(0.05, 100.0)
    runner.observe_load(0.1, 0.0)  # the load still rising: not judged (LOAD_SETTLE_S = 0.5 s)
    for k in range(5):
        runner.observe_load(0.6 + 0.1 * k, 30.0)
    runner.update(1.0)
    outcome = runner.outcomes[-1]
    assert outcome.bearing_force == pytest.approx(30.0)
    # settle_band(100 N) = max(2 % of 100 N, 5 N) = 5 N; the first sample furthest out is named
    assert outcome.conditions == ("load off: bearing force 30.0 N at t = 0.600 s, 100 N commanded (+- 5 N)",)


def test_set_points_from_outside_mark_the_segment(program: TestProgram) -> None:
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.observe_axial_setpoint(0.2, 0.0)  # before the program's set-point can have arrived: not judged
    runner.observe_axial_setpoint(0.7, 100.0)  # the program's own
    runner.update(1.0)
    assert runner.outcomes[-1].conditions_met
    runner.observe_axial_setpoint(1.2, 100.0)  # n0900 (starts at 1.0): its set-point in force
    runner.observe_axial_setpoint(1.6, 30.0)  # then someone called the service
    runner.observe_disturbance(1.7, "a message on /rig/spindle/command not sent by this session")
    runner.observe_disturbance(1.8, "a message on /rig/spindle/command not sent by this session")  # once
    runner.interrupt(2.0)
    assert runner.outcomes[-1].conditions == (
        "disturbed: the load controller's set-point was 30 N, not the program's 100 N",
        "disturbed: a message on /rig/spindle/command not sent by this session",
    )


def test_a_set_point_that_reaches_the_load_controller_late_is_not_a_disturbance(program: TestProgram) -> None:
    """Without real time the simulator runs ahead of the session: the load controller's state can
    show the previous segment's set-point well into the next segment's sim time."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.observe_axial_setpoint(0.1, 100.0)
    runner.update(1.0)  # n0900, 100 N
    runner.observe_axial_setpoint(1.1, 100.0)
    run_until(runner, 1.0, 2.6)
    runner.observe_status(status(5.0, StatusState.SLIPPING))
    runner.observe_status(status(6.0, StatusState.STABLE))
    runner.update(6.0)  # n1200, 150 N, starts at 6.0
    runner.observe_axial_setpoint(6.9, 100.0)  # still the previous segment's, 0.9 s in
    for k in range(10):
        runner.observe_load(7.0 + 0.1 * k, 100.0)  # not judged: the set-point has not arrived
    runner.observe_axial_setpoint(8.0, 150.0)
    for k in range(10):
        runner.observe_load(8.5 + 0.1 * k, 150.0)
    runner.interrupt(9.5)
    outcome = runner.outcomes[-1]
    assert outcome.name == "n1200" and outcome.conditions_met
    assert outcome.bearing_force == pytest.approx(150.0)


def test_a_segment_too_short_for_the_load_to_settle_is_not_judged_on_it(tmp_path: Path) -> None:
    path = tmp_path / "short.yaml"
    path.write_text(PROGRAM.replace("dwell_s: 1.0}", "dwell_s: 0.3}", 1), encoding="utf-8")
    runner = ProgramRunner(load_program(path))
    runner.start(0.0)
    for k in range(3):
        runner.observe_load(0.1 * k, 30.0 * k)  # still rising when the segment ends
    runner.update(0.3)
    outcome = runner.outcomes[-1]
    assert outcome.bearing_force == pytest.approx(30.0) and outcome.conditions_met


def test_a_run_up_is_judged_during_the_acceleration_from_its_start(program: TestProgram) -> None:
    """Paper section 4.2: under constant acceleration the slope of slip against time is judged
    during the run-up, and its time to stable counts from the run-up's start (Table 7's t = 0),
    whatever the speed then. The accel segment starts at 10.5 s and reaches 1500 rpm 1.57 s later;
    a stable status stamped 11.6 s resting on windows from 10.5 + 0.3 s on (evidence from
    11.6 - (1 + W40)) gives 1.1 s, although the target speed is not reached."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    runner.update(1.0)
    runner.update(1.5 + 1.0 + 4.0)
    (accel,) = runner.update(6.5 + 1.0 + 3.0)
    assert accel.start_time == pytest.approx(10.5) and accel.ramp_end > 11.6
    runner.observe_status(status(11.2, StatusState.STABLE))  # rests on windows from before the start
    runner.observe_status(status(10.5 + 1.0 + W40 - 0.01, StatusState.STABLE))  # just before: not yet
    runner.observe_status(status(11.6 + W40, StatusState.STABLE))
    run_until(runner, 10.5, accel.deadline + 0.01)
    outcome = runner.outcomes[-1]
    assert outcome.name == "accel" and outcome.verdict == Verdict.STABLE
    assert outcome.time_to_stable == pytest.approx(1.1 + W40)
    assert outcome.run_up and runner.outcomes[:-1] and not any(o.run_up for o in runner.outcomes[:-1])  # the others are step ramps


# -- commands ahead of time: the plan is where the spindle is -------------------------------------
RUN_UPS = """
name: run_ups
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 200, dwell_s: 1.0}
  - {name: accel_20, speed_rpm: 1500, acceleration_rad_s2: 20, axial_load_n: 200, dwell_s: 3.0}
  - {name: stop_20, speed_rpm: 0, ramp_s: 2.0, axial_load_n: 200, dwell_s: 1.0}
  - {name: n0900, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 200, until_stable: true, timeout_s: 3.0}
  - {name: stop, speed_rpm: 0, ramp_s: 1.0, axial_load_n: 200, dwell_s: 1.0}
"""
RUN_UP_S = 1500.0 * math.pi / 30.0 / 20.0
"""0 to 1500 rpm at 20 rad/s^2: 157.08 rad/s / 20 rad/s^2 = 7.854 s."""


@pytest.fixture
def run_ups(tmp_path: Path) -> TestProgram:
    path = tmp_path / "run_ups.yaml"
    path.write_text(RUN_UPS, encoding="utf-8")
    return load_program(path)


def test_a_dwell_segments_successor_is_commanded_ahead_stamped_with_its_start(run_ups: TestProgram) -> None:
    """Without real time the simulator runs ahead of the session's clock: a command stamped when
    the session notices a segment's end takes effect late, and the spindle does not follow the
    plan. The end of a dwell segment is known at its start, so the next command goes out up to
    COMMAND_LEAD_S ahead, stamped with that end, and the next plan starts there, however late the
    session notices it."""
    runner = ProgramRunner(run_ups)
    runner.start(10.0)
    load_up, accel = runner.commands_due(10.0)
    assert (load_up.segment.name, load_up.start_time) == ("load_up", 10.0)
    assert (accel.segment.name, accel.start_time) == ("accel_20", 11.0)  # 10 s + 1 s dwell
    assert runner.commands_due(10.5) == []  # each command once
    (started,) = runner.update(11.7)  # the session's clock: 0.7 s after load_up's end
    assert started is accel and started.start_time == 11.0
    assert started.ramp_end == pytest.approx(11.0 + RUN_UP_S)
    stop_due = 11.0 + RUN_UP_S + 3.0 - COMMAND_LEAD_S  # its start less the lead
    assert runner.commands_due(stop_due - 0.01) == []
    (stop,) = runner.commands_due(stop_due + 0.01)
    assert stop.segment.name == "stop_20" and stop.start_time == pytest.approx(11.0 + RUN_UP_S + 3.0)
    # the stop's successor is due at once (its start, 3 s on, is within the lead), n0900's too:
    # the segment after an until_stable one is not known ahead
    (n0900,) = runner.commands_due(stop.start_time - 1.0)
    assert n0900.segment.name == "n0900" and n0900.start_time == pytest.approx(stop.start_time + 3.0)
    runner.update(stop.start_time + 0.2)
    runner.update(n0900.start_time + 0.4)
    assert runner.current is n0900 and runner.commands_due(n0900.start_time + 3.9) == []
    runner.update(n0900.deadline + 0.3)  # times out; the next starts when the session notices
    (last,) = runner.commands_due(n0900.deadline + 0.3)
    assert last.segment.name == "stop" and last.start_time == pytest.approx(n0900.deadline + 0.3)


def stop_status(t: float, rpm: float) -> SlipObservation:
    return SlipObservation(time=t, state=StatusState.SLIPPING, slip_rate=0.1, inner_ring_speed=rpm_to_rad_s(rpm), cage_speed=20.0, window_revolutions=1)


def test_a_stop_is_judged_on_windows_after_its_ramp_only_and_a_turning_spindle_fails_it(run_ups: TestProgram) -> None:
    """A stopped spindle sends no pulses, so the last window of a stop closes during its ramp at
    the speed then: that window does not judge the stop. A window closing after the ramp end
    measures a spindle still turning: the stop's conditions fail (the 446 rpm of a command
    applied late, or a drive that does not stop)."""
    for late_rpm, expected in ((None, ()), (446.0, ("speed 446 rpm measured, 0 rpm commanded",))):
        runner = ProgramRunner(run_ups)
        runner.start(0.0)
        runner.update(1.0)
        runner.update(1.0 + RUN_UP_S + 3.0)
        stop = runner.current
        assert stop is not None and stop.segment.name == "stop_20"
        runner.observe_status(stop_status(stop.ramp_end - 0.3, 1000.0))  # the last window of the ramp
        if late_rpm is not None:
            runner.observe_status(stop_status(stop.ramp_end + 0.2, late_rpm))
        runner.update(stop.deadline)
        outcome = runner.outcomes[-1]
        assert outcome.name == "stop_20" and outcome.conditions == expected


def test_what_is_stamped_after_a_dwell_segments_end_belongs_to_the_next(run_ups: TestProgram) -> None:
    """The simulator, its next command queued, is in the next segment before the session notices
    the end of the running one: a status stamped after that end judges the next segment, not the
    running one (a run-up's windows at 1458 rpm made a stop "1458 rpm measured")."""
    runner = ProgramRunner(run_ups)
    runner.start(0.0)
    runner.update(1.0)
    runner.update(1.0 + RUN_UP_S + 3.0)
    stop = runner.current
    assert stop is not None and stop.segment.name == "stop_20"
    # stop_20 ends at stop.deadline; the session has not noticed yet when these arrive
    runner.observe_status(stop_status(stop.deadline - 0.5, 0.0))
    runner.observe_status(stop_status(stop.deadline + 0.5, 1458.0))
    runner.observe_load(stop.deadline + 0.5, 200.0)
    runner.update(stop.deadline + 0.6)
    ended = runner.outcomes[-1]
    assert ended.name == "stop_20" and ended.verdict is Verdict.SLIPPING and ended.measured_speed == 0.0 and ended.conditions_met
    runner.update(stop.deadline + 1.0)  # n0900 ramps 1 s: the status at +0.5 is in it, before the ramp end
    runner.observe_status(stop_status(stop.deadline + 1.5, 900.0))
    runner.update(stop.deadline + 4.0)
    n0900 = runner.outcomes[-1]
    assert n0900.name == "n0900" and n0900.measured_speed == pytest.approx(rpm_to_rad_s(900.0)) and n0900.conditions_met


def test_a_run_up_stable_during_its_acceleration_is_judged_on_the_speed_it_holds(run_ups: TestProgram) -> None:
    """A run-up's verdict comes during the acceleration (paper section 4.2); its speed is judged
    on the segment's last status, at the end of the hold: 1500 rpm met, 1400 rpm not."""
    for held_rpm, met in ((1500.0, True), (1400.0, False)):
        runner = ProgramRunner(run_ups)
        runner.start(0.0)
        (accel,) = runner.update(1.0)
        runner.observe_status(SlipObservation(**{**status(accel.start_time + 2.0, StatusState.STABLE).__dict__, "inner_ring_speed": 40.0}))
        runner.observe_status(stop_status(accel.deadline - 0.1, held_rpm))
        runner.update(accel.deadline)
        outcome = runner.outcomes[-1]
        assert outcome.name == "accel_20" and outcome.time_to_stable == pytest.approx(2.0) and outcome.conditions_met is met
        assert outcome.run_up and outcome.stable_speed == 40.0  # the speed of the status that made it stable


LATE = """
name: late
bearing: bearings/h7006c.yaml
stability_criterion: time
initial_speed_rpm: 900
segments:
  - {name: a, speed_rpm: 900, axial_load_n: 100, dwell_s: 1.0}
  - {name: b, speed_rpm: 900, axial_load_n: 300, dwell_s: 2.0}
  - {name: c, speed_rpm: 900, axial_load_n: 50, dwell_s: 2.0}
"""


@pytest.fixture
def late(tmp_path: Path) -> TestProgram:
    path = tmp_path / "late.yaml"
    path.write_text(LATE, encoding="utf-8")
    return load_program(path)


def feed_state(runner: ProgramRunner, t0: float, t1: float, setpoint: float, force: float) -> None:
    """The load controller's state every 10 ms from ``t0`` to ``t1`` (exclusive)."""
    for k in range(round((t1 - t0) / 0.01)):
        t = t0 + 0.01 * k
        runner.observe_axial_setpoint(t, setpoint)
        runner.observe_load(t, force)


def test_a_fixed_start_whose_set_point_came_late_is_flagged_though_its_mean_settles(late: TestProgram) -> None:
    """Segment b follows a dwell: its set-point goes ahead, stamped with its start (1.0 s), so its
    300 N is due from 1.0 + LOAD_SETTLE_S on. Here it reached the load controller only at 2.0 s:
    100 N on the bearing from 1.5 s to 2.0 s is 200 N off, beyond settle_band(300 N) = 6 N. The
    settled mean (from the set-point's arrival) alone would have said 300 N and "ok"."""
    runner = ProgramRunner(late)
    runner.start(0.0)
    feed_state(runner, 0.0, 1.0, 100.0, 100.0)
    runner.update(1.0)
    feed_state(runner, 1.0, 2.0, 100.0, 100.0)
    feed_state(runner, 2.0, 3.0, 300.0, 300.0)
    runner.update(3.0)
    a, b = runner.outcomes
    assert a.conditions_met
    assert b.bearing_force == pytest.approx(300.0)
    assert b.conditions == ("load off: bearing force 100.0 N at t = 1.500 s, 300 N commanded (+- 6 N)",)


def test_a_fixed_start_whose_set_point_came_in_time_is_ok(late: TestProgram) -> None:
    runner = ProgramRunner(late)
    runner.start(0.0)
    feed_state(runner, 0.0, 1.0, 100.0, 100.0)
    runner.update(1.0)
    feed_state(runner, 1.0, 1.3, 300.0, 200.0)  # rising: within LOAD_SETTLE_S, not judged
    feed_state(runner, 1.3, 3.0, 300.0, 301.0)
    runner.update(3.0)
    assert runner.outcomes[-1].conditions_met


def test_the_load_the_simulator_applied_is_judged_too(late: TestProgram) -> None:
    """The measured case: the load controller's state right, but the simulator applying a force
    seconds old (618 N in a 50 N segment): the segment is flagged from the truth's axial load."""
    runner = ProgramRunner(late)
    runner.start(0.0)
    feed_state(runner, 0.0, 1.0, 100.0, 100.0)
    runner.update(1.0)
    feed_state(runner, 1.0, 3.0, 300.0, 300.0)
    runner.update(3.0)  # c, 50 N, from 3.0 s
    feed_state(runner, 3.0, 5.0, 50.0, 50.0)
    for k in range(200):
        runner.observe_truth(3.0 + 0.01 * k, 3.0, 618.0 if k < 120 else 50.0)
    runner.update(5.0)
    c = runner.outcomes[-1]
    assert c.bearing_force == pytest.approx(50.0)
    assert c.conditions == ("load off: axial load on the simulated bearing 618.0 N at t = 3.500 s, 50 N commanded (+- 5 N)",)


def test_a_set_point_never_shown_is_flagged(late: TestProgram) -> None:
    runner = ProgramRunner(late)
    runner.start(0.0)
    feed_state(runner, 0.0, 1.0, 0.0, 0.0)  # the load controller still at its initial 0 N
    runner.update(1.0)
    assert runner.outcomes[-1].conditions == ("load off: the load controller never showed the set-point 100 N during the segment",)


SHORT_LOAD_UP = """
name: short_load_up
stability_criterion: time
bearing: bearings/h7006c.yaml
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 100, dwell_s: 0.3}
  - {name: n0900, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 100, dwell_s: 1.0}
"""


def test_a_dwell_shorter_than_the_settling_time_is_not_flagged_for_a_set_point_shown_after_it(tmp_path: Path) -> None:
    """A 0.3 s load-up dwell, shorter than LOAD_SETTLE_S (0.5 s): its set-point may reach the load
    controller after the dwell's end without the segment being off (the rule applies to segments
    longer than that). The session noticing the end late (here at 2.0 s of sim time, the
    simulator having run ahead) does not lengthen the segment: its end is its deadline, 0.3 s."""
    path = tmp_path / "short.yaml"
    path.write_text(SHORT_LOAD_UP, encoding="utf-8")
    runner = ProgramRunner(load_program(path))
    runner.start(0.0)
    feed_state(runner, 0.0, 0.3, 0.0, 0.0)  # the load controller still at its initial 0 N
    runner.update(2.0)
    load_up = runner.outcomes[-1]
    assert load_up.name == "load_up" and load_up.conditions == ()


def test_the_radial_force_on_the_bearing_is_judged_against_the_segments(tmp_path: Path) -> None:
    """A 500 N radial load at 90 deg: (0, 500) N expected in force.x/y; (500, 0) N is the right
    magnitude in the wrong direction, 707 N off, beyond settle_band(500 N) = 10 N."""
    path = tmp_path / "radial.yaml"
    path.write_text(LATE.replace("axial_load_n: 300,", "axial_load_n: 300, radial_load_n: 500, radial_azimuth_deg: 90,"), encoding="utf-8")
    program = load_program(path, RigLimits(1000.0, 1000.0, 1000.0, max_radial_load_n=800.0))
    assert program.segments[1].radial_components == pytest.approx((0.0, 500.0), abs=1e-9)
    runner = ProgramRunner(program)
    assert runner.loads_radially
    runner.start(0.0)
    feed_state(runner, 0.0, 1.0, 100.0, 100.0)
    runner.update(1.0)
    feed_state(runner, 1.0, 3.0, 300.0, 300.0)
    for k in range(200):
        t = 1.0 + 0.01 * k
        runner.observe_radial(t, 0.0, 500.0) if k < 100 else runner.observe_radial(t, 500.0, 0.0)
    runner.update(3.0)
    assert runner.outcomes[-1].conditions == ("load off: radial force on the bearing 500.0 N at t = 2.000 s, 500 N commanded (+- 10 N)",)


def test_set_points_of_every_fixed_start_go_at_once_and_stop_at_an_until_stable_end(program: TestProgram) -> None:
    """load_up (dwell 1 s) fixes n0900's start at 1.0 s; n0900 is until_stable, so n1200's start
    is not known: by default set-points of fixed starts go at once, without a lead; a lead of
    0.5 s holds n0900's back until 0.5 s before its start."""
    runner = ProgramRunner(program)
    runner.start(0.0)
    assert [(p.segment.name, p.start_time) for p in runner.setpoints_due(0.0)] == [("load_up", 0.0), ("n0900", 1.0)]
    assert runner.setpoints_due(0.1) == []
    assert [p.segment.name for p in runner.commands_due(0.1)] == ["load_up", "n0900"]  # the commands' own count
    runner.update(1.0)
    runner.update(7.0)  # n0900 times out at 1 + 1.5 + 4 = 6.5 s: n1200 starts when noticed
    assert [(p.segment.name, p.start_time) for p in runner.setpoints_due(7.0)] == [("n1200", 7.0)]
    led = ProgramRunner(program, setpoint_lead_s=0.5)
    led.start(0.0)
    assert [p.segment.name for p in led.setpoints_due(0.4)] == ["load_up"]
    assert [p.segment.name for p in led.setpoints_due(0.5)] == ["n0900"]
    # the session sends the first set-point before the program's clock starts (it starts once the
    # load controller shows it in force): not given again, the commands all the same
    loaded = ProgramRunner(program)
    loaded.start(0.0, setpoint_sent=True)
    assert [(p.segment.name, p.start_time) for p in loaded.setpoints_due(0.0)] == [("n0900", 1.0)]
    assert [p.segment.name for p in loaded.commands_due(0.0)] == ["load_up", "n0900"]


class WallClock:
    """A wall clock the test moves by hand (s)."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_a_segment_ending_at_its_deadline_waits_for_the_monitors_statuses_through_it(program: TestProgram) -> None:
    """With a monitor guard (a session's runner), a dwell segment whose deadline the clock has
    passed ends only once a status stamped at or after that deadline has come: the statuses of
    its last stretch, which a monitor lagging the clock delivers late, decide its verdict."""
    wall = WallClock()
    runner = ProgramRunner(program, monitor_guard_s=30.0, wall_clock=wall)
    runner.start(0.0)
    runner.observe_status(status(0.5, StatusState.SLIPPING))
    assert runner.update(1.2) == [] and not runner.outcomes  # the clock is past 1.0, the statuses are not
    runner.observe_status(status(0.9, StatusState.STABLE))  # late, from the segment's last stretch
    assert runner.update(1.3) == [] and not runner.outcomes
    runner.observe_status(status(1.0, StatusState.STABLE))  # at the deadline: every status of the segment is in
    (second,) = runner.update(1.3)
    assert second.segment.name == "n0900" and second.start_time == 1.0  # the plan's start, not the late end
    assert runner.outcomes[0].verdict is Verdict.STABLE and runner.unconfirmed == []


def test_a_segment_waits_for_the_monitor_no_longer_than_its_guard(program: TestProgram) -> None:
    wall = WallClock()
    runner = ProgramRunner(program, monitor_guard_s=30.0, wall_clock=wall)
    runner.start(0.0)
    runner.observe_status(status(0.5, StatusState.SLIPPING))
    assert runner.update(1.0) == []
    wall.now = 29.9
    assert runner.update(1.0) == []
    wall.now = 30.1
    (second,) = runner.update(1.0)
    assert second.segment.name == "n0900" and runner.outcomes[0].verdict is Verdict.SLIPPING
    assert runner.unconfirmed == ["load_up: the monitor's statuses end at 0.500 s, the segment at 1.000 s"]


def test_without_a_monitor_guard_a_segment_ends_at_its_deadline(program: TestProgram) -> None:
    runner = ProgramRunner(program)  # offline replays and the tests above: no monitor to wait for
    runner.start(0.0)
    (second,) = runner.update(1.0)
    assert second.segment.name == "n0900" and runner.outcomes[0].verdict is Verdict.UNKNOWN
