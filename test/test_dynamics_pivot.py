"""Gyroscopic pivoting (issue 23): the ball's pivot omega_t and pitch rate omega_p are dynamic
DOFs driven by the orbiting frame's gyroscopic moment and resisted by the transverse tractions
and the spin moments of both raceway contacts.

Expected values come from the literature, not from the engine: the gyroscopic moment
M_g = J omega_R omega_m sin(beta) with tan(beta) = sin(alpha)/(cos(alpha) + Dw/dm) (Harris and
Kotzalas, high-speed operation), and the pivoting limit of a ball held between two contacts
by friction mu: both contacts' transverse tractions act with the lever Dw/2, so the largest
moment they can give is mu (Q_i + Q_o) Dw/2 (Harris's mu Q Dw with Q the mean contact load).
The traction is a test-only law with a known limit, the exponential EHL curve
mu = mu_max (1 - exp(-SRR/SRR0)) applied to the magnitude of the sliding vector, and every
other resistance off, so that the rolling direction barely slides and the pivot alone is seen.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.engine import BearingDynamics

CONFIG = Path(__file__).resolve().parents[1] / "config"
BEARING = CONFIG / "bearings" / "h7006c.yaml"
RPM = 9000.0
"""The envelope's gyroscopic corner: M_g grows as the square of the speed (1.25 mN m at 100 N)."""
LOAD_N = 100.0
SRR0 = 0.01
"""Reference slide-to-roll ratio of the test law: its creep (linear) region is SRR < SRR0."""


def pivot_params(mu_max: float) -> BearingParameters:
    """H7006C without resistances, with the exponential traction law of limit ``mu_max``."""
    base = BearingParameters.from_yaml(BEARING).without_resistances()
    return base.replace(friction_model="ehl_traction", ehl_max_coefficient=mu_max, ehl_reference_srr=SRR0)


def harris_gyroscopic_moment(engine: BearingDynamics) -> tuple[float, float, float, float]:
    """(M_g in N m, Q_i + Q_o in N, u_e inner and outer in m/s) from the state: Harris's
    M_g = J omega_R omega_m sin(beta), J = m Dw^2/10 of a steel sphere, beta from the mean
    loaded contact angle, omega_R the ball's rolling speed relative to the orbiting frame."""
    p = engine.params
    obs = engine.observe()
    dw, dm = p.ball_diameter, p.pitch_diameter
    mass = p.ball_density * math.pi * dw**3 / 6.0
    inertia = mass * dw**2 / 10.0
    alpha_i, alpha_o = float(np.mean(obs.inner_contact_angles)), float(np.mean(obs.outer_contact_angles))
    alpha = 0.5 * (alpha_i + alpha_o)
    beta = math.atan(math.sin(alpha) / (math.cos(alpha) + dw / dm))
    omega_m = float(np.mean(obs.ball_orbit_speeds))
    omega_roll = float(np.mean(engine.ball[:, kn.B_SPIN])) + math.cos(beta) * omega_m
    moment = inertia * omega_roll * omega_m * math.sin(beta)
    loads = float(np.mean(obs.inner_contact_loads) + np.mean(obs.outer_contact_loads))
    ue_i = (obs.inner_ring_speed - omega_m) * (0.5 * dm - 0.5 * dw * math.cos(alpha_i))
    ue_o = omega_m * (0.5 * dm + 0.5 * dw * math.cos(alpha_o))
    return moment, loads, ue_i, ue_o


def mean_pivot(engine: BearingDynamics) -> float:
    return float(np.mean(engine.ball[:, kn.B_PIVOT]))


@pytest.fixture(scope="module")
def operating_point() -> tuple[float, float, float, float]:
    """M_g, Q_i + Q_o and the entrainment speeds at 9000 rpm, 100 N (they do not depend on
    the traction's limit: kinematics and the thrust equilibrium with centrifugal force)."""
    engine = BearingDynamics(pivot_params(0.05))
    engine.initialise(rpm_to_rad_s(RPM), LOAD_N)
    engine.advance(0.005)
    return harris_gyroscopic_moment(engine)


def test_gyroscopic_moment_is_harris_value(operating_point: tuple[float, float, float, float]) -> None:
    """The moment the pivot feels at 9000 rpm, 100 N is the review's 1252 uN m (5 %)."""
    assert operating_point[0] == pytest.approx(1252e-6, rel=0.05)


