"""The bearing dynamics engine: state, inputs over time, integration, observations.

Two formulations of the same model (see :mod:`.kernels`):

* ``"reduced"`` (default): quasi-static ball-raceway normal contact solved every step, ball
  orbit, spin, pivot and pitch (gyroscopic) and the flexible cage integrated with a linearly implicit Euler step
  (steps of tens of microseconds, real time with margin);
* ``"stiff"`` (reference): every body dynamic, the paper's IMPACT contacts with Hunt-Crossley
  damping integrated explicitly (steps of a fraction of a microsecond).

Inputs: the inner-ring speed follows a prescribed angular acceleration (constant over each
call of :meth:`BearingDynamics.advance`); the axial load (N) is a time signal given per call.
Cage speed and slip are outputs of the integration, never inputs. The mounting (an extra
diametral clearance, a misalignment at which the tilts are held, a spring or a rigid preload;
docs/model.md, "Mounting") is set when the engine is built and by its setters between steps.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np

from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.lubrication import film_thickness
from bearing_rig_sim.dynamics.parameters import BearingParameters, derive
from bearing_rig_sim.dynamics.step_limit import (
    SPEED_FRACTIONS,
    STIFF_SAFETY,
    OperatingEnvelope,
    StepLimit,
    StepLimitError,
    contact_state,
    reduced_limit,
    stiff_limit,
)
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.mounting import MountingConfig

MODELS = ("reduced", "stiff")
MIN_AXIAL_LOAD = 1.0
"""Smallest axial load (N) the engine accepts: an angular contact bearing with no axial load
has no defined contact angle and the quasi-static normal problem becomes singular. With a
preload (spring or rigid) the external load may be 0: the preload carries the balls."""

MAX_MISALIGNMENT = 0.01
"""Largest misalignment the engine accepts, rad per axis (34 arcmin: ten times what a single
angular contact bearing tolerates, a few arcmin by the catalogues; beyond it the held tilt
lifts the inner groove by more than its conformity can follow)."""

MAX_PRELOAD_FORCE = 10_000.0
"""Largest spring preload, N (the H7006C's static rating C0, 9-10 kN)."""

MAX_PRELOAD_DISPLACEMENT = 1e-4
"""Largest rigid preload displacement, m (100 um: tens of times a heavy preload of a spindle
bearing of this size)."""


SPEED_TOLERANCE = (0.01, 0.2)
"""Relative (1) and absolute (rad/s) margin of the run-time speed bounds (see
:meth:`BearingDynamics.check_state`). Legitimate runs at the shipped step (spin-ups at 80 and
1000 rad/s^2 to 3000-10 000 rpm and stops to rest, 10-1000 N) went at most 0.10 rad/s below
zero (ball orbit at rest under 1000 N) and 0.05 rad/s above the inner ring's peak; a diverging
step leaves the bounds by orders of magnitude within a few steps."""


CAGE_CENTRE_BOUND = 1.5
"""The cage centre may leave the axis by at most this many land clearances: at one clearance it
touches its land, whose contact (stiffness of the order of 1e7 N/m) lets it in by microns
under the few newtons the pockets give; half a clearance further means a diverged step."""


class DynamicsInputError(RigError):
    """An input of the dynamics engine is not finite or out of its range."""


class DynamicsDivergedError(RigError):
    """The integration produced a state no bearing can be in (non-finite, a body turning
    backwards or faster than the inner ring ever turned): a numerical fault, not a result."""


@functools.lru_cache(maxsize=1)
def _shipped_envelope() -> OperatingEnvelope:
    return OperatingEnvelope.from_rig_file()


@dataclass(frozen=True)
class Mounting:
    """How the bearing is mounted (SI units; docs/model.md, "Mounting"). All 0: as the bearing
    file describes it, a single bearing with the tilts held at zero.

    Attributes:
        clearance: extra diametral clearance P_d, m (negative: an interference fit;
            :meth:`BearingDynamics.set_clearance`).
        misalignment: (theta_x, theta_y) at which the inner ring's tilts are held with no
            moment applied, rad (:meth:`BearingDynamics.set_misalignment`; reduced model).
        preload_force: spring preload added to the axial load, N.
        preload_displacement: rigid preload of a back-to-back pair of this bearing, m
            (:meth:`BearingDynamics.set_preload`).
    """

    clearance: float = 0.0
    misalignment: tuple[float, float] = (0.0, 0.0)
    preload_force: float = 0.0
    preload_displacement: float = 0.0

    @classmethod
    def of(cls, section: MountingConfig) -> Mounting:
        """The engine's mounting from a validated ``mounting`` section of a rig file (or the
        command line's, checked against the same ranges)."""
        return cls(section.clearance_change_m, section.misalignment_rad, section.preload_n, section.preload_displacement_m)


@dataclass(frozen=True)
class Snapshot:
    """A copy of the complete engine state (restore it with :meth:`BearingDynamics.restore`)."""

    model: str
    ball: np.ndarray
    cage: np.ndarray
    ring: np.ndarray
    axial_load: float
    radial_load: float = 0.0
    radial_angle: float = 0.0
    moment: tuple[float, float] | None = None


@dataclass(frozen=True)
class Observation:
    """What the engine knows at one instant (SI units).

    Attributes:
        time: simulation time, s.
        inner_ring_angle: unwrapped inner-ring (spindle) angle, rad.
        inner_ring_speed: rad/s.
        cage_angle: unwrapped angle of the cage segment carrying the reflective strip, rad.
        cage_speed: mean speed of the cage segments, rad/s.
        ball_orbit_speeds: per ball, rad/s.
        ball_azimuths: per ball, the orbital angle of its centre from the bearing's x axis, in
            [0, 2 pi), rad.
        ball_spin_speeds: per ball, its rotation speed about its own axis, rad/s.
        ball_pivot_speeds: per ball, the pivot omega_t (rad/s, about the axis perpendicular to
            the rolling axis and the orbit radius: the gyroscopic moment's), sign of e_t.
        ball_pitch_speeds: per ball, the pitch rate omega_p (rad/s, about the third axis of the
            radial-axial plane, relative to raceway control: the rolling axis's tilt).
        inner_contact_loads / outer_contact_loads: per ball, N.
        inner_contact_angles / outer_contact_angles: per ball, rad.
        pocket_loads: per ball, signed (> 0: ball pushes the cage forward), N.
        inner_ring_axial_displacement: m.
        axial_load: applied axial load, N.
        cage_whirl_radius: distance of the cage centre from the bearing axis, m (reduced model;
            0 for the concentric stiff model).
        cage_centre: the cage centre's (x, y) displacement, m, in the bearing's frame (the
            radial load's azimuth is :attr:`BearingDynamics.radial_angle` from x).
        inner_ring_tilt: (theta_x, theta_y), rad (0 while held: no moment applied).
        ring_moment: (M_x, M_y), N m, the moment of the balls' inner contact loads on the inner
            ring (M_x = sum Q_i sin a_i R_i cos psi, M_y with sin psi, as
            :mod:`.quasi_static` counts it): with the tilts held, the reaction moment the
            spindle's second bearing supplies; under an applied moment, equal to it.
    """

    time: float
    inner_ring_angle: float
    inner_ring_speed: float
    cage_angle: float
    cage_speed: float
    ball_orbit_speeds: np.ndarray
    inner_contact_loads: np.ndarray
    outer_contact_loads: np.ndarray
    inner_contact_angles: np.ndarray
    outer_contact_angles: np.ndarray
    pocket_loads: np.ndarray
    inner_ring_axial_displacement: float
    axial_load: float
    cage_whirl_radius: float = 0.0
    cage_centre: tuple[float, float] = (0.0, 0.0)
    ball_pivot_speeds: np.ndarray | None = None
    ball_pitch_speeds: np.ndarray | None = None
    inner_ring_tilt: tuple[float, float] = (0.0, 0.0)
    ring_moment: tuple[float, float] = (0.0, 0.0)
    ball_azimuths: np.ndarray = field(default_factory=lambda: np.zeros(0))
    ball_spin_speeds: np.ndarray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True)
