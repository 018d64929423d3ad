"""The cage centre's in-plane motion (whirl) in the reduced model: the land's Ocvirk film and
contact, the pockets pushing the cage off centre, and the centred cage staying centred under a
pure axial load (docs/model.md, Cage whirl)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from bearing_rig_sim.config import ConfigError, read_mapping
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.parameters import derive

RPM = math.pi / 30.0
BEARING_FILE = Path(__file__).resolve().parents[1] / "config" / "bearings" / "h7006c.yaml"


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.calibrated()


@pytest.fixture(scope="module")
def oil_land(params: BearingParameters) -> np.ndarray:
    """The shipped bearing's kernel vector with a Newtonian land film of 0.05 Pa s (the
    closed forms are for a Newtonian fluid): land radius 22.85 mm (cage OD 45.7 mm), two lands
    of 1.75 mm, radial clearance 0.1 mm (config/bearings/h7006c.yaml)."""
    v, _ = derive(params)
    v = v.copy()
    v[kn.P_LAND_ETA], v[kn.P_LAND_TAUY], v[kn.P_LAND_CONS] = 0.05, 0.0, 0.0
    return v


def test_the_bearing_file_describes_the_land(params: BearingParameters, oil_land: np.ndarray) -> None:
    """The numbers the hand calculations below use are the bearing file's."""
    assert params.land_clearance == 1e-4 and params.land_width == 3.5e-3 and params.land_count == 2
    assert oil_land[kn.P_LAND_R] == pytest.approx(0.02285)
    assert oil_land[kn.P_LAND_OCV] == pytest.approx(2 * 0.02285 * 1.75e-3**3 / 1e-4**2)


@pytest.mark.parametrize(
    ("eps", "radial", "tangential"),
    [
        # Ocvirk, short journal bearing, pi film (Childs, Turbomachinery Rotordynamics, 1993,
        # ch. 3; the project's physics review): with U = R Omega = 0.02285 m x 100 rad/s
        # = 2.285 m/s, eta = 0.05 Pa s, L = 1.75 mm per land, two lands, c = 0.1 mm:
        # eta U L^3 / c^2 = 0.05 x 2.285 x 5.359375e-9 / 1e-8 = 0.0612309 N per land, 0.1224617 N.
        # F_r = -(eta U L^3/c^2) eps^2/(1 - eps^2)^2; F_t = (pi eta U L^3/(4 c^2)) eps/(1 - eps^2)^1.5
        # eps = 0.3: F_r = -0.1224617 x 0.09/0.8281 = -0.0133094 N;
        #            F_t = 0.0961818 x 0.3/0.8680812 = 0.0332391 N
        (0.3, -0.0133094, 0.0332391),
        # eps = 0.7: F_r = -0.1224617 x 0.49/0.2601 = -0.2307045 N;
        #            F_t = 0.0961818 x 0.7/0.3642100 = 0.1848558 N
        (0.7, -0.2307045, 0.1848558),
    ],
)
def test_land_film_force_is_ocvirks_short_bearing_force(oil_land: np.ndarray, eps: float, radial: float, tangential: float) -> None:
    """The cage displaced along x by eps c, turning at 100 rad/s, its centre at rest: the land
    pushes it back towards the axis (-x) with Ocvirk's radial force and along the direction of
    rotation (+y) with his tangential force; nothing touches (eps < 1)."""
    fx, fy, normal = kn.land_force(oil_land, eps * 1e-4, 0.0, 0.0, 0.0, 100.0)
    assert fx == pytest.approx(radial, rel=1e-5)
    assert fy == pytest.approx(tangential, rel=1e-5)
    assert normal == 0.0
    # the same displacement along y: the force turns with it (isotropic land)
    gx, gy, _ = kn.land_force(oil_land, 0.0, eps * 1e-4, 0.0, 0.0, 100.0)
    assert (gx, gy) == pytest.approx((-tangential, radial), rel=1e-5)


