"""EHL traction of a ball-raceway contact, integrated over the Hertz ellipse, and its table.

Local law (at each point of the contact ellipse, x rolling direction with the inlet at x = -b,
y transverse): the film shears at the local sliding speed |u| (race relative to ball) and
carries the smallest of three stresses (a visco-elasto-plastic film in the manner of Johnson
and Tevaarwerk 1977, Proc. R. Soc. A 356:215):

* viscous, Eyring: tau_v = tau_0 asinh(eta(p) |u| / (h tau_0)), eta(p) by Roelands;
* elastic build-up since the inlet: tau_e = G (|u| / u_e) (x + b_x(y)) / h;
* limiting shear stress: tau_L = Lambda p (Bair and Winer 1979).

Sliding across the ellipse: u_x = u_e (SRR + kappa_H y^2) - omega_s y, u_y = omega_s x, where
SRR is the slide-to-roll ratio at the contact centre, kappa_H y^2 Heathcote's differential
slip of a conforming groove (the contact surface, of transverse radius R_c = 2 r_g R/(r_g + R),
lies nearer the ball centre and farther from the ring axis away from y = 0) and omega_s the spin
about the contact normal (outer-raceway control, Harris and Kotzalas: zero at the outer contact,
omega_i sin(alpha_i) + omega_m (r_m / r) sin(alpha_i - alpha_o) at the inner one, omega_i sin(alpha)
at equal angles; :func:`spin_and_heathcote`). The film is the Hamrock-Dowson central film
(uniform; thermal and starvation reductions applied).

Integrated: rolling-direction traction coefficient mu = F_x / Q and dissipated power
P / (Q u_e) (sliding, spin and Heathcote losses together). The engine tabulates both per
contact at start-up over SRR x entrainment speed x load and interpolates in the kernels. The
inner contact's spin and Heathcote slip at a node follow from the contact angles of a
thrust-loaded ball whose inner contact carries the node's load at the node's entrainment speed,
centrifugal force in (:func:`~bearing_rig_sim.dynamics.ball_balance.thrust_contact_angles`); the
outer contact's Heathcote slip from its load's thrust angle at rest (:func:`node_spin_and_heathcote`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from bearing_rig_sim.bearing.hertz import HertzContact
from bearing_rig_sim.dynamics.lubrication import Lubricant, film_thickness

GRID = 24
"""Points per semi-axis direction of the ellipse quadrature (midpoint rule on the unit disc)."""
SRR_REF = 1e-5
"""Scale of the table's SRR axis: xi = asinh(SRR / SRR_REF), uniform in xi."""
SRR_MAX = 1.0
N_SRR = 97
N_SPEED = 14
N_LOAD = 12
SPEED_RANGE = (0.05, 0.05 * 800.0 ** (13 / 11))
"""Entrainment speeds of the table, m/s (log-spaced, 0.05 to 134.9 m/s): the nodes of a 0.05-40 m/s
axis of 12 (a factor 1.84 apart) and two more at that step. Lookups are clamped at the ends, and
NASA TP-2275's 35 mm bearing (config/bearings/tp2275.yaml) reaches 80.7 m/s at its inner contacts
at 72 000 rpm; the grease bearing stays below 10 m/s in the rig's envelope, where the nodes are
those of the 40 m/s axis."""
LOAD_RANGE = (0.5, 2000.0)
"""Contact loads of the table, N (log-spaced)."""
ODD_TAYLOR = 0.002
"""Relative distance from |SRR| within which :func:`table_lookup_full` places the odd part's
SRR by a first-order step from the rolling SRR's position instead of its own asinh."""
HEADER = 8
"""Header of a table in the parameter vector: n_srr, n_speed, n_load, xi_max, ln u0, d ln u,
ln q0, d ln q; then the pairs (mu, power)[contact, load, speed, srr] interleaved, so that one
lookup reads both from the same cache lines (:func:`mu_nodes` extracts the mu values)."""


