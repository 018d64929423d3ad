"""numba kernels of the bearing dynamics. Private: use :mod:`bearing_rig_sim.dynamics.engine`.

Conventions (every kernel):

* float64 arrays only, no Python objects; SI units (m, kg, s, N, rad).
* ``p``: parameter vector, indices ``P_*`` below (filled by ``parameters.derive``).
* ``ball``: shape (Z, NB), one row per ball, columns ``B_*``: orbital angle theta (rad), orbital
  speed omega_m (rad/s), spin omega_a (rad/s, absolute angular velocity component along the
  ball's rolling axis), ball-centre radius r_b and axial position z_b (m), radial and axial
  velocity (m/s; stiff model only), pivot omega_t (rad/s: absolute angular velocity component
  along e_t, perpendicular to the rolling axis and the orbit radius, the direction of the
  gyroscopic moment), pitch rate omega_p (rad/s: angular velocity about
  w = (cos beta, 0, sin beta) relative to raceway control, omega . w = omega_m sin(beta) +
  omega_p; 0 in the stiff model).
* ``cage``: shape (Z, NC), one row per cage segment (pocket), columns ``C_*``: angle phi (rad),
  speed Omega (rad/s).
* ``ring``: shape (NR,), ``R_*``: inner-ring angle (rad) and speed (rad/s), axial displacement
  (m) and axial velocity (m/s), time (s), radial displacement along x and y (m; quasi-static,
  reduced model only; ball j's radial direction is (cos theta_j, sin theta_j)); the cage
  centre's displacement (m) and velocity (m/s) along x and y (dynamic, reduced model only), the
  cage-land contact force (N) and the eccentricity factor of the land's viscous torque (1) of
  the last step; the tilts theta_x, theta_y (rad; quasi-static, reduced model, free only under
  an applied moment: the inner groove curvature centre of ball j moves axially by
  R_i (theta_x cos theta_j + theta_y sin theta_j), R_i = CI_R, as in dynamics/quasi_static.py)
  and the balls' moment on the ring at the last recorded step (N m; :func:`ring_moment`).
* ``out``: shape (Z, NO), per-ball diagnostics ``O_*`` (contact loads N, angles rad, pocket
  force N, sliding velocities m/s, tractions N), written by every step.
* ``stats``: shape (NS,), running integrals ``S_*`` (cage speed x dt, inner speed x dt, time,
  drive work: the drive torque x inner-ring speed x dt, J).

Frames: cylindrical (e_r, e_t, e_z) attached to each ball's orbital position, e_t in the
direction of rotation. The outer ring is fixed; the axial load pushes the inner ring in +z.
Groove curvature centres sit at (CI_R, CI_Z + delta_a) (inner) and (CO_R, CO_Z) (outer); an
extra diametral clearance P_d moves CO_R out by P_d/2 (the engine's ``set_clearance``).
Ball attitude: the reference rolling axis lies in the r-z plane at the pitch angle beta with
tan(beta) = sin(alpha)/(cos(alpha) + gamma) (Harris and Kotzalas), alpha the mean loaded contact
angle (raceway control: the ball's angular velocity relative to the orbiting frame has no
component along the third direction w of the r-z plane). The pivot omega_t and the pitch rate
omega_p are dynamic (reduced model): the rotating frame's gyroscopic moment
J omega_m (sin(beta) omega_roll + cos(beta) omega_p) drives the pivot, the transverse tractions
of both raceway contacts resist it, the gyroscopic coupling J omega_m cos(beta) omega_t turns it
into pitch and the change of both contacts' spin moments resists the pitch
(:func:`sliding_traction`, docs/model.md, "Ball attitude"). The stiff model holds the pitch.

Cage slip is not computed anywhere here: the cage speed results from integrating the
ball-pocket, rim and land forces, and the ball speeds from the raceway tractions.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from bearing_rig_sim.dynamics.traction import table_lookup, table_lookup_full, table_power

# -- parameter vector layout ------------------------------------------------------------------
P_Z = 0  # number of balls
P_RBALL = 1  # ball radius, m
P_RM = 2  # pitch radius, m
P_RI_GAP = 3  # inner groove radius minus ball radius, m
P_RO_GAP = 4  # outer groove radius minus ball radius, m
P_CI_R = 5  # inner groove curvature centre, radial, m (delta_a = 0)
P_CI_Z = 6  # inner groove curvature centre, axial, m (delta_a = 0)
P_CO_R = 7  # outer groove curvature centre, radial, m (plus half the extra diametral clearance P_d)
P_CO_Z = 8  # outer groove curvature centre, axial, m
P_K_IN = 9  # Hertz constant ball-inner, N/m^1.5
P_K_OUT = 10  # Hertz constant ball-outer, N/m^1.5
P_K_POCKET = 11  # Hertz constant ball-pocket, N/m^1.5
P_POCKET_CLEAR = 12  # circumferential pocket clearance per side, m
P_MBALL = 13  # ball mass, kg
P_IBALL = 14  # ball moment of inertia, kg m^2
P_JSEG = 15  # cage segment polar moment of inertia, kg m^2
P_LINK_K = 16  # cage rim torsional stiffness between segments, N m/rad
P_LINK_C = 17  # cage rim torsional damping, N m s/rad
P_HC_A = 18  # Hunt-Crossley coefficient a_e, s/m
P_HC_N = 19  # Hunt-Crossley exponent n
P_HC_D = 20  # penetration of full damping (IMPACT STEP), m
P_FRIC_MODEL = 21  # 0: paper's stepped Coulomb law, 1: EHL traction curve
P_MU_S = 22  # static friction coefficient
P_V_S = 23  # stiction transition velocity, m/s
P_MU_D = 24  # dynamic friction coefficient
P_V_D = 25  # friction transition velocity, m/s
P_EHL_MU = 26  # EHL limiting traction coefficient
P_EHL_SRR = 27  # EHL reference slide-roll ratio
P_MU_POCKET = 28  # ball-pocket friction coefficient
P_HYST = 29  # elastic hysteresis factor alpha_h
P_B_IN = 30  # semi-minor axis of the inner contact at 1 N, m (b = P_B_IN Q^(1/3))
P_B_OUT = 31  # semi-minor axis of the outer contact at 1 N, m
P_DRAG_LIN = 32  # ball drag, linear coefficient, N s/m
P_DRAG_QUAD = 33  # ball drag, quadratic coefficient, N s^2/m^2
P_LAND_VISC = 34  # cage land viscous torque coefficient (whole cage), N m s/rad
P_LAND_COULOMB = 35  # cage land boundary friction torque (whole cage), N m
P_M_INNER = 36  # inner ring axial mass, kg (stiff model)
P_HYST_IN = 37  # (3/16) alpha_h b(1 N) K_in^(4/3): hysteresis moment per penetration^2, N/m
P_HYST_OUT = 38  # same for the outer contact, N/m
P_DRAG_YIELD = 39  # ball drag, plastic (yield-stress) term, N
P_DRAG_POW = 40  # ball drag, power-law term coefficient, N (s/m)^n
P_DRAG_N = 41  # ball drag, power-law exponent n
P_LAND_POW = 42  # cage land torque, power-law coefficient (whole cage), N m (s/rad)^n
P_LAND_N = 43  # cage land torque, power-law exponent
P_FR_IN = 44  # Houpert rolling force of the inner contact at 1 m/s and 1 N, N: F = c u^0.66 Q^0.47
P_FR_OUT = 45  # same, outer contact
P_TABLE = 46  # index of the rheology traction table in this vector (0: none; see traction.py)
P_MU_SLOPE_MAX = 47  # steepest slope of the traction law: d mu/d SRR (models 1, 2) or d mu/ds, s/m (model 0)
P_CAGE_MASS = 48  # cage mass, kg (its centre's two in-plane translations, reduced model)
P_LAND_R = 49  # land (cage outer) radius, m
P_LAND_CLEAR = 50  # radial land clearance c, m
P_LAND_OCV = 51  # Ocvirk geometry factor of all lands, sum R L_land^3 / c^2, m^2
P_LAND_ETA = 52  # land film: Newtonian viscosity (oil x fill x scale), Pa s (0 for a grease)
P_LAND_TAUY = 53  # land film: grease yield stress x fill x scale, Pa
P_LAND_CONS = 54  # land film: grease consistency x fill x scale, Pa s^n (flow index P_LAND_N)
P_LAND_K = 55  # cage-land contact stiffness (conformal line contact, linearised), N/m
P_LAND_MU = 56  # cage-land contact friction coefficient, 1
P_CAGE_GRAV_Y = 57  # gravity on the cage centre along y (horizontal spindle), N
P_SPIN_IN = 58  # spin lever of the inner contact per sqrt(penetration), (3/8) a E(e^2), m^0.5 (x delta^0.5)
P_SPIN_OUT = 59  # same, outer contact
P_PRELOAD_D = 60  # rigid preload displacement of a back-to-back partner bearing, m (0: no partner)
P_PRELOAD_K = 61  # the partner's Z K_n (its balls at rest, the series Hertz constant), N/m^1.5
P_DRAG_LOAD_EXP = 62  # exponent k of the ball drag's load factor (Q_mean / P_DRAG_LOAD_REF)^k (0: no load factor)
P_DRAG_LOAD_REF = 63  # reference contact load of that factor, N
P_SIZE = 64

B_THETA, B_OMEGA, B_SPIN, B_R, B_Z, B_VR, B_VZ, B_PIVOT, B_PITCH = 0, 1, 2, 3, 4, 5, 6, 7, 8
NB = 9
C_PHI, C_OMEGA = 0, 1
NC = 2
R_ANGLE, R_OMEGA, R_DELTA, R_VDELTA, R_TIME, R_DX, R_DY = 0, 1, 2, 3, 4, 5, 6
R_CX, R_CY, R_CVX, R_CVY, R_LAND_N, R_LAND_F = 7, 8, 9, 10, 11, 12
R_TX, R_TY = 13, 14  # inner-ring tilts theta_x, theta_y (rad; free only under an applied moment)
R_MX, R_MY = 15, 16  # moment of the balls' inner contact loads on the ring, N m (last recorded step)
NR = 17
O_QI, O_QO, O_AI, O_AO, O_FP, O_SI, O_SO, O_FI, O_FO, O_POWER = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9
O_DRIVE = 10  # torque the drive applies to the inner ring against ball j's inner traction, N m
NO = 11
S_CAGE, S_INNER, S_TIME = 0, 1, 2
S_DRIVE = 3  # drive work, J
S_HEAT = 4  # heat dissipated (the engine's power loss, step by step), J
S_DAMP = 5  # heat of the pocket contacts' Hunt-Crossley damping, the cage rim's damping and the land's work on the moving cage centre, J
S_CONTACT_DAMP = 6  # heat of the raceway contacts' Hunt-Crossley damping (stiff model), J
NS = 7
G_QI, G_QO, G_NIR, G_NIZ, G_NOR, G_NOZ, G_DI, G_DO = 0, 1, 2, 3, 4, 5, 6, 7
NG = 8

SPIN_SIGN_SPEED = 1.0  # rad/s, smoothing speed of the sign of resistance moments and torques
DRAG_SIGN_SPEED = 0.01  # m/s, smoothing speed of the sign of the plastic (grease) ball drag
MIN_PENETRATION_FOR_JACOBIAN = 1e-10  # m, keeps the quasi-static Jacobian regular at zero load


@njit(cache=True)
def step_function(x: float, x0: float, h0: float, x1: float, h1: float) -> float:
    """The paper's STEP (docs/paper.md section 5, typo corrected): cubic from h0 at x0 to h1 at x1."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    d = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * d * d * (3.0 - 2.0 * d)


@njit(cache=True)
def traction_coefficient(p: np.ndarray, s: float, entrainment: float) -> tuple[float, float]:
    """Signed traction coefficient mu(s) and d mu/ds for sliding velocity s (m/s, race relative
    to ball; the force on the ball has the sign of s).

    Model 0, the paper's law (docs/paper.md section 4, labels corrected): a cubic STEP through zero
    from -mu_s to mu_s on |s| < v_s, a STEP from mu_s down to mu_d on v_s..v_d, mu_d beyond.
    Model 1, EHL: mu = mu_max (1 - exp(-|SRR|/SRR0)) sign(s), SRR = s / entrainment speed.
    """
    if p[P_FRIC_MODEL] == 0.0:
        mus, vs, mud, vd = p[P_MU_S], p[P_V_S], p[P_MU_D], p[P_V_D]
        a = abs(s)
        if a <= vs:
            d = (s + vs) / (2.0 * vs)
            return -mus + 2.0 * mus * d * d * (3.0 - 2.0 * d), 2.0 * mus * 6.0 * d * (1.0 - d) / (2.0 * vs)
        sg = 1.0 if s > 0.0 else -1.0
        if a < vd:
            d = (a - vs) / (vd - vs)
            return sg * (mus + (mud - mus) * d * d * (3.0 - 2.0 * d)), (mud - mus) * 6.0 * d * (1.0 - d) / (vd - vs)
        return sg * mud, 0.0
    ue = max(entrainment, 1e-3)
    srr = abs(s) / ue
    e = math.exp(-srr / p[P_EHL_SRR])
    mu = p[P_EHL_MU] * (1.0 - e)
    return (mu if s >= 0.0 else -mu), p[P_EHL_MU] * e / (p[P_EHL_SRR] * ue)


@njit(cache=True)
def contact_traction(p: np.ndarray, contact: int, s: float, entrainment: float, load: float) -> tuple[float, float, float]:
    """Traction coefficient, d mu/ds (s/m) and Houpert rolling force (N) of raceway contact
    ``contact`` (0 inner, 1 outer) at sliding velocity ``s`` (m/s), entrainment speed (m/s) and
    load (N). Model 2 interpolates the rheology table; models 0 and 1 use
    :func:`traction_coefficient` and leave the rolling force to :func:`spin_resistance` (0)."""
    if p[P_FRIC_MODEL] == 2.0:
        ue = max(entrainment, 1e-3)
        mu, slope, rolling = table_lookup(p, int(p[P_TABLE]), contact, s / ue, ue, load)
        return mu, slope / ue, p[P_FR_IN + contact] * rolling
    mu, dmu = traction_coefficient(p, s, entrainment)
    return mu, dmu, 0.0


@njit(cache=True)
def contact_power(p: np.ndarray, contact: int, s: float, entrainment: float, load: float) -> float:
    """Power (W) dissipated at a raceway contact: the rheology table's sliding, spin and
    Heathcote losses (model 2), else |mu Q s|."""
    if p[P_FRIC_MODEL] == 2.0:
        ue = max(entrainment, 1e-3)
        return table_power(p, int(p[P_TABLE]), contact, s / ue, ue, load) * load * ue
    mu, _ = traction_coefficient(p, s, entrainment)
    return abs(mu * load * s)