def test_a_whirling_centre_sees_the_wedge_of_omega_minus_twice_the_whirl_speed(oil_land: np.ndarray) -> None:
    """Reynolds' equation depends on the journal's speed and its centre's whirl speed psi_dot
    only through Omega - 2 psi_dot (Childs 1993): a cage turning at 300 rad/s whose centre
    orbits at 100 rad/s (velocity e psi_dot along +y at (e, 0)) feels the force of a cage
    turning at 100 rad/s about a fixed centre, and one that does not turn but whose centre
    orbits backwards at 50 rad/s the same too."""
    e = 0.5e-4
    fixed = kn.land_force(oil_land, e, 0.0, 0.0, 0.0, 100.0)[:2]
    assert kn.land_force(oil_land, e, 0.0, 0.0, e * 100.0, 300.0)[:2] == pytest.approx(fixed, rel=1e-9)
    assert kn.land_force(oil_land, e, 0.0, 0.0, -e * 50.0, 0.0)[:2] == pytest.approx(fixed, rel=1e-9)


@pytest.mark.parametrize("eps", [0.2, 0.6])
def test_land_film_with_squeeze_integrates_reynolds_pressure(oil_land: np.ndarray, eps: float) -> None:
    """Wedge and squeeze together against an independent integration of the short-bearing
    pressure. Reynolds' equation with the journal turning at Omega and its centre moving:
    d/dz (h^3 dp/dz) = 6 eta Omega dh/dth + 12 eta dh/dt, h = c (1 - eps cos th) (th from the
    minimum film), p = 0 at both land edges; integrated over the land width,
    P(th) = -(eta L^3/(2 c^2)) (eps Omega sin th - 2 eps_dot cos th)/(1 - eps cos th)^3, on the
    half ahead of the minimum film (th in (-pi, 0), the pi film of the classical dynamic short
    bearing), force -R int P (cos th, sin th) dth per land. A cage at 100 rad/s whose centre
    moves outward at 1 mm/s."""
    c, r_land, width, eta, omega = 1e-4, 0.02285, 1.75e-3, 0.05, 100.0
    eps_dot = 1e-3 / c

    def pressure(th: float) -> float:
        return -(eta * width**3 / (2 * c * c)) * (eps * omega * math.sin(th) - 2.0 * eps_dot * math.cos(th)) / (1.0 - eps * math.cos(th)) ** 3

    fr = -2 * r_land * quad(lambda th: pressure(th) * math.cos(th), -math.pi, 0.0)[0]
    ft = -2 * r_land * quad(lambda th: pressure(th) * math.sin(th), -math.pi, 0.0)[0]
    fx, fy, _ = kn.land_force(oil_land, eps * c, 0.0, 1e-3, 0.0, omega)
    assert fx == pytest.approx(fr, rel=1e-6)
    assert fy == pytest.approx(ft, rel=1e-6)
    # the squeeze resists the approach: more restoring force than the wedge alone
    assert fx < kn.land_force(oil_land, eps * c, 0.0, 0.0, 0.0, omega)[0]


def test_land_shear_factor_is_petroffs_eccentric_journal(oil_land: np.ndarray, params: BearingParameters) -> None:
    """The land torque's eccentricity factor: the mean of (c/h)^n over the land, for an oil
    (n = 1) 1/sqrt(1 - eps^2) (the eccentric journal's Couette torque: int dth/(1 - eps cos th)
    = 2 pi / sqrt(1 - eps^2)); for the grease (n = 0.5) the same mean by quadrature."""
    v = oil_land.copy()
    v[kn.P_LAND_N] = 1.0
    assert kn.land_shear_factor(v, 0.0) == 1.0
    assert kn.land_shear_factor(v, 0.5) == pytest.approx(1.0 / math.sqrt(0.75), rel=1e-6)
    assert kn.land_shear_factor(v, 0.9) == pytest.approx(1.0 / math.sqrt(0.19), rel=1e-4)
    v[kn.P_LAND_N] = 0.5
    exact = quad(lambda th: (1.0 - 0.8 * math.cos(th)) ** -0.5, 0.0, 2 * math.pi)[0] / (2 * math.pi)
    assert kn.land_shear_factor(v, 0.8) == pytest.approx(exact, rel=1e-5)


