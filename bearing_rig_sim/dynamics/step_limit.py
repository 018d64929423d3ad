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
  and cage). Linearised, the step is A-stable: tractions, pocket, rim and land are implicit. It
  fails through the traction's saturation: beyond the rising part of mu(s) the tangent slope is
  nearly zero, the step is explicit there, and the saturated traction of both raceways changes
  the ball's spin (inertia I_b = 0.4 m r^2, lever r) by r^2 mu (Q_i + Q_o) h / I_b of sliding
  speed in one step. Once that sweep exceeds the width of the traction curve's rising part the
  step jumps from one saturated side to the other and locks into a cycle: the slip it then
  reports is an artefact (up to 100 % and beyond). The allowed sweep is
  :data:`CRITICAL_SLIDING_SWEEP` (measured; docs/model.md, Integration); the limit is
  h < S_c I_b / (r^2 (c_i^2 mu_i Q_i + c_o^2 mu_o Q_o)), c = cos(alpha - beta) the lever factor
  of each contact on the spin, mu the traction law's coefficient at the sliding speed S_c and the
  contact's load and entrainment speed.

A step above the limit is refused at engine construction (:class:`StepLimitError`, one line
naming the file key, the value, the limit and the mechanism).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bearing_rig_sim.config import config_path, load_yaml
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.errors import RigError

STIFF_SAFETY = 0.5
"""Fraction of the stiff model's linear stability limit allowed (see the module docstring)."""

CRITICAL_SLIDING_SWEEP = 2.0
"""S_c, m/s: the sliding-speed sweep per step of the saturated traction allowed in the reduced
model. Measured, not derived: runs of the shipped H7006C from a pure-rolling start
(docs/model.md, Integration) found the critical step at 12 operating points from 900 rpm/100 N to
10 000 rpm/1000 N; with S_c = 2.0 m/s the limit over the envelope (5.0e-5 s, set at 1000 N) lies
below every one of them (the smallest, 6-7e-5 s at 10 000 rpm/500 N), and above the shipped step
with either shipped lubricant. Point by point the scaling holds within a factor of about 2.5,
not exactly: the bound is conservative (by 2 for oil-air and the ehl_traction law)."""

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
        doc = load_yaml(path or config_path("rig.yaml"))
        return cls(
            doc.section("spindle").number("max_speed_rad_s", gt=0.0),
            doc.section("loading_chain").number("max_setpoint_n", gt=0.0),
        )


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
    penetrations m."""

    inner_load: float
    outer_load: float
    inner_lever: float
    outer_lever: float
    inner_entrainment: float
    outer_entrainment: float
    inner_penetration: float
    outer_penetration: float


def contact_state(p: np.ndarray, ball: np.ndarray, ring: np.ndarray, geo: np.ndarray) -> ContactState:
    """The most loaded ball's contacts after a quasi-static solution (``geo`` as left by
    :func:`.kernels.solve_quasi_static`, balls at their rolling speeds)."""
    j = int(np.argmax(geo[:, kn.G_QI] + geo[:, kn.G_QO]))
    rb = ball[j, kn.B_R]
    nir, niz, nor, noz = geo[j, kn.G_NIR], geo[j, kn.G_NIZ], geo[j, kn.G_NOR], geo[j, kn.G_NOZ]
    r_ci, r_co, ci, co, *_ = kn.ball_kinematics(p, nir, niz, nor, noz, rb)
    wm = ball[j, kn.B_OMEGA]
    return ContactState(
        float(geo[j, kn.G_QI]), float(geo[j, kn.G_QO]), float(ci), float(co),
        float(abs((ring[kn.R_OMEGA] - wm) * r_ci)), float(abs(wm * r_co)),
        float(geo[j, kn.G_DI]), float(geo[j, kn.G_DO]),
    )


def sweep_traction(p: np.ndarray, contact: int, entrainment: float, load: float) -> float:
    """Traction coefficient of a raceway contact (0 inner, 1 outer) at the sliding speed of the
    allowed sweep, :data:`CRITICAL_SLIDING_SWEEP`, either way (the larger), at its entrainment
    speed (m/s) and load (N), from the engine's own traction law."""
    s = CRITICAL_SLIDING_SWEEP
    forward = kn.contact_traction(p, contact, s, entrainment, load)[0]
    backward = kn.contact_traction(p, contact, -s, entrainment, load)[0]
    return float(max(abs(forward), abs(backward)))


def symplectic_euler_limit(omega: float, zeta: float) -> float:
    """Largest step (s) of symplectic Euler on a damped oscillator of natural frequency
    ``omega`` (rad/s) and damping ratio ``zeta``: 2 (sqrt(1 + zeta^2) - zeta) / omega."""
    return 2.0 * (math.sqrt(1.0 + zeta * zeta) - zeta) / omega


def reduced_limit(p: np.ndarray, c: ContactState) -> float:
    """Traction-saturation limit of the reduced model's step at one operating point, s
    (no safety fraction; see the module docstring)."""
    r, ib = p[kn.P_RBALL], p[kn.P_IBALL]
    mu_i = sweep_traction(p, 0, c.inner_entrainment, c.inner_load)
    mu_o = sweep_traction(p, 1, c.outer_entrainment, c.outer_load)
    torque_per_r = c.inner_lever**2 * mu_i * c.inner_load + c.outer_lever**2 * mu_o * c.outer_load
    if torque_per_r <= 0.0:
        return math.inf
    return CRITICAL_SLIDING_SWEEP * ib / (r * r * torque_per_r)


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
