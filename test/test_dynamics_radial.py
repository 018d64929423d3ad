"""Radial load in the dynamic engine (reduced model): per-ball loads from the inner ring's
quasi-static balance at each ball's orbital position (kernels.solve_quasi_static), so loads,
ball speeds and pocket forces vary around the orbit (docs/model.md, Combined loads)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters, DynamicsInputError
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.quasi_static import LoadCase, QuasiStaticBearing
from bearing_rig_sim.rig.program import RigLimits, load_program

RPM = math.pi / 30.0
Z = 16


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.calibrated()


def _slip(params: BearingParameters, engine: BearingDynamics, duration: float) -> float:
    avg = engine.advance(duration)
    return 100.0 * (1.0 - avg.cage_speed / (params.epicyclic_ratio * avg.inner_ring_speed))


def test_the_full_model_equals_the_axisymmetric_one_under_pure_axial_load(params: BearingParameters) -> None:
    """The engine with its ring's radial DOFs active (started under a 300 N radial load that is
    then removed, so the ring's radial balance is solved every step) against the engine that
    never had a radial load: the same cage speed within 0.01 percentage points of slip (issue
    23), once the radial displacement has gone back to (almost) zero. The cage, pushed off
    centre by the pockets under the radial load, keeps whirling for a while after it is removed
    (its orbit decays slowly: the land film's radial force grows as eps^2), and the ball-speed
    variation of that orbit moves the ring by nanometres (< 1e-8 m against microns under the
    load)."""
    plain = BearingDynamics(params)
    plain.initialise(2700 * RPM, 200.0)
    full = BearingDynamics(params)
    full.initialise(2700 * RPM, 200.0, radial_load=300.0)
    full.advance(0.05)
    full.advance(0.25, radial_load=0.0)
    plain.advance(0.3)
    assert abs(full.ring[kn.R_DX]) < 1e-8 and abs(full.ring[kn.R_DY]) < 1e-8
    assert full.ring[kn.R_DX] != 0.0 or full.ring[kn.R_DY] != 0.0  # the radial path stayed active
    assert _slip(params, full, 0.1) == pytest.approx(_slip(params, plain, 0.1), abs=0.01)


def test_ball_loads_match_the_quasi_static_solution_and_stribeck(params: BearingParameters) -> None:
    """F_a = 163 N, F_r = 500 N at 900 rpm (centrifugal force 0.03 N: the low-speed case), balls
    at psi_j = 2 pi j / Z: the engine's per-ball inner loads and the ring's radial displacement
    against the Jones-Harris solver (dynamics/quasi_static.py, tested on its own against the
    closed forms) within 1 %, and the largest load against Stribeck/Sjovall's
    4.37 F_r / (Z cos 15 deg) = 141.4 N within 3 %."""
    engine = BearingDynamics(params)
    engine.initialise(900 * RPM, 163.0, radial_load=500.0)
    engine.advance(engine.time_step)
    obs = engine.observe()
    qs = QuasiStaticBearing(params).solve(LoadCase(163.0, 500.0))
    assert engine.ring[kn.R_DX] == pytest.approx(qs.displacement[1], rel=0.01)
    loaded = qs.inner_loads > 1.0
    # (0.5 N: the ball at the edge of the zone carries 1 N, set by sub-nanometre approaches)
    np.testing.assert_allclose(obs.inner_contact_loads[loaded], qs.inner_loads[loaded], rtol=0.01, atol=0.5)
    assert float(obs.inner_contact_loads.max()) == pytest.approx(4.37 * 500.0 / (Z * math.cos(math.radians(15.0))), rel=0.03)
    assert float(np.sum(obs.inner_contact_loads * np.sin(obs.inner_contact_angles))) == pytest.approx(163.0, rel=1e-6)


@pytest.mark.parametrize("rpm", [0.0, 1.0, 5.0, 20.0, 49.0])
def test_a_start_below_50_rpm_under_combined_load_has_half_the_bearing_loaded(params: BearingParameters, rpm: float) -> None:
    """The start (initialise) between rest and 50 rpm under F_r = 500 N with
    F_a = 1.216 F_r tan 15 deg = 162.9 N, where the centrifugal force is micro-newtons:
    Stribeck/Sjovall's zero-clearance case, a load zone of half the bearing (epsilon = 0.5):
    balls within 67.5 deg of the load (the nearest to 90 deg inside it, Z = 16) loaded, those
    112.5 deg or more from it carrying nothing at the inner raceway (< 1e-6 of the largest
    load), the largest load 4.37 F_r / (Z cos 15 deg) = 141.4 N within 3 %. Before
    kernels.ball_jacobian the start found no equilibrium from 5 to 49 rpm."""
    f_r = 500.0
    f_a = 1.216 * f_r * math.tan(math.radians(15.0))
    engine = BearingDynamics(params)
    engine.initialise(rpm * RPM, f_a, radial_load=f_r)
    engine.advance(engine.time_step)  # the observation's contact data come from a step
    obs = engine.observe()
    psi = np.degrees(np.abs(np.angle(np.exp(1j * engine.ball[:, kn.B_THETA]))))
    q_max = 4.37 * f_r / (Z * math.cos(math.radians(15.0)))
    inside, outside = psi < 67.5 + 1.0, psi > 112.5 - 1.0
    assert np.count_nonzero(inside) == 7 and np.count_nonzero(outside) == 7
    assert float(obs.inner_contact_loads.max()) == pytest.approx(q_max, rel=0.03)
    assert np.all(obs.inner_contact_loads[inside] > 0.2 * q_max)
    assert np.all(obs.inner_contact_loads[outside] < 1e-6 * q_max)


@pytest.mark.parametrize("rpm", [1.0, 10.0, 30.0, 49.0])
@pytest.mark.parametrize("moment", [None, (2.0, 0.5)])
def test_a_bearing_started_below_50_rpm_under_combined_load_runs(params: BearingParameters, rpm: float, moment: tuple[float, float] | None) -> None:
    """Started at 1-49 rpm under 163 N axial, 500 N radial at 0.4 rad and (with the tilts
    free) a moment of (2.0, 0.5) N m, 0.1 s at that speed: no divergence (the engine's own
    check after every 5 ms), every ball and the cage turning forwards no faster than the inner
    ring (0.2 rad/s tolerance: engine.SPEED_TOLERANCE), the ring's axial balance held
    (sum Q_i sin a_i = F_a), and the load distribution still Stribeck's: with F_a = 163 N close
    to 1.216 F_r tan 15 deg (epsilon = 0.5) Q(psi) = Q_max cos(psi)^1.5, so the ball nearest
    the load, within half a ball pitch (11.25 deg) of it wherever the balls have orbited to,
    carries between cos(11.25 deg)^1.5 and 1 times Q_max = 4.37 F_r / (Z cos 15 deg) (3 %
    margin); under the moment, the balls' moment on the ring is the applied one."""
    engine = BearingDynamics(params)
    engine.initialise(rpm * RPM, 163.0, radial_load=500.0, radial_angle=0.4, moment=moment)
    omega = rpm * RPM
    for _ in range(20):
        engine.advance(0.005)
        speeds = np.concatenate([engine.cage[:, kn.C_OMEGA], engine.ball[:, kn.B_OMEGA]])
        assert np.all(np.isfinite(speeds)) and speeds.min() >= -0.2 and speeds.max() <= omega + 0.2
    obs = engine.observe()
    assert float(np.sum(obs.inner_contact_loads * np.sin(obs.inner_contact_angles))) == pytest.approx(163.0, rel=1e-6)
    if moment is None:
        q_max = 4.37 * 500.0 / (Z * math.cos(math.radians(15.0)))
        assert 0.97 * math.cos(math.radians(11.25)) ** 1.5 * q_max < float(obs.inner_contact_loads.max()) < 1.03 * q_max
    else:
        np.testing.assert_allclose(obs.ring_moment, moment, atol=1e-6)
    assert 0.0 < engine.cage_speed < 0.5 * omega + 0.2


def test_a_radial_load_makes_ball_speeds_vary_and_exercises_the_pockets(params: BearingParameters) -> None:
    """Under pure axial load every ball orbits alike and pushes its pocket alike; with a radial
    load the balls leaving the load zone fall behind and the cage pulls them (pocket forces of
    both signs), the balls in the zone drive it: the pocket forces the flexible cage absorbs."""
    engine = BearingDynamics(params)
    engine.initialise(900 * RPM, 163.0)
    engine.advance(0.2)
    axial = engine.observe()
    assert np.ptp(axial.ball_orbit_speeds) < 1e-6 * np.mean(axial.ball_orbit_speeds)
    assert np.all(axial.pocket_loads > 0.0)
    engine.advance(0.3, radial_load=500.0)
    radial = engine.observe()
    assert np.ptp(radial.ball_orbit_speeds) > 0.01 * np.mean(radial.ball_orbit_speeds)
    assert radial.pocket_loads.max() > 0.5 and radial.pocket_loads.min() < -0.1
    # a load zone, not every ball: outside it the balls keep only the pinch of their centrifugal
    # force (under 0.1 N at 900 rpm), under 1 % of the largest load
    zone = radial.inner_contact_loads > 0.01 * radial.inner_contact_loads.max()
    assert 4 <= np.count_nonzero(~zone) <= 12
    # the load zone stays where the load is (+x) while the balls orbit through it
    x = np.cos(engine.ball[:, kn.B_THETA])
    assert float(np.mean(x[zone])) > 0.3


def test_the_stiff_model_refuses_a_radial_load(params: BearingParameters) -> None:
    engine = BearingDynamics(params, model="stiff")
    with pytest.raises(DynamicsInputError, match="radial_load needs the reduced model"):
        engine.advance(engine.time_step, radial_load=100.0)
    with pytest.raises(DynamicsInputError, match="radial_load"):
        BearingDynamics(params).advance(0.001, radial_load=-5.0)


PROGRAM = """
name: side_load
description: a radial load at speed
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 163, dwell_s: 0.3}
  - {name: side, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 163, radial_load_n: 500, moment_n_m: 1.5, dwell_s: 1.0}
"""


def test_a_program_asking_for_a_radial_load_the_rig_cannot_give_is_refused(tmp_path: Path) -> None:
    """The rig file's combined_loading limits (0 N and 0 N m for the paper's axial-only bench):
    the segment and the limit are named; a rig file that allows them passes the values on."""
    rig_doc = yaml.safe_load((Path(__file__).parents[1] / "config" / "rig.yaml").read_text())
    assert rig_doc["combined_loading"] == {"max_radial_setpoint_n": 0.0, "max_moment_setpoint_n_m": 0.0}
    program = tmp_path / "side.yaml"
    program.write_text(PROGRAM)
    axial_only = tmp_path / "rig.yaml"
    axial_only.write_text(yaml.safe_dump(rig_doc))
    with pytest.raises(
        ConfigError,
        match=r"segments\[1\]\.radial_load_n: segment 'side': 500 N is above the rig's limit of 0 N \(combined_loading\.max_radial_setpoint_n in rig\.yaml\)",
    ):
        load_program(program, RigLimits.from_rig_file(axial_only))
    rig_doc["combined_loading"]["max_radial_setpoint_n"] = 800.0
    axial_only.write_text(yaml.safe_dump(rig_doc))
    with pytest.raises(ConfigError, match=r"segments\[1\]\.moment_n_m: segment 'side': 1\.5 N m is beyond the rig's limit of 0 N m"):
        load_program(program, RigLimits.from_rig_file(axial_only))
    rig_doc["combined_loading"]["max_moment_setpoint_n_m"] = 5.0
    axial_only.write_text(yaml.safe_dump(rig_doc))
    side = load_program(program, RigLimits.from_rig_file(axial_only)).segments[1]
    assert (side.radial_load, side.moment) == (500.0, 1.5)
