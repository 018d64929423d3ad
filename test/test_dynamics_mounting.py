"""The mounting inputs of the dynamic engine: an extra diametral clearance, a misalignment at
which the inner ring's tilts are held, and a spring or rigid preload (docs/model.md, "Mounting").

References (hand calculations, each stated at its test; none uses the engine's kernels):

* Harris and Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1, "thrust-loaded ball
  bearing": with an extra diametral clearance P_d the free contact angle is
  a_f = acos(cos a0 - P_d / (2A)), A = (f_i + f_o - 1) D_w, and under a thrust load F_a the
  loaded angle a solves F_a / (Z K_n A^1.5) = sin a (cos a_f / cos a - 1)^1.5, each ball
  carrying Q = F_a / (Z sin a); the curvature centres' axial distance is then
  A cos a_f tan a, A sin a0 + delta_a in the engine's frame.
* The 5-DOF geometry of Harris (the one dynamics/quasi_static.py states), solved here with
  scipy for a held tilt: A1_j = A sin a0 + delta_a + R_i theta_x cos psi_j,
  A2_j = A cos a0 + delta_x cos psi_j, Q_j = K_n (|A_j| - A)^1.5 at rest.
* K_n = (K_i^(-2/3) + K_o^(-2/3))^(-3/2) (Harris and Kotzalas Eq. 7.19) from the Hertz
  constants of bearing/hertz.py at the free contact angle.

Balls at rest: no centrifugal force, so each ball lies on the line of its two curvature
centres, the case the thrust equation describes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq, fsolve

from bearing_rig_sim.config import config_path
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters, DynamicsInputError, Mounting
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.bearing.hertz import raceway_contacts
from bearing_rig_sim.dynamics.parameters import derive
from bearing_rig_sim.thermal.bearing import ThermalConfig
from bearing_rig_sim.thermal.coupling import ThermalCoupling
from bearing_rig_sim.bearing.materials import BEARING_STEEL


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.calibrated()


def _constants(p: BearingParameters) -> tuple[float, float, float]:
    """(A, K_n, R_i): curvature centres' distance (m), series Hertz constant (N/m^1.5) and the
    radius of the inner groove curvature centres' locus (m)."""
    inner, outer = raceway_contacts(
        p.ball_diameter,
        p.pitch_diameter,
        p.contact_angle,
        p.inner_curvature_ratio,
        p.outer_curvature_ratio,
        p.ball_modulus,
        p.ball_poisson,
        p.ring_modulus,
        p.ring_poisson,
    )
    k_n = (inner.stiffness ** (-2.0 / 3.0) + outer.stiffness ** (-2.0 / 3.0)) ** -1.5
    big_a = (p.inner_curvature_ratio + p.outer_curvature_ratio - 1.0) * p.ball_diameter
    r_i = 0.5 * p.pitch_diameter + (p.inner_curvature_ratio - 0.5) * p.ball_diameter * math.cos(p.contact_angle)
    return big_a, k_n, r_i


def _thrust(p: BearingParameters, load: float, clearance: float) -> tuple[float, float, float]:
    """Harris's thrust-loaded bearing: (loaded contact angle rad, ball load N, inner ring's axial
    displacement m in the engine's frame) under ``load`` N with the extra clearance P_d."""
    big_a, k_n, _ = _constants(p)
    z = p.ball_count
    free = math.acos(math.cos(p.contact_angle) - clearance / (2.0 * big_a))
    angle = brentq(
        lambda a: math.sin(a) * (math.cos(free) / math.cos(a) - 1.0) ** 1.5 - load / (z * k_n * big_a**1.5), free + 1e-12, 0.5 * math.pi - 1e-9, xtol=1e-15
    )
    return angle, load / (z * math.sin(angle)), big_a * math.cos(free) * math.tan(angle) - big_a * math.sin(p.contact_angle)


def _at_rest(engine: BearingDynamics, load: float) -> None:
    engine.initialise(0.0, load)
    engine.advance(10 * engine.time_step)