@njit(cache=True)
def ellipse_traction(
    p_max: float,
    a: float,
    b: float,
    h: float,
    eta0: float,
    z_roelands: float,
    tau0: float,
    lam: float,
    g_mod: float,
    u_e: float,
    srr: float,
    spin: float,
    heathcote: float,
) -> tuple[float, float]:
    """Traction coefficient F_x/Q and dissipation P/(Q u_e) of one contact (see module doc).

    Args: maximum Hertz pressure (Pa), transverse and rolling semi-axes a, b (m), film h (m),
    inlet viscosity (Pa s), Roelands index, Eyring stress (Pa), limiting shear coefficient,
    film shear modulus (Pa), entrainment speed (m/s), SRR at the centre, spin per entrainment
    speed omega_s/u_e (1/m), Heathcote coefficient kappa_H (1/m^2).
    """
    ln_eta0 = math.log(eta0)
    k_r = ln_eta0 + 9.67
    fx = 0.0
    pw = 0.0
    d = 2.0 / GRID
    omega_s = spin * u_e
    for i in range(GRID):
        xi = -1.0 + (i + 0.5) * d
        for j in range(GRID):
            yj = -1.0 + (j + 0.5) * d
            r2 = xi * xi + yj * yj
            if r2 >= 1.0:
                continue
            pr = p_max * math.sqrt(1.0 - r2)
            x = xi * b
            y = yj * a
            ux = u_e * (srr + heathcote * y * y) - omega_s * y
            uy = omega_s * x
            us = math.sqrt(ux * ux + uy * uy)
            if us <= 0.0:
                continue
            eta = eta0 * math.exp(k_r * (-1.0 + (1.0 + pr / 1.96e8) ** z_roelands))
            tau = tau0 * math.asinh(eta * us / (h * tau0))
            inlet = x + b * math.sqrt(1.0 - yj * yj)
            tau_e = g_mod * us / u_e * inlet / h
            if tau_e < tau:
                tau = tau_e
            if lam * pr < tau:
                tau = lam * pr
            fx += tau * ux / us
            pw += tau * us
    area = a * b * d * d
    q = 2.0 / 3.0 * math.pi * a * b * p_max
    return fx * area / q, pw * area / (q * u_e)


@dataclass(frozen=True)
class ContactKinematics:
    """Geometry of a raceway contact that the traction table needs (SI)."""

    hertz: HertzContact
    rx: float
    groove_radius: float
    inner: bool


def spin_and_heathcote(
    contact: ContactKinematics, alpha: float, ball_diameter: float, pitch_diameter: float, alpha_outer: float | None = None
) -> tuple[float, float]:
    """(omega_s / u_e in 1/m, kappa_H in 1/m^2) of a contact at the contact angle ``alpha``
    (rad), outer-raceway control (see module doc). For the inner contact ``alpha_outer`` is the
    outer contact's angle (default ``alpha``: equal angles); the ball's angular velocity is
    normal to the outer contact's normal, and with the orbit speed
    omega_m = omega_i (r_m - r cos alpha_i) / (r_m (1 + cos(alpha_i - alpha_o))) the inner contact
    spins at omega_i sin(alpha_i) + omega_m (r_m / r) sin(alpha_i - alpha_o), entrained at
    (omega_i - omega_m)(r_m - r cos alpha_i); at equal angles omega_s = omega_i sin(alpha)."""
    r = 0.5 * ball_diameter
    rm = 0.5 * pitch_diameter
    rc = 2.0 * contact.groove_radius * r / (contact.groove_radius + r)
    if contact.inner:
        ao = alpha if alpha_outer is None else alpha_outer
        r_race = rm - r * math.cos(alpha)
        orbit = r_race / (rm * (1.0 + math.cos(alpha - ao)))  # omega_m / omega_i
        spin = math.sin(alpha) + orbit * rm / r * math.sin(alpha - ao)  # omega_s / omega_i
        return spin / ((1.0 - orbit) * r_race), (1.0 / r + math.cos(alpha) / r_race) / (2.0 * rc)
    r_race = rm + r * math.cos(alpha)
    return 0.0, -(1.0 / r - math.cos(alpha) / r_race) / (2.0 * rc)


def table_axes() -> tuple[np.ndarray, np.ndarray]:
    """The logarithms of the table's entrainment speeds (m/s) and contact loads (N), ascending."""
    lu = np.linspace(math.log(SPEED_RANGE[0]), math.log(SPEED_RANGE[1]), N_SPEED)
    lq = np.linspace(math.log(LOAD_RANGE[0]), math.log(LOAD_RANGE[1]), N_LOAD)
    return lu, lq