def mean_pitch(engine: BearingDynamics) -> float:
    return float(np.mean(engine.ball[:, kn.B_PITCH]))


SETTLE_S = 0.3
"""Settling time of the (pivot, pitch) pair: its slow mode, the spin moments' slope over J plus
the gyroscopic coupling's (J omega_m cos(beta))^2 / (J k_transverse), has a time constant of
about 35 ms with the test law."""


def settled(mu: float) -> tuple[BearingDynamics, float, float, float]:
    """The engine with the test law of limit ``mu`` after :data:`SETTLE_S`, checked steady
    (pivot and pitch unchanged to 1e-3 over 50 ms more); (engine, omega_t, omega_p, J)."""
    engine = BearingDynamics(pivot_params(mu))
    engine.initialise(rpm_to_rad_s(RPM), LOAD_N)
    engine.advance(SETTLE_S)
    first, first_p = mean_pivot(engine), mean_pitch(engine)
    engine.advance(0.05)
    pivot, pitch = mean_pivot(engine), mean_pitch(engine)
    assert pivot == pytest.approx(first, rel=1e-3)
    assert pitch == pytest.approx(first_p, rel=1e-3)
    dw = engine.params.ball_diameter
    inertia = engine.params.ball_density * math.pi * dw**3 / 6.0 * dw**2 / 10.0
    return engine, pivot, pitch, inertia


def euler_balance(engine: BearingDynamics, pivot: float, pitch: float, inertia: float, mu: float) -> tuple[float, float, float, float]:
    """The steady Euler equation about e_t in the orbiting frame, from its terms' closed forms:
    (Harris's M_g, the two contacts' transverse moment r mu Q (1 - exp(-r|omega_t|/(SRR0 u_e)))
    of the test law, the tilted axis's share J omega_m cos(beta) |omega_p|, the transverse
    limit mu (Q_i + Q_o) Dw/2), N m."""
    moment, loads, ue_i, ue_o = harris_gyroscopic_moment(engine)
    obs = engine.observe()
    p = engine.params
    r = 0.5 * p.ball_diameter
    qi = float(np.mean(obs.inner_contact_loads))
    qo = loads - qi
    slide = abs(pivot) * r
    transverse = r * mu * (qi * (1.0 - math.exp(-slide / (SRR0 * ue_i))) + qo * (1.0 - math.exp(-slide / (SRR0 * ue_o))))
    alpha = 0.5 * (float(np.mean(obs.inner_contact_angles)) + float(np.mean(obs.outer_contact_angles)))
    beta = math.atan(math.sin(alpha) / (math.cos(alpha) + p.ball_diameter / p.pitch_diameter))
    omega_m = float(np.mean(obs.ball_orbit_speeds))
    tilt = inertia * omega_m * math.cos(beta) * abs(pitch)
    return moment, transverse, tilt, mu * loads * r


@pytest.mark.parametrize("ratio", [4.0, 2.0])
def test_no_pivoting_below_the_limit(operating_point: tuple[float, float, float, float], ratio: float) -> None:
    """Limit mu (Q_i + Q_o) Dw/2 = 4 and 2 times M_g: the ball does not pivot. Its transverse
    sliding settles in the law's creep region (slide-to-roll ratio below SRR0), and the steady
    Euler equation about e_t closes (5 %): M_g is carried by the two contacts' transverse
    tractions at that sliding plus the share the free pitch takes, J omega_m cos(beta) omega_p
    (the rolling axis tilted toward the bearing axis), and the transverse tractions carry most
    of it."""
    moment, loads, ue_i, ue_o = operating_point
    r = 0.5 * pivot_params(0.05).ball_diameter
    mu = ratio * moment / (loads * r)
    engine, pivot, pitch, inertia = settled(mu)
    moment, transverse, tilt, limit = euler_balance(engine, pivot, pitch, inertia, mu)
    assert abs(pivot) * r < SRR0 * min(ue_i, ue_o)
    assert transverse + tilt == pytest.approx(moment, rel=0.05)
    assert transverse > 0.5 * moment
    assert transverse < limit


