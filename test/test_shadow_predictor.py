"""The engine driven by measured inputs (bearing_rig_sim.shadow.predictor): it follows the speed
points exactly, applies the load it is given, settles within the shadow's settle time, and
restarts across gaps."""

from __future__ import annotations

import math

import pytest

from bearing_rig_sim.analysis.slip import BearingKinematics
from bearing_rig_sim.config import config_path, rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.shadow import ShadowSettings
from bearing_rig_sim.shadow.inputs import SpeedPoint
from bearing_rig_sim.shadow.predictor import MeasuredDrive

T0 = 1.7e9
"""A bench system clock, s."""


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    """The shadow twin's bearing and calibration (config/shadow.yaml), lubricant at its reference."""
    st = ShadowSettings.from_yaml()
    return BearingParameters.from_yaml(st.bearing_file, st.calibration_file)


def slip(kin: BearingKinematics, cage: float, inner: float) -> float:
    return float(kin.slip_rate(cage, inner))


def test_follows_a_ramp_and_applies_the_load(params: BearingParameters) -> None:
    drive = MeasuredDrive(params, load_at=lambda _t: 250.0)
    w0, a = 50.0, 40.0  # rad/s, rad/s^2
    for k in range(41):
        t = 0.01 * k
        drive.follow(SpeedPoint(T0 + t, w0 + a * t, 0.05))
    # mean of a linear ramp over [0.1, 0.3]: w0 + a * 0.2 (closed form)
    p = drive.predict(T0 + 0.1, T0 + 0.3)
    assert p is not None
    assert p.inner_ring_speed == pytest.approx(w0 + a * 0.2, rel=1e-4)
    assert p.axial_load == pytest.approx(250.0)
    assert drive.engine.inner_ring_speed == pytest.approx(w0 + a * 0.4, rel=1e-6)
    assert drive.time == pytest.approx(T0 + 0.4, abs=drive.engine.time_step)
    assert drive.predict(T0 + 0.3, T0 + 0.5) is None  # not yet reached


def test_slip_settles_within_the_settle_time(params: BearingParameters) -> None:
    settle = ShadowSettings.from_yaml().settle_s
    kin = BearingKinematics.from_config(config_path("bearings", "h7006c.yaml"))
    drive = MeasuredDrive(params, load_at=lambda _t: 100.0)
    w = rpm_to_rad_s(900.0)
    for k in range(121):
        drive.follow(SpeedPoint(T0 + 0.01 * k, w, 0.067))
    early = drive.predict(T0 + settle, T0 + settle + 0.15)
    late = drive.predict(T0 + 1.0, T0 + 1.15)
    assert early is not None and late is not None
    # once settled the slip over a cage revolution changes by less than a fifth of the
    # calibration's 0.047 pp RMS
    assert abs(slip(kin, early.cage_speed, early.inner_ring_speed) - slip(kin, late.cage_speed, late.inner_ring_speed)) < 0.01
    # and the slip is a real one: the kinematic start (zero slip) has been left
    assert slip(kin, late.cage_speed, late.inner_ring_speed) > 1.0


def test_a_gap_in_the_speed_points_restarts_the_engine(params: BearingParameters) -> None:
    drive = MeasuredDrive(params, max_speed_gap=0.5, load_at=lambda _t: 100.0)
    for k in range(11):
        drive.follow(SpeedPoint(T0 + 0.01 * k, 100.0, 0.06))
    drive.follow(SpeedPoint(T0 + 2.0, 150.0, 0.04))  # 1.9 s later: a stop or a sensor gap
    assert drive.restarts == 2 and drive.started_at == T0 + 2.0
    assert drive.engine.inner_ring_speed == 150.0
    assert drive.predict(T0 + 0.05, T0 + 2.0) is None


def test_no_start_before_a_force_is_known(params: BearingParameters) -> None:
    force = [math.nan]
    drive = MeasuredDrive(params, load_at=lambda _t: force[0])
    drive.follow(SpeedPoint(T0, 100.0, 0.06))
    assert drive.origin is None and drive.restarts == 0
    force[0] = 120.0
    drive.follow(SpeedPoint(T0 + 0.01, 100.0, 0.06))
    assert drive.restarts == 1 and drive.engine.axial_load == 120.0
