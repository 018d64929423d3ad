"""The spindle drive: per-chunk accelerations that follow the STEP ramp and constant acceleration,
commands taking effect from the current speed, queued commands, refusals.

Expectations are computed here from the profiles' own formulas (the paper's STEP cubic,
w0 + a t), not taken from the drive: the test integrates the accelerations the drive gives, as
the engine does (constant acceleration within a chunk), and compares the speeds reached.
"""

from __future__ import annotations

import math

import pytest

from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.speed_profile import SpeedProfileKind
from bearing_rig_sim.simulation.drive import SpindleCommand, SpindleCommandError, SpindleDrive, profile_from_code

STEP, ACCEL = SpeedProfileKind.STEP, SpeedProfileKind.CONSTANT_ACCELERATION
UNLIMITED = {"max_speed": math.inf, "max_acceleration": math.inf, "max_lead": math.inf}
"""A drive without limits: the profiles' arithmetic alone (the rig's limits are tested below)."""


def cubic(t: float, t0: float, w0: float, t1: float, w1: float) -> float:
    """The STEP drive function written out: w0 + (w1 - w0) D^2 (3 - 2 D), D = (t - t0)/(t1 - t0)."""
    if t <= t0:
        return w0
    if t >= t1:
        return w1
    d = (t - t0) / (t1 - t0)
    return w0 + (w1 - w0) * d * d * (3.0 - 2.0 * d)


def run(drive: SpindleDrive, speed: float, t: float, h: float, n: int, feedback: bool = True) -> list[tuple[float, float, float]]:
    """Integrate ``n`` chunks; returns (chunk end time, speed there, chunk acceleration)."""
    out = []
    for _ in range(n):
        a = drive.chunk_acceleration(t, h, speed if feedback else None)
        speed += a * h
        t += h
        out.append((t, speed, a))
    return out


def test_step_ramp_followed_at_every_chunk_boundary_and_ends_exactly():
    drive = SpindleDrive(0.0, **UNLIMITED)
    drive.submit(SpindleCommand(100.0, STEP, ramp_time=1.0), now=0.0, current_speed=0.0)
    trace = run(drive, 0.0, 0.0, 1e-3, 1500)
    for t, w, _ in trace[::37]:
        assert w == pytest.approx(cubic(t, 0.0, 0.0, 1.0, 100.0), abs=1e-9)
    end = [(t, w, a) for t, w, a in trace if t >= 1.0 - 1e-12]
    assert all(w == pytest.approx(100.0, abs=1e-9) for _, w, _ in end)
    assert all(abs(a) < 1e-6 for _, _, a in end[1:])  # after the ramp: no acceleration
    # without speed feedback the drive's own profile gives exactly zero after the ramp
    assert drive.chunk_acceleration(1.2, 1e-3) == 0.0
    # the chunk acceleration is the chord of the cubic: (w(t+h) - w(t)) / h
    assert drive.chunk_acceleration(0.5, 1e-3) == pytest.approx((cubic(0.501, 0, 0, 1, 100) - cubic(0.5, 0, 0, 1, 100)) / 1e-3)


def test_step_ramp_zero_duration_is_a_one_chunk_jump():
    drive = SpindleDrive(10.0, **UNLIMITED)
    drive.submit(SpindleCommand(50.0, STEP, ramp_time=0.0), now=2.0, current_speed=10.0)
    assert drive.chunk_acceleration(2.0, 1e-3, 10.0) == pytest.approx(40.0 / 1e-3)
    assert drive.chunk_acceleration(2.001, 1e-3, 50.0) == 0.0


@pytest.mark.parametrize("h", [1e-3, 3e-3])
def test_constant_acceleration_reaches_target_at_delta_w_over_alpha(h):
    drive = SpindleDrive(50.0, **UNLIMITED)
    drive.submit(SpindleCommand(150.0, ACCEL, acceleration=40.0), now=0.0, current_speed=50.0)
    trace = run(drive, 50.0, 0.0, h, int(round(3.0 / h)))
    reach = 100.0 / 40.0  # 2.5 s
    for t, w, a in trace:
        if t <= reach - h:
            assert a == pytest.approx(40.0, rel=1e-9)
            assert w == pytest.approx(50.0 + 40.0 * t, rel=1e-9)
        elif t >= reach + h:
            assert w == pytest.approx(150.0, abs=1e-9)
            assert a == pytest.approx(0.0, abs=1e-6)
    # the chunk holding the end of the ramp ends exactly on the target
    t_cross, w_cross, a_cross = next((t, w, a) for t, w, a in trace if t >= reach - 1e-12)
    assert w_cross == pytest.approx(150.0, abs=1e-9)
    assert 0.0 < a_cross <= 40.0 + 1e-9


def test_constant_deceleration_goes_down_to_the_target():
    drive = SpindleDrive(150.0, **UNLIMITED)
    drive.submit(SpindleCommand(30.0, ACCEL, acceleration=60.0), now=1.0, current_speed=150.0)
    trace = run(drive, 150.0, 1.0, 1e-3, 2500)
    assert trace[0][2] == pytest.approx(-60.0)
    t_end = 1.0 + 120.0 / 60.0
    assert [w for t, w, _ in trace if t >= t_end][0] == pytest.approx(30.0, abs=1e-9)
    assert trace[999][1] == pytest.approx(150.0 - 60.0 * 1.0, rel=1e-9)


