"""One ball between the raceways of an angular contact ball bearing: Jones' balance at speed.

The ball's two normal contacts follow from its centre and the two groove curvature centres (the
outer one fixed, the inner one offset by (a1, a2) in the ball's azimuthal plane); at speed the
centrifugal force and the gyroscopic moment, carried by the outer contact's friction
(outer-raceway control), enter its balance (Jones 1960; Harris and Kotzalas, *Rolling Bearing
Analysis*, 5th ed., vol. 2, ch. 3). :mod:`.quasi_static` balances the inner ring on these balls;
:func:`thrust_contact_angles` solves one ball of a thrust-loaded bearing for a given inner
contact load and entrainment speed, the angles the traction table takes its spin from
(:mod:`.traction`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Protocol

import numpy as np
from scipy.optimize import root

from bearing_rig_sim.bearing.hertz import HertzContact
from bearing_rig_sim.errors import RigError


class LoadDistributionError(RigError):
    """The quasi-static equilibrium could not be found (or a bad input)."""


GYROSCOPIC_FRICTION = 0.1
"""Friction coefficient, 1, bounding the gyroscopic moment a ball's contacts can hold:
M <= mu Q_i Dw / 2 (the couple of two opposed tangential forces at the raceways, the inner
contact the weaker; the usual estimate of Harris and Kotzalas, high-speed operation: about
7 mN m at 100 N here against M_g of 1.25 mN m at 9000 rpm). Above it the ball pivots and the
contacts hold only that much; a ball that barely touches the inner raceway holds next to none,
so the load passes continuously from the loaded balls to those resting on the outer raceway.
Range 0.05-0.15 (lubricated to boundary)."""
_ANGLE_ITERATIONS = 12
"""Fixed-point passes of a ball's speeds on its contact angles (they settle to 1e-12 rad in 3-5)."""
_ANGLE_TOL = 1e-12
"""rad: the contact angles' change below which a ball's speeds are taken as settled."""


class BallGeometry(Protocol):
    """What a ball's balance reads of a bearing (SI units; :class:`~.parameters.BearingParameters` has it)."""

    @property
    def ball_count(self) -> int: ...
    @property
    def ball_diameter(self) -> float: ...
    @property
    def pitch_diameter(self) -> float: ...
    @property
    def contact_angle(self) -> float: ...
    @property
    def inner_curvature_ratio(self) -> float: ...
    @property
    def outer_curvature_ratio(self) -> float: ...
    @property
    def ball_density(self) -> float: ...
    @property
    def combined_constant(self) -> float: ...
    def raceway_contacts(self) -> tuple[HertzContact, HertzContact]: ...


