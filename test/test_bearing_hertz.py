"""Hertz contact: the elliptical solution against independent closed forms.

References computed here, independently of ``bearing/hertz.py``:
* the complete elliptic integrals by Gauss-Legendre quadrature of their defining integrals and
  the ellipticity by bisection on Harris and Kotzalas Eq. 6.26 (exact closed form);
* Brewe and Hamrock's approximations (ASME J. Lubr. Tech. 1977), accurate to about 1-3 %;
* the sphere-on-flat limit, K = 4/3 E* sqrt(R).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.dynamics import BearingParameters, derive
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.bearing.hertz import point_contact, raceway_contacts

E_STEEL, NU_STEEL = 208e9, 0.3
DW, DM, ALPHA = 6.3e-3, 42.45e-3, math.radians(15.0)
NODES, WEIGHTS = np.polynomial.legendre.leggauss(400)


def _ellip(m: float) -> tuple[float, float]:
    """K(m), E(m) by quadrature over phi in (0, pi/2)."""
    phi = (NODES + 1.0) * math.pi / 4.0
    w = WEIGHTS * math.pi / 4.0
    s = 1.0 - m * np.sin(phi) ** 2
    return float(np.sum(w / np.sqrt(s))), float(np.sum(w * np.sqrt(s)))


def _reference_stiffness(rho: tuple[float, float, float, float]) -> float:
    """K of Q = K delta^1.5 from the exact closed form, computed independently."""
    rho_sum = sum(rho)
    f_rho = abs((rho[0] - rho[1]) + (rho[2] - rho[3])) / rho_sum

    def f_of(kappa: float) -> float:
        k, e = _ellip(1.0 - 1.0 / kappa**2)
        return ((kappa**2 + 1.0) * e - 2.0 * k) / ((kappa**2 - 1.0) * e)

    lo, hi = 1.0001, 100.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f_of(mid) < f_rho else (lo, mid)
    kappa = 0.5 * (lo + hi)
    k1, e2 = _ellip(1.0 - 1.0 / kappa**2)
    e_prime = E_STEEL / (1.0 - NU_STEEL**2)  # 2/((1-nu^2)/E + (1-nu^2)/E)
    delta_per_q23 = k1 * (9.0 * rho_sum / (2.0 * e2) / (math.pi * kappa * e_prime) ** 2) ** (1.0 / 3.0)
    return delta_per_q23**-1.5


def _raceway_rho(f: float, inner: bool) -> tuple[float, float, float, float]:
    gamma = DW * math.cos(ALPHA) / DM
    r2 = 2.0 * gamma / (DW * (1.0 - gamma)) if inner else -2.0 * gamma / (DW * (1.0 + gamma))
    return 2.0 / DW, 2.0 / DW, r2, -1.0 / (f * DW)


def test_sphere_on_flat_is_the_classical_hertz_law() -> None:
    c = point_contact(2 / DW, 2 / DW, 0.0, 0.0, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    e_star = E_STEEL / (2.0 * (1.0 - NU_STEEL**2))
    assert c.stiffness == pytest.approx(4.0 / 3.0 * e_star * math.sqrt(DW / 2), rel=1e-9)
    assert c.ellipticity == 1.0


@pytest.mark.parametrize("fi,fo", [(0.52, 0.53), (0.515, 0.525), (0.54, 0.54)])
def test_raceway_stiffness_matches_independent_closed_form(fi: float, fo: float) -> None:
    inner, outer = raceway_contacts(DW, DM, ALPHA, fi, fo, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)
    assert inner.stiffness == pytest.approx(_reference_stiffness(_raceway_rho(fi, True)), rel=5e-3)
    assert outer.stiffness == pytest.approx(_reference_stiffness(_raceway_rho(fo, False)), rel=5e-3)


@pytest.mark.parametrize("inner", [True, False])
def test_raceway_stiffness_within_two_percent_of_brewe_hamrock(inner: bool) -> None:
    rho = _raceway_rho(0.52 if inner else 0.53, inner)
    rx = 1.0 / (rho[0] + rho[2])  # rolling direction
    ry = 1.0 / (rho[1] + rho[3])  # transverse
    kappa = 1.0339 * (ry / rx) ** 0.636
    e2 = 1.0003 + 0.5968 * rx / ry
    f1 = 1.5277 + 0.6023 * math.log(ry / rx)
    r_eff = 1.0 / sum(rho)
    e_prime = E_STEEL / (1.0 - NU_STEEL**2)
    # delta = F [9/(2 E R) (Q/(pi kappa E'))^2]^(1/3)  (Hamrock and Dowson Eq. 3.xx)
    k_approx = (f1 * (9.0 / (2.0 * e2 * r_eff) / (math.pi * kappa * e_prime) ** 2) ** (1.0 / 3.0)) ** -1.5
    contact = raceway_contacts(DW, DM, ALPHA, 0.52, 0.53, E_STEEL, NU_STEEL, E_STEEL, NU_STEEL)[0 if inner else 1]
    assert contact.stiffness == pytest.approx(k_approx, rel=0.02)
    assert contact.ellipticity == pytest.approx(kappa, rel=0.03)


def test_kernel_force_against_approach_follows_the_hertz_law() -> None:
    """The engine's contact law (IMPACT form, damping off) against Q = K delta^1.5 with K from
    the independent closed form, for the configured curvatures, over 1-500 N."""
    params = BearingParameters.from_yaml().conservative()
    vec, _ = derive(params)
    k_ref = _reference_stiffness(_raceway_rho(params.inner_curvature_ratio, True))
    for q in (1.0, 10.0, 100.0, 500.0):
        delta = (q / k_ref) ** (2.0 / 3.0)
        force, _, _ = kn.impact_force(delta, 0.0, vec[kn.P_K_IN], vec)
        assert force == pytest.approx(q, rel=0.02)
    assert kn.impact_force(-1e-7, 0.0, vec[kn.P_K_IN], vec)[0] == 0.0  # no force when apart


def test_hunt_crossley_damping_dissipates_and_never_pulls() -> None:
    params = BearingParameters.from_yaml()
    vec, _ = derive(params)
    k = vec[kn.P_K_IN]
    delta = 2e-6
    static = kn.impact_force(delta, 0.0, k, vec)[0]
    assert kn.impact_force(delta, 0.01, k, vec)[0] > static  # approaching: more force
    assert kn.impact_force(delta, -0.01, k, vec)[0] < static  # separating: less force
    assert kn.impact_force(delta, -1e6, k, vec)[0] == 0.0  # but never adhesive