@njit(cache=True)
def impact_force(x: float, xdot: float, k: float, p: np.ndarray) -> tuple[float, float, float]:
    """Normal force of the paper's IMPACT law (Eq. 1) with Hertz exponent 1.5 and Hunt-Crossley
    damping (Eq. 5): F = K x^1.5 + STEP(x, 0, 0, d, 1) 1.5 a_e K x^n xdot, never adhesive.

    Args:
        x: penetration, m (contact when > 0).
        xdot: penetration rate, m/s.
        k: Hertz constant, N/m^1.5.

    Returns:
        (F, dF/dx, dF/dxdot) in N, N/m, N s/m.
    """
    if x <= 0.0:
        return 0.0, 0.0, 0.0
    sq = math.sqrt(x)
    elastic = k * x * sq
    xn = x * sq if p[P_HC_N] == 1.5 else x ** p[P_HC_N]
    c = step_function(x, 0.0, 0.0, p[P_HC_D], 1.0) * 1.5 * p[P_HC_A] * k * xn
    f = elastic + c * xdot
    if f <= 0.0:
        return 0.0, 0.0, 0.0
    return f, 1.5 * k * sq, c


@njit(cache=True)
def impact_damping_power(x: float, xdot: float, force: float, k: float) -> float:
    """Power (W) the damping of an :func:`impact_force` contact dissipates: the force beyond
    Hertz's K x^1.5 times the penetration rate (the force never adhesive, so once the damping
    would pull, its share is -K x^1.5 and the power still >= 0); 0 out of contact."""
    if x <= 0.0:
        return 0.0
    return (force - k * x * math.sqrt(x)) * xdot


@njit(cache=True)
def pocket_force(p: np.ndarray, u: float, udot: float) -> tuple[float, float, float]:
    """Ball-pocket contact (IMPACT law with the pocket Hertz constant).

    Args:
        u: circumferential offset of the ball centre ahead of the pocket centre at the pitch
           radius, m.
        udot: its rate, m/s.

    Returns:
        (Fs, dFs/du, dFs/dudot): Fs > 0 pushes the cage forward and the ball back, N.
    """
    clear = p[P_POCKET_CLEAR]
    if u > clear:
        f, kx, cx = impact_force(u - clear, udot, p[P_K_POCKET], p)
        return f, kx, cx
    if u < -clear:
        f, kx, cx = impact_force(-u - clear, -udot, p[P_K_POCKET], p)
        return -f, kx, cx
    return 0.0, 0.0, 0.0


@njit(cache=True)
def raceway_geometry(p: np.ndarray, rb: float, zb: float, delta_a: float) -> tuple:
    """Penetrations and unit normals of the two raceway contacts of a ball at (rb, zb).

    Returns (di, nir, niz, dist_i, do, nor, noz, dist_o): penetrations (m), unit vectors from
    each groove curvature centre to the ball centre, and the centre distances (m).
    """
    return shifted_raceway_geometry(p, rb, zb, delta_a, 0.0)


@njit(cache=True)
def shifted_raceway_geometry(p: np.ndarray, rb: float, zb: float, delta_a: float, shift: float) -> tuple:
    """:func:`raceway_geometry` with the inner ring displaced ``shift`` (m) radially outward at
    the ball (its radial displacement projected on the ball's radial direction; the tangential
    part changes the distances only to second order, as in Jones and Harris)."""
    dr = rb - p[P_CI_R] - shift
    dz = zb - (p[P_CI_Z] + delta_a)
    dist_i = math.sqrt(dr * dr + dz * dz)
    nir, niz = dr / dist_i, dz / dist_i
    er = rb - p[P_CO_R]
    ez = zb - p[P_CO_Z]
    dist_o = math.sqrt(er * er + ez * ez)
    nor, noz = er / dist_o, ez / dist_o
    return dist_i - p[P_RI_GAP], nir, niz, dist_i, dist_o - p[P_RO_GAP], nor, noz, dist_o


@njit(cache=True)
def partner_force(p: np.ndarray, delta_a: float) -> tuple[float, float, float]:
    """The axial force (N, along +z on the inner ring), its stiffness -dF/d(delta_a) (N/m) and the
    stored energy (J) of the rigidly preloaded partner of a back-to-back pair (P_PRELOAD_D, m;
    docs/model.md, "Mounting"): an identical bearing, balls at rest, axially loaded only, whose
    curvature centres are A sin a0 + d apart axially and A cos a0 - P_d/2 radially with
    d = P_PRELOAD_D - delta_a, so F = Z K_n (D - A)^1.5 (A sin a0 + d) / D, D the centres'
    distance, and the energy Z K_n (2/5) (D - A)^2.5. (0, 0, 0) without a partner."""
    s = p[P_PRELOAD_D]
    if s == 0.0:
        return 0.0, 0.0, 0.0
    big_a = p[P_RI_GAP] + p[P_RO_GAP]
    x = p[P_CI_Z] - p[P_CO_Z] + s - delta_a
    y = p[P_CI_R] - p[P_CO_R]
    dist = math.sqrt(x * x + y * y)
    gap = dist - big_a
    if gap <= 0.0:
        return 0.0, 0.0, 0.0
    k = p[P_PRELOAD_K]
    root = math.sqrt(gap)
    force = k * gap * root * x / dist
    stiff = k * (1.5 * root * x * x / (dist * dist) + gap * root * y * y / (dist * dist * dist))
    return force, stiff, 0.4 * k * gap * gap * root


@njit(cache=True)
def contact_jacobian(q: float, dq: float, nr: float, nz: float, dist: float) -> tuple:
    """d(-Q n)/dx for a contact force -Q(dist) n acting on the ball: returns (h_rr, h_rz, h_zz)."""
    t = q / dist
    return (-dq * nr * nr - t * (1.0 - nr * nr), -dq * nr * nz + t * nr * nz, -dq * nz * nz - t * (1.0 - nz * nz))


@njit(cache=True)
def ball_jacobian(
    p: np.ndarray,
    qi: float,
    qo: float,
    di: float,
    do: float,
    nir: float,
    niz: float,
    nor: float,
    noz: float,
    disti: float,
    disto: float,
    spin2: float,
    rb: float,
) -> tuple:
    """A ball's quasi-static Jacobian J = H_i + H_o + m omega^2 e_r e_r (``spin2`` = m omega^2)
    at contact loads ``qi``, ``qo`` (N), penetrations ``di``, ``do`` (m), normals and centre
    distances (:func:`shifted_raceway_geometry`), with the ball centre's radius ``rb`` (m).

    Returns (h_rr, h_rz, h_zz, d_rr, d_rz, d_zz, j_rr, j_rz, j_zz, det): the inner contact's
    block H_i coupling ball and ring, the ring's own stiffness D from it, and J with its
    determinant.

    A closed contact adds its normal stiffness 1.5 K sqrt(delta); so does an open one whose gap
    is below the other contact's penetration (within a Newton step of closing), with delta at
    least MIN_PENETRATION_FOR_JACOBIAN, as every open contact did before: a lightly loaded ball
    at the edge of a load zone, whose contact opens by a fraction of a nanometre as the ring
    moves, is stepped as before. A contact open by more adds nothing to the ball's J: that
    fictitious stiffness (3e5 N/m) would dwarf the groove's tangential stiffness Q/distance
    under a light load, and a ball outside a load zone at low speed, pressed on the outer
    groove by a centrifugal force of micro-newtons, crept down the groove by nanometres per
    Newton iteration (every step's 30 used up; no start found below 50 rpm under a radial load)
    instead of reaching its equilibrium in a few tens (lower on the groove, where the inner
    groove wedges it: at 163 N, 500 N the ball opposite the load at 6 deg on the outer
    raceway and 30 deg on the inner, the same from 5 to 900 rpm). The ring keeps the fictitious
    stiffness of such an inner contact in D (the ball held where it is), so its Schur system
    stays regular when no ball touches it, and its step moves it towards the balls.

    At speed, a ball on its outer contact alone has that contact's Jacobian at the load it will
    carry, m omega^2 r_b (barely touching, its tangential stiffness would be ~0 and the step
    along the groove unbounded), and a free ball (both contacts open) the isotropic secant
    stiffness that carries its centrifugal force across the outer gap in one step,
    m omega^2 r_b n_or/gap (plus m omega^2, J's own radial term). At rest a free ball keeps the
    regularising stiffness of both contacts, and so does one so slow that its centrifugal stiffness
    is below 1e-9 of the contacts'. A singular J (the ball on the line of the
    curvature centres at rest, both contacts barely touching) gets a spring of 1e-6 of its
    stiffness across that line."""
    ki, ko = p[P_K_IN], p[P_K_OUT]
    regular = 1.5 * ki * math.sqrt(MIN_PENETRATION_FOR_JACOBIAN)
    if di <= 0.0 and do <= 0.0:
        k = spin2 * rb * max(nor, 0.1) / max(-do, 1e-12) + spin2
        if k > 1e-9 * regular:  # free, at speed
            d_rr, d_rz, d_zz = contact_jacobian(0.0, regular, nir, niz, disti)
            return 0.0, 0.0, 0.0, d_rr, d_rz, d_zz, spin2 - k, 0.0, -k, k * (k - spin2)
        # at rest, or so slow that the centrifugal stiffness is below 1e-9 of the contacts' (a
        # subnormal speed made k (k - m omega^2) underflow to a zero determinant)
        di = do = MIN_PENETRATION_FOR_JACOBIAN
    if di > -max(do, MIN_PENETRATION_FOR_JACOBIAN):
        h_rr, h_rz, h_zz = contact_jacobian(qi, 1.5 * ki * math.sqrt(max(di, MIN_PENETRATION_FOR_JACOBIAN)), nir, niz, disti)
        d_rr, d_rz, d_zz = h_rr, h_rz, h_zz
    else:
        h_rr = h_rz = h_zz = 0.0
        d_rr, d_rz, d_zz = contact_jacobian(0.0, regular, nir, niz, disti)
        if spin2 > 0.0:
            # the outer contact's Jacobian at the load it carries alone at equilibrium,
            # m omega^2 r_b: barely touching, its tangential stiffness Q/distance is ~0
            qo = max(qo, spin2 * rb)
            do = max(do, (qo / ko) ** (2.0 / 3.0))
    o_rr, o_rz, o_zz = (
        contact_jacobian(qo, 1.5 * ko * math.sqrt(max(do, MIN_PENETRATION_FOR_JACOBIAN)), nor, noz, disto)
        if do > -max(di, MIN_PENETRATION_FOR_JACOBIAN)
        else (0.0, 0.0, 0.0)
    )
    j_rr, j_rz, j_zz = h_rr + o_rr + spin2, h_rz + o_rz, h_zz + o_zz
    det = j_rr * j_zz - j_rz * j_rz
    if abs(det) <= 1e-12 * (j_rr * j_rr + j_zz * j_zz):
        soft = 1e-6 * (abs(j_rr) + abs(j_zz)) + 1e-12
        j_rr -= soft
        j_zz -= soft
        det = j_rr * j_zz - j_rz * j_rz
    return h_rr, h_rz, h_zz, d_rr, d_rz, d_zz, j_rr, j_rz, j_zz, det


