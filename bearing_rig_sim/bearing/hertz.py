"""Elliptical Hertz point contact (Harris and Kotzalas, *Rolling Bearing Analysis*, ch. 6;
Hamrock and Dowson, *Ball Bearing Lubrication*, ch. 3).

The paper (docs/paper.md section 3) writes the ball-raceway stiffness with the two-sphere form
K = 4/3 E* sqrt(Re). For a ball in a grooved raceway the contact is elliptical; this module solves
the classical elliptical problem from the curvature sum and difference, with the complete elliptic
integrals, and gives the load-deflection constant of Q = K delta^1.5.

Conventions: curvatures in 1/m, convex surfaces positive, concave negative; loads in N,
deflections (approaches) in m, moduli in Pa.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq
from scipy.special import ellipe, ellipk


@dataclass(frozen=True)
class HertzContact:
    """Load-deflection data of one elliptical point contact.

    Attributes:
        stiffness: K in Q = K delta^1.5, N/m^1.5.
        ellipticity: kappa = a/b (semi-major over semi-minor axis), 1.
        first_kind: complete elliptic integral of the first kind at e^2 = 1 - 1/kappa^2, 1.
        second_kind: complete elliptic integral of the second kind, 1.
        curvature_sum: sum rho, 1/m.
        curvature_difference: F(rho), 1.
        reduced_modulus: E' = 2 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2), Pa.
    """

    stiffness: float
    ellipticity: float
    first_kind: float
    second_kind: float
    curvature_sum: float
    curvature_difference: float
    reduced_modulus: float

    def semi_axes(self, load: float) -> tuple[float, float]:
        """Semi-major and semi-minor axes (m) of the contact ellipse under ``load`` (N)."""
        q = max(load, 0.0)
        k, e2, rho, ep = self.ellipticity, self.second_kind, self.curvature_sum, self.reduced_modulus
        a = (6.0 * k * k * e2 * q / (math.pi * rho * ep)) ** (1.0 / 3.0)
        b = (6.0 * e2 * q / (math.pi * k * rho * ep)) ** (1.0 / 3.0)
        return a, b

    def approach(self, load: float) -> float:
        """Elastic approach delta (m) of the two bodies under ``load`` (N)."""
        return (max(load, 0.0) / self.stiffness) ** (2.0 / 3.0)

    def max_pressure(self, load: float) -> float:
        """Maximum Hertz pressure (Pa) under ``load`` (N)."""
        a, b = self.semi_axes(load)
        return 1.5 * load / (math.pi * a * b) if load > 0.0 else 0.0


def reduced_modulus(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """E' = 2 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2) in Pa (Hamrock and Dowson's convention;
    the paper's E* of docs/paper.md section 3 is E'/2)."""
    return 2.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)


def curvature_difference_of_ellipticity(kappa: float) -> float:
    """F(rho) as a function of the ellipticity kappa >= 1 (Harris and Kotzalas Eq. 6.26)."""
    m = 1.0 - 1.0 / (kappa * kappa)
    ek, ee = ellipk(m), ellipe(m)
    return ((kappa * kappa + 1.0) * ee - 2.0 * ek) / ((kappa * kappa - 1.0) * ee)


def point_contact(rho_1i: float, rho_1ii: float, rho_2i: float, rho_2ii: float, e1: float, nu1: float, e2: float, nu2: float) -> HertzContact:
    """Solve the elliptical Hertz point contact of two bodies.

    Args:
        rho_1i: body 1 curvature in plane I (rolling direction), 1/m.
        rho_1ii: body 1 curvature in plane II (transverse), 1/m.
        rho_2i: body 2 curvature in plane I, 1/m (concave negative).
        rho_2ii: body 2 curvature in plane II, 1/m (concave negative).
        e1, nu1: Young's modulus (Pa) and Poisson's ratio of body 1.
        e2, nu2: Young's modulus (Pa) and Poisson's ratio of body 2.

    Returns:
        The contact's load-deflection data.

    Raises:
        ValueError: non-positive curvature sum (the bodies do not touch at a point).
    """
    rho_sum = rho_1i + rho_1ii + rho_2i + rho_2ii
    if not rho_sum > 0.0:
        raise ValueError(f"curvature sum must be > 0 for a point contact, got {rho_sum}")
    f_rho = abs((rho_1i - rho_1ii) + (rho_2i - rho_2ii)) / rho_sum
    ep = reduced_modulus(e1, nu1, e2, nu2)
    if f_rho < 1e-9:
        kappa, ek, ee = 1.0, math.pi / 2.0, math.pi / 2.0
    else:
        kappa = brentq(lambda k: curvature_difference_of_ellipticity(k) - f_rho, 1.0 + 1e-9, 1e3, xtol=1e-14)
        m = 1.0 - 1.0 / (kappa * kappa)
        ek, ee = float(ellipk(m)), float(ellipe(m))
    # delta = F (9/(2 E Rsum) (Q/(pi kappa E'))^2)^(1/3)  ->  Q = K delta^1.5
    coef = ek * (9.0 * rho_sum / (2.0 * ee) / (math.pi * kappa * ep) ** 2) ** (1.0 / 3.0)
    stiffness = coef**-1.5
    return HertzContact(stiffness, kappa, ek, ee, rho_sum, f_rho, ep)


def raceway_contacts(
    ball_diameter: float,
    pitch_diameter: float,
    contact_angle: float,
    inner_curvature_ratio: float,
    outer_curvature_ratio: float,
    e_ball: float,
    nu_ball: float,
    e_ring: float,
    nu_ring: float,
) -> tuple[HertzContact, HertzContact]:
    """Ball-inner and ball-outer raceway contacts of a ball bearing (Harris and Kotzalas
    Eq. 2.27-2.31): gamma = Dw cos(alpha)/dm.

    Args:
        ball_diameter: Dw, m.
        pitch_diameter: dm, m.
        contact_angle: alpha, rad.
        inner_curvature_ratio: f_i = r_i/Dw, 1.
        outer_curvature_ratio: f_o = r_o/Dw, 1.
        e_ball, nu_ball, e_ring, nu_ring: elastic constants, Pa and 1.
    """
    gamma = ball_diameter * math.cos(contact_angle) / pitch_diameter
    rb = 2.0 / ball_diameter
    inner = point_contact(rb, rb, rb * gamma / (1.0 - gamma), -1.0 / (inner_curvature_ratio * ball_diameter), e_ball, nu_ball, e_ring, nu_ring)
    outer = point_contact(rb, rb, -rb * gamma / (1.0 + gamma), -1.0 / (outer_curvature_ratio * ball_diameter), e_ball, nu_ball, e_ring, nu_ring)
    return inner, outer