def test_land_contact_at_the_clearance(oil_land: np.ndarray) -> None:
    """Beyond the clearance the land touches: a linear line contact k d (k = (pi/4) E* L with
    the polyimide cage on steel: 1/E* = (1 - 0.34^2)/2.62 GPa + (1 - 0.3^2)/208 GPa) plus the
    film at its capped eccentricity, and Coulomb friction mu N against the cage's sliding."""
    e_star = 1.0 / ((1 - 0.34**2) / 2.62e9 + (1 - 0.3**2) / 208e9)
    k = math.pi / 4 * e_star * 3.5e-3
    assert oil_land[kn.P_LAND_K] == pytest.approx(k, rel=1e-9)
    d = 1e-6
    fx, fy, normal = kn.land_force(oil_land, 1e-4 + d, 0.0, 0.0, 0.0, 100.0)
    film_x, film_y, _ = kn.land_force(oil_land, kn.LAND_EPS_MAX * 1e-4, 0.0, 0.0, 0.0, 100.0)
    assert normal == pytest.approx(k * d, rel=1e-9)
    assert fx == pytest.approx(film_x - k * d, rel=1e-6)
    mu = oil_land[kn.P_LAND_MU]
    assert fy == pytest.approx(film_y - mu * k * d, rel=1e-3)  # surface slides +y at 2.3 m/s


def test_land_values_outside_their_range_are_refused() -> None:
    """A land clearance outside [1e-5, 1e-3] m, or a land count other than 1 or 2, is refused
    naming the key and the range."""
    data = read_mapping(BEARING_FILE)
    data["cage"]["land_radial_clearance_m"] = 0.002
    with pytest.raises(ConfigError, match=r"land_radial_clearance_m.*0\.001"):
        BearingParameters.from_mapping(data, "h7006c.yaml")
    data["cage"]["land_radial_clearance_m"] = 1e-4
    data["cage"]["land_count"] = 3
    with pytest.raises(ConfigError, match="land_count"):
        BearingParameters.from_mapping(data, "h7006c.yaml")


def test_a_centred_cage_stays_centred_under_pure_axial_load(params: BearingParameters) -> None:
    """By symmetry the pockets' forces cancel on the cage centre and the land film has no force
    at eps = 0: the cage centre stays on the axis, so the axial results are those of the
    concentric cage (the land torque's factor is 1)."""
    engine = BearingDynamics(params)
    engine.initialise(900 * RPM, 100.0)
    engine.advance(0.1)
    assert engine.cage_whirl_radius < 1e-12
    assert engine.ring[kn.R_LAND_F] == pytest.approx(1.0, abs=1e-12)
    assert engine.observe().cage_whirl_radius == engine.cage_whirl_radius


def _net_pocket_force(engine: BearingDynamics) -> np.ndarray:
    """Sum over the pockets of the ball's push on the cage: F_p along the pocket's
    circumferential direction t plus pocket friction mu_p F_p along its radial direction (the
    ball's front surface moves outward while it rolls)."""
    phi = engine.cage[:, kn.C_PHI]
    fp = engine.out[:, kn.O_FP]
    t = np.stack([-np.sin(phi), np.cos(phi)])
    r = np.stack([np.cos(phi), np.sin(phi)])
    mu = engine.params.pocket_friction
    return np.asarray((t * fp).sum(axis=1) + mu * (r * fp).sum(axis=1))


def test_a_radial_load_pushes_the_cage_off_centre_within_its_clearance(params: BearingParameters) -> None:
    """F_a = 163 N, F_r = 500 N at 900 rpm: balls in the load zone drive the cage, balls outside
    it are driven (pocket forces of both signs), and both push the cage the same way, so the
    cage leaves the axis. It settles at an offset within its land clearance where the land film
    carries the pockets' net force (Newton: the cage centre does not accelerate on average)."""
    engine = BearingDynamics(params)
    engine.initialise(900 * RPM, 163.0, radial_load=500.0)
    radii = []
    for _ in range(15):
        engine.advance(0.02)
        radii.append(engine.cage_whirl_radius)
    clearance = params.land_clearance
    assert max(radii) < clearance
    assert radii[-1] > 0.2 * clearance
    # the land's force balances the pockets' (the cage mass 1.7 g needs 0.02 N for 10 m/s^2)
    x, y, vx, vy = engine.ring[kn.R_CX : kn.R_CVY + 1]
    balance = []
    for _ in range(20):  # average over the ball passes
        engine.advance(engine.time_step)
        x, y, vx, vy = engine.ring[kn.R_CX : kn.R_CVY + 1]
        land = np.array(kn.land_force(engine.vector, x, y, vx, vy, engine.cage_speed)[:2])
        balance.append((land, _net_pocket_force(engine)))
    land = np.mean([b[0] for b in balance], axis=0)
    pockets = np.mean([b[1] for b in balance], axis=0)
    assert np.linalg.norm(pockets) > 1.0  # newtons: the pockets do push
    assert np.linalg.norm(land + pockets) < 0.05 * np.linalg.norm(pockets)


