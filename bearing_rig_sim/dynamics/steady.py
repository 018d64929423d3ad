"""Direct steady-state solver of the default (reduced) engine at constant speed and axial load.

Under a pure axial load every ball runs the same way, so a steady state is six numbers:
ball orbit speed omega_m and spin omega_a (rad/s), cage speed Omega (rad/s), the pocket
offset u = r_m (theta - phi) (m), the ball's pivot omega_t and its pitch rate omega_p (rad/s),
the same for every ball and pocket. Instead of integrating
the equations of motion until they settle, :class:`SteadySolver` solves for these six numbers
by Newton's method on a residual built from the engine's own step:

    g(x) = (step_h(x) - x) / h

where ``step_h`` is one linearly implicit step (:func:`.kernels.step_reduced`) of length h from
the symmetric state x. That step is x + (I - h J~)^-1 h f(x) with f the model's right-hand
side, so g(x) = 0 exactly where f(x) = 0: the solution is the engine's equilibrium under the
engine's own force laws, whatever they are, and no law is restated here. The Jacobian of g is
formed by finite differences (six more steps). At the solution that Jacobian is
(I - h J~)^-1 J, and its eigenvalues tell whether integration with step h would settle there
(all real parts negative) or leave: stability as the reference integrator sees it (an unstable
mode growing faster than 1/h looks stable to both).

The six unknowns are the reduced model's dynamic states (ball centres and the inner ring's
axial position are quasi-static: the step solves them itself). A dynamic state added to the
reduced model later must be added to x here; ``test/test_dynamics_steady.py`` compares the
solver with the integration over the paper's grid and would show the omission.

Time integration stays the reference. The solver falls back to it (:data:`METHOD_INTEGRATION`
or :data:`METHOD_INTEGRATION_NEWTON`) when Newton does not converge from the starting guess
or converges to an unstable equilibrium: it then integrates from the same start, trying Newton
on the settling state every few milliseconds, and averages the integration where Newton never
converges. :meth:`SteadySolver.integrate` is the reference itself.

The model can hold two stable steady states at one operating point (rolling with creep, and
gross skid); which one is found depends on where the solution starts: from the engine's
rolling start (:meth:`BearingDynamics.initialise`: kinematic speeds, balls touching their
pockets; :data:`ORIGIN_ROLLING_START`) or from a neighbouring point's solution
(:data:`ORIGIN_CONTINUATION`), as a live load sweep would. Each result says which.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit

from bearing_rig_sim.bearing.kinematics import epicyclic_ratio, slip_pct
from bearing_rig_sim.config import rad_s_to_rpm
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.engine import BearingDynamics, ChunkAverage, DynamicsInputError, Mounting
from bearing_rig_sim.dynamics.parameters import BearingParameters

SKID_SLIP_PCT = 20.0
"""Slip (%) above which a steady state is gross skid rather than rolling with creep (the
threshold the reproduction of the paper's load sweep uses)."""

ORIGIN_ROLLING_START = "rolling_start"
"""The solution started from the engine's rolling start at this point."""
ORIGIN_CONTINUATION = "continuation"
"""The solution started from a neighbouring point's steady state."""

METHOD_NEWTON = "newton"
"""Newton on the step residual converged to a stable equilibrium from the start."""
METHOD_INTEGRATION_NEWTON = "integration+newton"
"""Newton failed from the start; integration settled and Newton polished the settled state."""
METHOD_INTEGRATION = "integration"
"""Integration only (no stable equilibrium found by Newton): time averages over a window."""

STATE_ROLLING = "rolling"
STATE_SKID = "skid"

BASIN_S = 0.002
"""Integration from the rolling start before Newton, s: whether the rolling start ends in
rolling or in gross skid is decided within about a millisecond (the skid's slip passes 10 %
in 0.5 ms at the paper's grid points that skid); Newton then skips the slow tail."""
SETTLE_S = 0.15
"""Integration: settling time before averaging, s. The traction and pocket dynamics settle in a
few milliseconds; the margin covers light-load points where the cage takes longer."""
FALLBACK_CHUNK_S = 0.005
"""Integration fallback: Newton is tried again after each chunk of this length, s."""
AVERAGE_S = 0.05
"""Integration: averaging window of the steady cage speed, s."""
PERIODIC_SETTLE_S = 0.3
"""Combined load: settling time before averaging, s. Under a radial load the cage centre moves
off the axis to where its land film carries the pockets' net push; it gets there in about
0.2 s (docs/model.md, Cage whirl)."""
METHOD_PERIODIC = "integration-periodic"
"""Combined load: integration averaged over whole ball-pass periods (:meth:`SteadySolver.periodic`)."""
WHIRL_MIN_RADIUS = 0.01
"""Cage whirl: the centre orbits only if its rms distance from the axis over the window is at
least this fraction of the land clearance, 1 (1 um for the H7006C's 100 um: ten times the
0.1 um to which the engine resolves the centre's offset, docs/model.md, Cage whirl)."""
WHIRL_MIN_ANGLE = 0.25
"""Cage whirl: the centre orbits only if its net angle turned about the axis over the window
is at least this, rad (4 % of a turn; a centre held off the axis by a radial load turns by
hundredths of a radian as the balls pass)."""

_CONVERGED, _UNSTABLE, _NOT_CONVERGED = 0, 1, 2
_STEP_TOL = 1e-11
"""Newton converges when every speed update is below this fraction of the inner-ring speed
(and the pocket-offset update below this fraction of the pocket clearance)."""
_MAX_ITER = 40
_STABILITY_MARGIN = 1e-6
"""Eigenvalues of the step-residual Jacobian with real part above this (1/s, relative to the
largest magnitude) count as unstable."""


@njit(cache=True)
def _load_state(
    x: np.ndarray, omega_i: float, rm: float, base_ball: np.ndarray, base_ring: np.ndarray, ball: np.ndarray, cage: np.ndarray, ring: np.ndarray
) -> None:
    """Write the symmetric state x = (omega_m, omega_a, Omega, u, omega_t, omega_p) into the engine arrays."""
    z = ball.shape[0]
    ball[:, :] = base_ball
    ring[:] = base_ring
    ring[kn.R_OMEGA] = omega_i
    for j in range(z):
        theta = 2.0 * math.pi * j / z
        ball[j, kn.B_THETA] = theta
        ball[j, kn.B_OMEGA] = x[0]
        ball[j, kn.B_SPIN] = x[1]
        ball[j, kn.B_PIVOT] = x[4]
        ball[j, kn.B_PITCH] = x[5]
        cage[j, kn.C_PHI] = theta - x[3] / rm
        cage[j, kn.C_OMEGA] = x[2]


@njit(cache=True)
def _residual(p: np.ndarray, x: np.ndarray, omega_i: float, load: float, h: float, arrays: tuple, g: np.ndarray) -> None:
    """g = (step_h(x) - x) / h, averaged over balls and pockets (they are identical).

    ``arrays`` = (base_ball, base_ring, ball, cage, ring, out, stats, work): the ball positions
    and ring state to start each step from (the warm start of the normal-contact solution),
    then the engine-shaped arrays the step works in (see :mod:`.kernels`).
    """
    base_ball, base_ring, ball, cage, ring, out, stats, work = arrays
    rm = p[kn.P_RM]
    _load_state(x, omega_i, rm, base_ball, base_ring, ball, cage, ring)
    kn.step_reduced(p, ball, cage, ring, out, stats, work, 1, h, load, 0.0, 0)
    z = ball.shape[0]
    wm = 0.0
    wa = 0.0
    wc = 0.0
    u = 0.0
    wt = 0.0
    wp = 0.0
    for j in range(z):
        theta = 2.0 * math.pi * j / z
        wm += ball[j, kn.B_OMEGA]
        wa += ball[j, kn.B_SPIN]
        wt += ball[j, kn.B_PIVOT]
        wp += ball[j, kn.B_PITCH]
        wc += cage[j, kn.C_OMEGA]
        u += rm * ((ball[j, kn.B_THETA] - theta) - (cage[j, kn.C_PHI] - theta))
    g[0] = (wm / z - x[0]) / h
    g[1] = (wa / z - x[1]) / h
    g[2] = (wc / z - x[2]) / h
    g[3] = (u / z - x[3]) / h
    g[4] = (wt / z - x[4]) / h
    g[5] = (wp / z - x[5]) / h


@njit(cache=True)
def _keep_warm_start(arrays: tuple) -> None:
    """The normal-contact solution of the last residual step becomes the next warm start."""
    base_ball, base_ring, ball, ring = arrays[0], arrays[1], arrays[2], arrays[4]
    base_ball[:, kn.B_R] = ball[:, kn.B_R]
    base_ball[:, kn.B_Z] = ball[:, kn.B_Z]
    base_ring[kn.R_DELTA] = ring[kn.R_DELTA]


@njit(cache=True)
def _newton(p: np.ndarray, x: np.ndarray, omega_i: float, load: float, h: float, arrays: tuple, max_iter: int) -> tuple[int, int, float]:
    """Damped Newton on the step residual from ``x`` (updated in place); ``arrays`` as for
    :func:`_residual`, its base ball positions and ring state updated to each accepted iterate.

    Returns (status, iterations, largest real part of the Jacobian's eigenvalues, 1/s).
    """
    speed_scale = max(abs(omega_i), 1.0)
    clear = max(p[kn.P_POCKET_CLEAR], 1e-9)
    scale = np.array([speed_scale, speed_scale, speed_scale, clear, speed_scale, speed_scale])
    # residual norm: the increments of one step, relative to the unknowns' scales
    rscale = h / scale
    trust = np.array([0.2, 0.2, 0.2, 1.0, 0.2, 0.2]) * scale
    g = np.zeros(6)
    gt = np.zeros(6)
    jac = np.zeros((6, 6))
    xt = np.zeros(6)
    _residual(p, x, omega_i, load, h, arrays, g)
    _keep_warm_start(arrays)
    norm = np.max(np.abs(g * rscale))
    converged = False
    it = 0
    while it < max_iter and not converged:
        it += 1
        for k in range(6):
            e = 1e-7 * scale[k]
            xt[:] = x
            xt[k] += e
            _residual(p, xt, omega_i, load, h, arrays, gt)
            jac[:, k] = (gt - g) / e
        if not np.all(np.isfinite(jac)):
            return _NOT_CONVERGED, it, 0.0
        dx = -np.linalg.solve(jac, g)
        if not np.all(np.isfinite(dx)):
            return _NOT_CONVERGED, it, 0.0
        # a trust region: speeds move by at most 20 % of the inner-ring speed per iteration,
        # the pocket offset by at most the clearance
        limit = np.max(np.abs(dx) / trust)
        if limit > 1.0:
            dx /= limit
        lam = 1.0
        accepted = False
        new_norm = norm
        for _ in range(12):
            xt[:] = x + lam * dx
            _residual(p, xt, omega_i, load, h, arrays, gt)
            new_norm = np.max(np.abs(gt * rscale))
            if new_norm <= (1.0 - 1e-4 * lam) * norm:
                accepted = True
                break
            lam *= 0.5
        converged = np.max(np.abs(dx) / scale) < _STEP_TOL
        if not accepted and not converged:
            return _NOT_CONVERGED, it, 0.0
        if accepted:
            x[:] = xt
            g[:] = gt
            norm = new_norm
            _keep_warm_start(arrays)
    if not converged:
        return _NOT_CONVERGED, it, 0.0
    eig = np.linalg.eigvals(jac.astype(np.complex128))
    worst = np.max(eig.real)
    size = np.max(np.abs(eig))
    status = _UNSTABLE if worst > _STABILITY_MARGIN * size else _CONVERGED
    return status, it, worst


@dataclass(frozen=True)
class CageWhirl:
    """The cage centre's orbit about the bearing axis over a window (:func:`cage_whirl`).

    Attributes:
        radius: rms distance of the centre from the axis over the window, m.
        angle: net angle the centre turned about the axis, rad (> 0 in the cage's direction).
        frequency: the orbit's frequency, Hz, signed as ``angle``; None when it does not orbit.
        ratio: ``frequency`` over the cage's rotation frequency, 1; None when it does not orbit.
        reason: why there is no frequency (None when there is one).
    """

    radius: float
    angle: float
    frequency: float | None
    ratio: float | None
    reason: str | None


def cage_whirl(time: np.ndarray, x: np.ndarray, y: np.ndarray, *, land_clearance: float, cage_speed: float) -> CageWhirl:
    """The cage centre's whirl from its trajectory (x, y) (m, bearing frame, the axis at the
    origin) sampled at ``time`` (s, increasing), for a cage turning at ``cage_speed`` (rad/s,
    > 0 in the direction of rotation) in a land of radial clearance ``land_clearance`` (m).

    The rate of the centre's angle about the axis, unwrapped step by step, is averaged with
    weights r^2: the mean angular momentum over the mean polar moment, x dy - y dx over
    r^2 dt, formed from successive samples as
    sum(x_k y_(k+1) - y_k x_(k+1)) / sum((x_k x_(k+1) + y_k y_(k+1)) dt_k). That is the
    orbit's rate for a circular orbit, whole or partial (to (w dt)^2/3 relative: 8e-5 at 62 Hz
    and 40 us steps); white noise on the positions adds nothing to either sum on average (the
    two samples of each product are independent); and a step passing near the axis, where the
    angle is undefined and jumps by about pi, carries no weight, so a radial oscillation
    through the axis turns no net angle. No frequency (None, with the reason) when the rms
    radius is below :data:`WHIRL_MIN_RADIUS` of the clearance or the net angle (the rate times
    the window) below :data:`WHIRL_MIN_ANGLE`.
    """
    t = np.asarray(time, dtype=float)
    px = np.asarray(x, dtype=float)
    py = np.asarray(y, dtype=float)
    r = np.hypot(px, py)
    radius = float(np.sqrt(np.mean(r * r))) if r.size else 0.0
    if t.size < 3:
        return CageWhirl(radius, 0.0, None, None, "fewer than 3 samples of the cage centre")
    momentum = float(np.sum(px[:-1] * py[1:] - py[:-1] * px[1:]))
    polar = float(np.sum((px[:-1] * px[1:] + py[:-1] * py[1:]) * np.diff(t)))
    rate = momentum / polar if polar > 0.0 else 0.0
    angle = rate * float(t[-1] - t[0])
    if radius < WHIRL_MIN_RADIUS * land_clearance:
        reason = f"centred: rms {radius * 1e6:.3g} um from the axis, below {WHIRL_MIN_RADIUS:g} of the land clearance"
        return CageWhirl(radius, angle, None, None, reason)
    if abs(angle) < WHIRL_MIN_ANGLE:
        return CageWhirl(radius, angle, None, None, f"no orbit: the centre turned {angle:.3g} rad about the axis, below {WHIRL_MIN_ANGLE:g} rad")
    frequency = rate / (2.0 * math.pi)
    ratio = rate / cage_speed if cage_speed > 0.0 else None
    return CageWhirl(radius, angle, frequency, ratio, None)


@dataclass(frozen=True)
class SteadyState:
    """A steady operating point of the bearing (SI; slip in percent at the nominal angle): the
    steady solver's result, a coupled thermal steady state's (with its temperatures), a
    calibration's or a study's row.

    A row read back from a study's cache carries the first eight quantities only: the solver's
    unknowns are then NaN and its diagnostics empty.

    Attributes:
        inner_ring_speed: rad/s.
        axial_load: N.
        cage_speed: rad/s.
        slip_pct: cage slip S_c, % (paper Eq. 11-12, nominal contact angle).
        friction_torque: friction torque on the inner ring, N m (power loss over inner-ring speed).
        power_loss: power loss of the bearing, W (:meth:`BearingDynamics.power_loss`).
        film_min_inner / film_min_outer: minimum film thickness of the inner and outer contacts,
            m (:meth:`BearingDynamics.minimum_films`; NaN without a lubricant file).
        lubricant_temperature / outer_ring_temperature: degC, the coupled thermal steady state's
            (NaN: isothermal, at the bearing file's temperature; left out of equality, NaN being
            unequal to itself).
        ball_orbit_speed: rad/s.
        ball_spin_speed: rad/s (about the rolling axis, absolute).
        pocket_offset: m, ball centre ahead of its pocket centre at the pitch radius.
        ball_pivot_speed: rad/s, the ball's pivot omega_t (about e_t, driven by the gyroscopic
            moment, resisted by the transverse tractions).
        ball_pitch_speed: rad/s, the ball's pitch rate omega_p (its angular velocity about the
            third axis of the radial-axial plane, relative to raceway control: the rolling
            axis's tilt; resisted by the contacts' spin moments).
        origin: :data:`ORIGIN_ROLLING_START` or :data:`ORIGIN_CONTINUATION` (empty: not solved here).
        method: :data:`METHOD_NEWTON`, :data:`METHOD_INTEGRATION_NEWTON`,
            :data:`METHOD_INTEGRATION` or :data:`METHOD_PERIODIC` (empty: not solved here).
        iterations: Newton iterations of the last Newton run (0 if none converged).
        stable: True when Newton found the state and its Jacobian shows a stable equilibrium;
            False for an integration average (:data:`METHOD_INTEGRATION`), not checked.
    """

    inner_ring_speed: float
    axial_load: float
    cage_speed: float
    slip_pct: float
    friction_torque: float = math.nan
    power_loss: float = math.nan
    film_min_inner: float = math.nan
    film_min_outer: float = math.nan
    lubricant_temperature: float = field(default=math.nan, compare=False)
    outer_ring_temperature: float = field(default=math.nan, compare=False)
    ball_orbit_speed: float = math.nan
    ball_spin_speed: float = math.nan
    pocket_offset: float = math.nan
    ball_pivot_speed: float = 0.0
    ball_pitch_speed: float = 0.0
    origin: str = ""
    method: str = ""
    iterations: int = 0
    stable: bool = False

    @property
    def state(self) -> str:
        """:data:`STATE_SKID` above :data:`SKID_SLIP_PCT` of slip, else :data:`STATE_ROLLING`."""
        return STATE_SKID if self.slip_pct > SKID_SLIP_PCT else STATE_ROLLING

    @property
    def vector(self) -> np.ndarray:
        """(omega_m, omega_a, Omega, u, omega_t, omega_p): the solver's unknowns, to continue from."""
        return np.array([self.ball_orbit_speed, self.ball_spin_speed, self.cage_speed, self.pocket_offset, self.ball_pivot_speed, self.ball_pitch_speed])

    def as_row(self) -> dict[str, float]:
        """The point at the edge: rpm, N, %."""
        return {
            "rpm": round(rad_s_to_rpm(self.inner_ring_speed), 6),
            "axial_load_n": self.axial_load,
            "cage_rpm": round(rad_s_to_rpm(self.cage_speed), 4),
            "slip_pct": round(self.slip_pct, 4),
        }

    def losses_row(self, composite_roughness: float = 0.0) -> dict[str, object]:
        """Torque (N m), power (W), minimum films (um) and, with a composite roughness (m), the
        film parameter lambda = h_min / sigma of the thinner contact."""
        row: dict[str, object] = {
            "friction_torque_nm": round(self.friction_torque, 6),
            "power_loss_w": round(self.power_loss, 4),
            "film_min_um": {"inner": round(self.film_min_inner * 1e6, 4), "outer": round(self.film_min_outer * 1e6, 4)},
        }
        if composite_roughness > 0.0:
            row["lambda_ratio"] = round(min(self.film_min_inner, self.film_min_outer) / composite_roughness, 3)
        return row


class SteadySolver:
    """Steady states of one bearing's default engine; reuse it for many points.

    Args:
        params: bearing data.
        step: the step h of the residual, s (default: the engine's reduced time step; the
            solution does not depend on it, only the conditioning does).
        mounting: the engine's clearance, misalignment and preload (default none); a
            misalignment breaks the axial symmetry: use :meth:`periodic` then.
    """

    def __init__(self, params: BearingParameters, *, step: float | None = None, mounting: Mounting | None = None) -> None:
        self.params = params
        self.engine = BearingDynamics(params, mounting=mounting)
        self.step = float(step) if step is not None else self.engine.time_step
        self.basin_time = BASIN_S
        self.epicyclic_ratio = epicyclic_ratio(params.ball_diameter, params.pitch_diameter, params.contact_angle)
        z = params.ball_count
        self._ball = np.zeros((z, kn.NB))
        self._cage = np.zeros((z, kn.NC))
        self._ring = np.zeros(kn.NR)
        self._out = np.zeros((z, kn.NO))
        self._stats = np.zeros(kn.NS)
        self._work = np.zeros((z, kn.NW))
        self.last_average: ChunkAverage | None = None
        """The averaging window of the last :meth:`periodic` point (its heat among them)."""
        self.last_whirl: CageWhirl | None = None
        """The cage centre's whirl over the last :meth:`periodic` point's window (:func:`cage_whirl`)."""

    # -- public --------------------------------------------------------------------------------
    def solve(self, inner_ring_speed: float, axial_load: float, start: SteadyState | None = None) -> SteadyState:
        """The steady state at ``inner_ring_speed`` (rad/s, > 0) and ``axial_load`` (N).

        Args:
            start: a neighbouring point's solution to continue from; ``None`` starts from the
                engine's rolling start at this point.

        Raises:
            DynamicsInputError: a non-finite or out-of-range input.
        """
        omega, axial_load = self._inputs(inner_ring_speed, axial_load)
        engine = self.engine
        if start is None:
            origin = ORIGIN_ROLLING_START
            engine.initialise(omega, axial_load)
            # which state the rolling start ends in is decided in its first milliseconds
            engine.advance(self.basin_time)
            x0 = self._vector_of_engine()
        else:
            origin = ORIGIN_CONTINUATION
            # the neighbour's speeds scaled to this inner-ring speed; the engine's current ball
            # positions are only the warm start of the normal-contact solution
            # (the pivot grows as the gyroscopic moment, the square of the speed)
            ratio = omega / start.inner_ring_speed
            x0 = start.vector * np.array([ratio] * 3 + [1.0, ratio * ratio, ratio * ratio])
        x = x0.copy()
        status, iterations = self._newton(x, omega, axial_load)
        if status == _CONVERGED:
            return self._point(x, omega, axial_load, origin, METHOD_NEWTON, iterations)
        # fall back to the reference: integrate from the same start, trying Newton on the way
        if start is None:
            engine.initialise(omega, axial_load)
        else:
            self._load_engine(x0, omega)
        settled = 0.0
        while settled < SETTLE_S - 1e-12:
            engine.advance(FALLBACK_CHUNK_S, axial_load=axial_load)
            settled += FALLBACK_CHUNK_S
            x = self._vector_of_engine()
            status, iterations = self._newton(x, omega, axial_load)
            if status == _CONVERGED:
                return self._point(x, omega, axial_load, origin, METHOD_INTEGRATION_NEWTON, iterations)
        return self._averaged(omega, axial_load, origin)

    def integrate(self, inner_ring_speed: float, axial_load: float) -> SteadyState:
        """The reference: integrate from the rolling start for :data:`SETTLE_S`, then average
        the cage speed over :data:`AVERAGE_S`."""
        omega, axial_load = self._inputs(inner_ring_speed, axial_load)
        self.engine.initialise(omega, axial_load)
        self.engine.advance(SETTLE_S)
        return self._averaged(omega, axial_load, ORIGIN_ROLLING_START)

    def periodic(
        self, inner_ring_speed: float, axial_load: float, radial_load: float, *, radial_angle: float = 0.0, moment: tuple[float, float] | None = None
    ) -> SteadyState:
        """The steady state under a combined load (N; ``moment`` N m with the tilts free, see
        :meth:`BearingDynamics.set_moment`), averaged over whole ball-pass periods.

        Under a radial load (or a moment) the load zone is fixed in space while the balls orbit
        through it: the steady state is periodic at the ball-pass frequency Z Omega / (2 pi),
        not a fixed point, so the four-number solve of :meth:`solve` does not apply. The engine
        is integrated from the rolling start for :data:`PERIODIC_SETTLE_S`, then over the
        fewest whole ball-pass periods 2 pi / (Z Omega) covering :data:`AVERAGE_S` (to the step:
        0.4 % of a period at 900 rpm): cage speed, slip and the friction torque (the drive's
        work over the window) are averages over whole periods; ball speeds, pocket offset and
        films are the window's last state. The cage centre is sampled every step of the window:
        its whirl is :attr:`last_whirl` (:func:`cage_whirl`).

        Raises:
            DynamicsInputError: a non-finite or out-of-range input.
        """
        omega, axial_load = self._inputs(inner_ring_speed, axial_load)
        e = self.engine
        e.initialise(omega, axial_load, radial_load=radial_load, radial_angle=radial_angle, moment=moment)
        e.advance(PERIODIC_SETTLE_S)
        period = 2.0 * math.pi / (self.params.ball_count * max(e.cage_speed, 1e-9))
        avg = self._window(math.ceil(AVERAGE_S / period) * period)
        self.last_average = avg
        x = self._vector_of_engine()
        x[2] = avg.cage_speed
        return self._engine_point(x, omega, axial_load, avg.drive_work / avg.duration, ORIGIN_ROLLING_START, METHOD_PERIODIC, 0, False)

    def _window(self, duration: float) -> ChunkAverage:
        """Advance ``duration`` s one step at a time (the same steps as one call), sampling the
        cage centre each step into :attr:`last_whirl`; the window's averages."""
        e = self.engine
        n = max(int(round(duration / e.time_step)), 1)
        times, xs, ys = np.empty(n + 1), np.empty(n + 1), np.empty(n + 1)
        times[0], xs[0], ys[0] = e.time, e.ring[kn.R_CX], e.ring[kn.R_CY]
        total = np.zeros(7)  # duration, cage and inner-ring angle, drive work, heats
        for k in range(1, n + 1):
            a = e.advance(e.time_step)
            total += (a.duration, a.cage_speed * a.duration, a.inner_ring_speed * a.duration, a.drive_work, a.heat, a.damping_heat, a.contact_damping_heat)
            times[k], xs[k], ys[k] = e.time, e.ring[kn.R_CX], e.ring[kn.R_CY]
        t = float(total[0])
        avg = (
            ChunkAverage(t, float(total[1]) / t, float(total[2]) / t, *(float(v) for v in total[3:]))
            if t > 0.0
            else ChunkAverage(0.0, e.cage_speed, e.inner_ring_speed)
        )
        self.last_whirl = cage_whirl(times, xs, ys, land_clearance=self.params.land_clearance, cage_speed=avg.cage_speed)
        return avg

    def _averaged(self, omega: float, axial_load: float, origin: str) -> SteadyState:
        avg = self.engine.advance(AVERAGE_S, axial_load=axial_load)
        x = self._vector_of_engine()
        x[2] = avg.cage_speed
        return self._point(x, omega, axial_load, origin, METHOD_INTEGRATION, 0, stable=False)

    @staticmethod
    def _inputs(inner_ring_speed: float, axial_load: float) -> tuple[float, float]:
        omega = float(inner_ring_speed)
        if not math.isfinite(omega) or omega <= 0.0:
            raise DynamicsInputError(
                f"inner_ring_speed must be finite and > 0 (at rest there is no rolling steady state: the slip is undefined), got {inner_ring_speed!r}"
            )
        return omega, float(axial_load)

    def sweep_load(self, inner_ring_speed: float, loads: list[float]) -> list[SteadyState]:
        """Continuation along ``loads`` (N) at one speed, as a live load sweep: the first point
        from the rolling start, each next one from the previous solution."""
        points: list[SteadyState] = []
        for load in loads:
            points.append(self.solve(inner_ring_speed, load, points[-1] if points else None))
        return points

    # -- internals -----------------------------------------------------------------------------
    def _vector_of_engine(self) -> np.ndarray:
        e = self.engine
        rm = float(e.vector[kn.P_RM])
        u = rm * float(np.mean(e.ball[:, kn.B_THETA] - e.cage[:, kn.C_PHI]))
        return np.array(
            [
                float(np.mean(e.ball[:, kn.B_OMEGA])),
                float(np.mean(e.ball[:, kn.B_SPIN])),
                e.cage_speed,
                u,
                float(np.mean(e.ball[:, kn.B_PIVOT])),
                float(np.mean(e.ball[:, kn.B_PITCH])),
            ]
        )

    def _load_engine(self, x: np.ndarray, omega: float) -> None:
        e = self.engine
        _load_state(x, omega, float(e.vector[kn.P_RM]), e.ball.copy(), e.ring.copy(), e.ball, e.cage, e.ring)

    def _newton(self, x: np.ndarray, omega: float, load: float) -> tuple[int, int]:
        e = self.engine
        base_ball = e.ball.copy()
        base_ring = e.ring.copy()
        try:
            arrays = (base_ball, base_ring, self._ball, self._cage, self._ring, self._out, self._stats, self._work)
            status, iterations, _ = _newton(e.vector, x, omega, load + e.preload_force, self.step, arrays, _MAX_ITER)
        except np.linalg.LinAlgError:  # a singular Jacobian: no Newton step from here
            return _NOT_CONVERGED, 0
        return int(status), int(iterations)

    def _point(self, x: np.ndarray, omega: float, load: float, origin: str, method: str, iterations: int, stable: bool = True) -> SteadyState:
        e = self.engine
        # the engine's own diagnostics (power loss, films) at the solution: one step from it
        self._load_engine(x, omega)
        e.advance(e.time_step, axial_load=load)
        return self._engine_point(x, omega, load, e.power_loss(), origin, method, iterations, stable)

    def _engine_point(self, x: np.ndarray, omega: float, load: float, power: float, origin: str, method: str, iterations: int, stable: bool) -> SteadyState:
        """The point of the state ``x`` with the engine's films as they stand, power ``power`` W."""
        film_inner, film_outer = self.engine.minimum_films()
        slip = slip_pct(float(x[2]), omega, self.epicyclic_ratio)
        return SteadyState(
            inner_ring_speed=omega,
            axial_load=float(load),
            cage_speed=float(x[2]),
            ball_orbit_speed=float(x[0]),
            ball_spin_speed=float(x[1]),
            pocket_offset=float(x[3]),
            slip_pct=slip,
            friction_torque=power / omega,
            power_loss=power,
            film_min_inner=film_inner,
            film_min_outer=film_outer,
            origin=origin,
            method=method,
            iterations=iterations,
            stable=stable,
            ball_pivot_speed=float(x[4]),
            ball_pitch_speed=float(x[5]),
        )


@functools.lru_cache(maxsize=16)
def solver_for(params: BearingParameters) -> SteadySolver:
    """One solver per parameter set and process (the engine and its kernels built once), shared
    by calibration and the sweep's workers."""
    return SteadySolver(params)
