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
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import root

from bearing_rig_sim.dynamics.ball_balance import BallBalance, LoadDistributionError
from bearing_rig_sim.dynamics.parameters import BearingParameters
from bearing_rig_sim.bearing.materials import BEARING_STEEL


METHOD_NEWTON = "newton"
"""Newton (Powell's hybrid method) from the thrust-only start converged."""
METHOD_SPEED_CONTINUATION = "speed continuation"
"""Found by continuation in speed from rest (Newton from the start and continuation in load failed)."""
METHOD_LOAD_CONTINUATION = "load continuation"
"""Found by continuation in the radial load and moment from the axial load alone."""
_CONTINUATION_STEPS = 8
"""First step of a continuation path: this fraction of the way (in load; in the square of speed)."""
_MIN_STEP = 1.0 / 1024.0
"""Smallest step of a continuation path, fraction of the way."""
_RING_TOL = 1e-8
"""The ring's balance: largest unbalanced load relative to the largest applied one."""


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
            :data:`bearing_rig_sim.bearing.materials.BEARING_STEEL`; the same for rings and balls).
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
        load_zone: per ball, whether the ring presses it (its curvature centres farther apart
            than A); at rest exactly the balls with a load.
        method: how it was found: :data:`METHOD_NEWTON` from the thrust start, or after
            :data:`METHOD_SPEED_CONTINUATION` or :data:`METHOD_LOAD_CONTINUATION`.
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
    load_zone: np.ndarray
    method: str = METHOD_NEWTON

    @property
    def ball_load_max(self) -> float:
        """Largest contact load of any ball (inner or outer), N."""
        return float(max(self.inner_loads.max(), self.outer_loads.max()))

    @property
    def ball_load_min(self) -> float:
        """Smallest inner contact load of any ball, N (0 outside the load zone at rest; at speed
        a ball there is wedged by its centrifugal force, with loads of the order of F_c)."""
        return float(self.inner_loads.min())

    @property
    def loaded_balls(self) -> int:
        """Balls in the load zone (the ring presses them: their curvature centres farther apart
        than A), 1."""
        return int(np.count_nonzero(self.load_zone))

    @property
    def contact_angle_at_max_load(self) -> float:
        """Inner contact angle of the most loaded ball, rad."""
        return float(self.inner_angles[int(np.argmax(self.inner_loads))])