class BallBalance:
    """A ball of the bearing ``geometry`` between its raceways: geometry, Hertz constants and
    inertia for its balance (:meth:`_ball`)."""

    def __init__(self, geometry: BallGeometry) -> None:
        p = geometry
        self.z = p.ball_count
        self.dw = p.ball_diameter
        self.dm = p.pitch_diameter
        self.a0 = p.contact_angle
        self.gi = (p.inner_curvature_ratio - 0.5) * p.ball_diameter
        self.go = (p.outer_curvature_ratio - 0.5) * p.ball_diameter
        self.big_a = self.gi + self.go
        inner, outer = p.raceway_contacts()
        self.ki, self.ko = inner.stiffness, outer.stiffness
        self.kn = p.combined_constant
        self.mass = p.ball_density * math.pi * self.dw**3 / 6.0
        self.inertia = p.ball_density * math.pi * self.dw**5 / 60.0

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
        # Resting on the outer raceway under F_c alone (a_o = 0), its speeds at its own angles.
        ai_rest = math.atan2(a1, a2 - self.go)
        for _ in range(_ANGLE_ITERATIONS):
            orbit, _, _ = self._speeds(omega, ai_rest, 0.0)
            fc = 0.5 * self.mass * self.dm * orbit * orbit
            rest = self.go + (fc / self.ko) ** (2.0 / 3.0)
            previous, ai_rest = ai_rest, math.atan2(a1, a2 - rest)
            if abs(ai_rest - previous) < _ANGLE_TOL:
                break
        if math.hypot(a1, a2 - rest) <= self.gi:  # the inner raceway out of reach
            return 0.0, fc, ai_rest, 0.0, orbit, np.array([0.0, rest])
        # Both contacts: wedged between the raceways (the curvature centres closer than A, the
        # loads of the order of F_c) or loaded by the ring.
        d = math.hypot(a1, a2)
        # starts: the last solution, on the centre line with the approach split by Hertz, and on
        # the outer raceway where it meets the inner one nearest a_o = 0 (where F_c pushes it)
        reach = self.go + ((self.kn * max(d - self.big_a, 0.0) ** 1.5) / self.ko) ** (2.0 / 3.0)
        starts = [np.array([reach * a1 / d, reach * a2 / d]), self._wedge(a1, a2, rest)]
        if d <= self.big_a:
            starts.reverse()
        if x0 is not None:
            starts.insert(0, x0)
        x = starts[0]
        ai, ao = math.atan2(a1 - x[0], a2 - x[1]), math.atan2(x[0], x[1])
        for _ in range(_ANGLE_ITERATIONS):  # the speeds depend on the angles
            orbit, roll, beta = self._speeds(omega, ai, ao)
            fc = 0.5 * self.mass * self.dm * orbit * orbit
            mg = self.inertia * roll * orbit * math.sin(beta) if gyro else 0.0

            def residual(v: np.ndarray, fc: float = fc, mg: float = mg) -> np.ndarray:
                qi, qo, si, ci, so, co = self._contacts(a1, a2, v)
                held = math.copysign(min(abs(mg), GYROSCOPIC_FRICTION * qi * 0.5 * self.dw), mg)
                return np.array([qi * si - qo * so + 2.0 * held * co / self.dw, qi * ci - qo * co - 2.0 * held * so / self.dw + fc])

            x = self._ball_root(residual, [x, *starts[1:]], fc, a1, a2)
            qi, qo, si, ci, so, co = self._contacts(a1, a2, x)
            change = max(abs(math.atan2(si, ci) - ai), abs(math.atan2(so, co) - ao))
            ai, ao = math.atan2(si, ci), math.atan2(so, co)
            if change < _ANGLE_TOL:
                break
        return qi, qo, ai, ao, orbit, x

    def _ball_root(self, residual: Callable[[np.ndarray], np.ndarray], starts: list[np.ndarray], fc: float, a1: float, a2: float) -> np.ndarray:
        """The ball centre where ``residual`` (N) vanishes, from the first start that converges
        (to 1e-9 of the largest of F_c, the contact loads and 1 N; Powell's hybrid method, then
        Levenberg-Marquardt)."""
        message = ""
        for method in ("hybr", "lm"):
            for start in starts:
                sol = root(residual, start, method=method, options={"xtol": 1e-13})
                if not np.all(np.isfinite(sol.x)):
                    continue
                qi, qo, *_ = self._contacts(a1, a2, sol.x)
                if np.max(np.abs(residual(sol.x))) <= 1e-9 * max(fc, qi, qo, 1.0):
                    return np.asarray(sol.x, dtype=float)
                message = str(sol.message)
        raise LoadDistributionError(f"ball equilibrium not found at curvature-centre offsets ({a1:.4g}, {a2:.4g}) m: {message}")

    def _wedge(self, a1: float, a2: float, reach: float) -> np.ndarray:
        """Where the circle of radius ``reach`` about the outer curvature centre meets the
        circle of radius (f_i - 1/2) Dw about the inner one (a1, a2), on the side of the smaller
        outer contact angle in magnitude, further out radially where F_c pushes the ball (m)."""
        d = math.hypot(a1, a2)
        along = (d * d + reach * reach - self.gi * self.gi) / (2.0 * d)
        across = math.sqrt(max(reach * reach - along * along, 0.0))
        ux, uy = a1 / d, a2 / d
        # of the two points along * u +- across * (-uy, ux), the one further out radially
        side = 1.0 if ux >= 0.0 else -1.0
        return np.array([along * ux - side * across * uy, along * uy + side * across * ux])

    def _contacts(self, a1: float, a2: float, x: np.ndarray) -> tuple[float, float, float, float, float, float]:
        """Q_i, Q_o and the sines/cosines of a_i, a_o for the ball centre x = (X1, X2)."""
        do = math.hypot(x[0], x[1])
        di = math.hypot(a1 - x[0], a2 - x[1])
        qo = self.ko * (do - self.go) ** 1.5 if do > self.go else 0.0
        qi = self.ki * (di - self.gi) ** 1.5 if di > self.gi else 0.0
        return qi, qo, (a1 - x[0]) / di, (a2 - x[1]) / di, x[0] / do, x[1] / do


