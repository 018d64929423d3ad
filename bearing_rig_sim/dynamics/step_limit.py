"""The largest stable integration step of each model, from the bearing's own time scales.

The step is checked against the rig's operating envelope (:class:`OperatingEnvelope`: the
spindle's top speed and the largest axial load, ``config/rig.yaml``): the contact loads at the
envelope's corners come from the engine's own quasi-static solution (thrust equilibrium with
centrifugal force), so the limit follows the bearing, its lubricant and the rig.

* **Stiff model** (explicit symplectic Euler, dynamic Hertz contacts). The fastest mode is a
  ball between its two raceways: normal stiffness k = dQ/d delta = 1.5 K^(2/3) Q^(1/3) at each
  contact, the two in parallel on the ball's mass m, omega = sqrt((k_i + k_o)/m), with the
  Hunt-Crossley damping c = 1.5 a_e K delta^n of both contacts (damping ratio
  zeta = c/(2 m omega)). Symplectic Euler on x'' + 2 zeta omega x' + omega^2 x = 0 has the
  amplification matrix [[1 - 2 zeta omega h, -omega^2 h], [h (1 - 2 zeta omega h),
  1 - omega^2 h^2]] (trace 2 - 2 zeta omega h - omega^2 h^2, determinant 1 - 2 zeta omega h);
  the Jury conditions give h < 2 (sqrt(1 + zeta^2) - zeta) / omega. The cage rim's highest
  mode (adjacent segments in antiphase, omega = 2 sqrt(k_t/J_seg)) is checked the same way.
  Safety fraction 1/2: Hertz stiffness grows as Q^(1/3), so the limit holds for impacts up to
  2^6 = 64 times the largest quasi-static contact load.
* **Reduced model** (quasi-static normal contacts, linearly implicit Euler on ball orbit, spin
  and cage). Every velocity-dependent force (raceway tractions, ball drag, rolling-resistance
  moments, cage land torque) enters the step's Jacobian with a slope at least its secant
  through zero (:func:`.kernels.implicit_slope`), and the pocket contact, the rim and the cage
  centre's land film and contact (time constants down to a microsecond) with their tangent
  stiffness and damping: linearised, the step is A-stable, and a saturated traction
  cannot carry a sliding speed across zero in one step. What stays explicit over a step is the
  contact state, solved at its start: the normal loads depend on the ball's orbit speed through
  the centrifugal force m omega_m^2 r_b. A unit of orbit speed changes it by 2 m omega_m r_b
  and the outer load by at most that much (the ball's force balance), the outer traction by mu
  times it, acting on the orbit with lever r_b and on the spin with lever r cos(alpha_o - beta):
  a rank-one explicit coupling whose only eigenvalue, against the orbit inertia m r_b^2, is
  lambda = 2 mu omega_m. Explicit Euler keeps it stable for h < 2 / lambda, so the limit is
  h < 1 / (mu_max omega_m), mu_max the traction law's largest coefficient
  (:func:`traction_bound`) and omega_m the fastest ball orbit of the envelope. The dependence
  of the traction on the entrainment speed is frozen too; it is the slide-to-roll ratio times
  the implicit sliding slope (mu(SRR) with SRR = s/u_e), so below SRR = 1 it cannot
  destabilise the step (|1 - h b| <= 1 + h a for b <= a). The ball's pivot and pitch
  (gyroscopic) add nothing to the limit: the transverse tractions and the spin moments' change
  enter with their secant slopes (implicit), the gyroscopic terms are skew and taken
  trapezoidally with coefficients frozen over the step (J omega_m sin(beta) and
  J omega_m cos(beta): h omega_m < 5e-3 at the envelope's top), and the explicit dependences,
  of the transverse slope on the rolling sliding and of the spin moments on the raceway-control
  spins, run one way (the rolling traction depends on neither the pivot nor the pitch), a
  triangular coupling that cannot grow.
  docs/model.md, Integration.

A step above the limit is refused at engine construction (:class:`StepLimitError`, one line
naming the file key, the value, the limit and the mechanism).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.traction import mu_nodes
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.loading import LoadingChainConfig
from bearing_rig_sim.rig.spindle import SpindleConfig

STIFF_SAFETY = 0.5
"""Fraction of the stiff model's linear stability limit allowed (see the module docstring)."""

SPEED_FRACTIONS = (0.05, 0.1, 0.15, 0.25, 0.5, 0.75, 1.0)
"""Spindle speeds (fractions of the envelope's top speed) at which the limits are evaluated,
all at the envelope's largest axial load; the smallest limit counts."""


class StepLimitError(RigError):
    """An integration step above the model's stability limit."""


@dataclass(frozen=True)
class OperatingEnvelope:
    """The largest spindle speed (rad/s) and axial load (N) the rig can impose."""

    max_inner_ring_speed: float
    max_axial_load: float

    @classmethod
    def from_rig_file(cls, path: str | Path | None = None) -> OperatingEnvelope:
        """``spindle.max_speed_rad_s`` and ``loading_chain.max_setpoint_n`` of a rig file
        (default: the shipped ``config/rig.yaml``)."""
        return cls(SpindleConfig.from_yaml(path).max_speed_rad_s, LoadingChainConfig.from_yaml(path).max_setpoint_n)