class QuasiStaticBearing(BallBalance):
    """The bearing's geometry and Hertz constants for :meth:`solve` (each ball's balance:
    :class:`~.ball_balance.BallBalance`)."""

    def __init__(self, params: BearingParameters) -> None:
        super().__init__(params)
        self.ri = 0.5 * self.dm + self.gi * math.cos(self.a0)
        self.psi = 2.0 * math.pi * np.arange(self.z) / self.z

    # -- the ring ----------------------------------------------------------------------------
    def _offsets(self, u: np.ndarray, case: LoadCase) -> tuple[np.ndarray, np.ndarray]:
        """Each ball's curvature-centre offsets (A1_j, A2_j), m, under the ring's displacements ``u``."""
        c, s = np.cos(self.psi), np.sin(self.psi)
        a1 = self.big_a * math.sin(self.a0) + u[0] + case.axial_preload + self.ri * (u[3] * c + u[4] * s)
        a2 = self.big_a * math.cos(self.a0) + u[1] * c + u[2] * s - 0.5 * case.clearance
        return a1, a2

    def _balls(self, u: np.ndarray, case: LoadCase, centres: list[np.ndarray | None]) -> tuple[np.ndarray, ...]:
        qi, qo, ai, ao, wm = (np.zeros(self.z) for _ in range(5))
        a1, a2 = self._offsets(u, case)
        for j in range(self.z):
            qi[j], qo[j], ai[j], ao[j], wm[j], centres[j] = self._ball(float(a1[j]), float(a2[j]), case.inner_ring_speed, case.gyroscopic, centres[j])
        return qi, qo, ai, ao, wm

    def _load_zone(self, u: np.ndarray, case: LoadCase) -> np.ndarray:
        """Per ball: its curvature centres farther apart than A under the ring's displacements ``u``."""
        a1, a2 = self._offsets(u, case)
        return np.asarray(np.hypot(a1, a2) > self.big_a)

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
        for name in ("moment", "misalignment"):
            value = getattr(case, name)
            if value is not None and not all(math.isfinite(v) for v in value):
                raise LoadDistributionError(f"{name} must be finite, got {value!r}")
        centres: list[np.ndarray | None] = [None] * self.z
        u, unbalanced, message = self._equilibrium(case, self._start(case), centres)
        method = METHOD_NEWTON
        if unbalanced > _RING_TOL:
            u, unbalanced, method, message = self._continuation(case, centres)
        if unbalanced > _RING_TOL:
            raise LoadDistributionError(
                f"no quasi-static equilibrium found for {case}: the closest state leaves {unbalanced:.3g} of the largest applied load "
                f"unbalanced after Newton, continuation in speed and continuation in load ({message})"
            )
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
            load_zone=self._load_zone(u, case),
            method=method,
        )

    def _start(self, case: LoadCase) -> np.ndarray:
        """Newton's start: the thrust-only approach for F_a/(Z sin a0) at each ball, plus the
        radial share (m, m, m, rad, rad)."""
        u = np.array([0.0, 0.0, 0.0, *case.misalignment])
        q0 = max(case.axial_load, 1.0) / (self.z * math.sin(self.a0))
        u[0] = (q0 / self.kn) ** (2.0 / 3.0) / math.sin(self.a0)
        u[1] = 2.0 * (max(abs(case.radial_load), 1.0) / (self.z * self.kn)) ** (2.0 / 3.0) * math.copysign(1.0, case.radial_load)
        return u

    def _equilibrium(self, case: LoadCase, start: np.ndarray, centres: list[np.ndarray | None]) -> tuple[np.ndarray, float, str]:
        """Powell's hybrid method on the ring's free displacements from ``start``: the
        displacements, the largest unbalanced load relative to the largest applied one (forces
        in N, moments over R_i), and the solver's message. A ball whose balance fails counts as
        unbalanced (inf)."""
        held = case.moment is None
        target = np.array([case.axial_load, case.radial_load, 0.0, *(case.moment or (0.0, 0.0))])
        free = [0, 1, 2] if held else [0, 1, 2, 3, 4]
        u = start.copy()
        scale_x = 1e-6  # unknowns in micrometres / microradians x R_i
        scale_f = max(abs(case.axial_load), abs(case.radial_load), *(abs(m) / self.ri for m in case.moment or ()), 1.0)
        lengths = np.array([1.0, 1.0, 1.0, 1.0 / self.ri, 1.0 / self.ri])

        def residual(v: np.ndarray) -> np.ndarray:
            w = u.copy()
            w[free] = v * scale_x * lengths[free]
            qi, _, ai, _, _ = self._balls(w, case, centres)
            f = self._ring_forces(qi, ai) - target
            f[3:] /= self.ri
            return np.asarray(f[free] / scale_f)

        def jacobian(v: np.ndarray) -> np.ndarray:
            # forward differences with a step of 1e-6 um (or of 1e-6 relative): MINPACK's own
            # step is relative to the unknown, next to nothing for a displacement that a
            # symmetric load leaves at 1e-20 m, where its Jacobian column vanishes
            f0 = residual(v)
            jac = np.empty((f0.size, v.size))
            for k in range(v.size):
                w = v.copy()
                w[k] += 1e-6 * max(1.0, abs(v[k]))
                jac[:, k] = (residual(w) - f0) / (w[k] - v[k])
            return jac

        try:
            sol = root(residual, u[free] / (scale_x * lengths[free]), jac=jacobian, method="hybr", options={"xtol": 1e-12})
            unbalanced = float(np.max(np.abs(residual(sol.x))))
        except LoadDistributionError as exc:
            return start, math.inf, str(exc)
        u[free] = sol.x * scale_x * lengths[free]
        return u, unbalanced, str(sol.message)

    def _continuation(self, case: LoadCase, centres: list[np.ndarray | None]) -> tuple[np.ndarray, float, str, str]:
        """The fallbacks where Newton fails from its start, each step started from the last
        one's solution: continuation in load (from the axial load alone, the radial load and
        moment growing to the case's) at the case's speed; then continuation in speed from
        rest (no body force; the rest point itself found directly or by continuation in load)
        up to the case's speed. Returns (displacements, unbalance, method, message)."""
        u, unbalanced, message = self._load_path(case, centres)
        if unbalanced <= _RING_TOL:
            return u, unbalanced, METHOD_LOAD_CONTINUATION, message
        if case.inner_ring_speed > 0.0:
            rest = replace(case, inner_ring_speed=0.0)
            u, unbalanced, message = self._equilibrium(rest, self._start(rest), centres)
            if unbalanced > _RING_TOL:
                u, unbalanced, message = self._load_path(rest, centres)
            if unbalanced <= _RING_TOL:  # F_c grows as the square of the speed: steps in its square
                u, unbalanced, message = self._path(lambda f: replace(case, inner_ring_speed=case.inner_ring_speed * math.sqrt(f)), u, centres)
                if unbalanced <= _RING_TOL:
                    return u, unbalanced, METHOD_SPEED_CONTINUATION, message
        return u, unbalanced, "", message

    def _load_path(self, case: LoadCase, centres: list[np.ndarray | None]) -> tuple[np.ndarray, float, str]:
        """Continuation from the axial load alone to ``case``'s radial load and moment:
        (displacements, unbalance, message) of the last step reached."""
        if case.radial_load == 0.0 and case.moment is None:
            return self._start(case), math.inf, "no radial load or moment to continue in"

        def scaled(f: float) -> LoadCase:
            moment = None if case.moment is None else (case.moment[0] * f, case.moment[1] * f)
            return replace(case, radial_load=case.radial_load * f, moment=moment)

        u, unbalanced, message = self._equilibrium(scaled(0.0), self._start(case), centres)
        if unbalanced > _RING_TOL:
            return u, unbalanced, message
        return self._path(scaled, u, centres)

    def _path(self, case_at: Callable[[float], LoadCase], u: np.ndarray, centres: list[np.ndarray | None]) -> tuple[np.ndarray, float, str]:
        """Continuation along ``case_at(f)`` from f = 0 (solved: ``u``) to f = 1, the step
        halved where Newton fails from the last solution (down to :data:`_MIN_STEP`) and
        doubled after a success: (displacements, unbalance, message) of the last step reached."""
        f, step, unbalanced, message = 0.0, 1.0 / _CONTINUATION_STEPS, 0.0, ""
        while f < 1.0:
            trial = min(f + step, 1.0)
            w, unbalanced, message = self._equilibrium(case_at(trial), u, centres)
            if unbalanced <= _RING_TOL:
                f, u, step = trial, w, 2.0 * step
            elif step > _MIN_STEP:
                step *= 0.5
            else:
                return u, unbalanced, f"continuation stopped at {f:.4g} of the way: {message}"
        return u, unbalanced, message


def solve(params: BearingParameters, case: LoadCase) -> LoadDistribution:
    """Quasi-static load distribution of the bearing ``params`` under ``case``."""
    return QuasiStaticBearing(params).solve(case)