def test_a_cage_thrown_at_its_land_stays_within_the_clearance(params: BearingParameters) -> None:
    """The cage centre started at 0.9 of the clearance moving outward at 0.1 m/s (a knock, or
    the release of an unbalance) under pure axial load at 2700 rpm: the squeeze film and, if it
    reaches the land, the contact stop it within the clearance (plus the contact's micron),
    every step; then the orbit decays towards the axis."""
    engine = BearingDynamics(params)
    engine.initialise(2700 * RPM, 200.0)
    c = params.land_clearance
    engine.ring[kn.R_CX] = 0.9 * c
    engine.ring[kn.R_CVX] = 0.1
    worst = 0.0
    for _ in range(250):  # 10 ms, step by step
        engine.advance(engine.time_step)
        worst = max(worst, engine.cage_whirl_radius)
    assert worst < 1.02 * c
    first = engine.cage_whirl_radius
    engine.advance(0.2)
    assert engine.cage_whirl_radius < first


def test_the_pair_solver_and_the_pocket_directions_are_exact() -> None:
    """The step's helpers against the library: two right-hand sides of a cyclic tridiagonal
    system against numpy's dense solve; the pockets' directions t = (-sin phi, cos phi) by
    rotation against sin and cos, with segments off their nominal place by up to 1e-3 rad and
    one beyond it, after many revolutions."""
    rng = np.random.default_rng(7)
    n = 16
    diag, off = 3.0 + rng.random(n), -0.7
    a, b = rng.random(n), rng.random(n)
    dense = np.diag(diag) + off * (np.eye(n, k=1) + np.eye(n, k=-1))
    dense[0, -1] = dense[-1, 0] = off
    out_a, out_b = np.zeros(n), np.zeros(n)
    kn.cyclic_tridiagonal_pair(diag, off, a, b, out_a, out_b, np.zeros((n, 5)))
    np.testing.assert_allclose(out_a, np.linalg.solve(dense, a), rtol=1e-13)
    np.testing.assert_allclose(out_b, np.linalg.solve(dense, b), rtol=1e-13)
    cage = np.zeros((n, kn.NC))
    cage[:, kn.C_PHI] = 1234.5 + 2 * np.pi * np.arange(n) / n + rng.uniform(-1e-3, 1e-3, n)
    cage[5, kn.C_PHI] += 0.01
    tx, ty = np.zeros(n), np.zeros(n)
    kn.pocket_directions(cage, tx, ty, math.cos(2 * math.pi / n), math.sin(2 * math.pi / n))
    np.testing.assert_allclose(tx, -np.sin(cage[:, kn.C_PHI]), atol=1e-14)
    np.testing.assert_allclose(ty, np.cos(cage[:, kn.C_PHI]), atol=1e-14)


def test_a_small_whirl_under_axial_load_leaves_the_slip_alone(params: BearingParameters) -> None:
    """Under a pure axial load (900 rpm, 100 N) a cage knocked 20 um off the axis orbits
    (forward, at about 0.6 of its speed) on a shrinking orbit towards the few-micron limit cycle
    of the weakly unstable centred cage; the slip stays within 0.02 percentage points of the
    centred cage's."""
    centred = BearingDynamics(params)
    centred.initialise(900 * RPM, 100.0)
    knocked = BearingDynamics(params)
    knocked.initialise(900 * RPM, 100.0)
    knocked.ring[kn.R_CX] = 20e-6
    centred.advance(0.5)
    knocked.advance(0.5)
    x, y, vx, vy = knocked.ring[kn.R_CX : kn.R_CVY + 1]
    assert 0.0 < knocked.cage_whirl_radius < 20e-6
    assert 0.3 * knocked.cage_speed < (x * vy - y * vx) / (x * x + y * y) < knocked.cage_speed
    ratio = params.epicyclic_ratio
    slip = [100.0 * (1.0 - a.cage_speed / (ratio * a.inner_ring_speed)) for a in (centred.advance(0.5), knocked.advance(0.5))]
    assert slip[1] == pytest.approx(slip[0], abs=0.02)
