"""The rig twin: the engine driven chunk by chunk, the sensors' pulses, the counters' speeds and
the ground truth.

The speeds measured from pulses are checked against the engine's true speeds with bounds derived
here (exact at constant speed without jitter; the truncated jitter bounds the error otherwise);
the slip from the sensors over whole cage revolutions (the batch
:func:`~bearing_rig_sim.analysis.slip.whole_revolution_slip`, independent of the twin) is checked
against the ground truth over the same windows within 0.1 percentage points (issue 5).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from bearing_rig_sim.analysis.slip import BearingKinematics, whole_revolution_slip
from bearing_rig_sim.config import config_path
from bearing_rig_sim.dynamics import MIN_AXIAL_LOAD, BearingDynamics, BearingParameters
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.instruments.fibre_optic import JITTER_CLIP, FibreOpticSettings
from bearing_rig_sim.instruments.registry import InstrumentSet
from bearing_rig_sim.rig.speed_profile import SpeedProfileKind
from bearing_rig_sim.simulation.drive import SpindleCommand
from bearing_rig_sim.simulation.twin import AxialLoadError, MomentError, RadialLoadError, RigTwin, TwinError, twin_options
from conftest import bearing_section

RPM = math.pi / 30.0
BEARING = config_path("bearings", "h7006c.yaml")


def epicyclic_ratio() -> float:
    """n_s / n_i = (1 - Dw cos(alpha) / dm) / 2, from the bearing file's numbers (paper Eq. 12)."""
    g = bearing_section("geometry")
    return 0.5 * (1.0 - g["ball_diameter_m"] * math.cos(math.radians(g["contact_angle_deg"])) / g["pitch_diameter_m"])


def sensors(jitter: float = 0.0, spindle_strips: int = 4, cage_strips: int = 3, window: int = 1) -> InstrumentSet:
    def shaft(sensor_id: str, measures: str, strips: int, phase: float, seed: int) -> FibreOpticSettings:
        return FibreOpticSettings(
            kind="fibre_optic",
            topic=f"/rig/{sensor_id}/pulses",
            measures=measures,
            sensor_id=sensor_id,
            strip_count=strips,
            phase_rad=phase,
            timing_jitter_std_s=jitter,
            pulse_drop_probability=0.0,
            counter_revolutions_per_window=window,
            seed=seed,
        )

    return InstrumentSet({"spindle": shaft("spindle", "inner_ring_angle", spindle_strips, 0.0, 1), "cage": shaft("cage", "cage_angle", cage_strips, 0.5, 2)})


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.calibrated()


UNLIMITED_LOADERS = {"max_radial_load": math.inf, "max_moment": math.inf}
"""A bench with radial and moment loaders of any size (the shipped rig loads only axially)."""


def make_twin(params: BearingParameters, config: InstrumentSet | None = None, **options: float) -> RigTwin:
    """The simulator's twin (its shipped settings and rig limits) with unlimited loaders."""
    engine = BearingDynamics(params)
    return RigTwin(engine, config or sensors(), BearingKinematics.from_config(BEARING), **(twin_options() | UNLIMITED_LOADERS | options))


def test_counted_speeds_equal_the_true_speeds_at_constant_speed_without_jitter(params):
    twin = make_twin(params, initial_speed=1500 * RPM)
    for _ in range(800):
        out = twin.tick()
    truth, measured = out.truth, out.measured
    assert truth is not None
    assert truth.inner_ring_speed == pytest.approx(1500 * RPM, rel=1e-12)
    assert measured.inner_ring_speed == pytest.approx(truth.inner_ring_speed, rel=1e-6)
    assert measured.cage_speed == pytest.approx(truth.cage_speed, rel=1e-6)
    # pulse-counted angles: whole strip spacings, within one spacing of the true angle turned
    obs = twin.engine.observe()
    assert measured.inner_ring_angle % (2 * math.pi / 4) == pytest.approx(0.0, abs=1e-9)
    assert 0.0 <= obs.inner_ring_angle - measured.inner_ring_angle < 2 * (2 * math.pi / 4)