def srr_axis() -> np.ndarray:
    """The table's slide-to-roll ratios, ascending: uniform in asinh(SRR / SRR_REF) from -SRR_MAX
    to SRR_MAX, N_SRR of them."""
    xi_max = math.asinh(SRR_MAX / SRR_REF)
    return SRR_REF * np.sinh(np.linspace(-xi_max, xi_max, N_SRR))


def pack_table(mu: np.ndarray, power: np.ndarray) -> np.ndarray:
    """A table's flat array (layout: HEADER) from its traction coefficients and dissipations
    P / (Q u_e) at the nodes, each of shape (2, N_LOAD, N_SPEED, N_SRR) (contact, load, speed,
    SRR; axes of :func:`table_axes` and :func:`srr_axis`)."""
    lu, lq = table_axes()
    head = np.array([N_SRR, N_SPEED, N_LOAD, math.asinh(SRR_MAX / SRR_REF), lu[0], lu[1] - lu[0], lq[0], lq[1] - lq[0]])
    return np.concatenate([head, np.stack([mu, power], axis=-1).ravel()])


def node_spin_and_heathcote(
    contact: ContactKinematics, angles: np.ndarray, iq: int, iu: int, ball_diameter: float, pitch_diameter: float
) -> tuple[float, float]:
    """:func:`spin_and_heathcote` of ``contact`` at the table node (load ``iq``, speed ``iu``):
    an inner-contact node at the angles (alpha_i, alpha_o) = ``angles[iq, iu]`` (rad) of the
    ball whose inner contact carries that load at that entrainment speed; an outer-contact node
    (no spin under outer-raceway control; its Heathcote slip varies as cos(alpha)) at the thrust
    angle of its load at rest, ``angles[iq, 0, 1]``."""
    if contact.inner:
        return spin_and_heathcote(contact, float(angles[iq, iu, 0]), ball_diameter, pitch_diameter, float(angles[iq, iu, 1]))
    return spin_and_heathcote(contact, float(angles[iq, 0, 1]), ball_diameter, pitch_diameter)


def build_table(
    contacts: tuple[ContactKinematics, ContactKinematics],
    lub: Lubricant,
    temperature_c: float,
    *,
    angles: np.ndarray,
    ball_diameter: float,
    pitch_diameter: float,
) -> np.ndarray:
    """The traction table of both raceway contacts as a flat float64 array (layout: HEADER).

    ``angles``: the contact angles (alpha_i, alpha_o), rad, of the ball whose inner contact
    carries each node's load at each node's entrainment speed, shape (N_LOAD, N_SPEED, 2)
    (:func:`bearing_rig_sim.dynamics.ball_balance.thrust_contact_angles` at the nodes of
    :func:`table_axes`); the spin and Heathcote slip of each node follow from them
    (:func:`node_spin_and_heathcote`)."""
    srrs = srr_axis()
    lu, lq = table_axes()
    eta0 = lub.dynamic_viscosity(temperature_c)
    z = lub.roelands_index(temperature_c)
    mu = np.zeros((2, N_LOAD, N_SPEED, N_SRR))
    pw = np.zeros_like(mu)
    for c, contact in enumerate(contacts):
        for iq, q in enumerate(np.exp(lq)):
            a, b = contact.hertz.semi_axes(q)
            ph = contact.hertz.max_pressure(q)
            for iu, u in enumerate(np.exp(lu)):
                spin, kh = node_spin_and_heathcote(contact, angles, iq, iu, ball_diameter, pitch_diameter)
                film = film_thickness(lub, temperature_c, contact.hertz.reduced_modulus, contact.rx, contact.hertz.ellipticity, b, ph, u, q)
                h = max(film.central, 1e-9)
                for k, s in enumerate(srrs):
                    mu[c, iq, iu, k], pw[c, iq, iu, k] = ellipse_traction(
                        ph, a, b, h, eta0, z, lub.eyring_stress, lub.limiting_shear_coefficient, lub.shear_modulus, u, s, spin, kh
                    )
    return pack_table(mu, pw)


def mu_nodes(t: np.ndarray, base: int) -> np.ndarray:
    """The traction coefficients at the nodes of the table stored in ``t`` from index ``base``,
    shape (2 n_load n_speed, n_srr) (contact, load and speed flattened)."""
    ns, nu, nq = int(t[base]), int(t[base + 1]), int(t[base + 2])
    start = base + HEADER
    return np.asarray(t[start : start + 2 * 2 * ns * nu * nq : 2]).reshape(-1, ns)