@pytest.mark.parametrize("clearance", [12e-6, -6e-6])
def test_clearance_follows_the_thrust_equation(params: BearingParameters, clearance: float) -> None:
    """12 um more diametral clearance raises the H7006C's free contact angle from 15 to about
    19.6 deg (a light load's angle follows it), 6 um of interference lowers it; the loaded angle,
    the ball load and the ring's displacement are Harris's."""
    load = 300.0
    engine = BearingDynamics(params, mounting=Mounting(clearance=clearance))
    _at_rest(engine, load)
    obs = engine.observe()
    angle, q, delta = _thrust(params, load, clearance)
    np.testing.assert_allclose(obs.inner_contact_angles, angle, rtol=1e-6)
    np.testing.assert_allclose(obs.outer_contact_angles, angle, rtol=1e-6)
    np.testing.assert_allclose(obs.inner_contact_loads, q, rtol=1e-6)
    assert obs.inner_ring_axial_displacement == pytest.approx(delta, rel=1e-6, abs=1e-12)
    # the clearance moved the angle: the same load without it is a different state
    angle0, _, _ = _thrust(params, load, 0.0)
    assert abs(angle - angle0) > math.radians(0.5)


def test_clearance_set_between_steps(params: BearingParameters) -> None:
    """set_clearance between steps: the next steps settle on the new thrust equilibrium, and
    setting it back to 0 restores the bearing file's vector bit for bit."""
    engine = BearingDynamics(params)
    _at_rest(engine, 200.0)
    engine.set_clearance(8e-6)
    engine.advance(20 * engine.time_step)
    obs = engine.observe()
    angle, q, delta = _thrust(params, 200.0, 8e-6)
    np.testing.assert_allclose(obs.inner_contact_angles, angle, rtol=1e-6)
    np.testing.assert_allclose(obs.inner_contact_loads, q, rtol=1e-6)
    assert obs.inner_ring_axial_displacement == pytest.approx(delta, rel=1e-6)
    engine.set_clearance(0.0)
    vector, _ = derive(params)
    assert np.array_equal(engine.vector, vector)


def test_clearance_out_of_range_is_refused(params: BearingParameters) -> None:
    engine = BearingDynamics(params)
    with pytest.raises(DynamicsInputError, match="clearance"):
        engine.set_clearance(1e-3)  # the free contact angle would pass 90 deg
    with pytest.raises(DynamicsInputError, match="clearance"):
        engine.set_clearance(math.nan)