@njit(cache=True)
def solve_quasi_static(
    p: np.ndarray,
    ball: np.ndarray,
    ring: np.ndarray,
    geo: np.ndarray,
    work: np.ndarray,
    axial_load: float,
    tol: float,
    max_iter: int,
    radial_load: float = 0.0,
    radial_angle: float = 0.0,
) -> int:
    """Newton solution of the normal (radial-axial) equilibrium of every ball and of the inner
    ring under ``axial_load`` (N, along +z) and ``radial_load`` (N, >= 0, at the azimuth
    ``radial_angle`` from +x, rad: the load zone's azimuth), with centrifugal
    force m omega_m^2 r_b; gyroscopic moments neglected; tilts held where the ring has them
    (zero, or a misalignment: each ball's inner curvature centre then lifted axially by
    R_i (theta_x cos theta_j + theta_y sin theta_j)); a rigidly preloaded partner's axial force
    (:func:`partner_force`) added to the load. Ring unknowns: axial displacement and, with a
    radial load, a tilt (or a displacement left by one), the radial displacement (x, y); each ball's 2x2 block is eliminated onto them (a 3x3 Schur system).
    Updates ball B_R, B_Z and ring R_DELTA, R_DX, R_DY, and leaves in ``geo`` (Z, NG) the contact
    loads, normals and penetrations at the solution. ``work`` is scratch of shape (Z, 6).

    Returns the number of iterations used (max_iter + 1 if not converged).
    """
    z = ball.shape[0]
    m = p[P_MBALL]
    ki, ko = p[P_K_IN], p[P_K_OUT]
    partner = p[P_PRELOAD_D] != 0.0
    fp, kp, _ = partner_force(p, ring[R_DELTA])
    scale = tol * max(axial_load, abs(radial_load), fp, 1.0)
    tx, ty = ring[R_TX], ring[R_TY]
    tilted = tx != 0.0 or ty != 0.0  # held at a misalignment: the balls' loads vary around the orbit
    ri = p[P_CI_R]
    radial = radial_load != 0.0 or ring[R_DX] != 0.0 or ring[R_DY] != 0.0 or tilted
    load_x, load_y = radial_load * math.cos(radial_angle), radial_load * math.sin(radial_angle)
    for it in range(max_iter + 1):
        delta_a, dx, dy = ring[R_DELTA], ring[R_DX], ring[R_DY]
        ga, gx, gy = axial_load, load_x, load_y
        if partner:
            fp, kp, _ = partner_force(p, delta_a)
            ga += fp
        # Schur system S du = r of the ring's (delta_a, delta_x, delta_y), S symmetric in value
        s00 = s01 = s02 = s10 = s11 = s12 = s20 = s22 = 0.0
        r0 = r1 = r2 = 0.0
        worst = 0.0
        for j in range(z):
            rb, zb = ball[j, B_R], ball[j, B_Z]
            cth = sth = shift = lift = 0.0
            if radial:
                cth, sth = math.cos(ball[j, B_THETA]), math.sin(ball[j, B_THETA])
                shift = dx * cth + dy * sth
                if tilted:
                    lift = ri * (tx * cth + ty * sth)
            di, nir, niz, disti, do, nor, noz, disto = shifted_raceway_geometry(p, rb, zb, delta_a + lift, shift)
            qi = ki * di * math.sqrt(di) if di > 0.0 else 0.0
            qo = ko * do * math.sqrt(do) if do > 0.0 else 0.0
            geo[j, G_QI], geo[j, G_QO], geo[j, G_DI], geo[j, G_DO] = qi, qo, di, do
            geo[j, G_NIR], geo[j, G_NIZ], geo[j, G_NOR], geo[j, G_NOZ] = nir, niz, nor, noz
            w2 = ball[j, B_OMEGA] * ball[j, B_OMEGA]
            fr = -qi * nir - qo * nor + m * w2 * rb
            fz = -qi * niz - qo * noz
            worst = max(worst, abs(fr), abs(fz))
            ga += qi * niz
            if radial:
                gx += qi * nir * cth
                gy += qi * nir * sth
            if it == max_iter:
                continue
            hirr, hirz, hizz, drr, drz, dzz, a11, a12, a22, det = ball_jacobian(p, qi, qo, di, do, nir, niz, nor, noz, disti, disto, m * w2, rb)
            # u = J^-1 f; w = J^-1 b for the ring's axial (b = -Hi e_z) and radial (-Hi e_r) moves
            ux = (a22 * fr - a12 * fz) / det
            uz = (-a12 * fr + a11 * fz) / det
            wx = (-a22 * hirz + a12 * hizz) / det
            wz = (a12 * hirz - a11 * hizz) / det
            vx = (-a22 * hirr + a12 * hirz) / det
            vz = (a12 * hirr - a11 * hirz) / det
            work[j, 0], work[j, 1], work[j, 2], work[j, 3] = ux, uz, wx, wz
            # ring rows C = d(ring force)/d(ball): axial -(hirz, hizz), radial -(hirr, hirz) x direction
            ca_u = -(hirz * ux + hizz * uz)
            cr_u = -(hirr * ux + hirz * uz)
            r0 += ca_u
            s00 += dzz + hirz * wx + hizz * wz
            if radial:
                r1 += cr_u * cth
                r2 += cr_u * sth
                ca_v = drz + hirz * vx + hizz * vz  # (D - C W), axial row, radial column, per unit shift
                cr_w = drz + hirr * wx + hirz * wz  # radial row, axial column
                cr_v = drr + hirr * vx + hirz * vz  # radial row, radial column
                s01 += ca_v * cth
                s02 += ca_v * sth
                s10 += cr_w * cth
                s20 += cr_w * sth
                s11 += cr_v * cth * cth
                s12 += cr_v * cth * sth
                s22 += cr_v * sth * sth
                work[j, 4], work[j, 5] = vx, vz
        if worst < scale and abs(ga) < scale and abs(gx) < scale and abs(gy) < scale:
            return it
        if it == max_iter:
            break
        lim = 2e-6
        if partner:
            s00 -= kp
        if radial:
            r0 -= ga
            r1 -= gx
            r2 -= gy
            # Cramer's rule on [[s00, s01, s02], [s10, s11, s12], [s20, s12, s22]]
            c00 = s11 * s22 - s12 * s12
            c01 = s12 * s20 - s10 * s22
            c02 = s10 * s12 - s11 * s20
            det3 = s00 * c00 + s01 * c01 + s02 * c02
            if det3 == 0.0:  # no ring stiffness: see the axial case below
                dd, ex, ey = math.copysign(lim, -r0), 0.0, 0.0
            else:
                dd = (r0 * c00 + s01 * (r2 * s12 - r1 * s22) + s02 * (r1 * s12 - r2 * s11)) / det3
                ex = (s00 * (r1 * s22 - r2 * s12) + r0 * c01 + s02 * (r2 * s10 - r1 * s20)) / det3
                ey = (s00 * (s11 * r2 - s12 * r1) + s01 * (r1 * s20 - r2 * s10) + r0 * c02) / det3
            dd = min(max(dd, -lim), lim)
            ex = min(max(ex, -lim), lim)
            ey = min(max(ey, -lim), lim)
        elif s00 == 0.0:
            # no ring stiffness: every ball follows the ring, its outer contact open by more
            # than its inner one is closed (at rest, after the clearance grew): the ring moves
            # the step limit along the net force until the outer contacts close
            dd = math.copysign(lim, ga - r0)
            ex = 0.0
            ey = 0.0
        else:
            dd = min(max((r0 - ga) / s00, -lim), lim)
            ex = 0.0
            ey = 0.0
        ring[R_DELTA] = delta_a + dd
        ring[R_DX] = dx + ex
        ring[R_DY] = dy + ey
        for j in range(z):
            shift = ex * math.cos(ball[j, B_THETA]) + ey * math.sin(ball[j, B_THETA]) if radial else 0.0
            if radial:
                ball[j, B_R] += min(max(-(work[j, 0] + work[j, 2] * dd + work[j, 4] * shift), -lim), lim)
                ball[j, B_Z] += min(max(-(work[j, 1] + work[j, 3] * dd + work[j, 5] * shift), -lim), lim)
            else:
                ball[j, B_R] += min(max(-(work[j, 0] + work[j, 2] * dd), -lim), lim)
                ball[j, B_Z] += min(max(-(work[j, 1] + work[j, 3] * dd), -lim), lim)
    return max_iter + 1


@njit(cache=True)
def gauss_solve(a: np.ndarray, b: np.ndarray) -> None:
    """Solve a x = b in place (x into ``b``; ``a`` destroyed) by Gaussian elimination with
    partial pivoting, for the ring's small Schur systems."""
    n = b.shape[0]
    for k in range(n):
        piv = k
        for i in range(k + 1, n):
            if abs(a[i, k]) > abs(a[piv, k]):
                piv = i
        if piv != k:
            for c in range(n):
                a[k, c], a[piv, c] = a[piv, c], a[k, c]
            b[k], b[piv] = b[piv], b[k]
        for i in range(k + 1, n):
            f = a[i, k] / a[k, k]
            for c in range(k, n):
                a[i, c] -= f * a[k, c]
            b[i] -= f * b[k]
    for k in range(n - 1, -1, -1):
        acc = b[k]
        for c in range(k + 1, n):
            acc -= a[k, c] * b[c]
        b[k] = acc / a[k, k]


@njit(cache=True)
def solve_quasi_static_tilted(
    p: np.ndarray, ball: np.ndarray, ring: np.ndarray, geo: np.ndarray, work: np.ndarray, loads: np.ndarray, tol: float, max_iter: int
) -> int:
    """:func:`solve_quasi_static` with the inner ring's two tilts free under an applied moment.
    ``loads`` holds (F_a, F_x, F_y, M_x, M_y), N and N m (the radial load by its components), the
    moments counted as in dynamics/quasi_static.py: M_x = sum Q_i sin a_i R_i cos psi,
    M_y with sin psi (an axial force at psi = 0 gives M_x > 0). Ring unknowns (delta_a, delta_x,
    delta_y, theta_x, theta_y); ball j at orbital angle theta_j sees its inner curvature centre
    moved axially by a_j = delta_a + R_i (theta_x c_j + theta_y s_j) and radially by
    r_j = delta_x c_j + delta_y s_j (c_j, s_j the cosine and sine of theta_j). Each ball's block
    is eliminated onto (a_j, r_j) and mapped onto the five unknowns,
    S = sum B_j^T K_j B_j, a 5x5 Schur system. Updates ball B_R, B_Z and ring R_DELTA, R_DX,
    R_DY, R_TX, R_TY.

    Returns the number of iterations used (max_iter + 1 if not converged).
    """
    z = ball.shape[0]
    ri = p[P_CI_R]
    m, ki, ko = p[P_MBALL], p[P_K_IN], p[P_K_OUT]
    target = np.array([loads[0], loads[1], loads[2], loads[3] / ri, loads[4] / ri])
    scale = tol * max(np.max(np.abs(target)), 1.0)
    s = np.empty((5, 5))
    g = np.empty(5)
    ba = np.empty(5)  # d a_j / d(unknowns), lengths per R_i for the tilts
    br = np.empty(5)
    lim = 2e-6
    for it in range(max_iter + 1):
        delta_a, dx, dy, tx, ty = ring[R_DELTA], ring[R_DX], ring[R_DY], ring[R_TX], ring[R_TY]
        g[:] = target
        s[:] = 0.0
        fp, kp, _ = partner_force(p, delta_a)
        g[0] += fp
        s[0, 0] -= kp
        rhs = np.zeros(5)
        worst = 0.0
        for j in range(z):
            cth, sth = math.cos(ball[j, B_THETA]), math.sin(ball[j, B_THETA])
            lift = ri * (tx * cth + ty * sth)
            di, nir, niz, disti, do, nor, noz, disto = shifted_raceway_geometry(p, ball[j, B_R], ball[j, B_Z], delta_a + lift, dx * cth + dy * sth)
            qi = ki * di * math.sqrt(di) if di > 0.0 else 0.0
            qo = ko * do * math.sqrt(do) if do > 0.0 else 0.0
            geo[j, G_QI], geo[j, G_QO], geo[j, G_DI], geo[j, G_DO] = qi, qo, di, do
            geo[j, G_NIR], geo[j, G_NIZ], geo[j, G_NOR], geo[j, G_NOZ] = nir, niz, nor, noz
            spin2 = m * ball[j, B_OMEGA] ** 2
            res_r = spin2 * ball[j, B_R] - qi * nir - qo * nor
            res_z = -qi * niz - qo * noz
            worst = max(worst, abs(res_r), abs(res_z))
            # the ring's generalised forces, moments per R_i (unknowns: tilts times R_i)
            ba[0], ba[1], ba[2], ba[3], ba[4] = 1.0, 0.0, 0.0, cth, sth
            br[0], br[1], br[2], br[3], br[4] = 0.0, cth, sth, 0.0, 0.0
            for k in range(5):
                g[k] += qi * (niz * ba[k] + nir * br[k])
            if it == max_iter:
                continue
            # the ball's 2x2 Jacobian J = H_i + H_o + m omega^2 e_r e_r and its inverse
            h_rr, h_rz, h_zz, d_rr, d_rz, d_zz, j_rr, j_rz, j_zz, det = ball_jacobian(p, qi, qo, di, do, nir, niz, nor, noz, disti, disto, spin2, ball[j, B_R])
            inv_rr, inv_rz, inv_zz = j_zz / det, -j_rz / det, j_rr / det
            # the ball's step u = J^-1 f and its response to a unit local move of the inner
            # curvature centre, axial (w = -J^-1 H_i e_z) and radial (v = -J^-1 H_i e_r)
            u_r, u_z = inv_rr * res_r + inv_rz * res_z, inv_rz * res_r + inv_zz * res_z
            w_r, w_z = -(inv_rr * h_rz + inv_rz * h_zz), -(inv_rz * h_rz + inv_zz * h_zz)
            v_r, v_z = -(inv_rr * h_rr + inv_rz * h_rz), -(inv_rz * h_rr + inv_zz * h_rz)
            work[j, 0], work[j, 1], work[j, 2], work[j, 3], work[j, 4], work[j, 5] = u_r, u_z, w_r, w_z, v_r, v_z
            # the ring's local balance (axial a, radial r): right side -H_i u, stiffness H_i (I + [w v])
            rho_a, rho_r = -(h_rz * u_r + h_zz * u_z), -(h_rr * u_r + h_rz * u_z)
            k_aa, k_ar = d_zz + h_rz * w_r + h_zz * w_z, d_rz + h_rz * v_r + h_zz * v_z
            k_ra, k_rr = d_rz + h_rr * w_r + h_rz * w_z, d_rr + h_rr * v_r + h_rz * v_z
            for k in range(5):
                rhs[k] += ba[k] * rho_a + br[k] * rho_r
                for c in range(5):
                    s[k, c] += ba[k] * (k_aa * ba[c] + k_ar * br[c]) + br[k] * (k_ra * ba[c] + k_rr * br[c])
        if worst < scale and np.max(np.abs(g)) < scale:
            return it
        if it == max_iter:
            break
        for k in range(5):
            rhs[k] -= g[k]
        gauss_solve(s, rhs)
        for k in range(5):
            rhs[k] = min(max(rhs[k], -lim), lim)
        ring[R_DELTA] = delta_a + rhs[0]
        ring[R_DX] = dx + rhs[1]
        ring[R_DY] = dy + rhs[2]
        ring[R_TX] = tx + rhs[3] / ri
        ring[R_TY] = ty + rhs[4] / ri
        for j in range(z):
            cth, sth = math.cos(ball[j, B_THETA]), math.sin(ball[j, B_THETA])
            da = rhs[0] + rhs[3] * cth + rhs[4] * sth
            dr = rhs[1] * cth + rhs[2] * sth
            ball[j, B_R] += min(max(-(work[j, 0] + work[j, 2] * da + work[j, 4] * dr), -lim), lim)
            ball[j, B_Z] += min(max(-(work[j, 1] + work[j, 3] * da + work[j, 5] * dr), -lim), lim)
    return max_iter + 1


@njit(cache=True)
def ring_moment(p: np.ndarray, ball: np.ndarray, ring: np.ndarray, geo: np.ndarray) -> None:
    """The moment of the balls' inner contact loads on the inner ring (N m) into ring R_MX, R_MY,
    counted as in dynamics/quasi_static.py: M_x = sum Q_i sin a_i R_i cos theta_j, M_y with
    sin theta_j (sin a_i = -n_iz), from the contact state in ``geo`` solved at the balls' angles.
    With the tilts held it is the reaction moment the spindle's second bearing supplies; with
    them free it balances the applied moment."""
    mx = my = 0.0
    for j in range(ball.shape[0]):
        fa = -geo[j, G_QI] * geo[j, G_NIZ] * p[P_CI_R]
        mx += fa * math.cos(ball[j, B_THETA])
        my += fa * math.sin(ball[j, B_THETA])
    ring[R_MX], ring[R_MY] = mx, my


@njit(cache=True)
def ball_kinematics(p: np.ndarray, nir: float, niz: float, nor: float, noz: float, rb: float) -> tuple:
    """Lever arms of the ball's two raceway contacts, from the contact normals.

    Contact angles: cos(alpha_i) = -n_i,r, sin(alpha_i) = -n_i,z; cos(alpha_o) = n_o,r,
    sin(alpha_o) = n_o,z. The rolling axis pitch angle beta follows
    tan(beta) = sin(alpha)/(cos(alpha) + Dw/dm) with dm = 2 r_b and alpha the mean of the two
    contact angles (outer-raceway control, Harris and Kotzalas; equivalently
    tan(alpha - beta) = sin(alpha)/(dm/Dw + cos(alpha)), zero spin at the outer contact).
    Sliding velocities (race relative to ball, along e_t) are
    s_i = omega_i r_ci - A_im omega_m - A_ia omega_a and s_o = -A_om omega_m + A_oa omega_a,
    omega_a the absolute spin about the rolling axis; the rolling speed relative to the orbiting
    frame is omega_a + cos(beta) omega_m.
    Returns (r_ci, r_co, ci, co, A_im, A_ia, A_om, A_oa, cos_beta) with ci = cos(alpha_i - beta),
    co = cos(alpha_o - beta).
    """
    r = p[P_RBALL]
    cai, sai, cao, sao = -nir, -niz, nor, noz
    cm, sm = cai + cao, sai + sao  # bisector of the two contact directions
    nm = math.sqrt(cm * cm + sm * sm)
    cm /= nm
    sm /= nm
    den = cm + r / rb
    h = math.sqrt(sm * sm + den * den)
    cb, sb = den / h, sm / h
    ci = cai * cb + sai * sb
    co = cao * cb + sao * sb
    r_ci = rb - r * cai
    r_co = rb + r * cao
    return r_ci, r_co, ci, co, r_ci + r * ci * cb, r * ci, r_co - r * co * cb, r * co, cb