@njit(cache=True)
def _table_position(t: np.ndarray, base: int, srr: float, speed: float, load: float) -> tuple[int, int, int, float, float, float, float, float]:
    """Cell indices and weights of (asinh(SRR/SRR_REF), ln u_e, ln Q) in a table, clamped at
    its edges, and ln u_e, ln Q."""
    ns = int(t[base])
    nu = int(t[base + 1])
    nq = int(t[base + 2])
    xi_max = t[base + 3]
    dxi = 2.0 * xi_max / (ns - 1)
    xi = math.asinh(srr / SRR_REF)
    fs = min(max((xi + xi_max) / dxi, 0.0), ns - 1.000001)
    lu = math.log(max(speed, 1e-9))
    lq = math.log(max(load, 1e-9))
    fu = min(max((lu - t[base + 4]) / t[base + 5], 0.0), nu - 1.000001)
    fq = min(max((lq - t[base + 6]) / t[base + 7], 0.0), nq - 1.000001)
    i_s, i_u, i_q = int(fs), int(fu), int(fq)
    return i_s, i_u, i_q, fs - i_s, fu - i_u, fq - i_q, lu, lq


@njit(cache=True, inline="always")
def _mirrored(ns: int, fp: float) -> tuple[int, int, float, float]:
    """Cell indices and weights of an SRR's node position ``fp`` >= the table's centre and of its
    mirror image (-SRR), clamped at the table's edge."""
    fp = min(fp, ns - 1.000001)
    fm = max(ns - 1.0 - fp, 0.0)
    i_p, i_m = int(fp), int(fm)
    return i_p, i_m, fp - i_p, fm - i_m


@njit(cache=True)
def table_lookup_full(
    t: np.ndarray, base: int, contact: int, srr: float, odd_srr: float, speed: float, load: float, spin_a: float = -1.0, spin_b: float = -1.0
) -> tuple[float, float, float, float, float, float, float]:
    """One pass over the cells of a table for ``contact``: (mu, d mu / d SRR,
    u_e^0.66 Q^0.47, P / (Q u_e)) at ``srr`` and, when ``odd_srr`` >= 0, the odd part
    (mu(+odd_srr) - mu(-odd_srr))/2 at ``odd_srr`` (else 0): the law with the offset of spin and
    Heathcote slip at SRR = 0 taken out, rising from 0 and saturating like it; then the odd part
    at ``spin_a`` and at ``spin_b`` when they are >= 0 (else 0; the spin moment's two SRRs,
    :func:`.kernels.spin_moment_change`). The speed and load position is computed once for
    all."""
    ns = int(t[base])
    nu = int(t[base + 1])
    size = ns * nu * int(t[base + 2])
    i_s, i_u, i_q, ws, wu, wq, lu, lq = _table_position(t, base, srr, speed, load)
    odd = odd_srr >= 0.0
    spin = spin_a >= 0.0 and spin_b >= 0.0
    i_p = i_m = ia_p = ia_m = ib_p = ib_m = 0
    wp = wm = wa_p = wa_m = wb_p = wb_m = 0.0
    xi_max = t[base + 3]
    dxi = 2.0 * xi_max / (ns - 1)
    root = math.sqrt(SRR_REF * SRR_REF + srr * srr)
    if odd:
        d = odd_srr - abs(srr)
        if 0.0 <= d <= ODD_TAYLOR * abs(srr):
            # close to |srr|: asinh to first order from srr's own position (d asinh(x/R)/dx =
            # 1/sqrt(R^2 + x^2)); the second-order term is below 2e-6 of a cell
            fp = abs(i_s + ws - 0.5 * (ns - 1)) + 0.5 * (ns - 1) + d / root / dxi
        else:
            fp = (math.asinh(odd_srr / SRR_REF) + xi_max) / dxi
        i_p, i_m, wp, wm = _mirrored(ns, fp)
    if spin:
        fa = (math.asinh(spin_a / SRR_REF) + xi_max) / dxi
        d = spin_b - spin_a
        if abs(d) <= ODD_TAYLOR * spin_a:
            # close to spin_a (a small pitch rate): asinh to first order, as for odd_srr
            fb = fa + d / math.sqrt(SRR_REF * SRR_REF + spin_a * spin_a) / dxi
        else:
            fb = (math.asinh(spin_b / SRR_REF) + xi_max) / dxi
        ia_p, ia_m, wa_p, wa_m = _mirrored(ns, fa)
        ib_p, ib_m, wb_p, wb_m = _mirrored(ns, fb)
    mu0 = 0.0
    mu1 = 0.0
    pw = 0.0
    mu_odd = 0.0
    mu_a = 0.0
    mu_b = 0.0
    for dq in range(2):
        cq = wq if dq == 1 else 1.0 - wq
        for du in range(2):
            cu = wu if du == 1 else 1.0 - wu
            cell = base + HEADER + 2 * (contact * size + ((i_q + dq) * nu + (i_u + du)) * ns)
            k = cell + 2 * i_s
            w = cq * cu
            mu0 += w * t[k]
            mu1 += w * t[k + 2]
            pw += w * ((1.0 - ws) * t[k + 1] + ws * t[k + 3])
            if odd:
                plus = (1.0 - wp) * t[cell + 2 * i_p] + wp * t[cell + 2 * i_p + 2]
                minus = (1.0 - wm) * t[cell + 2 * i_m] + wm * t[cell + 2 * i_m + 2]
                mu_odd += w * (plus - minus)
            if spin:
                plus = (1.0 - wa_p) * t[cell + 2 * ia_p] + wa_p * t[cell + 2 * ia_p + 2]
                minus = (1.0 - wa_m) * t[cell + 2 * ia_m] + wa_m * t[cell + 2 * ia_m + 2]
                mu_a += w * (plus - minus)
                plus = (1.0 - wb_p) * t[cell + 2 * ib_p] + wb_p * t[cell + 2 * ib_p + 2]
                minus = (1.0 - wb_m) * t[cell + 2 * ib_m] + wb_m * t[cell + 2 * ib_m + 2]
                mu_b += w * (plus - minus)
    mu = mu0 + ws * (mu1 - mu0)
    slope = (mu1 - mu0) / dxi / root
    rolling = math.exp(0.66 * lu + 0.47 * lq) if load > 0.0 else 0.0
    return mu, slope, rolling, pw, 0.5 * mu_odd, 0.5 * mu_a, 0.5 * mu_b


