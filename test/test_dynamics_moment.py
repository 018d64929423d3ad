"""Moments and tilts of the inner ring in the dynamic engine (reduced model).

With a moment applied (``BearingDynamics.set_moment``) the inner ring's two tilts join its
axial and radial displacements as unknowns of the normal solve made every step; with none they
are held at zero (as the spindle's second bearing holds them) and the balls' moment on the ring
is reported as the reaction. Moments are counted as dynamics/quasi_static.py counts them:
M_x = sum Q_i sin a_i R_i cos psi, M_y with sin psi.

References: the Jones-Harris solver (dynamics/quasi_static.py, tested on its own against
Stribeck/Sjovall and Harris's thrust equilibrium), evaluated at the engine's own ball positions
relative to the load; and a hand calculation. An angular contact bearing's contact lines meet
the axis at its pressure centre, R_i tan a from the plane of the inner groove's curvature
centres (R_i the radius of their locus; Harris and Kotzalas, vol. 1, ch. 1): loads along them
have no moment about it. So a radial force F_r through the pressure centre (F_r at the centre
plane plus M = F_r R_i tan a) moves the ring without tilting it, and on an axially preloaded
bearing it adds to each ball a load antisymmetric about the load direction,
Q(psi) = Q_a + K cos psi with Q_a = F_a / (Z sin a) and K = 2 F_r / (Z cos a) (the balance of
the axial and radial forces, for K << Q_a); with the tilt held, the reaction moment of a radial
load is F_r R_i tan a.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters, DynamicsInputError
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.quasi_static import LoadCase, QuasiStaticBearing
from conftest import bearing_section

RPM = math.pi / 30.0
SPEED = 900 * RPM
"""The low-speed case: centrifugal force 0.03 N against ball loads of 10-140 N."""
GEOMETRY = bearing_section("geometry")
Z = GEOMETRY["ball_count"]
R_I = 0.5 * GEOMETRY["pitch_diameter_m"] + (GEOMETRY["inner_groove_curvature_ratio"] - 0.5) * GEOMETRY["ball_diameter_m"] * math.cos(
    math.radians(GEOMETRY["contact_angle_deg"])
)
"""Radius of the inner groove curvature centres' locus, m (21.347 mm)."""


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.calibrated()


def _turn(vector: tuple[float, float], angle: float) -> tuple[float, float]:
    c, s = math.cos(angle), math.sin(angle)
    return c * vector[0] - s * vector[1], s * vector[0] + c * vector[1]


def _engine(params: BearingParameters, axial: float, radial: float, angle: float, moment: tuple[float, float] | None) -> BearingDynamics:
    engine = BearingDynamics(params)
    engine.initialise(SPEED, axial, radial_load=radial, radial_angle=angle, moment=moment)
    engine.advance(0.1)
    return engine


def _reference(params: BearingParameters, engine: BearingDynamics, case: LoadCase, angle: float):  # type: ignore[no-untyped-def]
    """The Jones-Harris solution with the balls at the engine's azimuths relative to the load."""
    solver = QuasiStaticBearing(params)
    solver.psi = engine.ball[:, kn.B_THETA] - angle
    return solver.solve(case)


def test_combined_axial_radial_and_moment_match_the_quasi_static_solver(params: BearingParameters) -> None:
    """F_a = 163 N, F_r = 500 N at 0.5 rad, a moment of (2.5, 0.3) N m in the load's frame (the
    reaction with the tilt held is 2.83 N m: the ring tilts by about a milliradian) at 900 rpm,
    after 0.1 s: per-ball inner loads within 1 % of the largest (and 1 % per ball in the zone),
    tilts within 1 %, the balls' moment on the ring the applied one."""
    angle = 0.5
    moment = _turn((2.5, 0.3), angle)
    engine = _engine(params, 163.0, 500.0, angle, moment)
    obs = engine.observe()
    qs = _reference(params, engine, LoadCase(163.0, 500.0, moment=(2.5, 0.3), inner_ring_speed=SPEED, gyroscopic=False), angle)
    q, ref = obs.inner_contact_loads, qs.inner_loads
    assert np.max(np.abs(q - ref)) < 0.01 * ref.max()
    zone = ref > 1.0
    np.testing.assert_allclose(q[zone], ref[zone], rtol=0.01, atol=0.5)
    tilt = _turn(qs.tilt, angle)
    assert math.hypot(*tilt) > 5e-4  # a real tilt, not the held ring
    np.testing.assert_allclose(obs.inner_ring_tilt, tilt, rtol=0.01, atol=0.01 * math.hypot(*tilt))
    np.testing.assert_allclose(obs.ring_moment, moment, rtol=1e-6, atol=1e-6)