@pytest.mark.parametrize("ratio", [0.5, 0.25])
def test_pitch_takes_the_excess_above_the_limit(operating_point: tuple[float, float, float, float], ratio: float) -> None:
    """Limit 0.5 and 0.25 times M_g: the contacts cannot carry M_g by transverse traction, so
    the ball's rotation axis turns (pivoting): in the steady Euler equation about e_t the free
    pitch's share J omega_m cos(beta) |omega_p| is at least the excess M_g - limit, the
    transverse moment stays below the limit, and the two close the balance (5 %)."""
    moment, loads, ue_i, ue_o = operating_point
    r = 0.5 * pivot_params(0.05).ball_diameter
    mu = ratio * moment / (loads * r)
    engine, pivot, pitch, inertia = settled(mu)
    moment, transverse, tilt, limit = euler_balance(engine, pivot, pitch, inertia, mu)
    assert tilt >= moment - limit
    assert transverse < limit
    assert transverse + tilt == pytest.approx(moment, rel=0.05)


def pivot_acceleration(mu: float) -> tuple[float, float, float]:
    """Mean pivot acceleration (rad/s^2) over 0.6-1.2 ms from the rolling start, its closed
    form with the transverse traction saturated and the same instants' M_g, and the pivot's
    sliding speed r |omega_t| at 1.2 ms (m/s). The closed form: Euler's equations in the frame
    orbiting at omega_m with the constant excess moment A J = M_g - mu (Q_i + Q_o) Dw/2 about e_t
    and the free pitch coupling pivot and pitch at Omega = omega_m cos(beta) (the spin moments
    neglected over the millisecond): omega_t = (A/Omega) sin(Omega t), so the mean acceleration
    over [t1, t2] is A (sin(Omega t2) - sin(Omega t1)) / (Omega (t2 - t1))."""
    engine = BearingDynamics(pivot_params(mu))
    engine.initialise(rpm_to_rad_s(RPM), LOAD_N)
    r = 0.5 * engine.params.ball_diameter
    dw = engine.params.ball_diameter
    inertia = engine.params.ball_density * math.pi * dw**3 / 6.0 * dw**2 / 10.0
    engine.advance(0.0006)
    w1 = mean_pivot(engine)
    m1, q1, _, _ = harris_gyroscopic_moment(engine)
    engine.advance(0.0006)
    w2 = mean_pivot(engine)
    m2, q2, _, _ = harris_gyroscopic_moment(engine)
    obs = engine.observe()
    alpha = 0.5 * (float(np.mean(obs.inner_contact_angles)) + float(np.mean(obs.outer_contact_angles)))
    beta = math.atan(math.sin(alpha) / (math.cos(alpha) + dw / engine.params.pitch_diameter))
    big_omega = float(np.mean(obs.ball_orbit_speeds)) * math.cos(beta)
    excess = 0.5 * (m1 + m2) - mu * r * 0.5 * (q1 + q2)
    factor = (math.sin(big_omega * 0.0012) - math.sin(big_omega * 0.0006)) / (big_omega * 0.0006)
    return abs(w2 - w1) / 0.0006, excess / inertia * factor, abs(w2) * r


def test_pivoting_above_the_limit(operating_point: tuple[float, float, float, float]) -> None:
    """Limit 0.5 and 0.25 times M_g, from the rolling start: the ball pivots, its pivot
    accelerating as Euler's equations with the excess (M_g - limit) give (5 %), faster the more
    M_g exceeds the limit, its transverse sliding beyond the creep region after a millisecond
    (SRR above 3 SRR0, where the law gives 95 % of its limit)."""
    moment, loads, ue_i, ue_o = operating_point
    r = 0.5 * pivot_params(0.05).ball_diameter
    rates = []
    for ratio in (0.5, 0.25):
        measured, expected, slide = pivot_acceleration(ratio * moment / (loads * r))
        assert expected > 0.0
        assert measured == pytest.approx(expected, rel=0.05)
        rates.append(measured)
        assert slide > 3.0 * SRR0 * max(ue_i, ue_o)
    assert rates[1] > 1.3 * rates[0]


