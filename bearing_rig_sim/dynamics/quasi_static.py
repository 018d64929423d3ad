"""Quasi-static load distribution of an angular contact ball bearing under combined load
(Jones 1960; Harris and Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 2, ch. 2-3).

The outer ring is fixed. The inner ring has five degrees of freedom: axial displacement
delta_a, radial displacements delta_x, delta_y and tilts theta_x, theta_y (rad). Ball j sits at
azimuth psi_j = 2 pi j / Z (ball 0 on +x). In the ball's azimuthal plane the inner groove
curvature centre is displaced from the outer one by (Harris's 5-DOF geometry)

    A1_j = A sin a0 + delta_a + R_i (theta_x cos psi_j + theta_y sin psi_j)   (axial)
    A2_j = A cos a0 + delta_x cos psi_j + delta_y sin psi_j - P_d / 2          (radial)

with A = (f_i + f_o - 1) Dw the unloaded distance of the curvature centres, a0 the free contact
angle, R_i the radius of the locus of the inner groove curvature centres and P_d an extra
diametral clearance (negative: an interference). theta_x is the tilt that lifts the inner ring
axially at psi = 0; theta_y at psi = 90 deg. Moments are counted the same way:
M_x = sum Q_i sin a_i R_i cos psi, M_y = sum Q_i sin a_i R_i sin psi (N m).

Each ball's normal contacts follow from its centre and the two groove curvature centres: the
approach is the centre distance minus (f - 1/2) Dw, the load Q = K delta^1.5 (Hertz constants of
:func:`.hertz.raceway_contacts`), the loaded contact angle the direction of that line.

* **At rest** (no speed) the ball carries no body force: it lies on the line joining the two
  curvature centres, Q_i = Q_o = K_n (|A_j| - A)^1.5 with K_n the series constant, and both
  contact angles are atan(A1_j / A2_j).
* **At speed** (Jones) the ball centre (X1, X2 from the outer curvature centre) is an unknown:
  the centrifugal force F_c = m d_m omega_m^2 / 2 and the gyroscopic moment
  M_g = J omega_R omega_m sin(beta) (J = rho pi Dw^5 / 60), carried by the outer contact's
  friction (outer-raceway control, lambda_o = 2, lambda_i = 0), enter the ball's balance

      Q_i sin a_i - Q_o sin a_o + 2 M_g cos(a_o) / Dw = 0
      Q_i cos a_i - Q_o cos a_o - 2 M_g sin(a_o) / Dw + F_c = 0

  with the ball's orbit and rolling speeds from outer-raceway-control kinematics at its own
  contact angles (Harris and Kotzalas). These speeds are an input of the load distribution only;
  the dynamic engine computes its cage and ball speeds from the tractions. A ball outside the
  load zone (the curvature centres closer than A, or no inner contact when resting on the outer
  raceway under F_c) carries Q_o = F_c at a_o = 0 and no inner load (no gyroscopic moment:
  nothing holds it by friction; pinched between centres closer than A its two loads would be of
  the order of F_c, a few newtons at most at the rig's top speed).

The inner ring's balance: F_a = sum Q_i sin a_i, F_x = sum Q_i cos a_i cos psi,
F_y = sum Q_i cos a_i sin psi, and the two moments. With ``moment=None`` the tilts are held (at
the misalignment given; as the spindle's second bearing holds them) and the reaction moment is
reported. Solved with :func:`scipy.optimize.root` on the ring's displacements (the balls' own
balances nested, each a 2x2 Newton problem).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import root

from bearing_rig_sim.dynamics.parameters import BearingParameters
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.thermal.materials import BEARING_STEEL


class LoadDistributionError(RigError):
    """The quasi-static equilibrium could not be found (or a bad input)."""


def thermal_clearance_change(
    params: BearingParameters, inner_ring_c: float, outer_ring_c: float, balls_c: float, reference_c: float, expansion: float | None = None
) -> float:
    """Change of the diametral clearance P_d (m) when the rings and balls leave the temperature
    ``reference_c`` at which the clearance was set (degC each; add it to
    :attr:`LoadCase.clearance`): each free body grows by alpha dT times its diameter (Harris and
    Kotzalas, *Essential Concepts*, thermal expansion and clearance), so

        dP_d = alpha [(d_m + D_w) dT_outer - (d_m - D_w) dT_inner - 2 D_w dT_balls],

    the outer raceway's diameter growing the clearance, the inner raceway's and the two balls'
    diameters across it taking it up. A spindle's inner ring, warmer than its outer, loses
    clearance (or gains preload). The fits (shaft and housing expanding with their rings) are
    not in it.

    Args:
        expansion: linear expansion coefficient, 1/K (default: bearing steel,
            :data:`bearing_rig_sim.thermal.materials.BEARING_STEEL`; the same for rings and balls).
    """
    alpha = BEARING_STEEL.expansion if expansion is None else float(expansion)
    for name, value in (("inner_ring_c", inner_ring_c), ("outer_ring_c", outer_ring_c), ("balls_c", balls_c), ("reference_c", reference_c)):
        if not math.isfinite(value) or not -60.0 <= value <= 400.0:
            raise LoadDistributionError(f"{name} must be a temperature within -60..400 degC, got {value!r}")
    if not 0.0 <= alpha <= 3e-5:
        raise LoadDistributionError(f"expansion must be within 0..3e-5 1/K, got {expansion!r}")
    dm, dw = params.pitch_diameter, params.ball_diameter
    return alpha * ((dm + dw) * (outer_ring_c - reference_c) - (dm - dw) * (inner_ring_c - reference_c) - 2.0 * dw * (balls_c - reference_c))


@dataclass(frozen=True)
class LoadCase:
    """Loads and fits of one quasi-static problem (SI units).

    Attributes:
        axial_load: F_a, N (> 0 pushes the inner ring into its contacts).
        radial_load: F_r, N, along +x (psi = 0 is the most loaded ball).
        moment: (M_x, M_y), N m, or None: the tilts held at ``misalignment``, moment reported.
        inner_ring_speed: rad/s (0: no centrifugal or gyroscopic term).
        clearance: extra diametral clearance P_d, m (negative: interference fit or preload
            by radial interference).
        axial_preload: rigid axial displacement added to the inner ring's, m.
        misalignment: (theta_x, theta_y) of the inner ring against the outer, rad.
        gyroscopic: include the gyroscopic moment (Jones); the centrifugal force is always in.
    """

    axial_load: float
    radial_load: float = 0.0
    moment: tuple[float, float] | None = None
    inner_ring_speed: float = 0.0
    clearance: float = 0.0
    axial_preload: float = 0.0
    misalignment: tuple[float, float] = (0.0, 0.0)
    gyroscopic: bool = True


@dataclass(frozen=True)
class LoadDistribution:
    """Solution of :func:`solve`.

    Attributes:
        azimuths: psi of each ball, rad.
        inner_loads, outer_loads: Q per ball, N.
        inner_angles, outer_angles: loaded contact angles per ball, rad (of the line through the
            ball centre and the curvature centre, also where the ball does not touch).
        displacement: (delta_a, delta_x, delta_y) of the inner ring, m.
        tilt: (theta_x, theta_y), rad.
        reaction_moment: (M_x, M_y) the balls exert on the inner ring, N m (equal and opposite
            to what holds the tilt when ``moment`` was None).
        orbit_speeds: ball orbit speeds used for the body forces, rad/s.
    """

    azimuths: np.ndarray
    inner_loads: np.ndarray
    outer_loads: np.ndarray
    inner_angles: np.ndarray
    outer_angles: np.ndarray
    displacement: tuple[float, float, float]
    tilt: tuple[float, float]
    reaction_moment: tuple[float, float]
    orbit_speeds: np.ndarray

    @property
    def ball_load_max(self) -> float:
        """Largest contact load of any ball (inner or outer), N."""
        return float(max(self.inner_loads.max(), self.outer_loads.max()))

    @property
    def ball_load_min(self) -> float:
        """Smallest inner contact load of any ball, N (0 outside the load zone)."""
        return float(self.inner_loads.min())

    @property
    def loaded_balls(self) -> int:
        """Balls with an inner contact load, 1."""
        return int(np.count_nonzero(self.inner_loads > 0.0))

    @property
    def contact_angle_at_max_load(self) -> float:
        """Inner contact angle of the most loaded ball, rad."""
        return float(self.inner_angles[int(np.argmax(self.inner_loads))])


class QuasiStaticBearing:
    """The bearing's geometry and Hertz constants for :meth:`solve`."""

    def __init__(self, params: BearingParameters) -> None:
        p = params
        self.z = p.ball_count
        self.dw = p.ball_diameter
        self.dm = p.pitch_diameter
        self.a0 = p.contact_angle
        self.gi = (p.inner_curvature_ratio - 0.5) * p.ball_diameter
        self.go = (p.outer_curvature_ratio - 0.5) * p.ball_diameter
        self.big_a = self.gi + self.go
        self.ri = 0.5 * self.dm + self.gi * math.cos(self.a0)
        inner, outer = p.raceway_contacts()
        self.ki, self.ko = inner.stiffness, outer.stiffness
        self.kn = p.combined_constant
        self.mass = p.ball_density * math.pi * self.dw**3 / 6.0
        self.inertia = p.ball_density * math.pi * self.dw**5 / 60.0
        self.psi = 2.0 * math.pi * np.arange(self.z) / self.z

    # -- one ball ----------------------------------------------------------------------------
    def _speeds(self, omega: float, ai: float, ao: float) -> tuple[float, float, float]:
        """Orbit speed, rolling speed (rad/s) and pitch angle beta of outer-raceway control
        (Harris and Kotzalas) at contact angles ai, ao."""
        g = self.dw / self.dm
        beta = math.atan2(math.sin(ao), math.cos(ao) + g)
        orbit = omega * (1.0 - g * math.cos(ai)) / (1.0 + math.cos(ai - ao))
        tb = math.tan(beta)
        den = (
            ((math.cos(ao) + tb * math.sin(ao)) / (1.0 + g * math.cos(ao)) + (math.cos(ai) + tb * math.sin(ai)) / (1.0 - g * math.cos(ai))) * g * math.cos(beta)
        )
        return orbit, omega / den, beta

    def _ball(self, a1: float, a2: float, omega: float, gyro: bool, x0: np.ndarray | None) -> tuple[float, float, float, float, float, np.ndarray]:
        """Contact loads and angles (Q_i, Q_o, a_i, a_o), orbit speed and the ball centre
        (X1, X2) for curvature-centre offsets a1 (axial) and a2 (radial), m."""
        if omega == 0.0:
            d = math.hypot(a1, a2)
            q = self.kn * (d - self.big_a) ** 1.5 if d > self.big_a else 0.0
            a = math.atan2(a1, a2)
            x = np.array([self.go * math.sin(a), self.go * math.cos(a)])
            return q, q, a, a, 0.0, x
        d = math.hypot(a1, a2)
        ai = ao = math.atan2(a1, a2)
        if x0 is None:  # the static position: on the centre line, the approach split by Hertz
            q = self.kn * max(d - self.big_a, 0.0) ** 1.5
            reach = self.go + (q / self.ko) ** (2.0 / 3.0)
            x0 = np.array([reach * math.sin(ai), reach * math.cos(ai)])
        x = x0.copy()
        for _ in range(3):  # speeds depend on the angles
            orbit, roll, beta = self._speeds(omega, ai, ao)
            fc = 0.5 * self.mass * self.dm * orbit * orbit
            # Outside the load zone: the ball rests on the outer raceway under F_c alone (at
            # a_o = 0; no inner contact to carry a gyroscopic moment by friction).
            rest = self.go + (fc / self.ko) ** (2.0 / 3.0)
            if d <= self.big_a or math.hypot(a1, a2 - rest) <= self.gi:
                return 0.0, fc, math.atan2(a1, a2 - rest), 0.0, orbit, np.array([0.0, rest])
            mg = self.inertia * roll * orbit * math.sin(beta) if gyro else 0.0

            def residual(v: np.ndarray, fc: float = fc, mg: float = mg) -> np.ndarray:
                qi, qo, si, ci, so, co = self._contacts(a1, a2, v)
                return np.array([qi * si - qo * so + 2.0 * mg * co / self.dw, qi * ci - qo * co - 2.0 * mg * so / self.dw + fc])

            sol = root(residual, x, method="hybr", options={"xtol": 1e-13})
            if not sol.success and np.max(np.abs(residual(sol.x))) > 1e-6 * max(fc, 1.0):
                raise LoadDistributionError(f"ball equilibrium not found at offsets ({a1:.4g}, {a2:.4g}) m: {sol.message}")
            x = sol.x
            qi, qo, si, ci, so, co = self._contacts(a1, a2, x)
            ai, ao = math.atan2(si, ci), math.atan2(so, co)
        return qi, qo, ai, ao, orbit, x

    def _contacts(self, a1: float, a2: float, x: np.ndarray) -> tuple[float, float, float, float, float, float]:
        """Q_i, Q_o and the sines/cosines of a_i, a_o for the ball centre x = (X1, X2)."""
        do = math.hypot(x[0], x[1])
        di = math.hypot(a1 - x[0], a2 - x[1])
        qo = self.ko * (do - self.go) ** 1.5 if do > self.go else 0.0
        qi = self.ki * (di - self.gi) ** 1.5 if di > self.gi else 0.0
        return qi, qo, (a1 - x[0]) / di, (a2 - x[1]) / di, x[0] / do, x[1] / do

    # -- the ring ----------------------------------------------------------------------------
    def _balls(self, u: np.ndarray, case: LoadCase, centres: list[np.ndarray | None]) -> tuple[np.ndarray, ...]:
        da, dx, dy, tx, ty = u
        z = self.z
        qi, qo, ai, ao, wm = (np.zeros(z) for _ in range(5))
        for j in range(z):
            c, s = math.cos(self.psi[j]), math.sin(self.psi[j])
            a1 = self.big_a * math.sin(self.a0) + da + case.axial_preload + self.ri * (tx * c + ty * s)
            a2 = self.big_a * math.cos(self.a0) + dx * c + dy * s - 0.5 * case.clearance
            qi[j], qo[j], ai[j], ao[j], wm[j], centres[j] = self._ball(a1, a2, case.inner_ring_speed, case.gyroscopic, centres[j])
        return qi, qo, ai, ao, wm

    def _ring_forces(self, qi: np.ndarray, ai: np.ndarray) -> np.ndarray:
        c, s = np.cos(self.psi), np.sin(self.psi)
        fa = qi * np.sin(ai)
        fr = qi * np.cos(ai)
        return np.array([fa.sum(), (fr * c).sum(), (fr * s).sum(), (fa * self.ri * c).sum(), (fa * self.ri * s).sum()])

    def solve(self, case: LoadCase) -> LoadDistribution:
        """The inner ring's equilibrium under ``case``.

        Raises:
            LoadDistributionError: a non-finite or out-of-range input, or no equilibrium found.
        """
        for name in ("axial_load", "radial_load", "inner_ring_speed", "clearance", "axial_preload"):
            if not math.isfinite(getattr(case, name)):
                raise LoadDistributionError(f"{name} must be finite, got {getattr(case, name)!r}")
        if case.axial_load <= 0.0 and case.axial_preload <= 0.0:
            raise LoadDistributionError(f"axial_load must be > 0 N for a single angular contact bearing, got {case.axial_load!r}")
        if case.inner_ring_speed < 0.0:
            raise LoadDistributionError(f"inner_ring_speed must be >= 0 rad/s, got {case.inner_ring_speed!r}")
        held = case.moment is None
        target = np.array([case.axial_load, case.radial_load, 0.0, *(case.moment or (0.0, 0.0))])
        free = [0, 1, 2] if held else [0, 1, 2, 3, 4]
        u = np.array([0.0, 0.0, 0.0, *case.misalignment])
        # Start: the thrust-only approach for F_a/(Z sin a0) at each ball, plus the radial share.
        q0 = max(case.axial_load, 1.0) / (self.z * math.sin(self.a0))
        u[0] = (q0 / self.kn) ** (2.0 / 3.0) / math.sin(self.a0)
        u[1] = 2.0 * (max(abs(case.radial_load), 1.0) / (self.z * self.kn)) ** (2.0 / 3.0) * math.copysign(1.0, case.radial_load)
        scale_x = 1e-6  # unknowns in micrometres / microradians x R_i
        scale_f = max(abs(case.axial_load), abs(case.radial_load), 1.0)
        centres: list[np.ndarray | None] = [None] * self.z
        lengths = np.array([1.0, 1.0, 1.0, 1.0 / self.ri, 1.0 / self.ri])

        def residual(v: np.ndarray) -> np.ndarray:
            w = u.copy()
            w[free] = v * scale_x * lengths[free]
            qi, _, ai, _, _ = self._balls(w, case, centres)
            f = self._ring_forces(qi, ai) - target
            f[3:] /= self.ri
            return f[free] / scale_f

        sol = root(residual, u[free] / (scale_x * lengths[free]), method="hybr", options={"xtol": 1e-12})
        if np.max(np.abs(residual(sol.x))) > 1e-8:
            raise LoadDistributionError(f"no quasi-static equilibrium found for {case}: {sol.message}")
        u[free] = sol.x * scale_x * lengths[free]
        qi, qo, ai, ao, wm = self._balls(u, case, centres)
        forces = self._ring_forces(qi, ai)
        return LoadDistribution(
            azimuths=self.psi.copy(),
            inner_loads=qi,
            outer_loads=qo,
            inner_angles=ai,
            outer_angles=ao,
            displacement=(float(u[0]), float(u[1]), float(u[2])),
            tilt=(float(u[3]), float(u[4])),
            reaction_moment=(float(forces[3]), float(forces[4])),
            orbit_speeds=wm,
        )


def solve(params: BearingParameters, case: LoadCase) -> LoadDistribution:
    """Quasi-static load distribution of the bearing ``params`` under ``case``."""
    return QuasiStaticBearing(params).solve(case)