class ChunkAverage:
    """Time averages over one :meth:`BearingDynamics.advance` call: cage and inner-ring
    speed (rad/s) over ``duration`` (s), and the work the drive did on the inner ring over it,
    ``drive_work`` (J: the integral of :meth:`BearingDynamics.drive_torque` times the inner-ring
    speed, step by step), the heat the bearing dissipated over it, ``heat`` (J: the integral of
    :meth:`BearingDynamics.power_loss`, step by step), ``damping_heat`` (J: the pocket
    contacts' Hunt-Crossley damping, the cage rim's damping and, reduced model, the guiding
    land's work on the moving cage centre: film squeeze and whirl, contact damping and
    friction) and ``contact_damping_heat`` (J: the raceway contacts' Hunt-Crossley damping,
    stiff model; the reduced model's normal contacts are quasi-static)."""

    duration: float
    cage_speed: float
    inner_ring_speed: float
    drive_work: float = 0.0
    heat: float = 0.0
    damping_heat: float = 0.0
    contact_damping_heat: float = 0.0


def _finite(name: str, value: float, lo: float | None = None) -> float:
    x = float(value)
    if not math.isfinite(x):
        raise DynamicsInputError(f"{name} must be finite, got {value!r}")
    if lo is not None and x < lo:
        raise DynamicsInputError(f"{name} must be >= {lo}, got {value!r}")
    return x