def test_with_no_moment_the_tilt_is_held_and_the_reaction_reported(params: BearingParameters) -> None:
    """F_a = 163 N, F_r = 500 N along +x, no moment: no tilt; the reaction moment is the
    quasi-static solver's (tilts held) within 1 % and the hand value F_r R_i tan a0 = 2.86 N m
    within 3 % (the loaded balls' contact angles spread around a0 = 15 deg). A moment then
    released returns the ring to the held tilt."""
    engine = _engine(params, 163.0, 500.0, 0.0, None)
    obs = engine.observe()
    assert obs.inner_ring_tilt == (0.0, 0.0)
    qs = _reference(params, engine, LoadCase(163.0, 500.0, inner_ring_speed=SPEED, gyroscopic=False), 0.0)
    assert obs.ring_moment[0] == pytest.approx(qs.reaction_moment[0], rel=0.01)
    assert abs(obs.ring_moment[1]) < 0.01 * obs.ring_moment[0]
    assert obs.ring_moment[0] == pytest.approx(500.0 * R_I * math.tan(math.radians(GEOMETRY["contact_angle_deg"])), rel=0.03)
    engine.set_moment((1.0, 0.0))
    engine.advance(0.01)
    assert engine.observe().inner_ring_tilt != (0.0, 0.0)
    engine.set_moment(None)
    engine.advance(0.01)
    assert engine.observe().inner_ring_tilt == (0.0, 0.0)
    assert engine.observe().ring_moment[0] == pytest.approx(obs.ring_moment[0], rel=0.01)


def test_a_force_through_the_pressure_centre_loads_the_balls_as_q_a_plus_k_cos_psi(params: BearingParameters) -> None:
    """F_a = 300 N, F_r = 40 N at 60 deg with M = F_r R_i tan a along it (the force acting at the
    pressure centre), tilts free: each ball carries Q_a + K cos(psi) (psi from the load
    direction, at the balls' own orbital angles) within 1 % of Q_a, antisymmetric about Q_a in
    the tilt's direction, and the ring does not tilt (< 1e-5 rad; the same moment alone, a pure
    couple, tilts the single bearing a hundred times more: it carries a couple only by changing
    its contact angles). The angle a is the loaded contact angle at 300 N from the Jones-Harris
    thrust solution (Harris's thrust equation, 0.01 deg in test_dynamics_quasi_static.py)."""
    axial, radial, angle = 300.0, 40.0, math.radians(60.0)
    a = float(QuasiStaticBearing(params).solve(LoadCase(axial)).inner_angles[0])
    moment = _turn((radial * R_I * math.tan(a), 0.0), angle)
    engine = _engine(params, axial, radial, angle, moment)
    obs = engine.observe()
    psi = engine.ball[:, kn.B_THETA] - angle
    q_a = axial / (Z * math.sin(a))
    k = 2.0 * radial / (Z * math.cos(a))
    np.testing.assert_allclose(obs.inner_contact_loads, q_a + k * np.cos(psi), rtol=0.0, atol=0.01 * q_a)
    assert max(abs(t) for t in obs.inner_ring_tilt) < 1e-5
    couple = _engine(params, axial, 0.0, angle, moment)
    assert math.hypot(*couple.observe().inner_ring_tilt) > 100.0 * math.hypot(*obs.inner_ring_tilt)


def test_a_moment_needs_the_reduced_model_and_finite_values(params: BearingParameters) -> None:
    with pytest.raises(DynamicsInputError, match="moment needs the reduced model"):
        BearingDynamics(params, model="stiff").set_moment((1.0, 0.0))
    with pytest.raises(DynamicsInputError, match="moment M_y must be finite"):
        BearingDynamics(params).set_moment((1.0, math.nan))


@pytest.mark.parametrize(
    "rpm,axial,radial,moment",
    [(770.0, 250.0, 640.0, (0.8, -4.1)), (8760.0, 310.0, 250.0, (3.9, 0.9)), (270.0, 710.0, 300.0, (-4.1, 1.6))],
)
def test_moments_applied_changed_and_released_at_speed_stay_within_bounds(
    params: BearingParameters, rpm: float, axial: float, radial: float, moment: tuple[float, float]
) -> None:
    """Moments of up to 4.3 N m (tilts of milliradians) applied under a radial load at speed,
    held through an acceleration of 500 rad/s^2 and released: the engine's run-time check
    (:meth:`BearingDynamics.check_state`, after every advance) passes, the balls' moment on the
    ring balances the applied one within 1 % (of its size) at every chunk, and after release the
    tilt is held again."""
    engine = BearingDynamics(params)
    engine.initialise(rpm * RPM, axial)
    engine.advance(0.05, radial_load=radial, radial_angle=2.0)
    engine.set_moment(moment)
    for accel in (0.0, 500.0, 0.0):
        for _ in range(5):
            engine.advance(0.01, inner_ring_acceleration=accel)
            np.testing.assert_allclose(engine.observe().ring_moment, moment, atol=0.01 * math.hypot(*moment))
    engine.set_moment(None)
    engine.advance(0.05)
    assert engine.observe().inner_ring_tilt == (0.0, 0.0)