def test_command_starts_from_the_current_speed_not_the_old_profile():
    drive = SpindleDrive(0.0, **UNLIMITED)
    drive.submit(SpindleCommand(100.0, STEP, ramp_time=1.0), now=0.0, current_speed=0.0)
    # the spindle is actually at 37 rad/s when the next command arrives at t = 0.4 s
    drive.submit(SpindleCommand(80.0, STEP, ramp_time=2.0), now=0.4, current_speed=37.0)
    p = drive.profile
    assert (p.start_time, p.start_speed, p.target_speed, p.ramp_time) == (0.4, 37.0, 80.0, 2.0)
    trace = run(drive, 37.0, 0.4, 1e-3, 2600)
    for t, w, _ in trace[::101]:
        assert w == pytest.approx(cubic(t, 0.4, 37.0, 2.4, 80.0), abs=1e-9)


def test_speed_drift_is_corrected_in_the_next_chunk():
    drive = SpindleDrive(100.0, **UNLIMITED)
    # the spindle is 0.5 rad/s off the profile: the next chunk brings it back
    a = drive.chunk_acceleration(3.0, 1e-3, 99.5)
    assert 99.5 + a * 1e-3 == pytest.approx(100.0, abs=1e-12)


def test_future_command_waits_for_its_time():
    drive = SpindleDrive(20.0, **UNLIMITED)
    drive.submit(SpindleCommand(60.0, STEP, ramp_time=0.5, time=0.2005), now=0.1, current_speed=20.0)
    assert len(drive.pending) == 1
    assert drive.chunk_acceleration(0.200, 1e-3, 20.0) == 0.0  # not yet: 0.2005 is inside this chunk
    assert drive.chunk_acceleration(0.201, 1e-3, 20.0) > 0.0  # takes effect at the next boundary
    assert drive.pending == ()
    assert drive.profile.start_time == 0.201 and drive.profile.start_speed == 20.0
    # a command stamped in the past takes effect at once
    drive.submit(SpindleCommand(10.0, STEP, ramp_time=0.0, time=0.05), now=0.3, current_speed=25.0)
    assert drive.profile.start_time == 0.3 and drive.profile.start_speed == 25.0


@pytest.mark.parametrize(
    ("command", "field"),
    [
        (SpindleCommand(math.nan), "target_speed"),
        (SpindleCommand(math.inf), "target_speed"),
        (SpindleCommand(-1.0), "target_speed"),
        (SpindleCommand(700.0), "target_speed"),  # above the 600 rad/s limit below
        (SpindleCommand(100.0, STEP, ramp_time=-0.1), "ramp_time"),
        (SpindleCommand(100.0, STEP, ramp_time=math.nan), "ramp_time"),
        (SpindleCommand(100.0, ACCEL, acceleration=0.0), "acceleration"),
        (SpindleCommand(100.0, ACCEL, acceleration=-5.0), "acceleration"),
        (SpindleCommand(100.0, ACCEL, acceleration=math.nan), "acceleration"),
        (SpindleCommand(100.0, ACCEL, acceleration=5000.0), "acceleration"),  # above 1000 rad/s^2
        (SpindleCommand(100.0, STEP, time=math.nan), "time"),
        (SpindleCommand(100.0, STEP, time=1.7e9), "time"),  # another clock: far ahead
    ],
)
def test_invalid_commands_are_refused_and_the_last_valid_one_kept(command, field):
    drive = SpindleDrive(0.0, max_speed=600.0, max_acceleration=1000.0, max_lead=10.0)
    drive.submit(SpindleCommand(120.0, STEP, ramp_time=1.0), now=0.0, current_speed=0.0)
    before = drive.profile
    with pytest.raises(SpindleCommandError, match=field) as info:
        drive.submit(command, now=0.5, current_speed=60.0)
    assert isinstance(info.value, RigError)
    assert drive.profile == before and drive.pending == ()
    assert drive.chunk_acceleration(0.5, 1e-3, cubic(0.5, 0, 0, 1, 120)) > 0.0  # still ramping to 120


def test_profile_codes_of_the_message():
    assert profile_from_code(0) is STEP
    assert profile_from_code(1) is ACCEL
    with pytest.raises(SpindleCommandError, match="profile"):
        profile_from_code(7)


def test_bad_chunk_and_bad_limits_are_refused():
    drive = SpindleDrive(0.0, **UNLIMITED)
    with pytest.raises(SpindleCommandError, match="h"):
        drive.chunk_acceleration(0.0, 0.0)
    with pytest.raises(SpindleCommandError, match="current_speed"):
        drive.chunk_acceleration(0.0, 1e-3, math.nan)
    with pytest.raises(SpindleCommandError, match="max_speed"):
        SpindleDrive(0.0, **(UNLIMITED | {"max_speed": 0.0}))
    with pytest.raises(SpindleCommandError, match="initial_speed"):
        SpindleDrive(-3.0, **UNLIMITED)