@dataclass(frozen=True)
class StepLimit:
    """A model's largest allowed step and why.

    Attributes:
        model: ``"reduced"`` or ``"stiff"``.
        limit: largest allowed step (the safety fraction applied), s.
        mechanism: what sets it, with the operating point, for the error message.
    """

    model: str
    limit: float
    mechanism: str


@dataclass(frozen=True)
class ContactState:
    """One ball's raceway contacts at an operating point (from the quasi-static solution).

    Loads N, lever factors cos(alpha - beta) on the spin (1), entrainment speeds m/s,
    penetrations m, the ball's orbit speed rad/s."""

    inner_load: float
    outer_load: float
    inner_lever: float
    outer_lever: float
    inner_entrainment: float
    outer_entrainment: float
    inner_penetration: float
    outer_penetration: float
    orbit_speed: float = 0.0


def contact_state(p: np.ndarray, ball: np.ndarray, ring: np.ndarray, geo: np.ndarray) -> ContactState:
    """The most loaded ball's contacts after a quasi-static solution (``geo`` as left by
    :func:`.kernels.solve_quasi_static`, balls at their rolling speeds)."""
    j = int(np.argmax(geo[:, kn.G_QI] + geo[:, kn.G_QO]))
    rb = ball[j, kn.B_R]
    nir, niz, nor, noz = geo[j, kn.G_NIR], geo[j, kn.G_NIZ], geo[j, kn.G_NOR], geo[j, kn.G_NOZ]
    r_ci, r_co, ci, co, *_ = kn.ball_kinematics(p, nir, niz, nor, noz, rb)
    wm = ball[j, kn.B_OMEGA]
    return ContactState(
        float(geo[j, kn.G_QI]),
        float(geo[j, kn.G_QO]),
        float(ci),
        float(co),
        float(abs((ring[kn.R_OMEGA] - wm) * r_ci)),
        float(abs(wm * r_co)),
        float(geo[j, kn.G_DI]),
        float(geo[j, kn.G_DO]),
        float(abs(wm)),
    )


def traction_bound(p: np.ndarray) -> float:
    """The largest traction coefficient the engine's law can give (1): the rheology table's
    largest |mu| (its interpolation is a convex combination of its nodes), the EHL law's
    mu_max, or the stepped Coulomb law's larger of mu_s and mu_d."""
    model = p[kn.P_FRIC_MODEL]
    if model == 2.0:
        return float(np.max(np.abs(mu_nodes(p, int(p[kn.P_TABLE])))))
    if model == 1.0:
        return float(abs(p[kn.P_EHL_MU]))
    return float(max(abs(p[kn.P_MU_S]), abs(p[kn.P_MU_D])))


def symplectic_euler_limit(omega: float, zeta: float) -> float:
    """Largest step (s) of symplectic Euler on a damped oscillator of natural frequency
    ``omega`` (rad/s) and damping ratio ``zeta``: 2 (sqrt(1 + zeta^2) - zeta) / omega."""
    return 2.0 * (math.sqrt(1.0 + zeta * zeta) - zeta) / omega


def reduced_limit(p: np.ndarray, c: ContactState) -> float:
    """Limit of the reduced model's step at one operating point, s: the explicit centrifugal
    coupling of the contact loads, h < 1 / (mu_max omega_m) (module docstring)."""
    rate = traction_bound(p) * c.orbit_speed
    return math.inf if rate <= 0.0 else 1.0 / rate


def contact_mode(p: np.ndarray, c: ContactState) -> tuple[float, float]:
    """Natural frequency (rad/s) and damping ratio of a ball between its two raceways."""
    m = p[kn.P_MBALL]
    stiffness = damping = 0.0
    for k_hertz, q, delta in ((p[kn.P_K_IN], c.inner_load, c.inner_penetration), (p[kn.P_K_OUT], c.outer_load, c.outer_penetration)):
        if q <= 0.0 or delta <= 0.0:
            continue
        stiffness += 1.5 * k_hertz ** (2.0 / 3.0) * q ** (1.0 / 3.0)
        ramp = kn.step_function(delta, 0.0, 0.0, p[kn.P_HC_D], 1.0)
        damping += ramp * 1.5 * p[kn.P_HC_A] * k_hertz * delta ** p[kn.P_HC_N]
    omega = math.sqrt(stiffness / m)
    return omega, damping / (2.0 * m * omega) if omega > 0.0 else 0.0


def stiff_limit(p: np.ndarray, c: ContactState) -> tuple[float, str]:
    """Linear stability limit (s, no safety fraction) of the stiff model's fastest mode at one
    operating point, and the mode's name."""
    omega, zeta = contact_mode(p, c)
    contact = symplectic_euler_limit(omega, zeta) if omega > 0.0 else math.inf
    jseg, kt, ct = p[kn.P_JSEG], p[kn.P_LINK_K], p[kn.P_LINK_C]
    omega_rim = 2.0 * math.sqrt(kt / jseg)
    rim = symplectic_euler_limit(omega_rim, 2.0 * ct / (jseg * omega_rim))
    if rim < contact:
        return rim, f"cage rim mode, {omega_rim / (2.0 * math.pi):.3g} Hz"
    return contact, f"ball-raceway Hertz contact, {omega / (2.0 * math.pi):.3g} Hz at Q = {c.inner_load:.0f}/{c.outer_load:.0f} N"