@njit(cache=True)
def smooth_sign(x: float) -> float:
    """Sign of x, smoothed over |x| < SPIN_SIGN_SPEED (algebraic, cheaper than tanh)."""
    y = x / SPIN_SIGN_SPEED
    return y / math.sqrt(1.0 + y * y)


@njit(cache=True)
def spin_resistance(p: np.ndarray, di: float, do: float, fpocket: float, omega_roll: float) -> float:
    """Moment (N m) resisting the ball's rolling: elastic hysteresis (3/16) alpha_h Q b at both
    raceways (written with the penetrations: Q b = b(1 N) K^(4/3) delta^2), Houpert's EHL
    rolling force F_R = c u^0.66 Q^0.47 at both raceways with the lever R (u = R |omega_roll|,
    Q = K delta^1.5; with the rheology model the steppers add it from the contacts' entrainment
    speeds instead), plus pocket friction mu_p |F_p| R, with a smoothed sign of the rolling
    speed."""
    dip, dop = max(di, 0.0), max(do, 0.0)
    hyst = p[P_HYST_IN] * dip**2 + p[P_HYST_OUT] * dop**2
    r = p[P_RBALL]
    if p[P_FRIC_MODEL] != 2.0 and (p[P_FR_IN] > 0.0 or p[P_FR_OUT] > 0.0):  # model 2: from the table lookup
        u066 = (r * abs(omega_roll)) ** 0.66
        qi = p[P_K_IN] * dip * math.sqrt(dip)
        qo = p[P_K_OUT] * dop * math.sqrt(dop)
        hyst += r * u066 * (p[P_FR_IN] * qi**0.47 + p[P_FR_OUT] * qo**0.47)
    return (hyst + p[P_MU_POCKET] * abs(fpocket) * r) * smooth_sign(omega_roll)


@njit(cache=True)
def cyclic_tridiagonal(diag: np.ndarray, off: float, rhs: np.ndarray, out: np.ndarray, work: np.ndarray) -> None:
    """Solve a symmetric cyclic tridiagonal system with constant off-diagonal ``off``
    (Sherman-Morrison on the Thomas algorithm). ``diag``, ``rhs`` and ``out`` have length
    n >= 3; ``work`` is scratch of shape (n, 4)."""
    n = diag.shape[0]
    gamma = -diag[0]
    for i in range(n):
        work[i, 0] = diag[i]  # modified diagonal
        work[i, 2] = rhs[i]  # solution for the right-hand side
        work[i, 3] = 0.0  # solution for the correction vector
    work[0, 0] -= gamma
    work[n - 1, 0] -= off * off / gamma
    work[0, 3] = gamma
    work[n - 1, 3] = off
    work[0, 1] = off / work[0, 0]
    work[0, 2] /= work[0, 0]
    work[0, 3] /= work[0, 0]
    for i in range(1, n):
        den = work[i, 0] - off * work[i - 1, 1]
        work[i, 1] = off / den
        work[i, 2] = (work[i, 2] - off * work[i - 1, 2]) / den
        work[i, 3] = (work[i, 3] - off * work[i - 1, 3]) / den
    for i in range(n - 2, -1, -1):
        work[i, 2] -= work[i, 1] * work[i + 1, 2]
        work[i, 3] -= work[i, 1] * work[i + 1, 3]
    fact = (work[0, 2] + off * work[n - 1, 2] / gamma) / (1.0 + work[0, 3] + off * work[n - 1, 3] / gamma)
    for i in range(n):
        out[i] = work[i, 2] - fact * work[i, 3]


@njit(cache=True)
def cyclic_tridiagonal_pair(diag: np.ndarray, off: float, rhs_a: np.ndarray, rhs_b: np.ndarray, out_a: np.ndarray, out_b: np.ndarray, work: np.ndarray) -> None:
    """:func:`cyclic_tridiagonal` for two right-hand sides sharing one factorisation; ``work``
    is scratch of shape (n, 5)."""
    n = diag.shape[0]
    gamma = -diag[0]
    for i in range(n):
        work[i, 0] = diag[i]
        work[i, 2] = rhs_a[i]
        work[i, 3] = 0.0
        work[i, 4] = rhs_b[i]
    work[0, 0] -= gamma
    work[n - 1, 0] -= off * off / gamma
    work[0, 3] = gamma
    work[n - 1, 3] = off
    inv = 1.0 / work[0, 0]
    work[0, 1] = off * inv
    work[0, 2] *= inv
    work[0, 3] *= inv
    work[0, 4] *= inv
    for i in range(1, n):
        inv = 1.0 / (work[i, 0] - off * work[i - 1, 1])
        work[i, 1] = off * inv
        work[i, 2] = (work[i, 2] - off * work[i - 1, 2]) * inv
        work[i, 3] = (work[i, 3] - off * work[i - 1, 3]) * inv
        work[i, 4] = (work[i, 4] - off * work[i - 1, 4]) * inv
    for i in range(n - 2, -1, -1):
        work[i, 2] -= work[i, 1] * work[i + 1, 2]
        work[i, 3] -= work[i, 1] * work[i + 1, 3]
        work[i, 4] -= work[i, 1] * work[i + 1, 4]
    den = 1.0 + work[0, 3] + off * work[n - 1, 3] / gamma
    fact_a = (work[0, 2] + off * work[n - 1, 2] / gamma) / den
    fact_b = (work[0, 4] + off * work[n - 1, 4] / gamma) / den
    for i in range(n):
        out_a[i] = work[i, 2] - fact_a * work[i, 3]
        out_b[i] = work[i, 4] - fact_b * work[i, 3]


@njit(cache=True)
def cage_land_torque(p: np.ndarray, omega: float, z: int, factor: float = 1.0, normal: float = 0.0) -> tuple[float, float]:
    """Land friction torque on one cage segment (N m, resisting) and its derivative.

    ``factor`` multiplies the film's rate-dependent shear (the eccentric film's Couette shear,
    :func:`land_shear_factor`; 1 for a centred cage) and ``normal`` (N) is the cage-land contact
    force, which adds the boundary friction mu_land N R_land of the contact."""
    y = omega / SPIN_SIGN_SPEED
    q = 1.0 / math.sqrt(1.0 + y * y)
    coulomb = p[P_LAND_COULOMB] + p[P_LAND_MU] * normal * p[P_LAND_R]
    t = (coulomb * y * q + factor * p[P_LAND_VISC] * omega) / z
    dt = (coulomb * q * q * q / SPIN_SIGN_SPEED + factor * p[P_LAND_VISC]) / z
    if p[P_LAND_POW] > 0.0:
        a = max(abs(omega), SPIN_SIGN_SPEED)
        an = math.sqrt(a) if p[P_LAND_N] == 0.5 else a ** p[P_LAND_N]
        t += factor * p[P_LAND_POW] * an * y * q / z
        dt += factor * p[P_LAND_POW] * p[P_LAND_N] * an / a / z
    return t, dt


LAND_EPS_MAX = 0.95
"""Eccentricity ratio at which the land film's force stops growing: Ocvirk's forces diverge as
eps -> 1 and the short-bearing theory no longer holds in a film of a few per cent of the
clearance; beyond it the cage-land contact (at eps = 1) takes over."""
LAND_SIGN_SPEED = 1e-3
"""rad/s, smoothing of the sign of eps (Omega - 2 psi_dot), which decides the half of the land
that carries pressure (pi film)."""
LAND_SLIDE_SPEED = 0.01
"""m/s, smoothing of the sign of the sliding speed at the cage-land contact."""
LAND_MIN_SHEAR_SPEED = 1.0
"""rad/s, cage speed below which the land's apparent (grease) viscosity is that of 1 rad/s."""


@njit(cache=True)
def land_viscosity(p: np.ndarray, omega: float) -> float:
    """Viscosity (Pa s) of the land film at cage speed ``omega`` (rad/s): the oil's, or the
    grease's apparent viscosity tau_y/g + K g^(n-1) at the film's shear rate g = R |omega| / c
    (the same wall stress as the land torque), the fill and scale included."""
    eta = p[P_LAND_ETA]
    if p[P_LAND_TAUY] > 0.0 or p[P_LAND_CONS] > 0.0:
        g = p[P_LAND_R] * max(abs(omega), LAND_MIN_SHEAR_SPEED) / p[P_LAND_CLEAR]
        gn = math.sqrt(g) if p[P_LAND_N] == 0.5 else g ** p[P_LAND_N]
        eta += (p[P_LAND_TAUY] + p[P_LAND_CONS] * gn) / g
    return eta


@njit(cache=True)
def ocvirk_force(eta: float, geometry: float, eps: float, eps_omega: float, eps_dot: float) -> tuple[float, float]:
    """Short-journal-bearing (Ocvirk) film force on the journal, pi film, with whirl and squeeze.

    Args:
        eta: viscosity, Pa s.
        geometry: R L^3 / c^2 summed over the lands, m^2 (R journal radius, L land width, c
            radial clearance).
        eps: eccentricity ratio e/c, 0 <= eps < 1.
        eps_omega: eps (Omega - 2 psi_dot), rad/s: Omega the journal's speed, psi_dot the whirl
            speed of its centre (the wedge term of Reynolds' equation).
        eps_dot: d eps/dt, 1/s (the squeeze term).

    Returns:
        (F_r, F_t), N: along the eccentricity (outward, > 0 pushes the journal further out) and
        perpendicular to it in the direction of rotation. For a journal turning at Omega about a
        fixed centre (U = R Omega): F_r = -(eta U L^3/c^2) eps^2/(1 - eps^2)^2,
        F_t = (pi eta U L^3/(4 c^2)) eps/(1 - eps^2)^1.5; the squeeze adds
        -(eta R L^3/c^2) pi (1 + 2 eps^2) eps_dot / (2 (1 - eps^2)^2.5) and
        2 (eta R L^3/c^2) eps eps_dot/(1 - eps^2)^2 (the half carrying pressure is the one
        ahead of the minimum film for eps_omega > 0 and behind it for eps_omega < 0).
    """
    one = 1.0 - eps * eps
    a = eta * geometry
    sg = eps_omega / math.sqrt(eps_omega * eps_omega + LAND_SIGN_SPEED * LAND_SIGN_SPEED)
    fr = -a * (eps * eps_omega * sg / (one * one) + 0.5 * math.pi * (1.0 + 2.0 * eps * eps) * eps_dot / (one * one * math.sqrt(one)))
    ft = a * (0.25 * math.pi * eps_omega / (one * math.sqrt(one)) + 2.0 * eps * eps_dot * sg / (one * one))
    return fr, ft


@njit(cache=True)
def land_force(p: np.ndarray, x: float, y: float, vx: float, vy: float, omega: float) -> tuple[float, float, float]:
    """Force of the guiding land on the cage centre at (x, y) (m, from the bearing axis) moving at
    (vx, vy) (m/s), the cage turning at ``omega`` (rad/s): the Ocvirk film
    (:func:`ocvirk_force`, eps capped at :data:`LAND_EPS_MAX`) plus, once the eccentricity
    reaches the clearance, a Hunt-Crossley contact k d (1 + 1.5 a_e d_dot) with Coulomb friction
    mu_land N against the sliding of the cage's surface. Returns (F_x, F_y, N) in N."""
    c = p[P_LAND_CLEAR]
    e = math.sqrt(x * x + y * y)
    if e > 1e-12 * c:
        rx, ry = x / e, y / e
        ratio = 1.0 / c
    else:
        v = math.sqrt(vx * vx + vy * vy)
        rx, ry = (vx / v, vy / v) if v > 0.0 else (1.0, 0.0)
        ratio = 1.0 / c
    eps = e / c
    if eps > LAND_EPS_MAX:
        eps = LAND_EPS_MAX
        ratio = LAND_EPS_MAX / e
    vr = vx * rx + vy * ry
    vt = vy * rx - vx * ry
    fr, ft = ocvirk_force(land_viscosity(p, omega), p[P_LAND_OCV], eps, eps * omega - 2.0 * ratio * vt, vr / c)
    normal = 0.0
    if e > c:
        d = e - c
        normal = max(p[P_LAND_K] * d * (1.0 + 1.5 * p[P_HC_A] * vr), 0.0)
        fr -= normal
        slide = (omega * p[P_LAND_R] + vt) / LAND_SLIDE_SPEED
        ft -= p[P_LAND_MU] * normal * slide / math.sqrt(1.0 + slide * slide)
    return fr * rx - ft * ry, fr * ry + ft * rx, normal


@njit(cache=True)
def land_shear_factor(p: np.ndarray, eps: float) -> float:
    """Mean over the land of (c/h)^n, h = c (1 - eps cos theta): how much an eccentric film
    shears more than a centred one for a wall stress growing as the shear rate^n (n = 1 for an
    oil: 1/sqrt(1 - eps^2), Petroff's torque of the eccentric journal). Trapezoidal rule with
    32 points over the period (17 by symmetry; relative error 3e-5 at eps = 0.95), eps capped
    at :data:`LAND_EPS_MAX`."""
    if eps <= 0.0:
        return 1.0
    eps = min(eps, LAND_EPS_MAX)
    n = p[P_LAND_N]
    total = 0.0
    for i in range(17):
        w = 1.0 - eps * math.cos(math.pi * i / 16.0)
        f = 1.0 / math.sqrt(w) if n == 0.5 else w ** (-n)
        total += 0.5 * f if i == 0 or i == 16 else f
    return total / 16.0


@njit(cache=True)
def link_strain(cage: np.ndarray, k: int, z: int) -> float:
    """Angular strain (rad) of the cage rim between segment k and k+1 (cyclic)."""
    nxt = cage[0, C_PHI] + 2.0 * math.pi if k == z - 1 else cage[k + 1, C_PHI]
    return nxt - cage[k, C_PHI] - 2.0 * math.pi / z