@njit(cache=True)
def table_lookup_power(t: np.ndarray, base: int, contact: int, srr: float, speed: float, load: float) -> tuple[float, float, float, float]:
    """:func:`table_lookup` and :func:`table_power` in one pass over the cell (one position
    computation): (mu, d mu / d SRR, u_e^0.66 Q^0.47, P / (Q u_e))."""
    mu, slope, rolling, pw, _, _, _ = table_lookup_full(t, base, contact, srr, -1.0, speed, load)
    return mu, slope, rolling, pw


@njit(cache=True)
def table_lookup(t: np.ndarray, base: int, contact: int, srr: float, speed: float, load: float) -> tuple[float, float, float]:
    """Interpolate a traction table stored in ``t`` from index ``base``: returns
    (mu, d mu / d SRR, u_e^0.66 Q^0.47) for ``contact`` (0 inner, 1 outer). Trilinear in
    (asinh(SRR/SRR_REF), ln u_e, ln Q), clamped at the table's edges; the last value is the
    speed-load factor of Houpert's rolling force, from the same logarithms
    (:func:`table_lookup_full` without the dissipation)."""
    mu, slope, rolling, _, _, _, _ = table_lookup_full(t, base, contact, srr, -1.0, speed, load)
    return mu, slope, rolling


@njit(cache=True)
def table_power(t: np.ndarray, base: int, contact: int, srr: float, speed: float, load: float) -> float:
    """Interpolated dissipation P / (Q u_e) of ``contact`` (same grid as :func:`table_lookup`)."""
    return table_lookup_full(t, base, contact, srr, -1.0, speed, load)[3]


@njit(cache=True)
def table_odd(t: np.ndarray, base: int, contact: int, srr: float, speed: float, load: float) -> float:
    """The odd part (mu(+SRR) - mu(-SRR))/2 of ``contact``'s traction at ``srr`` >= 0
    (:func:`table_lookup_full`)."""
    return table_lookup_full(t, base, contact, srr, srr, speed, load)[4]
