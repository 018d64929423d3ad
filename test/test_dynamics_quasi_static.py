"""The quasi-static load distribution under combined load (dynamics/quasi_static.py) against
closed forms and hand calculations typed from the literature.

Bearing data (config/bearings/h7006c.yaml, paper Table 2): Z = 16, Dw = 6.3 mm, d_m = 42.45 mm,
a0 = 15 deg, f_i + f_o - 1 = B = 0.05; Hertz constants K_i = 2.30e10 and K_o = 2.09e10 N/m^1.5
(docs/model.md, Contacts), in series K_n = (K_i^(-2/3) + K_o^(-2/3))^(-3/2) = 7.75e9 N/m^1.5.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.quasi_static import LoadCase, LoadDistributionError, QuasiStaticBearing

Z = 16
DW = 6.3e-3
DM = 42.45e-3
A0 = math.radians(15.0)
B = 0.05
K_I, K_O = 2.30e10, 2.09e10
K_N = (K_I ** (-2.0 / 3.0) + K_O ** (-2.0 / 3.0)) ** -1.5
RPM = math.pi / 30.0


@pytest.fixture(scope="module")
def bearing() -> QuasiStaticBearing:
    return QuasiStaticBearing(BearingParameters.from_yaml())


def test_hertz_constants_are_the_documented_ones(bearing: QuasiStaticBearing) -> None:
    assert bearing.ki == pytest.approx(K_I, rel=0.01) and bearing.ko == pytest.approx(K_O, rel=0.01)
    assert bearing.kn == pytest.approx(K_N, rel=0.01)


@pytest.mark.parametrize("axial", [50.0, 100.0, 300.0, 700.0, 1000.0])
def test_pure_axial_load_follows_harris_thrust_equilibrium(bearing: QuasiStaticBearing, axial: float) -> None:
    """Harris and Kotzalas: sin a (cos a0 / cos a - 1)^1.5 = F_a / (Z K_n (B Dw)^1.5), and every
    ball carries Q = F_a / (Z sin a) (at rest: no body forces)."""
    rhs = axial / (Z * K_N * (B * DW) ** 1.5)
    angle = brentq(lambda a: math.sin(a) * (math.cos(A0) / math.cos(a) - 1.0) ** 1.5 - rhs, A0 + 1e-9, math.radians(60.0), xtol=1e-14)
    sol = bearing.solve(LoadCase(axial))
    np.testing.assert_allclose(sol.inner_angles, angle, atol=math.radians(0.01))
    np.testing.assert_allclose(sol.inner_loads, axial / (Z * math.sin(angle)), rtol=0.01)
    np.testing.assert_allclose(sol.outer_loads, sol.inner_loads, rtol=1e-9)
    assert sol.loaded_balls == Z
    assert abs(sol.displacement[1]) < 1e-12 and max(abs(m) for m in sol.reaction_moment) < 1e-9


def test_stribeck_sjovall_half_loaded_ring(bearing: QuasiStaticBearing) -> None:
    """Zero clearance, tilt held, F_a = 1.216 F_r tan a0 (the half-loaded ring, epsilon = 0.5):
    Q_max = 4.37 F_r / (Z cos a0) (Harris and Kotzalas, load distribution, Sjovall integral
    J_r(0.5) = 0.2288). F_r = 500 N: F_a = 1.216 x 500 x tan 15 deg = 162.9 N,
    Q_max = 4.37 x 500 / (16 cos 15 deg) = 141.4 N; within 3 %. The load zone is half the ring:
    the balls within +-90 deg of the load carry it (7 to 9 of 16, the ones at +-90 deg on its
    edge), the others none."""
    fr = 500.0
    fa = 1.216 * fr * math.tan(A0)
    assert fa == pytest.approx(162.9, abs=0.1)
    q_max = 4.37 * fr / (Z * math.cos(A0))
    assert q_max == pytest.approx(141.4, abs=0.1)
    sol = bearing.solve(LoadCase(fa, fr))
    assert sol.ball_load_max == pytest.approx(q_max, rel=0.03)
    assert int(np.argmax(sol.inner_loads)) == 0  # the ball at psi = 0, under the load
    assert 7 <= sol.loaded_balls <= 9
    behind = np.cos(sol.azimuths) < -1e-9
    assert np.all(sol.inner_loads[behind] == 0.0)


def test_combined_load_is_in_equilibrium_and_symmetric(bearing: QuasiStaticBearing) -> None:
    """The ring's balance (sum of the inner contact forces = the applied loads) and the mirror
    symmetry of a radial load along psi = 0 (ball j and ball Z - j carry the same)."""
    fa, fr = 300.0, 400.0
    sol = bearing.solve(LoadCase(fa, fr))
    qi, ai, psi = sol.inner_loads, sol.inner_angles, sol.azimuths
    assert float(np.sum(qi * np.sin(ai))) == pytest.approx(fa, rel=1e-6)
    assert float(np.sum(qi * np.cos(ai) * np.cos(psi))) == pytest.approx(fr, rel=1e-6)
    assert abs(float(np.sum(qi * np.cos(ai) * np.sin(psi)))) < 1e-6 * fr
    mirror = (Z - np.arange(Z)) % Z
    np.testing.assert_allclose(qi, qi[mirror], rtol=1e-6, atol=1e-9)
    assert sol.displacement[1] > 0.0  # the ring moves towards the load
    # Loads fall monotonically from psi = 0 to 180 deg.
    half = qi[: Z // 2 + 1]
    assert np.all(np.diff(half) <= 1e-9)


def test_the_held_tilt_reaction_moment_round_trips(bearing: QuasiStaticBearing) -> None:
    """With the tilt held the balls exert a moment M on the ring; applying that moment with the
    tilt free gives the same tilt (zero) and the same loads."""
    held = bearing.solve(LoadCase(200.0, 300.0))
    assert held.reaction_moment[0] > 0.0  # the loaded side pushes the ring's axial face harder
    free = bearing.solve(LoadCase(200.0, 300.0, moment=held.reaction_moment))
    assert max(abs(t) for t in free.tilt) < 1e-7
    np.testing.assert_allclose(free.inner_loads, held.inner_loads, rtol=1e-4, atol=1e-6)


def test_a_moment_tilts_the_ring_and_shifts_the_load(bearing: QuasiStaticBearing) -> None:
    """A moment M_x under pure axial load: the balls at psi = 0 load up, those opposite unload,
    and the moment balance holds."""
    sol = bearing.solve(LoadCase(300.0, 0.0, moment=(2.0, 0.0)))
    assert sol.inner_loads[0] > sol.inner_loads[Z // 2]
    assert sol.reaction_moment[0] == pytest.approx(2.0, rel=1e-6)
    assert sol.tilt[0] > 0.0


def _hand_high_speed_angles(axial: float, omega_i: float, ball_density: float) -> tuple[float, float]:
    """Jones's ball balance without gyroscopic moment, by hand, for a pure thrust load: every
    ball alike, so the inner contact carries Q_i sin a_i = F_a / Z and the outer contact takes
    the centrifugal force too, Q_o sin a_o = F_a/Z, Q_o cos a_o = Q_i cos a_i + F_c,
    F_c = m d_m omega_m^2 / 2, omega_m = omega_i (1 - g cos a_i) / (1 + cos(a_i - a_o))
    (outer-raceway control, g = Dw/d_m). The curvature centres stay A cos a0 apart radially:
    (f_o - 1/2) Dw + delta_o) cos a_o + ((f_i - 1/2) Dw + delta_i) cos a_i = A cos a0, one
    equation in a_i (bisection), the Hertz approaches delta = (Q/K)^(2/3)."""
    m = ball_density * math.pi * DW**3 / 6.0
    g = DW / DM
    gi, go = 0.02 * DW, 0.03 * DW  # f_i = 0.52, f_o = 0.53 (the bearing file)
    a_big = gi + go
    fz = axial / Z

    def outer(ai: float) -> tuple[float, float, float]:
        qi = fz / math.sin(ai)
        ao = ai
        for _ in range(60):
            wm = omega_i * (1.0 - g * math.cos(ai)) / (1.0 + math.cos(ai - ao))
            fc = 0.5 * m * DM * wm * wm
            ao = math.atan2(fz, qi * math.cos(ai) + fc)
        qo = math.hypot(fz, qi * math.cos(ai) + fc)
        return qi, qo, ao

    def radial(ai: float) -> float:
        qi, qo, ao = outer(ai)
        return (go + (qo / K_O) ** (2 / 3)) * math.cos(ao) + (gi + (qi / K_I) ** (2 / 3)) * math.cos(ai) - a_big * math.cos(A0)

    ai = brentq(radial, math.radians(5.0), math.radians(45.0), xtol=1e-14)
    return ai, outer(ai)[2]


@pytest.mark.parametrize("rpm,axial", [(10_000, 100.0), (9000, 300.0)])
def test_high_speed_contact_angles_match_the_hand_calculation(bearing: QuasiStaticBearing, rpm: float, axial: float) -> None:
    """With speed the outer contact angle falls and the inner one rises from the static
    angle; both as the hand calculation above (gyroscopic moment off) within 0.05 deg."""
    static = bearing.solve(LoadCase(axial)).inner_angles[0]
    sol = bearing.solve(LoadCase(axial, inner_ring_speed=rpm * RPM, gyroscopic=False))
    hand_i, hand_o = _hand_high_speed_angles(axial, rpm * RPM, BearingParameters.from_yaml().ball_density)
    assert sol.outer_angles[0] < static < sol.inner_angles[0]
    np.testing.assert_allclose(sol.inner_angles, hand_i, atol=math.radians(0.05))
    np.testing.assert_allclose(sol.outer_angles, hand_o, atol=math.radians(0.05))
    assert sol.outer_loads[0] > sol.inner_loads[0]  # the outer contact carries the centrifugal force too


def test_the_gyroscopic_moment_shifts_the_angles_slightly(bearing: QuasiStaticBearing) -> None:
    """Jones's gyroscopic moment, carried at the outer contact, changes the loaded angles by
    less than the centrifugal force does (a spindle bearing's ball of 6.3 mm): under a degree."""
    case = dict(axial_load=100.0, inner_ring_speed=10_000 * RPM)
    with_g = bearing.solve(LoadCase(**case))
    without = bearing.solve(LoadCase(**case, gyroscopic=False))
    assert 0.0 < abs(with_g.inner_angles[0] - without.inner_angles[0]) < math.radians(1.0)


@pytest.mark.parametrize("case", [LoadCase(0.0), LoadCase(100.0, inner_ring_speed=-1.0), LoadCase(float("nan"))])
def test_bad_cases_are_refused(bearing: QuasiStaticBearing, case: LoadCase) -> None:
    with pytest.raises(LoadDistributionError):
        bearing.solve(case)


def test_the_traction_tables_node_angles_are_the_rings_at_the_same_load_and_speed() -> None:
    """The angles the traction table takes its spin from (a thrust-loaded ball whose inner
    contact carries a given load at a given entrainment speed) are the ring solution's: at
    10 000 rpm / 100 N and 9000 rpm / 300 N (angles validated by hand above), the inner load and
    inner entrainment speed (omega_i - omega_m)(d_m - Dw cos a_i)/2 of the ring's solution,
    given to :func:`thrust_contact_angles`, give back its angles within 0.01 deg. At a crawl
    (0.05 m/s) both are the thrust angle of the load at rest, Harris and Kotzalas' equation with
    F_a = Z Q sin a: cos a = cos a0 / (1 + (Q / (K_n (B Dw)^1.5))^(2/3))."""
    from bearing_rig_sim.dynamics.ball_balance import thrust_contact_angles
    from bearing_rig_sim.dynamics.quasi_static import solve

    params = BearingParameters.from_yaml()
    r, rm = 0.5 * DW, 0.5 * DM
    for rpm, axial in ((10_000, 100.0), (9000, 300.0)):
        omega = rpm * RPM
        ring = solve(params, LoadCase(axial, inner_ring_speed=omega))
        ai, ao, q = ring.inner_angles[0], ring.outer_angles[0], ring.inner_loads[0]
        orbit = omega * (rm - r * math.cos(ai)) / (rm * (1.0 + math.cos(ai - ao)))
        entrainment = (omega - orbit) * (rm - r * math.cos(ai))
        got = thrust_contact_angles(params, np.array([q]), np.array([entrainment]))[0, 0]
        np.testing.assert_allclose(got, [ai, ao], atol=math.radians(0.01))
        assert got[1] < got[0]  # opened apart by the centrifugal force
    loads = np.array([5.0, 50.0, 500.0])
    crawl = thrust_contact_angles(params, loads, np.array([0.05]))[:, 0]
    rest = np.arccos(math.cos(A0) / (1.0 + (loads / (K_N * (B * DW) ** 1.5)) ** (2.0 / 3.0)))
    np.testing.assert_allclose(crawl[:, 0], rest, atol=math.radians(0.01))
    np.testing.assert_allclose(crawl[:, 1], rest, atol=math.radians(0.01))