@njit(cache=True)
def implicit_slope(mu: float, dmu: float, s: float, cap: float = math.inf) -> float:
    """Slope (s/m) with which the linearly implicit step treats a traction coefficient mu(s):
    the larger of the tangent d mu/ds and the secant mu(s)/s through the origin (never < 0),
    the secant at most ``cap``, the law's steepest slope: a curve through the origin never has
    a steeper secant, and where an interpolated table is not exactly 0 at s = 0 the secant of
    a vanishing s would otherwise be unbounded (and the step's 2x2 blocks singular).

    With a slope at least the secant, the linearised traction mu(s_n) + k (s - s_n) vanishes
    between 0 and s_n, so one implicit step cannot carry the sliding speed across zero into the
    opposite saturation however narrow the traction curve's rising part is (docs/model.md,
    Integration): the saturated traction acts as a linear damper of coefficient Q mu(s_n)/s_n,
    integrated implicitly (A-stable)."""
    k = max(dmu, 0.0)
    if s * mu > 0.0:
        k = max(k, min(mu / s, cap))
    return k


@njit(cache=True)
def slope_cap(p: np.ndarray, entrainment: float) -> float:
    """The traction law's steepest d mu/ds (s/m) at an entrainment speed (m/s; floored at 1 mm/s
    as in the laws)."""
    if p[P_FRIC_MODEL] == 0.0:
        return p[P_MU_SLOPE_MAX]
    return p[P_MU_SLOPE_MAX] / max(entrainment, 1e-3)


@njit(cache=True, inline="always")
def sliding_traction(
    p: np.ndarray, contact: int, s: float, st: float, entrainment: float, load: float, spin: float, dspin: float, rho: float
) -> tuple[float, float, float, float, float, float, float]:
    """:func:`contact_traction` and :func:`contact_power` together (one table pass) of a raceway
    contact sliding at ``s`` (m/s, rolling direction) and ``st`` (m/s, transverse: the ball's
    pivot r omega_t), with the transverse traction coefficient per unit transverse sliding k_t
    (s/m) and the change of the contact's spin moment when its spin goes from ``spin`` to
    ``spin + dspin`` (rad/s, the ball's pitch rate's share): (mu, d mu/ds, Houpert rolling force
    N, power W, k_t, dC N m, k_C N m s). The transverse traction is the law applied to the
    magnitude of the sliding vector |s_v| = sqrt(s^2 + st^2) along the sliding,
    mu_t = mu(|s_v|) st/|s_v| = k_t st, as a rheological film carries its shear stress along
    its shear; mu is the law's odd part (:func:`.traction.table_lookup_full`: the rheology
    table's offset at SRR = 0, from spin and Heathcote slip, acts in the rolling direction only,
    which keeps the law of s), and k_t is at most the law's steepest slope. The spin moment is
    C(spin) = Q rho mu_odd(|spin| rho / u_e) sgn(spin), rho = (3/8) a E(e^2) the Hertz
    pressure's mean lever over the contact ellipse (``rho``, m; exact for a saturated law:
    (3 pi/16) mu Q a on a circle); dC = C(spin + dspin) - C(spin) with its secant k_C = dC/dspin (at most the
    law's steepest slope Q rho^2 d mu/ds). One table pass for all."""
    smag = math.sqrt(s * s + st * st)
    cap = slope_cap(p, entrainment)
    s0 = spin * rho
    s1 = (spin + dspin) * rho
    kc_cap = load * rho * rho * cap
    if p[P_FRIC_MODEL] == 2.0:
        ue = max(entrainment, 1e-3)
        mu, slope, rolling, pw, odd, m0, m1 = table_lookup_full(p, int(p[P_TABLE]), contact, s / ue, smag / ue, ue, load, abs(s0) / ue, abs(s1) / ue)
        kt = min(odd / smag, cap) if smag > 1e-12 else cap
        dc = load * rho * (math.copysign(m1, s1) - math.copysign(m0, s0))
        kc = min(max(dc / dspin, 0.0), kc_cap) if abs(dspin * rho) > 1e-12 else kc_cap
        return mu, slope / ue, p[P_FR_IN + contact] * rolling, pw * load * ue, kt, dc, kc
    mu, dmu = traction_coefficient(p, s, entrainment)
    kt = cap
    if smag > 1e-12:
        mut, _ = traction_coefficient(p, smag, entrainment)
        kt = min(abs(mut) / smag, cap)
    m0, _ = traction_coefficient(p, abs(s0), entrainment)
    m1, _ = traction_coefficient(p, abs(s1), entrainment)
    dc = load * rho * (math.copysign(abs(m1), s1) - math.copysign(abs(m0), s0))
    kc = min(max(dc / dspin, 0.0), kc_cap) if abs(dspin * rho) > 1e-12 else kc_cap
    return mu, dmu, 0.0, abs(mu * load * s), kt, dc, kc


@njit(cache=True, inline="always")
def ball_tractions(
    p: np.ndarray, ball: np.ndarray, j: int, omega_i: float, qi: float, qo: float, nir: float, niz: float, nor: float, noz: float, di: float, do: float
) -> tuple:
    """Raceway tractions of ball j (shared by both models), with the contacts' loads (N),
    normals and penetrations (m).

    Returns (fi, fo, kti, kto, si, so, r_ci, ci, co, aim, aia, aom, aoa, cos_beta, f_roll, pi,
    po, fri, k_pivot, m_pitch, k_pitch): traction forces on the ball along e_t (N), their slopes dF/ds (N s/m,
    clipped at >= 0 for the implicit step), sliding velocities (m/s), the lever arms of
    :func:`ball_kinematics`, the sum of the two contacts' Houpert rolling forces (N; model 2
    only, else 0), the two contacts' dissipated power in the rolling direction (W,
    :func:`contact_power`), the inner contact's rolling force (N) and the transverse
    tractions' coefficient per unit pivot sliding, Q_i k_t,i + Q_o k_t,o (N s/m,
    :func:`sliding_traction`): both
    contacts' transverse tractions, k_pivot r omega_t together, make the moment
    -r k_pivot r omega_t on the pivot; the moment -m_pitch (N m) of both contacts' spin
    moments on the ball's pitch rate omega_p (about w = (cos beta, sin beta) in (e_r, e_z), the
    ball's angular velocity relative to the raceway-control state, ``B_PITCH``) and its
    secant slope k_pitch (N m s) per omega_p. The spin of each contact (ball relative to race,
    about the normal from the ball centre, n = (n_r, n_z)) at raceway control is
    (omega_a a + omega_m sin(beta) w - Omega_race e_z) . n with a = (sin beta, -cos beta) the
    rolling axis; omega_p adds (w . n) omega_p: cos(alpha_o - beta) omega_p at the outer
    contact, -cos(alpha_i - beta) omega_p at the inner. Only the change of the spin moments
    from the raceway-control state acts on omega_p (that state's spin losses are in the
    rolling-direction law, the table's offset), projected on w.
    """
    rb = ball[j, B_R]
    r_ci, r_co, ci, co, aim, aia, aom, aoa, cb = ball_kinematics(p, nir, niz, nor, noz, rb)
    wm, wa = ball[j, B_OMEGA], ball[j, B_SPIN]
    si = omega_i * r_ci - aim * wm - aia * wa
    so = -aom * wm + aoa * wa
    uei, ueo = abs((omega_i - wm) * r_ci), abs(wm * r_co)
    st = p[P_RBALL] * ball[j, B_PIVOT]
    wp = ball[j, B_PITCH]
    sb = math.sqrt(max(1.0 - cb * cb, 0.0))
    # spins at raceway control: a . n = sin(alpha_i - beta) (inner), -sin(alpha_o - beta) (outer)
    spin_i = wa * (nir * sb - niz * cb) - wm * sb * ci - omega_i * niz
    spin_o = wa * (nor * sb - noz * cb) + wm * sb * co
    # the spin levers (3/8) a E(e^2): a grows as Q^(1/3) = K^(1/3) delta^(1/2)
    rho_i = p[P_SPIN_IN] * math.sqrt(max(di, 0.0))
    rho_o = p[P_SPIN_OUT] * math.sqrt(max(do, 0.0))
    mui, dmui, fri, pi, kni, dci, kci = sliding_traction(p, 0, si, st, uei, qi, spin_i, -ci * wp, rho_i)
    muo, dmuo, fro, po, kno, dco, kco = sliding_traction(p, 1, so, st, ueo, qo, spin_o, co * wp, rho_o)
    kti = qi * implicit_slope(mui, dmui, si, slope_cap(p, uei))
    kto = qo * implicit_slope(muo, dmuo, so, slope_cap(p, ueo))
    kpiv = qi * kni + qo * kno
    mpitch = co * dco - ci * dci
    kpitch = ci * ci * kci + co * co * kco
    return qi * mui, qo * muo, kti, kto, si, so, r_ci, ci, co, aim, aia, aom, aoa, cb, fri + fro, pi, po, fri, kpiv, mpitch, kpitch


@njit(cache=True)
def cage_segment_torque(p: np.ndarray, cage: np.ndarray, k: int, z: int, factor: float = 1.0, normal: float = 0.0) -> tuple[float, float]:
    """Rim (stiffness and damping) and land torques on cage segment k, N m, and the slope with
    which the implicit step treats the land torque (N m s/rad; :func:`implicit_slope`);
    ``factor`` and ``normal`` as in :func:`cage_land_torque`."""
    km = z - 1 if k == 0 else k - 1
    kp = 0 if k == z - 1 else k + 1
    w = cage[k, C_OMEGA]
    tl, dtl = cage_land_torque(p, w, z, factor, normal)
    dtl = implicit_slope(tl, dtl, w)
    tau = p[P_LINK_K] * (link_strain(cage, k, z) - link_strain(cage, km, z))
    tau += p[P_LINK_C] * (cage[kp, C_OMEGA] - 2.0 * cage[k, C_OMEGA] + cage[km, C_OMEGA])
    return tau - tl, dtl


@njit(cache=True)
def record(
    out: np.ndarray, j: int, qi: float, qo: float, nir: float, niz: float, nor: float, noz: float, fs: float, si: float, so: float, fi: float, fo: float
) -> None:
    """Write ball j's diagnostics into ``out`` (angles from the contact normals)."""
    out[j, O_QI], out[j, O_QO] = qi, qo
    out[j, O_AI], out[j, O_AO] = math.atan2(-niz, -nir), math.atan2(noz, nor)
    out[j, O_FP], out[j, O_SI], out[j, O_SO], out[j, O_FI], out[j, O_FO] = fs, si, so, fi, fo


@njit(cache=True, inline="always")
def contact_moments(
    p: np.ndarray,
    inner_scale: float,
    wa: float,
    omega_roll: float,
    sg: float,
    rb: float,
    r_ci: float,
    r_co: float,
    fi: float,
    fo: float,
    si: float,
    so: float,
    pi: float,
    po: float,
    fri: float,
    fro: float,
    qi: float,
    qo: float,
    di: float,
) -> tuple[float, float, float, float]:
    """The raceway contacts' actions besides their rolling-direction traction (docs/thermal.md,
    Energy), from the contacts' tractions F (N), sliding velocities s (m/s), dissipated powers
    P (W, :func:`contact_power`), Houpert rolling forces (N; model 2, from the table lookup),
    loads (N) and the inner penetration (m); ``inner_scale`` is :func:`inner_speed_scale` of the
    inner ring's speed and ``sg`` :func:`smooth_sign` of the rolling speed omega_roll. Returns
    (t_inner, m_outer, m_ring, t_orbit):

    * ``t_inner`` (N m, about the bearing axis, resisting the inner ring): the inner contact's
      loss beyond traction x sliding (the rheology table's spin and Heathcote losses), taken
      from the ring that turns through the contact, (P_i - F_i s_i) / omega_i (under
      outer-raceway control the spin there is the ring's own rotation about the contact
      normal), plus the moment F_R,i r_ci of the EHL rolling force on the ring's surface;
    * ``m_outer`` (N m, resisting the ball's rotation about its rolling axis): the outer
      contact's loss beyond traction x sliding (Heathcote's differential slip; no spin there)
      taken from the ball, the outer ring being fixed: (P_o - F_o s_o) / omega_a;
    * ``m_ring`` (N m, about the ball's rolling axis): the inner contact's elastic-hysteresis
      moment (as in :func:`spin_resistance`), whose reaction acts on the inner ring; its
      component along the bearing axis, m_ring cos(beta), is part of the drive torque;
    * ``t_orbit`` (N m, on the ball's orbit): the EHL rolling forces of both contacts, which act
      on each surface against its motion through the contact (the moment they make on the ball
      is in :func:`spin_resistance` / the rolling force of the stepper), with the inlet
      pressure's force through the ball centre, F_H = 2 F_R (2 R_x / D_w) = 2 F_R r_c / r_b,
      forward at the inner contact and backward at the outer (Harris and Kotzalas, *Advanced
      Concepts*, ch. 5, hydrodynamic rolling and pressure forces; Gupta's ADORE). A contact
      then loses 2 F_R u_e in pure rolling, F_R u_e on each surface.

    The first two are smoothed to zero below 1 rad/s of the speed they divide by. Models 0 and
    1 have no loss beyond traction x sliding; their Houpert force takes u_e = R |omega_roll|
    as in :func:`spin_resistance`."""
    r = p[P_RBALL]
    dip = max(di, 0.0)
    m_ring = p[P_HYST_IN] * dip * dip
    t_inner = 0.0
    m_outer = 0.0
    if p[P_FRIC_MODEL] == 2.0:
        t_inner = (pi - fi * si) * inner_scale
        wa2 = max(abs(wa), SPIN_SIGN_SPEED)
        m_outer = (po - fo * so) * wa / (wa2 * wa2)
    elif p[P_FR_IN] > 0.0 or p[P_FR_OUT] > 0.0:
        u066 = (r * abs(omega_roll)) ** 0.66
        fri = p[P_FR_IN] * u066 * qi**0.47 if qi > 0.0 else 0.0
        fro = p[P_FR_OUT] * u066 * qo**0.47 if qo > 0.0 else 0.0
    t_inner += fri * r_ci * sg
    t_orbit = (fri * (2.0 * r_ci - rb) - fro * (2.0 * r_co - rb)) * sg
    return t_inner, m_outer, m_ring * sg, t_orbit


@njit(cache=True)
def inner_speed_scale(omega_i: float) -> float:
    """1 / omega_i (s/rad) for :func:`contact_moments`, smoothed to omega_i / (1 rad/s)^2 below
    1 rad/s (a loss divided by the speed it is drawn through, without a pole at rest)."""
    w = max(omega_i, SPIN_SIGN_SPEED)
    return omega_i / (w * w)