def _held_tilt(p: BearingParameters, load: float, theta: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Ball loads (N), contact angles (rad) and the ring's radial displacement delta_x (m) at psi_j = 2 pi j / Z of the bearing at rest
    under ``load`` N with its inner ring tilted by theta_x = ``theta`` (held) and free to move
    axially and along x (y by symmetry): Harris's 5-DOF geometry, solved with scipy."""
    big_a, k_n, r_i = _constants(p)
    psi = 2.0 * math.pi * np.arange(p.ball_count) / p.ball_count
    a0 = p.contact_angle

    def balls(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        a1 = big_a * math.sin(a0) + u[0] + r_i * theta * np.cos(psi)
        a2 = big_a * math.cos(a0) + u[1] * np.cos(psi)
        gap = np.maximum(np.hypot(a1, a2) - big_a, 0.0)
        return k_n * gap**1.5, np.arctan2(a1, a2)

    def residual(u: np.ndarray) -> np.ndarray:
        q, a = balls(u * 1e-6)
        return np.array([np.sum(q * np.sin(a)) - load, np.sum(q * np.cos(a) * np.cos(psi))])

    _, _, delta = _thrust(p, load, 0.0)
    sol = fsolve(residual, np.array([delta * 1e6, 0.0]), xtol=1e-13)
    assert np.max(np.abs(residual(sol))) < 1e-7 * load
    q, a = balls(sol * 1e-6)
    return q, a, float(sol[1] * 1e-6)


def test_misalignment_loads_vary_around_the_orbit(params: BearingParameters) -> None:
    """A held tilt of 1 mrad about y (theta_x: the inner ring lifted towards the outer at
    psi = 0) under 300 N: every ball's load is that of the 5-DOF geometry at its azimuth, the
    rings in axial balance (sum Q sin a = F_a) and the reaction moment
    M_x = sum Q sin a R_i cos psi positive.

    With the radial displacement free, the tilt about the centre plane is, to first order, a
    tilt about the pressure centre (where the contact lines meet the axis, R_i tan a from that
    plane: it changes no ball's approach) plus a radial shift R_i theta tan a, which the free
    ring undoes: delta_x = -R_i theta tan a to first order, and the loads vary at second order,
    symmetric about the tilt axis (psi -> -psi), most loaded at psi = 0 and least at +-90 deg."""
    load, theta = 300.0, 1e-3
    engine = BearingDynamics(params, mounting=Mounting(misalignment=(theta, 0.0)))
    _at_rest(engine, load)
    obs = engine.observe()
    q, a, delta_x = _held_tilt(params, load, theta)
    np.testing.assert_allclose(obs.inner_contact_loads, q, rtol=1e-5)
    np.testing.assert_allclose(obs.inner_contact_angles, a, rtol=1e-5)
    assert obs.inner_ring_tilt == (theta, 0.0)
    assert float(np.sum(obs.inner_contact_loads * np.sin(obs.inner_contact_angles))) == pytest.approx(load, rel=1e-8)
    psi = 2.0 * math.pi * np.arange(params.ball_count) / params.ball_count
    _, _, r_i = _constants(params)
    mx = float(np.sum(q * np.sin(a) * r_i * np.cos(psi)))
    assert mx > 0.5  # N m: a real reaction, not rounding
    assert obs.ring_moment[0] == pytest.approx(mx, rel=1e-5)
    assert abs(obs.ring_moment[1]) < 1e-6 * mx
    assert engine.ring[kn.R_DX] == pytest.approx(delta_x, rel=1e-5)
    angle, _, _ = _thrust(params, load, 0.0)
    assert delta_x == pytest.approx(-r_i * theta * math.tan(angle), rel=0.1)
    loads = obs.inner_contact_loads
    np.testing.assert_allclose(loads[1:], loads[1:][::-1], rtol=1e-6)
    z = params.ball_count
    assert int(np.argmax(loads)) == 0
    assert int(np.argmin(loads)) in (z // 4, 3 * z // 4)
    ratio = loads.max() / loads.min()
    assert ratio == pytest.approx(q.max() / q.min(), rel=1e-5)
    assert ratio > 1.2


def test_misalignment_is_where_a_released_moment_leaves_the_tilts(params: BearingParameters) -> None:
    engine = BearingDynamics(params, mounting=Mounting(misalignment=(0.0, -5e-4)))
    engine.set_moment((0.1, 0.0))
    engine.set_moment(None)
    assert (engine.ring[kn.R_TX], engine.ring[kn.R_TY]) == (0.0, -5e-4)
    with pytest.raises(DynamicsInputError, match="misalignment"):
        engine.set_misalignment((0.02, 0.0))
    with pytest.raises(DynamicsInputError, match="reduced model"):
        BearingDynamics(params, model="stiff", mounting=Mounting(misalignment=(1e-4, 0.0)), check_step=False)


def test_spring_preload_adds_to_the_axial_load(params: BearingParameters) -> None:
    """A 150 N spring with 50 N on the lever is Harris's thrust bearing under 200 N; with the
    spring the external load may be zero."""
    engine = BearingDynamics(params, mounting=Mounting(preload_force=150.0))
    _at_rest(engine, 50.0)
    angle, q, delta = _thrust(params, 200.0, 0.0)
    obs = engine.observe()
    np.testing.assert_allclose(obs.inner_contact_loads, q, rtol=1e-6)
    assert obs.inner_ring_axial_displacement == pytest.approx(delta, rel=1e-6)
    _at_rest(engine, 0.0)
    _, q150, _ = _thrust(params, 150.0, 0.0)
    np.testing.assert_allclose(engine.observe().inner_contact_loads, q150, rtol=1e-6)


@pytest.mark.parametrize("clearance", [0.0, 4e-6])
def test_rigid_preload_pair_shares_the_displacement(params: BearingParameters, clearance: float) -> None:
    """A back-to-back pair preloaded by 20 um with no external load: the two identical
    bearings carry the same load, each displaced by half the preload, so each ball's load is
    K_n (D - A)^1.5 with D the curvature centres' distance at an axial offset of
    A sin a0 + 10 um (and a radial one of A cos a0 - P_d/2)."""
    s = 20e-6
    big_a, k_n, _ = _constants(params)
    a0 = params.contact_angle
    axial, radial = big_a * math.sin(a0) + 0.5 * s, big_a * math.cos(a0) - 0.5 * clearance
    dist = math.hypot(axial, radial)
    q = k_n * (dist - big_a) ** 1.5
    engine = BearingDynamics(params, mounting=Mounting(clearance=clearance, preload_displacement=s))
    _at_rest(engine, 0.0)
    obs = engine.observe()
    assert obs.inner_ring_axial_displacement == pytest.approx(0.5 * s, rel=1e-7)
    np.testing.assert_allclose(obs.inner_contact_loads, q, rtol=1e-6)
    np.testing.assert_allclose(obs.inner_contact_angles, math.atan2(axial, radial), rtol=1e-7)
    assert q * params.ball_count * axial / dist > 20.0  # N: a real preload (150 N without the clearance)


def test_rigid_preload_unloads_the_partner_under_a_large_load(params: BearingParameters) -> None:
    """Under an external load large enough to push the ring past the preload displacement the
    partner lifts off and the bearing carries the load alone (Harris's thrust equation)."""
    engine = BearingDynamics(params, mounting=Mounting(preload_displacement=2e-6))
    _at_rest(engine, 800.0)
    angle, q, delta = _thrust(params, 800.0, 0.0)
    assert delta > 2e-6
    np.testing.assert_allclose(engine.observe().inner_contact_loads, q, rtol=1e-6)


def test_stiff_model_conserves_energy_with_a_rigid_preload_and_clearance(params: BearingParameters) -> None:
    """Stiff model, friction, damping and drive off, a 20 um preloaded pair with 2 um extra
    clearance, after an external load step that sets the ring vibrating against the partner:
    the total mechanical energy (with the partner's Hertz energy Z K_n (2/5) (D - A)^2.5) stays
    within a small part of the energy the partner exchanges with the ring. A partner force that
    were not the derivative of that energy would make it drift by the order of F_p times the
    ring's travel."""
    clean = BearingParameters.from_yaml().conservative()
    e = BearingDynamics(clean, model="stiff", mounting=Mounting(clearance=2e-6, preload_displacement=20e-6))
    e.initialise(900 * math.pi / 30.0, 20.0)
    e.set_inner_ring_speed(0.0)
    e.axial_load = 80.0  # load step from the 20 N equilibrium
    e0 = e.energy()
    partner = []
    energies = [e0]
    for _ in range(25):
        e.advance(0.002)
        energies.append(e.energy())
        partner.append(kn.partner_force(e.vector, e.ring[kn.R_DELTA])[2])
    exchanged = float(np.ptp(partner))
    assert exchanged > 1e-5  # J: the partner takes part
    assert float(np.ptp(energies)) < 0.05 * exchanged


def test_thermal_coupling_can_apply_the_rings_expansion(params: BearingParameters) -> None:
    """With ``expansion`` the coupling sets the engine's clearance, at each network step, to its
    starting one plus the rings' and balls' expansion since the start (Harris and Kotzalas: each
    free body grows by alpha dT times its diameter, the outer raceway's diameter d_m + D_w
    growing the clearance, the inner raceway's d_m - D_w and two balls taking it up); a warmer
    inner ring takes clearance up."""
    engine = BearingDynamics(params, mounting=Mounting(clearance=3e-6))
    engine.initialise(6000 * math.pi / 30.0, 200.0)
    coupling = ThermalCoupling(engine, ThermalConfig.from_yaml(config_path("bearings", "h7006c.yaml")), interval=0.05, tables=False, expansion=True)
    start = {n: coupling.temperature(n) for n in ("inner_ring", "outer_ring", "balls")}
    for _ in range(4):
        engine.advance(0.05)
        coupling.advance(0.05)
    rise = {n: coupling.temperature(n) - start[n] for n in start}
    assert rise["inner_ring"] > 0.0
    dm, dw, alpha = params.pitch_diameter, params.ball_diameter, BEARING_STEEL.expansion
    expected = 3e-6 + alpha * ((dm + dw) * rise["outer_ring"] - (dm - dw) * rise["inner_ring"] - 2.0 * dw * rise["balls"])
    assert engine.clearance == pytest.approx(expected, rel=1e-9, abs=1e-15)
    assert engine.clearance != 3e-6