class BearingDynamics:
    """Integrates the equations of motion of one angular contact ball bearing.

    Args:
        params: bearing data (see :class:`BearingParameters`).
        model: ``"reduced"`` (default, real time) or ``"stiff"`` (reference).
        time_step: integration step, s; defaults to the model's step in the bearing file.
        strip_segment: index of the cage segment carrying the reflective strip (sensor).
        envelope: the rig's top speed and largest axial load, for the step's stability limit
            (default: the shipped ``config/rig.yaml``).
        check_step: refuse a step above the model's stability limit (:mod:`.step_limit`);
            False only to study a diverging integration.
        mounting: clearance, misalignment and preload (:class:`Mounting`; default none), set
            before the step's stability limit is found.

    Raises:
        StepLimitError: the step exceeds the model's stability limit over the envelope.
    """

    def __init__(
        self,
        params: BearingParameters,
        *,
        model: str = "reduced",
        time_step: float | None = None,
        strip_segment: int = 0,
        envelope: OperatingEnvelope | None = None,
        check_step: bool = True,
        mounting: Mounting | None = None,
    ) -> None:
        if model not in MODELS:
            raise DynamicsInputError(f"model must be one of {', '.join(MODELS)}, got {model!r}")
        self.params = params
        self.model = model
        self.vector, self.geometry = derive(params)
        self._outer_centre = float(self.vector[kn.P_CO_R])
        self.clearance = 0.0
        """Extra diametral clearance P_d, m (:meth:`set_clearance`)."""
        self.misalignment = (0.0, 0.0)
        """(theta_x, theta_y) at which the tilts are held with no moment applied, rad."""
        self.preload_force = 0.0
        """Spring preload added to the axial load, N."""
        self.preload_displacement = 0.0
        """Rigid preload displacement of a back-to-back pair, m (0: a single bearing)."""
        mounting = mounting or Mounting()
        self.set_clearance(mounting.clearance)
        self.set_preload(mounting.preload_force, mounting.preload_displacement)
        self.misalignment = self._misalignment(mounting.misalignment)
        default_dt = params.reduced_time_step if model == "reduced" else params.stiff_time_step
        self.time_step = _finite("time_step", time_step if time_step is not None else default_dt, 1e-9)
        z = params.ball_count
        if not 0 <= strip_segment < z:
            raise DynamicsInputError(f"strip_segment must be in 0..{z - 1}, got {strip_segment}")
        self.strip_segment = strip_segment
        self.ball = np.zeros((z, kn.NB))
        self.cage = np.zeros((z, kn.NC))
        self.ring = np.zeros(kn.NR)
        self.out = np.zeros((z, kn.NO))
        self.stats = np.zeros(kn.NS)
        self.dissipated = 0.0
        """Heat dissipated since the engine was built, J (:attr:`ChunkAverage.heat`,
        :attr:`ChunkAverage.damping_heat` and :attr:`ChunkAverage.contact_damping_heat` summed
        over every :meth:`advance`)."""
        self.damping_dissipated = 0.0
        """The damping's share of :attr:`dissipated`, J."""
        self.work = np.zeros((z, kn.NW))
        self.record_every = 0
        self.axial_load = 0.0
        self.radial_load = 0.0
        """Radial load on the inner ring, N (reduced model; tilts held), at :attr:`radial_angle`."""
        self.radial_angle = 0.0
        """Azimuth of the radial load from the bearing's x axis, rad (the load zone's azimuth)."""
        self.moment: tuple[float, float] | None = None
        """Applied moment (M_x, M_y) on the inner ring, N m (counted as :mod:`.quasi_static`
        does), or None: the tilts held at :attr:`misalignment` (zero by default), as the
        spindle's second bearing holds them (:meth:`set_moment`)."""
        self._step = kn.step_reduced if model == "reduced" else kn.step_stiff
        self._peak_speed = 0.0
        self.envelope = envelope if envelope is not None else _shipped_envelope()
        self.step_limit = self._stability_limit(self.envelope)
        """The model's largest stable step over the envelope (:class:`.step_limit.StepLimit`)."""
        if check_step and self.time_step > self.step_limit.limit:
            key = f"integration.{model}_time_step_s" if time_step is None else "time_step"
            raise StepLimitError(
                f"{params.source}: {key} = {self.time_step:g} s exceeds the stability limit "
                f"{self.step_limit.limit:.3g} s of the {model} model ({self.step_limit.mechanism})"
            )
        self.initialise(0.0, 100.0)

    def _stability_limit(self, envelope: OperatingEnvelope) -> StepLimit:
        """The smallest stability limit over the envelope's speeds at its largest load."""
        load = max(envelope.max_axial_load, MIN_AXIAL_LOAD)
        best, why = math.inf, "no operating point solved"
        for fraction in SPEED_FRACTIONS:
            omega = fraction * envelope.max_inner_ring_speed
            try:
                self.initialise(omega, load)
            except DynamicsInputError:
                continue
            state = contact_state(self.vector, self.ball, self.ring, self.work[:, : kn.NG])
            rpm = omega * 30.0 / math.pi
            if self.model == "reduced":
                limit = reduced_limit(self.vector, state)
                mechanism = f"explicit centrifugal coupling of the contact loads at {rpm:.0f} rpm, {load:g} N: ball orbit {state.orbit_speed:.0f} rad/s"
            else:
                linear, mode = stiff_limit(self.vector, state)
                limit = STIFF_SAFETY * linear
                mechanism = f"{STIFF_SAFETY:g} x the explicit limit of the {mode}, {rpm:.0f} rpm, {load:g} N"
            if limit < best:
                best, why = limit, mechanism
        return StepLimit(self.model, best, why)

    # -- set-up --------------------------------------------------------------------------------
    def initialise(
        self,
        inner_ring_speed: float,
        axial_load: float,
        *,
        time: float = 0.0,
        radial_load: float = 0.0,
        radial_angle: float = 0.0,
        moment: tuple[float, float] | None = None,
    ) -> None:
        """Start from the static equilibrium under ``axial_load`` (N; and ``radial_load``, N at the
        azimuth ``radial_angle`` from x, rad, reduced model only; and ``moment``, N m, with the
        tilts free, see :meth:`set_moment`) with the balls and cage at
        the kinematic (rolling) speeds for ``inner_ring_speed`` (rad/s) at the loaded contact
        angle, each ball touching the driving side of its pocket. The dynamics then find the real
        operating point.
        """
        omega = _finite("inner_ring_speed", inner_ring_speed, 0.0)
        load = _finite("axial_load", axial_load, self._min_axial_load())
        radial = self._radial(radial_load)
        angle = _finite("radial_angle", radial_angle)
        applied = self._moment(moment)
        v, p = self.vector, self.params
        z = p.ball_count
        rm = v[kn.P_RM]
        # Initial approach along the contact line: Q = F/(Z sin a0) at both contacts.
        q0 = (load + self.preload_force) / (z * max(math.sin(p.contact_angle), 0.05))
        approach = (q0 / v[kn.P_K_IN]) ** (2 / 3) + (q0 / v[kn.P_K_OUT]) ** (2 / 3)
        self.ring[:] = 0.0
        # a rigid pair shares its preload displacement: at least half of it on this ring
        self.ring[kn.R_DELTA] = max(approach / max(math.sin(p.contact_angle), 0.05), 0.5 * self.preload_displacement)
        self.ring[kn.R_TX], self.ring[kn.R_TY] = self.misalignment
        self.ring[kn.R_OMEGA] = omega
        self.ring[kn.R_TIME] = time
        self._peak_speed = omega
        theta = 2.0 * math.pi * np.arange(z) / z
        self.ball[:] = 0.0
        self.ball[:, kn.B_THETA] = theta
        self.ball[:, kn.B_R] = rm
        self.ball[:, kn.B_OMEGA] = omega * p.epicyclic_ratio
        if self.clearance != 0.0:
            # on the outer groove at the free contact angle the clearance gives, the inner ring
            # moved axially by the change of the curvature centres' axial distance
            big_a, gap_o = v[kn.P_RI_GAP] + v[kn.P_RO_GAP], v[kn.P_RO_GAP]
            free = math.acos(min(max((v[kn.P_CI_R] - v[kn.P_CO_R]) / big_a, -1.0), 1.0))
            self.ball[:, kn.B_R] = v[kn.P_CO_R] + gap_o * math.cos(free)
            self.ball[:, kn.B_Z] = v[kn.P_CO_Z] + gap_o * math.sin(free)
            lift = big_a * (math.sin(free) - math.sin(p.contact_angle))
            self.ring[kn.R_DELTA] = max(lift + approach / max(math.sin(free), 0.05), 0.5 * self.preload_displacement)
        for _ in range(3):  # speeds and loaded angle depend on each other through centrifugal force
            # 1e-11 of the load; under a few newtons that is below the rounding of the contact
            # forces (K delta^1.5 with delta ~ 1e-7 m), so the steps' own 1e-9 is accepted there,
            # with more iterations: between rest and 50 rpm the balls outside a load zone slide
            # down the outer groove under centrifugal forces of micro-newtons until the inner
            # groove wedges them (kernels.ball_jacobian), at most about 900 Newton iterations
            # over 0-10 000 rpm, 1-1000 N axial, 0-1000 N radial, 0-5 N m (one-off, about 1 us
            # each).
            if self._solve_normal(load, radial, angle, applied, 1e-11, 200) > 200 and self._solve_normal(load, radial, angle, applied, 1e-9, 50_000) > 50_000:
                raise DynamicsInputError(f"no static equilibrium found for axial load {load} N, radial load {radial} N at {omega} rad/s")
            self._set_rolling_speeds(omega)
        kn.ring_moment(v, self.ball, self.ring, self.work[:, : kn.NG])
        # Balls just touching the driving side of their pockets (zero force): the cage is
        # carried from the first step instead of crossing the clearance and striking the balls.
        self.cage[:, kn.C_PHI] = theta - v[kn.P_POCKET_CLEAR] / rm
        self.cage[:, kn.C_OMEGA] = np.mean(self.ball[:, kn.B_OMEGA])
        self.axial_load = load
        self.radial_load = radial
        self.radial_angle = angle
        self.moment = applied
        self.stats[:] = 0.0
        self.out[:] = 0.0

    def _solve_normal(self, load: float, radial: float, angle: float, moment: tuple[float, float] | None, tol: float, max_iter: int) -> int:
        """The normal problem (:func:`.kernels.solve_quasi_static`, or its tilted form under a
        moment) at the current ball positions and speeds; the Newton iterations used."""
        v, geo, scratch = self.vector, self.work[:, : kn.NG], self.work[:, kn.NG : kn.NG + 6]
        load += self.preload_force
        if moment is None:
            return int(kn.solve_quasi_static(v, self.ball, self.ring, geo, scratch, load, tol, max_iter, radial, angle))
        loads = np.array([load, radial * math.cos(angle), radial * math.sin(angle), *moment])
        return int(kn.solve_quasi_static_tilted(v, self.ball, self.ring, geo, scratch, loads, tol, max_iter))

    def _moment(self, moment: tuple[float, float] | None) -> tuple[float, float] | None:
        if moment is None:
            return None
        if len(moment) != 2:
            raise DynamicsInputError(f"moment must be (M_x, M_y) in N m or None, got {moment!r}")
        mx, my = _finite("moment M_x", moment[0]), _finite("moment M_y", moment[1])
        if self.model != "reduced":
            raise DynamicsInputError(f"moment needs the reduced model (the {self.model} model is axisymmetric), got {moment!r}")
        return mx, my

    def set_moment(self, moment: tuple[float, float] | None) -> None:
        """Apply the moment (M_x, M_y) (N m, counted as :mod:`.quasi_static` does:
        M_x = sum Q_i sin a_i R_i cos psi) on the inner ring from the next step on, its two tilts
        then free unknowns of the normal solve made every step; None holds the tilts at the misalignment again
        (as the spindle's second bearing holds them) and the ring's moment is the reaction
        (:attr:`Observation.ring_moment`). Reduced model only."""
        self.moment = self._moment(moment)
        if self.moment is None:
            self.ring[kn.R_TX], self.ring[kn.R_TY] = self.misalignment

    @property
    def mounting(self) -> Mounting:
        """The current clearance, misalignment and preload."""
        return Mounting(self.clearance, self.misalignment, self.preload_force, self.preload_displacement)

    def _min_axial_load(self) -> float:
        return 0.0 if self.preload_force > 0.0 or self.preload_displacement > 0.0 else MIN_AXIAL_LOAD

    def set_clearance(self, clearance: float) -> None:
        """Set the extra diametral clearance P_d (m; negative: an interference fit) from the next
        step on: the outer groove curvature centres move radially out by P_d/2, so the free
        contact angle becomes acos(cos a0 - P_d/(2A)) (A = (f_i + f_o - 1) D_w; the geometry of
        :mod:`.quasi_static`). Usable between steps (a ring's thermal expansion,
        :func:`.quasi_static.thermal_clearance_change`); the next step's normal solve (reduced
        model) or the balls' contacts (stiff model) take it up.

        Raises:
            DynamicsInputError: not finite, or outside -A..2A (cos a0 - cos 80 deg) (a free
                contact angle above 80 deg).
        """
        p_d = _finite("clearance", clearance)
        v = self.vector
        big_a = float(v[kn.P_RI_GAP] + v[kn.P_RO_GAP])
        top = 2.0 * big_a * (math.cos(self.params.contact_angle) - math.cos(math.radians(80.0)))
        if not -big_a <= p_d <= top:
            raise DynamicsInputError(f"clearance must be within {-big_a:.4g}..{top:.4g} m (free contact angle below 80 deg), got {clearance!r}")
        v[kn.P_CO_R] = self._outer_centre + 0.5 * p_d
        self.clearance = p_d

    def _misalignment(self, misalignment: tuple[float, float]) -> tuple[float, float]:
        if len(misalignment) != 2:
            raise DynamicsInputError(f"misalignment must be (theta_x, theta_y) in rad, got {misalignment!r}")
        tx, ty = _finite("misalignment theta_x", misalignment[0]), _finite("misalignment theta_y", misalignment[1])
        if max(abs(tx), abs(ty)) > MAX_MISALIGNMENT:
            raise DynamicsInputError(f"misalignment must be within +-{MAX_MISALIGNMENT:g} rad per axis, got {misalignment!r}")
        if (tx, ty) != (0.0, 0.0) and self.model != "reduced":
            raise DynamicsInputError(f"misalignment needs the reduced model (the {self.model} model is axisymmetric), got {misalignment!r}")
        return tx, ty

    def set_misalignment(self, misalignment: tuple[float, float]) -> None:
        """Hold the inner ring's tilts at (theta_x, theta_y) (rad, counted as
        :mod:`.quasi_static` counts them: theta_x lifts the inner ring axially at psi = 0) from
        the next step on while no moment is applied (as the spindle's second bearing holds them,
        off line by this much); under an applied moment the tilts stay free. Reduced model."""
        self.misalignment = self._misalignment(misalignment)
        if self.moment is None:
            self.ring[kn.R_TX], self.ring[kn.R_TY] = self.misalignment

    def set_preload(self, force: float = 0.0, displacement: float = 0.0) -> None:
        """Set the preload from the next step on: ``force`` (N, >= 0), a spring's constant axial
        force added to the axial load (the rig's lever and wire rope acting through a spring);
        ``displacement`` (m, >= 0), the rigid preload of a back-to-back pair of this bearing:
        the partner, at rest and loaded axially only, pushes the inner ring with
        F_p(d) = Z K_n (D - A)^1.5 (A sin a0 + d)/D, D = sqrt((A sin a0 + d)^2 + (A cos a0 - P_d/2)^2),
        d = displacement - delta_a (:func:`.kernels.partner_force`). 0 and 0: no preload."""
        f = _finite("preload force", force, 0.0)
        s = _finite("preload displacement", displacement, 0.0)
        if f > MAX_PRELOAD_FORCE:
            raise DynamicsInputError(f"preload force must be within 0..{MAX_PRELOAD_FORCE:g} N, got {force!r}")
        if s > MAX_PRELOAD_DISPLACEMENT:
            raise DynamicsInputError(f"preload displacement must be within 0..{MAX_PRELOAD_DISPLACEMENT:g} m, got {displacement!r}")
        self.preload_force = f
        self.preload_displacement = s
        self.vector[kn.P_PRELOAD_D] = s

    def _radial(self, radial_load: float) -> float:
        radial = _finite("radial_load", radial_load, 0.0)
        if radial > 0.0 and self.model != "reduced":
            raise DynamicsInputError(f"radial_load needs the reduced model (the {self.model} model is axisymmetric), got {radial_load!r}")
        return radial

    def _set_rolling_speeds(self, omega_i: float) -> None:
        """Ball orbit and spin speeds of pure rolling at both raceways (zero sliding)."""
        v = self.vector
        for j in range(self.params.ball_count):
            rb, zb, theta = self.ball[j, kn.B_R], self.ball[j, kn.B_Z], self.ball[j, kn.B_THETA]
            shift = self.ring[kn.R_DX] * math.cos(theta) + self.ring[kn.R_DY] * math.sin(theta)
            lift = v[kn.P_CI_R] * (self.ring[kn.R_TX] * math.cos(theta) + self.ring[kn.R_TY] * math.sin(theta))
            _, nir, niz, _, _, nor, noz, _ = kn.shifted_raceway_geometry(v, rb, zb, self.ring[kn.R_DELTA] + lift, shift)
            r_ci, _, _, _, aim, aia, aom, aoa, _ = kn.ball_kinematics(v, nir, niz, nor, noz, rb)
            # s_i = 0 and s_o = 0: a 2x2 linear system in (omega_m, omega_a)
            det = aim * aoa + aia * aom
            self.ball[j, kn.B_OMEGA] = omega_i * r_ci * aoa / det
            self.ball[j, kn.B_SPIN] = omega_i * r_ci * aom / det

    def set_inner_ring_speed(self, omega: float) -> None:
        """Impose the inner-ring speed (rad/s) from now on (a drive speed jump)."""
        self.ring[kn.R_OMEGA] = _finite("inner_ring_speed", omega, 0.0)
        self._peak_speed = max(self._peak_speed, self.ring[kn.R_OMEGA])

    # -- integration ---------------------------------------------------------------------------
    def advance(
        self,
        duration: float,
        *,
        axial_load: float | None = None,
        inner_ring_acceleration: float = 0.0,
        radial_load: float | None = None,
        radial_angle: float | None = None,
    ) -> ChunkAverage:
        """Integrate for ``duration`` seconds (rounded to whole steps).

        Args:
            duration: s, >= 0.
            axial_load: N applied to the inner ring during the interval (default: unchanged).
            radial_load: N on the inner ring during the interval (default: unchanged;
                reduced model only): each ball's loads follow from the ring's quasi-static
                balance at its orbital position, so they vary around the orbit.
            radial_angle: the radial load's azimuth from the bearing's x axis, rad, where the
                load zone is centred (default: unchanged).
            inner_ring_acceleration: rad/s^2, constant during the interval; the speed stops at
                zero rather than reverse.

        Returns:
            time averages of cage and inner-ring speed over the interval.
        """
        duration = _finite("duration", duration, 0.0)
        if axial_load is not None:
            self.axial_load = _finite("axial_load", axial_load, self._min_axial_load())
        if radial_load is not None:
            self.radial_load = self._radial(radial_load)
        if radial_angle is not None:
            self.radial_angle = _finite("radial_angle", radial_angle)
        accel = _finite("inner_ring_acceleration", inner_ring_acceleration)
        n = int(round(duration / self.time_step))
        slowing = -accel * self.time_step  # 0 for a subnormal deceleration
        if slowing * n > self.ring[kn.R_OMEGA]:
            n = int(self.ring[kn.R_OMEGA] / slowing)
        self.stats[:] = 0.0
        if n > 0:
            self._step(
                self.vector,
                self.ball,
                self.cage,
                self.ring,
                self.out,
                self.stats,
                self.work,
                n,
                self.time_step,
                self.axial_load + self.preload_force,
                accel,
                0,
                self.radial_load,
                self.radial_angle,
                *(self.moment or (0.0, 0.0)),
                self.moment is not None,
            )
        self.check_state()
        t = self.stats[kn.S_TIME]
        if t <= 0.0:
            return ChunkAverage(0.0, self.cage_speed, self.inner_ring_speed)
        heat, damping, contact = float(self.stats[kn.S_HEAT]), float(self.stats[kn.S_DAMP]), float(self.stats[kn.S_CONTACT_DAMP])
        self.dissipated += heat + damping + contact
        self.damping_dissipated += damping
        return ChunkAverage(t, self.stats[kn.S_CAGE] / t, self.stats[kn.S_INNER] / t, float(self.stats[kn.S_DRIVE]), heat, damping, contact)

    def check_state(self) -> None:
        """Raise if the state is one no bearing can be in (a numerical fault).

        The inner ring is the only driven body; balls and cage are carried by friction, so none
        can turn faster than the fastest the inner ring has turned since the start, nor
        backwards (:data:`SPEED_TOLERANCE` margin). A dry bearing (``params.dry``: no fluid
        damps the cage) is allowed to turn backwards as fast as that: a free cage that runs
        into balls the stopped ring pinches rebounds off them, at most as fast as it came
        (restitution below 1). A finite state outside those bounds, like a non-finite one,
        means the integration diverged.

        Raises:
            DynamicsDivergedError: naming the quantity, its value, the bounds and the time.
        """
        omega = float(self.ring[kn.R_OMEGA])
        if omega > self._peak_speed:
            self._peak_speed = omega
        rel, absolute = SPEED_TOLERANCE
        hi = self._peak_speed * (1.0 + rel) + absolute
        lo = -hi if self.params.dry else -absolute
        fault = kn.speed_outlier(self.ball, self.cage, self.ring, lo, hi)  # one compiled pass per chunk
        t = self.time
        if fault == 0:
            bound = CAGE_CENTRE_BOUND * self.params.land_clearance
            if self.cage_whirl_radius > bound:
                raise DynamicsDivergedError(
                    f"dynamics diverged at t = {t:.6g} s: cage centre {self.cage_whirl_radius * 1e6:.6g} um from the axis, "
                    f"beyond {CAGE_CENTRE_BOUND:g} x the land clearance {self.params.land_clearance * 1e6:g} um ({self._step_hint()})"
                )
            return
        if fault == 1:
            raise DynamicsDivergedError(f"dynamics diverged at t = {t:.6g} s: non-finite state ({self._step_hint()})")
        name, speeds = ("cage speed", self.cage[:, kn.C_OMEGA]) if fault == 2 else ("ball orbit speed", self.ball[:, kn.B_OMEGA])
        worst = float(speeds[np.argmax(np.abs(speeds - 0.5 * (lo + hi)))])
        raise DynamicsDivergedError(
            f"dynamics diverged at t = {t:.6g} s: {name} {worst:.6g} rad/s outside [{'-' if self.params.dry else ''}{0.0 if not self.params.dry else self._peak_speed:.6g}, {self._peak_speed:.6g}] rad/s "
            f"(the inner ring's fastest so far) ({self._step_hint()})"
        )

    def _step_hint(self) -> str:
        return f"time step {self.time_step:g} s, stability limit {self.step_limit.limit:.3g} s"

    def mean_speeds(self, duration: float, *, axial_load: float | None = None, settle: float = 0.0) -> ChunkAverage:
        """Run ``settle`` seconds, then average cage and inner speeds over ``duration`` seconds."""
        if settle > 0.0:
            self.advance(settle, axial_load=axial_load)
        return self.advance(duration, axial_load=axial_load)

    # -- state ---------------------------------------------------------------------------------
    def snapshot(self) -> Snapshot:
        """A copy of the complete state."""
        return Snapshot(self.model, self.ball.copy(), self.cage.copy(), self.ring.copy(), self.axial_load, self.radial_load, self.radial_angle, self.moment)

    def restore(self, snap: Snapshot) -> None:
        """Return to a state taken by :meth:`snapshot` (same model and bearing)."""
        if snap.model != self.model or snap.ball.shape != self.ball.shape:
            raise DynamicsInputError("snapshot belongs to another model or bearing")
        self.ball[:] = snap.ball
        self.cage[:] = snap.cage
        self.ring[:] = snap.ring
        self.axial_load = snap.axial_load
        self.radial_load = snap.radial_load
        self.radial_angle = snap.radial_angle
        self.moment = snap.moment
        # A snapshot was taken of an accepted state: its speeds are within the bounds it had.
        carried = max(float(np.max(snap.cage[:, kn.C_OMEGA])), float(np.max(snap.ball[:, kn.B_OMEGA])))
        self._peak_speed = max(self._peak_speed, float(snap.ring[kn.R_OMEGA]), carried)

    @property
    def time(self) -> float:
        """Simulation time, s."""
        return float(self.ring[kn.R_TIME])

    @property
    def inner_ring_speed(self) -> float:
        """Inner-ring speed, rad/s."""
        return float(self.ring[kn.R_OMEGA])

    @property
    def cage_whirl_radius(self) -> float:
        """Distance of the cage centre from the bearing axis, m (its orbit is the cage whirl)."""
        return math.hypot(float(self.ring[kn.R_CX]), float(self.ring[kn.R_CY]))

    @property
    def cage_speed(self) -> float:
        """Mean cage-segment speed, rad/s."""
        return float(np.mean(self.cage[:, kn.C_OMEGA]))

    def energy(self) -> float:
        """Total mechanical energy, J (meaningful for the stiff model, whose state is complete)."""
        return float(kn.mechanical_energy(self.vector, self.ball, self.cage, self.ring, self.axial_load + self.preload_force))

    def power_loss(self) -> float:
        """Power dissipated in the bearing at the last step, W: raceway contacts (sliding, spin,
        Heathcote), rolling resistances, pocket friction and drag of every ball, plus the cage
        land. With the outer ring fixed it equals the friction torque times the inner-ring speed."""
        v, z = self.vector, self.params.ball_count
        land = 0.0
        factor, normal = float(self.ring[kn.R_LAND_F]) or 1.0, float(self.ring[kn.R_LAND_N])
        for k in range(z):
            w = float(self.cage[k, kn.C_OMEGA])
            tl, _ = kn.cage_land_torque(v, w, z, factor, normal)
            land += abs(tl * w)
        return float(np.sum(self.out[:, kn.O_POWER])) + land

    def drive_torque(self) -> float:
        """Torque the drive applies to the inner ring at the last step, N m: the moment about the
        axis of the balls' traction forces at the inner contacts, sum of Q_i mu_i r_ci (the
        ring's own inertia aside: its rotation is prescribed). At steady state it equals
        :meth:`friction_torque`; while the balls and cage speed up it also carries their
        acceleration."""
        return float(np.sum(self.out[:, kn.O_DRIVE]))

    def friction_torque(self) -> float:
        """Bearing friction torque on the inner ring, N m (power loss over inner-ring speed)."""
        w = self.inner_ring_speed
        return self.power_loss() / w if w > 0.0 else 0.0

    def minimum_films(self) -> tuple[float, float]:
        """Minimum film thickness (m) of the inner and outer contacts at the mean ball load and
        speed (Hamrock-Dowson with thermal and starvation reductions); (nan, nan) without a
        lubricant file."""
        p = self.params
        lub = p.lubricant
        if lub is None:
            return math.nan, math.nan
        o = self.out
        alpha_i, alpha_o = float(np.mean(o[:, kn.O_AI])), float(np.mean(o[:, kn.O_AO]))
        inner, outer = p.raceway_contacts(0.5 * (alpha_i + alpha_o))
        r, rm = 0.5 * p.ball_diameter, 0.5 * p.pitch_diameter
        wm = float(np.mean(self.ball[:, kn.B_OMEGA]))
        films = []
        for con, q, alpha, speed, sign in (
            (inner, float(np.mean(o[:, kn.O_QI])), alpha_i, abs(self.inner_ring_speed - wm) * (rm - r * math.cos(alpha_i)), -1.0),
            (outer, float(np.mean(o[:, kn.O_QO])), alpha_o, wm * (rm + r * math.cos(alpha_o)), 1.0),
        ):
            rx = r * (1.0 + sign * p.ball_diameter * math.cos(alpha) / p.pitch_diameter)
            _, b = con.semi_axes(q)
            film = film_thickness(lub, p.lubricant_temperature, con.reduced_modulus, rx, con.ellipticity, b, con.max_pressure(q), speed, q)
            films.append(film.minimum)
        return films[0], films[1]

    def angles(self) -> tuple[float, float, float]:
        """Time (s), inner-ring angle (rad) and the strip-carrying cage segment's angle (rad): what
        the fibre-optic sensors see, without the copies of :meth:`observe`."""
        return float(self.ring[kn.R_TIME]), float(self.ring[kn.R_ANGLE]), float(self.cage[self.strip_segment, kn.C_PHI])

    def observe(self) -> Observation:
        """The current state as an :class:`Observation` (copies)."""
        o = self.out
        return Observation(
            time=self.time,
            inner_ring_angle=float(self.ring[kn.R_ANGLE]),
            inner_ring_speed=self.inner_ring_speed,
            cage_angle=float(self.cage[self.strip_segment, kn.C_PHI]),
            cage_speed=self.cage_speed,
            ball_orbit_speeds=self.ball[:, kn.B_OMEGA].copy(),
            inner_contact_loads=o[:, kn.O_QI].copy(),
            outer_contact_loads=o[:, kn.O_QO].copy(),
            inner_contact_angles=o[:, kn.O_AI].copy(),
            outer_contact_angles=o[:, kn.O_AO].copy(),
            pocket_loads=o[:, kn.O_FP].copy(),
            inner_ring_axial_displacement=float(self.ring[kn.R_DELTA]),
            axial_load=self.axial_load,
            cage_whirl_radius=self.cage_whirl_radius,
            cage_centre=(float(self.ring[kn.R_CX]), float(self.ring[kn.R_CY])),
            ball_pivot_speeds=self.ball[:, kn.B_PIVOT].copy(),
            ball_pitch_speeds=self.ball[:, kn.B_PITCH].copy(),
            inner_ring_tilt=(float(self.ring[kn.R_TX]), float(self.ring[kn.R_TY])),
            ring_moment=(float(self.ring[kn.R_MX]), float(self.ring[kn.R_MY])),
            ball_azimuths=np.mod(self.ball[:, kn.B_THETA], 2.0 * math.pi),
            ball_spin_speeds=self.ball[:, kn.B_SPIN].copy(),
        )