def test_counted_speeds_with_jitter_stay_within_the_jitter_bound(params):
    jitter = 1e-6
    twin = make_twin(params, sensors(jitter=jitter), initial_speed=2100 * RPM)
    errors = []
    for _ in range(600):
        out = twin.tick()
        if out.spindle_pulses and out.time > 0.2:
            assert out.truth is not None
            period = 2 * math.pi / out.truth.inner_ring_speed
            bound = 2 * JITTER_CLIP * jitter / period  # both ends of a one-revolution window
            errors.append(abs(out.measured.inner_ring_speed / out.truth.inner_ring_speed - 1.0) / bound)
    assert errors and max(errors) <= 1.0
    assert max(errors) > 0.0  # the jitter is really there


def test_pulses_are_ordered_inside_their_chunk_and_counted_whole(params):
    twin = make_twin(params, initial_speed=900 * RPM)
    spindle, cage = [], []
    for _ in range(500):
        out = twin.tick()
        for p in out.spindle_pulses + out.cage_pulses:
            assert out.start_time < p.time <= out.time + 1e-12
        spindle += out.spindle_pulses
        cage += out.cage_pulses
    t = [p.time for p in spindle]
    assert all(b > a for a, b in zip(t, t[1:]))
    assert [p.pulse_index for p in spindle] == list(range(len(spindle)))
    assert all(p.strip_count == 4 and p.revolution == p.pulse_index // 4 and p.sensor_id == "spindle" for p in spindle)
    assert all(p.strip_count == 3 and p.sensor_id == "cage" for p in cage)
    # 0.5 s at 900 rpm = 7.5 revolutions = 30 strip passages (one may fall either side)
    assert abs(len(spindle) - 30) <= 1
    # the cage turns at about 0.43 of the spindle (a few percent of slip)
    assert len(cage) / 3 == pytest.approx(7.5 * epicyclic_ratio(), rel=0.1)


def test_truth_summary_fields(params):
    twin = make_twin(params, initial_speed=1200 * RPM, initial_axial_load=150.0)
    for _ in range(100):
        out = twin.tick()
    t = out.truth
    assert t is not None
    ratio = epicyclic_ratio()
    assert t.time == pytest.approx(0.1, abs=1e-9)
    assert t.step_count == 100 * 25  # 1 ms chunks of 40 us steps
    assert t.theoretical_cage_speed == pytest.approx(ratio * 1200 * RPM, rel=1e-12)
    assert t.slip_rate == pytest.approx((1.0 - t.cage_speed / (ratio * t.inner_ring_speed)) * 100.0, rel=1e-9)
    assert 0.0 < t.slip_rate < 10.0
    assert t.axial_load == 150.0
    # 16 balls share the axial load along their contact angle: Q ~ F / (Z sin a)
    assert t.inner_contact_load_mean == pytest.approx(150.0 / (16 * math.sin(t.inner_contact_angle)), rel=0.05)
    assert t.inner_contact_load_max >= t.inner_contact_load_mean > 0.0
    assert t.outer_contact_load_max >= t.outer_contact_load_mean > 0.0
    assert math.radians(10) < t.inner_contact_angle < math.radians(25)
    assert t.inner_ring_axial_displacement > 0.0
    assert t.inner_ring_acceleration == pytest.approx(0.0, abs=1e-6)
    assert t.cage_whirl_radius == 0.0  # axial load only: the cage stays on the axis
    assert twin.tick(with_truth=False).truth is None


def test_truth_carries_the_cage_whirl_radius(params):
    """A cage knocked off the axis (40 um, 20 mm/s outward): the truth's whirl radius is the
    engine's cage-centre distance at the chunk's end, non-zero and within the land clearance."""
    twin = make_twin(params, initial_speed=1200 * RPM, initial_axial_load=150.0)
    twin.engine.ring[kn.R_CX] = 40e-6
    twin.engine.ring[kn.R_CVX] = 0.02
    out = twin.tick()
    assert out.truth is not None
    radius = out.truth.cage_whirl_radius
    assert radius == math.hypot(twin.engine.ring[kn.R_CX], twin.engine.ring[kn.R_CY])
    assert 0.0 < radius < params.land_clearance


def test_sensor_slip_agrees_with_ground_truth_over_whole_revolution_windows(params):
    """Issue 5: within 0.1 percentage points, through a STEP ramp, a hold, a constant
    acceleration and a hold, with the shipped sensors (config/rig.yaml: 4 strips, 1 us jitter)."""
    twin = RigTwin(BearingDynamics(params), InstrumentSet.from_rig_file(), BearingKinematics.from_config(BEARING), **twin_options())
    twin.command_spindle(SpindleCommand(1500 * RPM, SpeedProfileKind.STEP, ramp_time=1.0))
    times, inner, cage, spindle_t, cage_t = [0.0], [0.0], [0.0], [], []
    for i in range(2700):
        if i == 1500:
            twin.command_spindle(SpindleCommand(1800 * RPM, SpeedProfileKind.CONSTANT_ACCELERATION, acceleration=40.0))
        out = twin.tick()
        assert out.truth is not None
        times.append(out.time)
        inner.append(out.truth.inner_ring_speed)
        cage.append(out.truth.cage_speed)
        spindle_t += [p.time for p in out.spindle_pulses]
        cage_t += [p.time for p in out.cage_pulses]
    assert inner[-1] == pytest.approx(1800 * RPM, rel=1e-9)  # the ramp ended (31.4 rad/s at 40 rad/s^2)
    windows = whole_revolution_slip(np.array(cage_t), 4, np.array(spindle_t), 4, BearingKinematics.from_config(BEARING))
    # ground truth over each window: mean true speeds (trapezoid over the chunks), their slip
    t = np.array(times)
    turned_inner = np.concatenate([[0.0], np.cumsum(np.diff(t) * 0.5 * (np.array(inner[1:]) + np.array(inner[:-1])))])
    turned_cage = np.concatenate([[0.0], np.cumsum(np.diff(t) * 0.5 * (np.array(cage[1:]) + np.array(cage[:-1])))])
    start = windows.end_time - 2 * math.pi / windows.cage_speed
    duration = windows.end_time - start
    mean_inner = (np.interp(windows.end_time, t, turned_inner) - np.interp(start, t, turned_inner)) / duration
    mean_cage = (np.interp(windows.end_time, t, turned_cage) - np.interp(start, t, turned_cage)) / duration
    truth_slip = (1.0 - mean_cage / (epicyclic_ratio() * mean_inner)) * 100.0
    moving = mean_inner > 20.0
    assert moving.sum() >= 18  # about 10 cage revolutions per second at 1500-1800 rpm
    difference = np.abs(windows.slip_pct[moving] - truth_slip[moving])
    assert difference.max() < 0.1
    accelerating = moving & (windows.end_time > 1.6) & (windows.end_time < 2.2)
    assert accelerating.sum() >= 5  # the constant-acceleration stretch is covered


def test_axial_load_is_validated_and_raised_to_the_engine_minimum(params):
    twin = make_twin(params, initial_speed=500 * RPM, initial_axial_load=100.0)
    with pytest.raises(AxialLoadError, match="finite"):
        twin.set_axial_load(math.nan)
    with pytest.raises(AxialLoadError, match=">= 0"):
        twin.set_axial_load(-5.0)
    assert twin.axial_load == 100.0 and not twin.load_clamped
    assert twin.set_axial_load(0.3) == MIN_AXIAL_LOAD
    assert twin.load_clamped and twin.requested_axial_load == 0.3
    out = twin.tick()
    assert out.truth is not None and out.truth.axial_load == MIN_AXIAL_LOAD
    assert twin.set_axial_load(250.0) == 250.0 and not twin.load_clamped
    out = twin.tick()
    assert out.truth is not None and out.truth.axial_load == 250.0


def test_radial_load_is_the_magnitude_of_its_components_and_reaches_the_engine(params):
    """force.x, force.y (3-4-5: 300 N, 400 N) give a 500 N radial load applied every chunk; a
    non-finite component or a bad axial force leaves both loads as they were; the axisymmetric
    stiff model refuses any radial load."""
    twin = make_twin(params, initial_speed=900 * RPM, initial_axial_load=163.0)
    assert twin.set_loads(163.0, 300.0, -400.0) == (163.0, 500.0)
    twin.tick()
    assert twin.engine.radial_load == 500.0
    assert twin.engine.radial_angle == pytest.approx(math.atan2(-4.0, 3.0), abs=1e-15)  # the load zone's azimuth
    with pytest.raises(RadialLoadError, match="force.y must be a finite"):
        twin.set_loads(200.0, 0.0, math.inf)
    with pytest.raises(AxialLoadError, match=">= 0"):
        twin.set_loads(-1.0, 0.0, 0.0)
    assert (twin.axial_load, twin.radial_load) == (163.0, 500.0)
    assert twin.set_loads(163.0) == (163.0, 0.0)
    twin.tick()
    assert twin.engine.radial_load == 0.0
    stiff = RigTwin(
        BearingDynamics(params, model="stiff"),
        sensors(),
        BearingKinematics.from_config(BEARING),
        **(twin_options() | UNLIMITED_LOADERS | {"initial_axial_load": 163.0}),
    )
    with pytest.raises(RadialLoadError, match="reduced model"):
        stiff.set_loads(163.0, 1.0, 0.0)
    assert stiff.set_loads(170.0, 0.0, 0.0) == (170.0, 0.0)


def test_the_rig_files_radial_limit_bounds_the_radial_force(tmp_path):
    """The rig file is the authority on the loading chain: the shipped one (the paper's bench
    loads only axially, combined_loading limits 0 N and 0 N m) refuses any radial force or
    moment, naming the limit and the value, and keeps the loads it had; a rig file stating a
    radial loader of 800 N takes 800 N and refuses 800.5 N."""
    shipped = RigTwin.from_files(initial_axial_load=163.0)
    with pytest.raises(RadialLoadError, match=r"radial force: 5 N is above the rig's limit of 0 N \(combined_loading\.max_radial_setpoint_n in rig\.yaml\)"):
        shipped.set_loads(200.0, 3.0, 4.0)
    with pytest.raises(MomentError, match=r"moment: 1 N m is above the rig's limit of 0 N m \(combined_loading\.max_moment_setpoint_n_m in rig\.yaml\)"):
        shipped.set_loads(200.0, 0.0, 0.0, 0.0, 1.0)
    assert (shipped.axial_load, shipped.radial_load, shipped.moment) == (163.0, 0.0, (0.0, 0.0))
    assert shipped.set_loads(200.0, 0.0, 0.0) == (200.0, 0.0)
    doc = yaml.safe_load(config_path("rig.yaml").read_text())
    doc["combined_loading"]["max_radial_setpoint_n"] = 800.0
    radial_rig = tmp_path / "radial_rig.yaml"
    radial_rig.write_text(yaml.safe_dump(doc))
    twin = RigTwin.from_files(None, None, radial_rig, initial_axial_load=163.0)
    assert twin.set_loads(163.0, 0.0, 800.0) == (163.0, 800.0)
    with pytest.raises(RadialLoadError, match=r"800\.5 N is above the rig's limit of 800 N \(combined_loading\.max_radial_setpoint_n in radial_rig\.yaml\)"):
        twin.set_loads(163.0, 0.0, 800.5)
    assert twin.radial_load == 800.0


def test_deceleration_to_rest_keeps_whole_chunks_and_the_counters_fall_to_zero(params):
    twin = make_twin(params, initial_speed=30.0, counter_timeout=0.5)
    twin.command_spindle(SpindleCommand(0.0, SpeedProfileKind.STEP, ramp_time=0.3))
    last = 0.0
    for _ in range(1200):
        out = twin.tick()
        assert out.time - last == pytest.approx(1e-3, abs=1e-9)  # the clock keeps its pace
        last = out.time
    assert out.truth is not None and out.truth.inner_ring_speed == 0.0
    assert math.isnan(out.truth.slip_rate)  # undefined at rest
    assert (out.measured.inner_ring_speed, out.measured.cage_speed) == (0.0, 0.0)


def test_bad_chunk_lengths_are_refused(params):
    with pytest.raises(TwinError, match="whole number"):
        make_twin(params, chunk=1.05e-3)
    with pytest.raises(TwinError, match="chunk"):
        make_twin(params, chunk=0.0)
    twin = make_twin(params)
    with pytest.raises(TwinError, match="whole number"):
        twin.tick(1e-5)
