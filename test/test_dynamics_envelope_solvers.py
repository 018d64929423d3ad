"""Every point of the envelope solves: the quasi-static load distribution
(dynamics/quasi_static.py) and the engine's steady states (dynamics/steady.py), property-tested
with Hypothesis over speeds 0-10 000 rpm, axial loads 10-1000 N, radial loads 0-2000 N and
moments up to 5 N m (a couple that alone tilts this bearing's inner ring by milliradians:
docs/model.md, Moments and tilts).

The assertions are laws, not the code's numbers:

* the inner ring's balance: the contact forces on it equal the applied loads and moments
  (sum Q_i sin a_i = F_a, sum Q_i cos a_i (cos psi, sin psi) = (F_r, 0), and the moments with the
  tilts free) within 1e-6 of the largest applied load: the solver stops at 1e-8 of it, and
  1e-6 of 1000 N is a millinewton, far below anything a load cell resolves;
* each ball's balance (Jones 1960) with the gyroscopic moment off: Q_i sin a_i = Q_o sin a_o and
  Q_o cos a_o - Q_i cos a_i = F_c = m d_m omega_m^2 / 2, m = rho pi Dw^3 / 6 from the bearing
  file (1e-6 of the ball's largest load or 1 uN, the ball's own tolerance being 1e-9 of it);
  with the gyroscopic moment on, the couple's tangential force 2 M_g / Dw (at most
  2 J omega_R omega_m / Dw, J = rho pi Dw^5 / 60, omega_R <= omega_i d_m / Dw) bounds the axial
  mismatch;
* loads finite and non-negative; every loaded contact angle within +-90 deg (the grooves are
  whole circles: a ring tilted or pulled back far enough loads a ball on the other flank, at a
  negative angle);
* at rest, the closed forms: Harris's thrust equilibrium under an axial load alone,
  sin a (cos a0 / cos a - 1)^1.5 = F_a / (Z K_n (B Dw)^1.5), every ball alike (0.01 deg);
  Stribeck/Sjovall's half-loaded ring at F_a = 1.216 F_r tan a0:
  Q_max = 4.37 F_r / (Z cos a0) (Harris and Kotzalas; Sjovall holds the angle fixed, so 5 %:
  the loaded angle grows by up to a degree and a half at 2000 N, cos of which moves Q_max by
  about 1 %, and the integral's discretisation over 16 balls by about 2 %).

Derandomised (a fixed sequence of examples, no database): the same examples in every run.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.engine import DynamicsInputError
from bearing_rig_sim.dynamics.quasi_static import LoadCase, LoadDistribution, QuasiStaticBearing
from bearing_rig_sim.dynamics.steady import METHOD_INTEGRATION, SteadySolver

RPM = math.pi / 30.0
MAX_SPEED = 10_000 * RPM
MAX_MOMENT = 5.0
"""N m: module docstring."""
BALANCE = 1e-6
"""Relative tolerance of the balances (module docstring)."""
PARAMS = BearingParameters.from_yaml()
Z = PARAMS.ball_count
DW = PARAMS.ball_diameter
DM = PARAMS.pitch_diameter
A0 = PARAMS.contact_angle
B = PARAMS.inner_curvature_ratio + PARAMS.outer_curvature_ratio - 1.0
BALL_MASS = PARAMS.ball_density * math.pi * DW**3 / 6.0
BALL_INERTIA = PARAMS.ball_density * math.pi * DW**5 / 60.0

speeds = st.one_of(st.just(0.0), st.just(MAX_SPEED), st.floats(0.0, 100.0 * RPM), st.floats(0.0, MAX_SPEED))
axials = st.one_of(st.just(10.0), st.just(1000.0), st.floats(10.0, 1000.0))
radials = st.one_of(st.just(0.0), st.just(2000.0), st.floats(0.0, 2000.0))
moments = st.one_of(
    st.none(),
    st.builds(lambda m, d: (m * math.cos(d), m * math.sin(d)), st.one_of(st.just(MAX_MOMENT), st.floats(0.0, MAX_MOMENT)), st.floats(-math.pi, math.pi)),
)
cases = st.builds(LoadCase, axial_load=axials, radial_load=radials, moment=moments, inner_ring_speed=speeds, gyroscopic=st.booleans())


@pytest.fixture(scope="module")
def bearing() -> QuasiStaticBearing:
    return QuasiStaticBearing(PARAMS)


def assert_ring_balance(sol: LoadDistribution, case: LoadCase, ri: float) -> None:
    """The contact forces on the inner ring are the applied loads (moments too when given)."""
    qi, ai, psi = sol.inner_loads, sol.inner_angles, sol.azimuths
    scale = max(case.axial_load, abs(case.radial_load), *(abs(m) / ri for m in case.moment or ()))
    fa = qi * np.sin(ai)
    fr = qi * np.cos(ai)
    forces = [float(fa.sum()), float((fr * np.cos(psi)).sum()), float((fr * np.sin(psi)).sum())]
    assert forces == pytest.approx([case.axial_load, case.radial_load, 0.0], abs=BALANCE * scale), (case, forces)
    moment = [float((fa * ri * np.cos(psi)).sum()), float((fa * ri * np.sin(psi)).sum())]
    assert moment == pytest.approx(list(sol.reaction_moment), abs=BALANCE * scale * ri)
    if case.moment is not None:
        assert moment == pytest.approx(list(case.moment), abs=BALANCE * scale * ri), (case, moment)


def assert_balls(sol: LoadDistribution, case: LoadCase) -> None:
    """Loads and angles in range; each ball's balance (module docstring)."""
    qi, qo, ai, ao = sol.inner_loads, sol.outer_loads, sol.inner_angles, sol.outer_angles
    for values in (qi, qo, ai, ao, sol.orbit_speeds):
        assert np.all(np.isfinite(values))
    assert np.all(qi >= 0.0) and np.all(qo >= 0.0)
    loaded = qi > 0.0
    assert np.all(np.abs(ai[loaded]) < 0.5 * math.pi), np.degrees(ai[loaded])
    assert np.all(np.abs(ao[qo > 0.0]) < 0.5 * math.pi), np.degrees(ao)
    if case.inner_ring_speed == 0.0:
        np.testing.assert_allclose(qo, qi, rtol=1e-12)
        return
    fc = 0.5 * BALL_MASS * DM * sol.orbit_speeds**2
    assert np.all(sol.orbit_speeds >= 0.0) and np.all(sol.orbit_speeds <= case.inner_ring_speed)
    tol = BALANCE * np.maximum(np.maximum(qi, qo), 1.0)
    radial = qo * np.cos(ao) - qi * np.cos(ai) - fc
    axial = qi * np.sin(ai) - qo * np.sin(ao)
    if case.gyroscopic:
        couple = 2.0 * BALL_INERTIA * (case.inner_ring_speed * DM / DW) * sol.orbit_speeds / DW
        assert np.all(np.abs(axial) <= couple + tol), (case, axial, couple)
        assert np.all(np.abs(radial) <= couple + tol), (case, radial, couple)
    else:
        assert np.all(np.abs(axial) <= tol), (case, axial)
        assert np.all(np.abs(radial) <= tol), (case, radial)