@njit(cache=True)
def ball_power(
    wm: float,
    wa: float,
    rb: float,
    omega_i: float,
    fi: float,
    fo: float,
    si: float,
    so: float,
    mres: float,
    fd: float,
    t_inner: float,
    m_ring: float,
    t_orbit: float,
    cb: float,
    pivot: float = 0.0,
) -> float:
    """Power (W) dissipated at ball j, each term the work its force or moment takes from the
    drive or the bodies in the equations of motion (so that drive work = heat + kinetic and
    stored energy; :func:`contact_moments`): traction x sliding at both contacts, the inner
    contact's moments on the ring (t_inner omega_i), the moments resisting the ball's rotation
    (rolling resistance, pocket friction, the outer contact's Heathcote moment: ``mres``) at its
    spin omega_a plus the inner ring's share of the hysteresis through its rotation
    (m_ring cos(beta) omega_i), the EHL forces on its orbit, the drag, and ``pivot``: the
    transverse tractions x the pivot sliding, k_pivot (r omega_t)^2, taken from the ball's
    pivot."""
    return fi * si + fo * so + t_inner * omega_i + mres * wa + m_ring * cb * omega_i - t_orbit * wm + fd * rb * wm + pivot


@njit(cache=True)
def ball_drag(p: np.ndarray, v: float, load: float) -> tuple[float, float]:
    """Drag on a ball moving at ``v`` (m/s) and its derivative:
    F = c1 v + c2 v|v| + (c_y + c_n |v|^n) sgn(v) (N; the sign smoothed over 1 cm/s),
    dF/dv (N s/m). The plastic and power-law part is scaled by (load / Q_ref)^k when
    ``P_DRAG_LOAD_EXP`` = k is not zero (the paper model's ball-set resistance, whose load law
    follows its contact damping; ``load`` the ball's mean raceway load, N)."""
    f = p[P_DRAG_LIN] * v + p[P_DRAG_QUAD] * v * abs(v)
    df = p[P_DRAG_LIN] + 2.0 * p[P_DRAG_QUAD] * abs(v)
    if p[P_DRAG_YIELD] > 0.0 or p[P_DRAG_POW] > 0.0:
        y = v / DRAG_SIGN_SPEED
        q = 1.0 / math.sqrt(1.0 + y * y)
        a = max(abs(v), DRAG_SIGN_SPEED)
        an = math.sqrt(a) if p[P_DRAG_N] == 0.5 else a ** p[P_DRAG_N]
        plastic = p[P_DRAG_YIELD] + p[P_DRAG_POW] * an
        dplastic = p[P_DRAG_POW] * p[P_DRAG_N] * an / a
        if p[P_DRAG_LOAD_EXP] != 0.0:
            scale = (max(load, 0.0) / p[P_DRAG_LOAD_REF]) ** p[P_DRAG_LOAD_EXP]
            plastic *= scale
            dplastic *= scale
        f += plastic * y * q
        df += plastic * q * q * q / DRAG_SIGN_SPEED + dplastic
    return f, df


@njit(cache=True)
def finish_step(ring: np.ndarray, stats: np.ndarray, omega_i_old: float, omega_i: float, cage_mean: float, dt: float) -> None:
    """Advance the inner ring's angle (trapezoidal in its prescribed speed) and the clock, and
    accumulate the running integrals of cage and inner-ring speed."""
    ring[R_ANGLE] += 0.5 * (omega_i_old + omega_i) * dt
    ring[R_OMEGA] = omega_i
    ring[R_TIME] += dt
    stats[S_CAGE] += cage_mean * dt
    stats[S_INNER] += omega_i * dt
    stats[S_TIME] += dt


@njit(cache=True)
def pocket_directions(cage: np.ndarray, tx: np.ndarray, ty: np.ndarray, pitch_c: float, pitch_s: float) -> None:
    """Circumferential directions t_k = (-sin phi_k, cos phi_k) of the cage's pockets into
    ``tx``, ``ty``: segment 0's by the library, the others by rotating it through the pitch
    2 pi/Z (``pitch_c``, ``pitch_s`` its cosine and sine) and the segment's small offset d from
    its nominal place (series to d^4, exact to 1e-16 for |d| < 1e-3 rad; the library beyond)."""
    z = cage.shape[0]
    c, s = math.cos(cage[0, C_PHI]), math.sin(cage[0, C_PHI])
    for k in range(z):
        d = cage[k, C_PHI] - cage[0, C_PHI] - 2.0 * math.pi * k / z
        if abs(d) < 1e-3:
            d2 = d * d
            cd, sd = 1.0 - 0.5 * d2 * (1.0 - d2 / 12.0), d * (1.0 - d2 / 6.0)
            ck, sk = c * cd - s * sd, s * cd + c * sd
        else:
            ck, sk = math.cos(cage[k, C_PHI]), math.sin(cage[k, C_PHI])
        tx[k], ty[k] = -sk, ck
        c, s = c * pitch_c - s * pitch_s, s * pitch_c + c * pitch_s


@njit(cache=True)
def cage_centre_forces(p: np.ndarray, ring: np.ndarray, omega_c: float) -> tuple:
    """Land force on the cage centre (plus gravity with a horizontal spindle) and its Jacobians,
    for the implicit step: (F_x, F_y, N, Kxx, Kxy, Kyx, Kyy, Cxx, Cxy, Cyx, Cyy), N, N/m, N s/m
    (K = dF/dx, C = dF/dv by forward differences: the film force is linear in the velocity at a
    given position, so its tangent is its secant). Stores the contact force and the land
    torque's eccentricity factor in ``ring``."""
    x, y, vx, vy = ring[R_CX], ring[R_CY], ring[R_CVX], ring[R_CVY]
    fx, fy, normal = land_force(p, x, y, vx, vy, omega_c)
    hx = 1e-4 * p[P_LAND_CLEAR]
    hv = 1e-5
    f1x, f1y, _ = land_force(p, x + hx, y, vx, vy, omega_c)
    f2x, f2y, _ = land_force(p, x, y + hx, vx, vy, omega_c)
    f3x, f3y, _ = land_force(p, x, y, vx + hv, vy, omega_c)
    f4x, f4y, _ = land_force(p, x, y, vx, vy + hv, omega_c)
    ring[R_LAND_N] = normal
    ring[R_LAND_F] = land_shear_factor(p, math.sqrt(x * x + y * y) / p[P_LAND_CLEAR])
    return (
        fx,
        fy + p[P_CAGE_GRAV_Y],
        normal,
        (f1x - fx) / hx,
        (f2x - fx) / hx,
        (f1y - fy) / hx,
        (f2y - fy) / hx,
        (f3x - fx) / hv,
        (f4x - fx) / hv,
        (f3y - fy) / hv,
        (f4y - fy) / hv,
    )


@njit(cache=True)
def land_centre_heat(
    p: np.ndarray,
    cx: float,
    cy: float,
    cvx: float,
    cvy: float,
    dvx: float,
    dvy: float,
    dt: float,
    fcx: float,
    fcy: float,
    kxx: float,
    kxy: float,
    kyx: float,
    kyy: float,
    cxx: float,
    cxy: float,
    cyx: float,
    cyy: float,
) -> float:
    """Heat (W, over one reduced step) of the guiding land's work on the moving cage centre:
    the film's squeeze and whirl (Ocvirk) forces and the land contact's damping and friction,
    as the implicit step applied them (F + K dx + C dv, :func:`cage_centre_forces`, gravity
    aside), times the centre's mean velocity over the step, with the sign of a loss; the land
    contact's elastic force k d stores its work (:func:`mechanical_energy`) and is left out.
    The centre's kinetic energy changes by m_c dv . (v + dv/2), so with this heat its account
    closes to the step's rounding. Negative when the film's wedge drives the whirl (a centre
    whirling below half the cage speed): the model takes that work from no torque on the cage."""
    v1x, v1y = cvx + dvx, cvy + dvy
    fx = fcx + dt * (kxx * v1x + kxy * v1y) + cxx * dvx + cxy * dvy
    fy = fcy - p[P_CAGE_GRAV_Y] + dt * (kyx * v1x + kyy * v1y) + cyx * dvx + cyy * dvy
    mx, my = 0.5 * (cvx + v1x), 0.5 * (cvy + v1y)
    e = math.sqrt(cx * cx + cy * cy)
    if e > p[P_LAND_CLEAR]:
        elastic = p[P_LAND_K] * (e - p[P_LAND_CLEAR]) / e
        fx += elastic * cx
        fy += elastic * cy
    return -(fx * mx + fy * my)


@njit(cache=True, inline="always")
def reduced_ball_row(
    p: np.ndarray,
    ball: np.ndarray,
    cage: np.ndarray,
    geo: np.ndarray,
    work: np.ndarray,
    out: np.ndarray,
    j: int,
    w0: int,
    omega_i: float,
    inner_scale: float,
    dt: float,
    centre: bool,
    keep: bool,
    cx: float,
    cy: float,
    cvx: float,
    cvy: float,
    drive: float,
    heat: float,
    damp: float,
) -> tuple[float, float, float, float, float, float, float, float, float]:
    """Ball ``j``'s stage of a reduced step (:func:`step_reduced`): its raceway tractions and
    resistances at the step's start, its linearly implicit (orbit, spin) block with the pivot's
    and pitch's rows eliminated onto it, and the elimination data the cage's solve and the
    back-substitution read (``work[j, w0 + ...]``).

    Returns the step's running sums with this ball's share added (``drive``: the drive torque
    on the inner ring at the start, N m; ``heat``: W; ``damp``: the Hunt-Crossley heat of the
    pockets, W; added here in the order of the single loop they came from, so the sums are
    the same to the last bit) and the ball's terms of the cage centre's 2x2 block (m11, m12,
    m21, m22, kg) and of its right side (rcx, rcy, N).
    """
    rm = p[P_RM]
    r = p[P_RBALL]
    rb = ball[j, B_R]
    qi, qo, nir, niz, nor, noz = geo[j, G_QI], geo[j, G_QO], geo[j, G_NIR], geo[j, G_NIZ], geo[j, G_NOR], geo[j, G_NOZ]
    fi, fo, kti, kto, si, so, r_ci, ci, co, aim, aia, aom, aoa, cb, froll, pi, po, fri, kpiv, mpitch, kpitch = ball_tractions(
        p, ball, j, omega_i, qi, qo, nir, niz, nor, noz, geo[j, G_DI], geo[j, G_DO]
    )
    drive += fi * r_ci
    wm, wa, wt, wp = ball[j, B_OMEGA], ball[j, B_SPIN], ball[j, B_PIVOT], ball[j, B_PITCH]
    fd, dfd = ball_drag(p, rb * wm, 0.5 * (qi + qo))
    dfd = implicit_slope(fd, dfd, rb * wm)
    cph, sph = work[j, w0 + 21], -work[j, w0 + 20]
    # pocket gap and its rate with the cage centre off the axis (t = (-sin, cos) phi)
    gap = rm * (ball[j, B_THETA] - cage[j, C_PHI]) - (cy * cph - cx * sph)
    rate = rm * (wm - cage[j, C_OMEGA]) - (cvy * cph - cvx * sph) + cage[j, C_OMEGA] * (cx * cph + cy * sph)
    fs, ku, cu = pocket_force(p, gap, rate)
    damp += cu * rate * rate  # Hunt-Crossley: the damping force c u_dot times u_dot
    omega_roll = wa + cb * wm
    sg = smooth_sign(omega_roll)
    sroll = sg
    t_inner, m_outer, m_ring, t_orbit = contact_moments(
        p, inner_scale, wa, omega_roll, sg, rb, r_ci, aom + r * co * cb, fi, fo, si, so, pi, po, fri, froll - fri, qi, qo, geo[j, G_DI]
    )
    drive += t_inner + m_ring * cb
    mres = spin_resistance(p, geo[j, G_DI], geo[j, G_DO], fs, omega_roll) + r * froll * sg + m_outer
    kres = implicit_slope(mres, 0.0, omega_roll)  # secant: a damper on the rolling speed
    # the tractions' generalised forces on orbit and spin are their levers in the contact
    # points' speeds (A_m, A_a; :func:`ball_kinematics`): the orbit's lever A_m is the ball
    # centre's r_b plus the raceway-control pitch rotation's share r sin(beta) sin(alpha - beta)
    gm = aim * fi + aom * fo - rb * fd - rm * fs + t_orbit
    ga = r * (ci * fi - co * fo) - mres
    jmm = -kti * aim * aim - kto * aom * aom - dfd * rb * rb
    jma = -kti * aim * aia + kto * aom * aoa
    jam = r * (-ci * kti * aim + co * kto * aom) - kres * cb
    jaa = r * (-ci * kti * aia - co * kto * aoa) - kres
    ee = cu + dt * ku
    e = rm * rm * ee
    ib = p[P_IBALL]
    b11 = p[P_MBALL] * rb * rb - dt * jmm + dt * e
    b12 = -dt * jma
    b21 = -dt * jam
    b22 = ib - dt * jaa
    # the pivot omega_t and the pitch rate omega_p: the orbiting frame's gyroscopic terms,
    # g = J omega_m sin(beta) times (cos(beta) omega_t, omega_t, -omega_roll) on (orbit, spin,
    # pivot) and gc = J omega_m cos(beta) times (-omega_p, omega_t) on (pivot, pitch), skew and
    # taken trapezoidally (they keep the energy exactly); the transverse tractions' moment
    # -r k_pivot r omega_t and the spin moments' change -m_pitch implicitly (secants through
    # zero); the (pivot, pitch) rows are eliminated onto the 2x2 block (Schur complement). With
    # no traction at either contact (k_pivot = 0: frictionless or unloaded) the gyroscopic
    # terms are left out
    sbg = math.sqrt(max(1.0 - cb * cb, 0.0))
    g = ib * wm * sbg if kpiv > 0.0 else 0.0
    gc = ib * wm * cb if kpiv > 0.0 else 0.0
    hg = 0.5 * dt * g
    hgc = 0.5 * dt * gc
    gm += g * cb * wt
    ga += g * wt
    s11 = ib + dt * r * r * kpiv
    s22 = ib + dt * kpitch
    dinv = 1.0 / (s11 * s22 + hgc * hgc)
    rt = dt * (-g * omega_roll - gc * wp - r * r * kpiv * wt)
    rp = dt * (gc * wt - mpitch)
    r3 = (s22 * rt - hgc * rp) * dinv
    t1, t2 = s22 * hg * cb * dinv, s22 * hg * dinv
    b11 += hg * cb * t1
    b12 += hg * cb * t2
    b21 += hg * t1
    b22 += hg * t2
    work[j, w0 + 29] = r3
    work[j, w0 + 30] = t1
    work[j, w0 + 31] = t2
    work[j, w0 + 32] = (hgc * rt + s11 * rp) * dinv
    work[j, w0 + 33] = hgc * hg * cb * dinv
    work[j, w0 + 34] = hgc * hg * dinv
    det = b11 * b22 - b12 * b21
    i11, i12, i21, i22 = b22 / det, -b12 / det, -b21 / det, b11 / det
    r1 = dt * (gm - dt * rm * ku * rate) + hg * cb * r3
    r2 = dt * ga + hg * r3
    x2 = i11 * r1 + i12 * r2
    work[j, w0 + 0] = i11
    work[j, w0 + 1] = i21
    work[j, w0 + 2] = x2
    work[j, w0 + 3] = i21 * r1 + i22 * r2
    work[j, w0 + 4] = e
    work[j, w0 + 5] = ku * rate
    work[j, w0 + 6] = fs
    d11 = d12 = d21 = d22 = dcx = dcy = 0.0
    if centre:
        # coupling of the pocket's force to the cage centre: g = dt r_m E (dt e i11 - 1)
        # <= 0, its direction on the cage n = t + mu_p sgn(roll) r (pocket friction)
        mup = p[P_MU_POCKET]
        g = dt * rm * ee * (dt * e * i11 - 1.0)
        nx = -sph + mup * sroll * cph
        ny = cph + mup * sroll * sph
        work[j, w0 + 22] = g
        work[j, w0 + 23] = nx
        work[j, w0 + 24] = ny
        work[j, w0 + 25] = g * -sph
        work[j, w0 + 26] = g * cph
        d11 = g / rm * nx * -sph
        d12 = g / rm * nx * cph
        d21 = g / rm * ny * -sph
        d22 = g / rm * ny * cph
        fp = fs + dt * ku * rate + ee * rm * x2
        dcx = nx * fp
        dcy = ny * fp
    work[j, w0 + 10] = r_ci * kti * aim  # the inner traction's implicit part, per d omega_m
    work[j, w0 + 11] = r_ci * kti * aia  # and per d omega_a (for the drive torque)
    power = ball_power(wm, wa, rb, omega_i, fi, fo, si, so, mres, fd, t_inner, m_ring, t_orbit, cb, kpiv * (r * wt) ** 2 + mpitch * wp)
    if keep:
        record(out, j, qi, qo, nir, niz, nor, noz, fs, si, so, fi, fo)
        out[j, O_POWER] = power
        out[j, O_DRIVE] = fi * r_ci + t_inner + m_ring * cb
    return drive, heat + power, damp, d11, d12, d21, d22, dcx, dcy