def thrust_contact_angles(ball: BallGeometry, loads: np.ndarray, speeds: np.ndarray) -> np.ndarray:
    """The contact angles (alpha_i, alpha_o), rad, of a ball of a thrust-loaded bearing whose
    inner contact carries each of ``loads`` (N) at each inner-contact entrainment speed of
    ``speeds`` (m/s, ascending), shape (len(loads), len(speeds), 2): Jones' ball balance
    (centrifugal force and gyroscopic moment, outer-raceway control; module doc) with no
    clearance, solved for the axial offset and the shaft speed that give that load and that
    entrainment speed, (omega_i - omega_m)(d_m/2 - D_w cos(alpha_i)/2).

    At rest both angles are the thrust angle of the load; with speed the centrifugal force opens
    them apart (alpha_i grows, alpha_o falls). The traction table takes its spin from them
    (:func:`.traction.build_table`). A node whose balance is not found (a load too small to hold
    the ball against its centrifugal force at that speed, far outside a bearing's operating range)
    keeps the angles of the node below it in speed.
    """
    b = BallBalance(ball)
    a2 = b.big_a * math.cos(b.a0)
    rm, r = 0.5 * b.dm, 0.5 * b.dw
    out = np.empty((len(loads), len(speeds), 2))
    for iq, q in enumerate(np.asarray(loads, dtype=float)):
        d_rest = b.big_a + (q / b.kn) ** (2.0 / 3.0)
        a1 = math.sqrt(max(d_rest * d_rest - a2 * a2, 0.0))
        alpha = math.atan2(a1, a2)
        angles = (alpha, alpha)
        omega = 0.0
        centre: np.ndarray | None = None
        for iu, u in enumerate(np.asarray(speeds, dtype=float)):
            if omega == 0.0:  # the first speed: the rolling kinematics at the rest angle
                orbit_ratio = b._speeds(1.0, alpha, alpha)[0]
                omega = u / ((1.0 - orbit_ratio) * (rm - r * math.cos(alpha)))
            else:
                omega *= u / float(speeds[iu - 1])

            def balance(
                v: np.ndarray, q: float = q, u: float = u, omega: float = omega, centre: np.ndarray | None = centre
            ) -> tuple[np.ndarray, tuple[float, float], np.ndarray]:
                """Relative misfits of the inner load and the entrainment speed at the axial
                offset v[0] A and the shaft speed v[1] omega; the angles and the ball centre."""
                qi, _, ai, ao, orbit, x = b._ball(v[0] * b.big_a, a2, v[1] * omega, True, centre)
                entrainment = (v[1] * omega - orbit) * (rm - r * math.cos(ai))
                return np.array([qi / q - 1.0, entrainment / u - 1.0]), (ai, ao), x

            try:
                with np.errstate(all="ignore"):  # trial points of the root finder that fling the ball off
                    sol = root(lambda v: balance(v)[0], np.array([a1 / b.big_a, 1.0]), method="hybr", options={"xtol": 1e-12})
                    misfit, found, x = balance(sol.x)
                if sol.success and float(np.max(np.abs(misfit))) < 1e-8:
                    a1, omega = float(sol.x[0]) * b.big_a, float(sol.x[1]) * omega
                    angles, centre = found, x
            except LoadDistributionError:
                pass
            out[iq, iu] = angles
    return out