@pytest.mark.slow
@settings(max_examples=300, derandomize=True, database=None, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(case=cases)
def test_every_point_of_the_envelope_has_a_balanced_load_distribution(bearing: QuasiStaticBearing, case: LoadCase) -> None:
    sol = bearing.solve(case)
    assert_ring_balance(sol, case, bearing.ri)
    assert_balls(sol, case)


@settings(max_examples=40, derandomize=True, database=None, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(axial=axials)
def test_at_rest_an_axial_load_follows_harris_thrust_equilibrium(bearing: QuasiStaticBearing, axial: float) -> None:
    k_n = (PARAMS.raceway_contacts()[0].stiffness ** (-2.0 / 3.0) + PARAMS.raceway_contacts()[1].stiffness ** (-2.0 / 3.0)) ** -1.5
    rhs = axial / (Z * k_n * (B * DW) ** 1.5)
    angle = brentq(lambda a: math.sin(a) * (math.cos(A0) / math.cos(a) - 1.0) ** 1.5 - rhs, A0 + 1e-9, math.radians(60.0), xtol=1e-14)
    sol = bearing.solve(LoadCase(axial))
    np.testing.assert_allclose(sol.inner_angles, angle, atol=math.radians(0.01))
    np.testing.assert_allclose(sol.inner_loads, axial / (Z * math.sin(angle)), rtol=1e-3)


@settings(max_examples=40, derandomize=True, database=None, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(radial=st.floats(50.0, 2000.0))
def test_at_rest_the_half_loaded_ring_follows_sjovall(bearing: QuasiStaticBearing, radial: float) -> None:
    sol = bearing.solve(LoadCase(1.216 * radial * math.tan(A0), radial))
    assert sol.ball_load_max == pytest.approx(4.37 * radial / (Z * math.cos(A0)), rel=0.05)
    behind = np.cos(sol.azimuths) < -1e-9
    assert np.all(sol.inner_loads[behind] == 0.0)


@pytest.mark.parametrize(
    "rpm,axial,radial",
    [(5000, 100.0, 200.0), (7000, 100.0, 200.0), (9000, 100.0, 200.0), (9000, 300.0, 400.0), (9000, 100.0, 400.0), (7000, 10.0, 0.0)],
)
def test_the_points_where_newton_lost_the_balls_at_the_load_zone_edge_solve(bearing: QuasiStaticBearing, rpm: float, axial: float, radial: float) -> None:
    """The combined-load sweep's points that found no equilibrium when a ball leaving the load
    zone dropped its wedge load of the order of F_c at once (and 7000 rpm under 10 N, where that
    jump spanned the applied load)."""
    case = LoadCase(axial, radial, inner_ring_speed=rpm * RPM)
    sol = bearing.solve(case)
    assert_ring_balance(sol, case, bearing.ri)
    assert_balls(sol, case)


SPEED_TOLERANCE = 0.2
"""rad/s: the engine's absolute speed tolerance (engine.SPEED_TOLERANCE)."""


@pytest.fixture(scope="module")
def steady() -> SteadySolver:
    return SteadySolver(BearingParameters.calibrated())


@settings(max_examples=300, derandomize=True, database=None, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(
    speed=st.one_of(st.just(MAX_SPEED), st.floats(0.1 * RPM, 100.0 * RPM), st.floats(0.1 * RPM, MAX_SPEED)),
    axial=axials,
)
def test_every_speed_and_axial_load_of_the_envelope_has_a_steady_state(steady: SteadySolver, speed: float, axial: float) -> None:
    """The engine's steady state (Newton on its own step, the integration its fallback): finite;
    the cage and the balls' orbit turning forwards and no faster than pure rolling at any contact
    angle, omega_i (1 - Dw cos a / d_m) / 2 <= omega_i / 2 (the inner ring is the only driven
    body), within the engine's speed tolerance; the friction torque and power dissipated, not
    gained (>= 0); a state Newton found says it is stable, an average says it is not."""
    point = steady.solve(speed, axial)
    values = [point.cage_speed, point.ball_orbit_speed, point.ball_spin_speed, point.slip_pct, point.power_loss, point.friction_torque]
    assert all(math.isfinite(v) for v in values), point
    for rate in (point.cage_speed, point.ball_orbit_speed):
        assert -SPEED_TOLERANCE <= rate <= 0.5 * speed + SPEED_TOLERANCE, point
    assert point.power_loss >= 0.0 and point.friction_torque >= 0.0, point
    assert point.stable == (point.method != METHOD_INTEGRATION)


def test_at_rest_there_is_no_steady_state_and_the_solver_says_why(steady: SteadySolver) -> None:
    with pytest.raises(DynamicsInputError, match="at rest there is no rolling steady state"):
        steady.solve(0.0, 100.0)


@pytest.mark.slow
@settings(max_examples=40, derandomize=True, database=None, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(speed=st.one_of(st.just(MAX_SPEED), st.floats(10.0 * RPM, MAX_SPEED)), axial=axials, radial=radials, moment=moments)
def test_every_combined_load_of_the_envelope_has_a_periodic_steady_state(
    steady: SteadySolver, speed: float, axial: float, radial: float, moment: tuple[float, float] | None
) -> None:
    """The periodic steady state under a combined load (integrated and averaged over whole
    ball-pass periods): the same bounds as the axial one's (forty cases: each integrates 0.35 s)."""
    point = steady.periodic(speed, axial, radial, moment=moment)
    assert all(math.isfinite(v) for v in (point.cage_speed, point.ball_orbit_speed, point.power_loss)), point
    for rate in (point.cage_speed, point.ball_orbit_speed):
        assert -SPEED_TOLERANCE <= rate <= 0.5 * speed + SPEED_TOLERANCE, point
    assert point.power_loss >= 0.0, point