@njit(cache=True, inline="always")
def reduced_cage_rows(
    p: np.ndarray, cage: np.ndarray, work: np.ndarray, w0: int, dt: float, land_f: float, land_n: float, heat: float, damp: float
) -> tuple[float, float]:
    """The cage segments' stage of a reduced step: each segment's diagonal and right side of
    the cyclic tridiagonal system (``work[:, w0 + 7]`` and ``w0 + 8``), its rim, land and
    pocket terms with the balls' blocks eliminated onto it. Returns the running sums ``heat``
    with the land's heat and ``damp`` with the rims' damping heat added (W)."""
    z = cage.shape[0]
    rm = p[P_RM]
    kl, cl = p[P_LINK_K], p[P_LINK_C]
    lc = cl + dt * kl
    diag = work[:, w0 + 7]
    rhs = work[:, w0 + 8]
    for k in range(z):
        km = z - 1 if k == 0 else k - 1
        kp = 0 if k == z - 1 else k + 1
        tau, dtl = cage_segment_torque(p, cage, k, z, land_f, land_n)
        w = cage[k, C_OMEGA]
        tl, _ = cage_land_torque(p, w, z, land_f, land_n)
        heat += abs(tl * w)
        dw = cage[kp, C_OMEGA] - w
        damp += cl * dw * dw  # the rim's damping between segments k and k+1
        e = work[k, w0 + 4]
        gc = rm * work[k, w0 + 6] + tau
        diag[k] = p[P_JSEG] + 2.0 * dt * lc + dt * e + dt * dtl - dt * dt * e * e * work[k, w0 + 0]
        rhs[k] = dt * (gc + dt * kl * (cage[kp, C_OMEGA] - 2.0 * cage[k, C_OMEGA] + cage[km, C_OMEGA]) + dt * rm * work[k, w0 + 5]) + dt * e * work[k, w0 + 2]
    return heat, damp


@njit(cache=True, inline="always")
def reduced_centre_solve(
    work: np.ndarray, w0: int, dt: float, lc: float, m11: float, m12: float, m21: float, m22: float, rcx: float, rcy: float
) -> tuple[float, float]:
    """The cage centre's stage of a reduced step: the segments' response to its velocity change
    (A Y = g t, ``work[:, w0 + 27]`` and ``w0 + 28``) eliminated onto its 2x2 block, solved for
    its velocity change (dv_x, dv_y, m/s); the segments' speed changes ``work[:, w0 + 9]`` take
    their share of it."""
    z = work.shape[0]
    diag = work[:, w0 + 7]
    d_omega = work[:, w0 + 9]
    yx = work[:, w0 + 27]
    yy = work[:, w0 + 28]
    cyclic_tridiagonal_pair(diag, -dt * lc, work[:, w0 + 25], work[:, w0 + 26], yx, yy, work[:, NG : NG + 5])
    for k in range(z):
        g = work[k, w0 + 22]
        nx, ny = work[k, w0 + 23], work[k, w0 + 24]
        m11 -= g * nx * yx[k]
        m12 -= g * nx * yy[k]
        m21 -= g * ny * yx[k]
        m22 -= g * ny * yy[k]
        rcx += g / dt * nx * d_omega[k]
        rcy += g / dt * ny * d_omega[k]
    det2 = m11 * m22 - m12 * m21
    dvx = dt * (m22 * rcx - m12 * rcy) / det2
    dvy = dt * (m11 * rcy - m21 * rcx) / det2
    for j in range(z):
        d_omega[j] += yx[j] * dvx + yy[j] * dvy
    return dvx, dvy


@njit(cache=True, inline="always")
def reduced_update(
    p: np.ndarray, ball: np.ndarray, cage: np.ndarray, work: np.ndarray, out: np.ndarray, w0: int, dt: float, dvx: float, dvy: float, keep: bool, drive: float
) -> tuple[float, float]:
    """The back-substitution of a reduced step: each ball's orbit, spin, pivot and pitch from
    its pocket's closing speed, the segments' speeds, and both advanced in angle. Returns the
    running drive torque ``drive`` less the tractions' implicit parts (N m) and the sum of the
    segments' new speeds (rad/s)."""
    z = ball.shape[0]
    rm = p[P_RM]
    d_omega = work[:, w0 + 9]
    cage_sum = 0.0
    for j in range(z):
        # the pocket's closing speed seen by the ball: r_m d Omega + t . d v (over r_m)
        coup = dt * work[j, w0 + 4] * (d_omega[j] + (work[j, w0 + 20] * dvx + work[j, w0 + 21] * dvy) / rm)
        d_wm = work[j, w0 + 2] + work[j, w0 + 0] * coup
        d_wa = work[j, w0 + 3] + work[j, w0 + 1] * coup
        ball[j, B_OMEGA] += d_wm
        ball[j, B_SPIN] += d_wa
        ball[j, B_PIVOT] += work[j, w0 + 29] - work[j, w0 + 30] * d_wm - work[j, w0 + 31] * d_wa
        ball[j, B_PITCH] += work[j, w0 + 32] - work[j, w0 + 33] * d_wm - work[j, w0 + 34] * d_wa
        # the drive torque of the traction the step applied: Q mu at the start plus its
        # implicit part, k_t ds with ds = -(A_im d omega_m + A_ia d omega_a)
        d_drive = work[j, w0 + 10] * d_wm + work[j, w0 + 11] * d_wa
        drive -= d_drive
        if keep:
            out[j, O_DRIVE] -= d_drive
        cage[j, C_OMEGA] += d_omega[j]
        ball[j, B_THETA] += dt * ball[j, B_OMEGA]
        cage[j, C_PHI] += dt * cage[j, C_OMEGA]
        cage_sum += cage[j, C_OMEGA]
    return drive, cage_sum


@njit(cache=True)
def step_reduced(
    p: np.ndarray,
    ball: np.ndarray,
    cage: np.ndarray,
    ring: np.ndarray,
    out: np.ndarray,
    stats: np.ndarray,
    work: np.ndarray,
    n_steps: int,
    dt: float,
    axial_load: float,
    inner_acceleration: float,
    record_every: int,
    radial_load: float = 0.0,
    radial_angle: float = 0.0,
    moment_x: float = 0.0,
    moment_y: float = 0.0,
    tilt_free: bool = False,
) -> int:
    """Advance the default (reduced) model by ``n_steps`` steps of ``dt`` seconds.

    Normal contacts are quasi-static (solved every step); ball orbit and spin, the cage
    segments and the cage centre's two translations are integrated with a linearly implicit
    Euler step that treats the stiff traction, pocket, rim and land-film couplings implicitly
    (block elimination onto a cyclic tridiagonal system of the segments bordered by the cage
    centre's 2x2 block). The pocket gap of ball j is u = r_m (theta_j - phi_j) - e . t_j (e the
    cage centre, t_j the pocket's circumferential direction): the pockets push the cage centre
    along t_j, and pocket friction along the pocket's radial direction (the ball's surface
    moves radially there). The inner ring turns at the prescribed speed, changing at
    ``inner_acceleration`` (rad/s^2). With ``tilt_free`` the inner ring's tilts are unknowns of
    the normal solve under the moment (``moment_x``, ``moment_y``, N m;
    :func:`solve_quasi_static_tilted`); otherwise they stay where they are (held). ``work`` is
    scratch of shape (Z, NW). Diagnostics go to ``out`` on the last step and every
    ``record_every`` steps.

    A step's stages: the contacts (the quasi-static normal solve), the cage centre's film and
    land forces, each ball's tractions, resistances and block (:func:`reduced_ball_row`), the
    cage segments' rows (:func:`reduced_cage_rows`) and their cyclic tridiagonal solve, the cage
    centre's (:func:`reduced_centre_solve`), and the back-substitution
    (:func:`reduced_update`).

    Returns the largest number of quasi-static Newton iterations used.
    """
    z = ball.shape[0]
    mc = p[P_CAGE_MASS]
    kl, cl = p[P_LINK_K], p[P_LINK_C]
    geo = work[:, 0:NG]
    qs_work = work[:, NG : NG + 6]  # the quasi-static solve's scratch, free again after it
    tri_work = work[:, NG + 4 : NG + 8]
    w0 = NG + 8  # per-ball elimination data
    loads = np.array([axial_load, radial_load * math.cos(radial_angle), radial_load * math.sin(radial_angle), moment_x, moment_y])
    worst_iter = 0
    lc = cl + dt * kl
    pitch_c, pitch_s = math.cos(2.0 * math.pi / z), math.sin(2.0 * math.pi / z)
    for step in range(n_steps):
        omega_i_old = ring[R_OMEGA]
        omega_i = omega_i_old + inner_acceleration * dt
        if tilt_free:
            it = solve_quasi_static_tilted(p, ball, ring, geo, qs_work, loads, 1e-9, 30)
        else:
            it = solve_quasi_static(p, ball, ring, geo, qs_work, axial_load, 1e-9, 30, radial_load, radial_angle)
        worst_iter = max(worst_iter, it)
        keep = step == n_steps - 1 or (record_every > 0 and step % record_every == 0)
        if keep:
            ring_moment(p, ball, ring, geo)
        cx, cy, cvx, cvy = ring[R_CX], ring[R_CY], ring[R_CVX], ring[R_CVY]
        # the cage centre moves once something pushes it off the axis: a radial load or a state
        # left off it; a centred cage under a purely axial load is an exact equilibrium (the
        # pockets' forces cancel, the film has none) and skips the centre's terms. The cage's
        # weight (horizontal spindle) acts on a moving centre but does not set it moving alone:
        # it stays the land's boundary friction mu m_c g r (docs/model.md, "Cage whirl")
        centre = radial_load != 0.0 or tilt_free or ring[R_TX] != 0.0 or ring[R_TY] != 0.0 or cx != 0.0 or cy != 0.0 or cvx != 0.0 or cvy != 0.0
        heat = 0.0
        damp = 0.0
        fcx = fcy = land_n = kxx = kxy = kyx = kyy = cxx = cxy = cyx = cyy = 0.0
        if centre:
            omega_c = 0.0
            for k in range(z):
                omega_c += cage[k, C_OMEGA]
            fcx, fcy, land_n, kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy = cage_centre_forces(p, ring, omega_c / z)
            pocket_directions(cage, work[:, w0 + 20], work[:, w0 + 21], pitch_c, pitch_s)
        else:
            ring[R_LAND_N], ring[R_LAND_F] = 0.0, 1.0
            work[:, w0 + 20] = 0.0
            work[:, w0 + 21] = 0.0
        land_f = ring[R_LAND_F]
        # the cage centre's 2x2 block: m_c - dt (dt K + C) - sum (g/r_m) n t^T, and its right side
        m11 = mc - dt * (dt * kxx + cxx)
        m12 = -dt * (dt * kxy + cxy)
        m21 = -dt * (dt * kyx + cyx)
        m22 = mc - dt * (dt * kyy + cyy)
        rcx = fcx + dt * (kxx * cvx + kxy * cvy)
        rcy = fcy + dt * (kyx * cvx + kyy * cvy)
        drive = 0.0
        inner_scale = inner_speed_scale(omega_i)
        for j in range(z):
            drive, heat, damp, d11, d12, d21, d22, dcx, dcy = reduced_ball_row(
                p, ball, cage, geo, work, out, j, w0, omega_i, inner_scale, dt, centre, keep, cx, cy, cvx, cvy, drive, heat, damp
            )
            if centre:
                m11 -= d11
                m12 -= d12
                m21 -= d21
                m22 -= d22
                rcx += dcx
                rcy += dcy
        heat, damp = reduced_cage_rows(p, cage, work, w0, dt, land_f, land_n, heat, damp)
        cyclic_tridiagonal(work[:, w0 + 7], -dt * lc, work[:, w0 + 8], work[:, w0 + 9], tri_work)
        dvx = dvy = 0.0
        if centre:
            dvx, dvy = reduced_centre_solve(work, w0, dt, lc, m11, m12, m21, m22, rcx, rcy)
            ring[R_CVX] = cvx + dvx
            ring[R_CVY] = cvy + dvy
            ring[R_CX] = cx + dt * ring[R_CVX]
            ring[R_CY] = cy + dt * ring[R_CVY]
            damp += land_centre_heat(p, cx, cy, cvx, cvy, dvx, dvy, dt, fcx, fcy, kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy)
        drive, cage_sum = reduced_update(p, ball, cage, work, out, w0, dt, dvx, dvy, keep, drive)
        stats[S_DRIVE] += drive * omega_i * dt
        stats[S_HEAT] += heat * dt
        stats[S_DAMP] += damp * dt
        finish_step(ring, stats, omega_i_old, omega_i, cage_sum / z, dt)
    return worst_iter