def test_shipped_twin_pivots_only_by_micro_slip() -> None:
    """The shipped grease twin at 900 and 2700 rpm, 100 N: the rheology law's limit
    Lambda (Q_i + Q_o) Dw/2 (about 10 mN m) is 800 and 90 times M_g, so the pivot is micro-slip:
    its sliding a small fraction of the rolling contacts' own slide-to-roll ratio."""
    params = BearingParameters.from_yaml(BEARING, CONFIG / "calibration" / "h7006c_table3.yaml")
    engine = BearingDynamics(params)
    r = 0.5 * params.ball_diameter
    for rpm in (900.0, 2700.0):
        engine.initialise(rpm_to_rad_s(rpm), LOAD_N)
        engine.advance(0.05)
        moment, loads, ue_i, ue_o = harris_gyroscopic_moment(engine)
        assert params.lubricant is not None
        assert moment < 0.02 * params.lubricant.limiting_shear_coefficient * loads * r
        assert abs(mean_pivot(engine)) * r < 2e-3 * min(ue_i, ue_o)


@pytest.mark.parametrize("contact", [0, 1])
def test_transverse_law_is_the_tables_odd_part(contact: int) -> None:
    """The transverse traction reads the rheology table's odd part (mu(+SRR) - mu(-SRR))/2: equal
    to it from two lookups at nodes and between them, zero at SRR = 0 though the table is not
    (spin and Heathcote offset), rising with SRR and bounded by the film's limiting shear
    coefficient Lambda."""
    from bearing_rig_sim.dynamics.parameters import traction_table
    from bearing_rig_sim.dynamics.traction import SRR_REF, table_lookup, table_odd

    params = BearingParameters.from_yaml(BEARING, CONFIG / "calibration" / "h7006c_table3.yaml")
    assert params.lubricant is not None
    t = traction_table(params)
    ns, xi_max = int(t[0]), t[3]
    u, q = 3.0, 100.0
    assert abs(table_lookup(t, 0, 1, 0.0, u, q)[0]) > 1e-3  # the table's own offset
    assert table_odd(t, 0, contact, 0.0, u, q) == pytest.approx(0.0, abs=1e-12)
    prev = 0.0
    for i in (52.0, 60.0, 60.5, 70.0, 80.25, 96.0):
        srr = SRR_REF * math.sinh(-xi_max + i * 2.0 * xi_max / (ns - 1))
        odd = table_odd(t, 0, contact, srr, u, q)
        both = 0.5 * (table_lookup(t, 0, contact, srr, u, q)[0] - table_lookup(t, 0, contact, -srr, u, q)[0])
        assert odd == pytest.approx(both, rel=1e-6, abs=1e-15)  # (the last node: the edge clamp)
        assert prev < odd < params.lubricant.limiting_shear_coefficient
        prev = odd


@pytest.mark.parametrize("contact", [0, 1])
def test_spin_lever_is_the_hertz_pressures_mean_distance(contact: int) -> None:
    """The spin moment's lever rho (docs/model.md, Ball attitude) is the mean distance from the
    contact centre under the Hertz pressure p0 sqrt(1 - x^2/a^2 - y^2/b^2) (Johnson, Contact
    Mechanics, 3.4): integrated numerically over the ellipse here at 100 N, the kernel's lever at
    the same contact's penetration agrees (1e-6); on a circle the integral is Johnson's
    (3 pi/16) a, the Coulomb spin moment's lever."""
    from scipy.integrate import dblquad

    from bearing_rig_sim.dynamics.parameters import derive

    params = BearingParameters.from_yaml(BEARING)
    vector, _ = derive(params)
    hertz = params.raceway_contacts()[contact]
    load = 100.0
    a, b = hertz.semi_axes(load)

    def mean_distance(a: float, b: float) -> float:
        # polar coordinates on the unit disc, x = a s cos(phi), y = b s sin(phi), dA = a b s ds dphi
        def weight(s: float, phi: float) -> float:
            return math.sqrt(1.0 - s * s) * s

        def moment(s: float, phi: float) -> float:
            return weight(s, phi) * s * math.hypot(a * math.cos(phi), b * math.sin(phi))

        num = dblquad(moment, 0.0, 2.0 * math.pi, 0.0, 1.0, epsabs=1e-14, epsrel=1e-10)[0]
        den = dblquad(weight, 0.0, 2.0 * math.pi, 0.0, 1.0, epsabs=1e-14, epsrel=1e-10)[0]
        return num / den

    assert mean_distance(1.0, 1.0) == pytest.approx(3.0 * math.pi / 16.0, rel=1e-8)
    penetration = (load / hertz.stiffness) ** (2.0 / 3.0)
    lever = vector[kn.P_SPIN_IN + contact] * math.sqrt(penetration)
    assert lever == pytest.approx(mean_distance(a, b), rel=1e-6)