NW = NG + 8 + 35
"""Columns of the reduced model's scratch array (w0 + 20 onwards: the cage centre's coupling;
w0 + 29 onwards: the pivot's and the pitch's elimination)."""


ENTRAINMENT_FLOOR = 1e-3
"""The entrainment speed below which the rheology table is read at this speed, m/s
(:func:`contact_traction`)."""


@njit(cache=True, inline="always")
def stiff_ball_row(
    p: np.ndarray,
    ball: np.ndarray,
    cage: np.ndarray,
    out: np.ndarray,
    torque: np.ndarray,
    j: int,
    omega_i: float,
    dt: float,
    delta_a: float,
    vdelta: float,
    keep: bool,
    drive: float,
    heat: float,
    damp: float,
    contact_damp: float,
    ring_force: float,
) -> tuple[float, float, float, float, float]:
    """Ball ``j``'s stage of a stiff step (:func:`step_stiff`): its Hertz contacts with their
    damping, tractions and resistances, then its momenta and position (symplectic Euler; the
    pivot first, the raceway tractions linearly implicit). Returns the step's running sums with
    this ball's share added, in the order of the single loop they came from: the drive torque
    (N m), heat and pocket damping heat (W), the raceway contacts' damping heat (W) and the
    axial force on the inner ring (N); ``torque[j]`` gets the pocket's torque on segment j."""
    rm = p[P_RM]
    r = p[P_RBALL]
    m = p[P_MBALL]
    ib = p[P_IBALL]
    rb, zb, vr, vz = ball[j, B_R], ball[j, B_Z], ball[j, B_VR], ball[j, B_VZ]
    di, nir, niz, disti, do, nor, noz, disto = raceway_geometry(p, rb, zb, delta_a)
    rate_i, rate_o = nir * vr + niz * (vz - vdelta), nor * vr + noz * vz
    qi, _, _ = impact_force(di, rate_i, p[P_K_IN], p)
    qo, _, _ = impact_force(do, rate_o, p[P_K_OUT], p)
    # the raceway contacts' Hunt-Crossley damping: the force beyond Hertz's, times the rate
    contact_damp += impact_damping_power(di, rate_i, qi, p[P_K_IN]) + impact_damping_power(do, rate_o, qo, p[P_K_OUT])
    fi, fo, kti, kto, si, so, r_ci, ci, co, aim, aia, aom, aoa, cb, froll, pi, po, fri, kpiv, _, _ = ball_tractions(
        p, ball, j, omega_i, qi, qo, nir, niz, nor, noz, di, do
    )
    wm, wa, wt = ball[j, B_OMEGA], ball[j, B_SPIN], ball[j, B_PIVOT]
    if p[P_FRIC_MODEL] == 2.0:
        # the rheology table's offset at SRR = 0 (spin and Heathcote slip, which go with
        # the rolling) fades out below the table's entrainment floor: a contact that
        # does not roll has no spin, and no traction without sliding
        _, r_co, _, _, _, _, _, _, _ = ball_kinematics(p, nir, niz, nor, noz, rb)
        uei, ueo = abs((omega_i - wm) * r_ci), abs(wm * r_co)
        if uei < ENTRAINMENT_FLOOR and qi > 0.0:
            fi -= (1.0 - uei / ENTRAINMENT_FLOOR) * qi * contact_traction(p, 0, 0.0, uei, qi)[0]
        if ueo < ENTRAINMENT_FLOOR and qo > 0.0:
            fo -= (1.0 - ueo / ENTRAINMENT_FLOOR) * qo * contact_traction(p, 1, 0.0, ueo, qo)[0]
    drive += fi * r_ci
    g = ib * wm * math.sqrt(max(1.0 - cb * cb, 0.0)) if kpiv > 0.0 else 0.0  # gyroscopic terms (see step_reduced)
    fd, _ = ball_drag(p, rb * wm, 0.5 * (qi + qo))
    gap, rate = rm * (ball[j, B_THETA] - cage[j, C_PHI]), rm * (wm - cage[j, C_OMEGA])
    fs, _, _ = pocket_force(p, gap, rate)
    x = abs(gap) - p[P_POCKET_CLEAR]
    damp += impact_damping_power(x, rate if gap > 0.0 else -rate, abs(fs), p[P_K_POCKET])
    t_inner, m_outer, m_ring, t_orbit = contact_moments(
        p,
        inner_speed_scale(omega_i),
        wa,
        wa + cb * wm,
        smooth_sign(wa + cb * wm),
        rb,
        r_ci,
        aom + r * co * cb,
        fi,
        fo,
        si,
        so,
        pi,
        po,
        fri,
        froll - fri,
        qi,
        qo,
        di,
    )
    drive += t_inner + m_ring * cb
    mres = spin_resistance(p, di, do, fs, wa + cb * wm) + r * froll * smooth_sign(wa + cb * wm) + m_outer
    # momenta at the current positions (p_theta first: p_r's update needs it)
    # the pivot first: its gyroscopic coupling then acts on orbit and spin with the new
    # pivot (symplectic Euler on the skew terms: bounded energy error)
    # the raceway tractions linearly implicit (their slopes, as step_reduced): at a low
    # entrainment speed the traction's slope in the sliding speed grows as 1/u_e
    # (u_e >= 1 mm/s), so that dt r^2 k_t / J reaches 3 for a ball at rest; explicit,
    # its spin and pivot chattered at +-0.09 rad/s every other step, a bounded
    # oscillation whose f s read as 4.5 mW of heat with no drive work
    wt_old = wt
    wt = (ib * wt - dt * g * (wa + cb * wm)) / (ib + dt * r * r * kpiv)
    ball[j, B_PIVOT] = wt
    gm = aim * fi + aom * fo - rb * fd - rm * fs + t_orbit + g * cb * wt  # levers as step_reduced
    ga = r * (ci * fi - co * fo) - mres + g * wt
    b11 = m * rb * rb + dt * (kti * aim * aim + kto * aom * aom)
    b12 = dt * (kti * aim * aia - kto * aom * aoa)
    b21 = dt * r * (ci * kti * aim - co * kto * aom)
    b22 = ib + dt * r * (ci * kti * aia + co * kto * aoa)
    det = b11 * b22 - b12 * b21
    d_wm = dt * (b22 * gm - b12 * ga) / det
    d_wa = dt * (b11 * ga - b21 * gm) / det
    d_drive = r_ci * kti * (aim * d_wm + aia * d_wa)  # the inner traction's implicit part
    drive -= d_drive
    ptheta = m * rb * rb * (wm + d_wm)
    wnew = wm + d_wm
    vr_new = vr + dt * (rb * wnew * wnew + (-qi * nir - qo * nor) / m)
    vz_new = vz + dt * (-qi * niz - qo * noz) / m
    ball[j, B_SPIN] = wa + d_wa
    ball[j, B_THETA] += dt * wnew
    rb_new = rb + dt * vr_new
    ball[j, B_R] = rb_new
    ball[j, B_Z] = zb + dt * vz_new
    ball[j, B_VR], ball[j, B_VZ] = vr_new, vz_new
    ball[j, B_OMEGA] = ptheta / (m * rb_new * rb_new)
    ring_force += qi * niz
    torque[j] = rm * fs
    # the tractions' heat as the implicit step applies them: the force at the step's end
    # times the step's mean sliding (exactly the kinetic energy a linear law takes)
    dsi, dso = -aim * d_wm - aia * d_wa, -aom * d_wm + aoa * d_wa
    pivot = kpiv * r * r * wt * 0.5 * (wt_old + wt)
    power = ball_power(wm, wa, rb, omega_i, fi + kti * dsi, fo + kto * dso, si + 0.5 * dsi, so + 0.5 * dso, mres, fd, t_inner, m_ring, t_orbit, cb, pivot)
    heat += power
    if keep:
        record(out, j, qi, qo, nir, niz, nor, noz, fs, si, so, fi, fo)
        out[j, O_POWER] = power
        out[j, O_DRIVE] = fi * r_ci + t_inner + m_ring * cb - d_drive
    return drive, heat, damp, contact_damp, ring_force


@njit(cache=True)
def step_stiff(
    p: np.ndarray,
    ball: np.ndarray,
    cage: np.ndarray,
    ring: np.ndarray,
    out: np.ndarray,
    stats: np.ndarray,
    work: np.ndarray,
    n_steps: int,
    dt: float,
    axial_load: float,
    inner_acceleration: float,
    record_every: int,
    radial_load: float = 0.0,
    radial_angle: float = 0.0,
    moment_x: float = 0.0,
    moment_y: float = 0.0,
    tilt_free: bool = False,
) -> int:
    """Advance the stiff reference model by ``n_steps`` explicit steps of ``dt`` seconds.

    Every body is dynamic: ball centres move in r, theta, z under Hertz contacts with
    Hunt-Crossley damping (the paper's IMPACT law), the inner ring moves axially under the
    applied load, friction and resistances as in the reduced model. Symplectic Euler in the
    canonical polar coordinates (momenta first, then positions), so that with friction and
    damping off the energy error stays bounded. Needs steps well below a microsecond.
    ``work`` is scratch of shape (Z, NW). ``radial_load`` must be 0 (axisymmetric; ``radial_angle``
    and the moment unused, ``tilt_free`` False). Returns 0.
    """
    z = ball.shape[0]
    jseg = p[P_JSEG]
    torque = work[:, 0]
    for step in range(n_steps):
        omega_i_old = ring[R_OMEGA]
        omega_i = omega_i_old + inner_acceleration * dt
        delta_a, vdelta = ring[R_DELTA], ring[R_VDELTA]
        ring_force = axial_load + partner_force(p, delta_a)[0]
        drive = 0.0
        heat = 0.0
        damp = 0.0
        contact_damp = 0.0
        keep = step == n_steps - 1 or (record_every > 0 and step % record_every == 0)
        for j in range(z):
            drive, heat, damp, contact_damp, ring_force = stiff_ball_row(
                p, ball, cage, out, torque, j, omega_i, dt, delta_a, vdelta, keep, drive, heat, damp, contact_damp, ring_force
            )
        stats[S_DRIVE] += drive * omega_i * dt
        for k in range(z):
            tau, _ = cage_segment_torque(p, cage, k, z)
            torque[k] += tau
            tl, _ = cage_land_torque(p, cage[k, C_OMEGA], z)
            heat += abs(tl * cage[k, C_OMEGA])
            dw = cage[0 if k == z - 1 else k + 1, C_OMEGA] - cage[k, C_OMEGA]
            damp += p[P_LINK_C] * dw * dw  # the rim's damping between segments k and k+1
        stats[S_HEAT] += heat * dt
        stats[S_DAMP] += damp * dt
        stats[S_CONTACT_DAMP] += contact_damp * dt
        cage_sum = 0.0
        for k in range(z):
            cage[k, C_OMEGA] += dt * torque[k] / jseg
            cage[k, C_PHI] += dt * cage[k, C_OMEGA]
            cage_sum += cage[k, C_OMEGA]
        vdelta_new = vdelta + dt * ring_force / p[P_M_INNER]
        ring[R_VDELTA] = vdelta_new
        ring[R_DELTA] = delta_a + dt * vdelta_new
        finish_step(ring, stats, omega_i_old, omega_i, cage_sum / z, dt)
    return 0


@njit(cache=True)
def mechanical_energy(p: np.ndarray, ball: np.ndarray, cage: np.ndarray, ring: np.ndarray, axial_load: float) -> float:
    """Total mechanical energy (J) of the stiff model: kinetic energy of balls (orbit, radial,
    axial, spin, pivot), cage segments and the inner ring's axial motion, plus Hertz potentials
    (2/5 K x^2.5) of raceway and pocket contacts, rim strain energy and the potential
    -F_a delta_a of the constant axial load. The reduced model's cage centre adds its kinetic
    energy, the land contact's strain energy k d^2 / 2 and the potential of the cage's weight,
    and moves the pockets' gaps by its offset (the stiff model's centre stays on the axis)."""
    z = ball.shape[0]
    m, ib, jseg, rm = p[P_MBALL], p[P_IBALL], p[P_JSEG], p[P_RM]
    e = 0.5 * p[P_M_INNER] * ring[R_VDELTA] ** 2 - axial_load * ring[R_DELTA] + partner_force(p, ring[R_DELTA])[2]
    cx, cy = ring[R_CX], ring[R_CY]
    e += 0.5 * p[P_CAGE_MASS] * (ring[R_CVX] ** 2 + ring[R_CVY] ** 2) - p[P_CAGE_GRAV_Y] * cy
    d = math.sqrt(cx * cx + cy * cy) - p[P_LAND_CLEAR]
    if d > 0.0:
        e += 0.5 * p[P_LAND_K] * d * d
    clear = p[P_POCKET_CLEAR]
    for j in range(z):
        rb = ball[j, B_R]
        e += 0.5 * m * (ball[j, B_VR] ** 2 + ball[j, B_VZ] ** 2 + (rb * ball[j, B_OMEGA]) ** 2)
        e += 0.5 * ib * (ball[j, B_SPIN] ** 2 + ball[j, B_PIVOT] ** 2 + ball[j, B_PITCH] ** 2)
        di, _, _, _, do, _, _, _ = raceway_geometry(p, rb, ball[j, B_Z], ring[R_DELTA])
        if di > 0.0:
            e += 0.4 * p[P_K_IN] * di**2.5
        if do > 0.0:
            e += 0.4 * p[P_K_OUT] * do**2.5
        phi = cage[j, C_PHI]
        x = abs(rm * (ball[j, B_THETA] - phi) - (cy * math.cos(phi) - cx * math.sin(phi))) - clear
        if x > 0.0:
            e += 0.4 * p[P_K_POCKET] * x**2.5
        e += 0.5 * jseg * cage[j, C_OMEGA] ** 2
        e += 0.5 * p[P_LINK_K] * link_strain(cage, j, z) ** 2
    return e


@njit(cache=True)
def speed_outlier(ball: np.ndarray, cage: np.ndarray, ring: np.ndarray, lo: float, hi: float) -> int:
    """The first thing wrong with the state, in one pass: 0 none; 1 a non-finite value; 2 a cage
    segment's speed outside [lo, hi] rad/s; 3 a ball's orbit speed outside it."""
    if not (np.all(np.isfinite(ball)) and np.all(np.isfinite(cage)) and np.all(np.isfinite(ring))):
        return 1
    for k in range(cage.shape[0]):
        w = cage[k, C_OMEGA]
        if w < lo or w > hi:
            return 2
    for k in range(ball.shape[0]):
        w = ball[k, B_OMEGA]
        if w < lo or w > hi:
            return 3
    return 0
