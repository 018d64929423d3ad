"""The load controller's operation of the axial loading chain on the simulation clock (no ROS).

:class:`AxialLoadOperation` is what the ``load_controller`` node does, without the node: it owns a
:class:`~bearing_rig_sim.rig.loading.LoadingChain`, takes axial-load set-point requests from any
source (topic, service, parameter), answers each with accepted/refused and a reason, steps the
chain by the simulation time elapsed between two clock readings, says when the state and the
diagnostics are due, and keeps the health shown on ``/diagnostics``.

Policies (the node's documentation repeats them):

* **Stepping.** :meth:`AxialLoadOperation.advance_to` steps the chain by the sim time elapsed
  since the last call, in sub-steps of at most ``max_substep_s`` (1 ms), so the chain keeps up
  however many clock ticks arrive at once when the simulator runs faster than real time. The
  first clock reading only starts the count. :meth:`AxialLoadOperation.follow` does the same in
  samples: one step (and one result, i.e. one force message) per ``sample_period_s`` of sim
  time on the grid of its multiples, however late and in whatever chunks the clock is read, so
  the node can wake up once per chunk of wall time and still publish the forces at their rate. A clock that goes back (a simulator restart, a
  replay that loops) restarts the count without stepping; a forward gap longer than
  ``max_clock_gap_s`` (a paused process, a clock jump) is stepped as ``max_clock_gap_s`` only.
* **Set-points.** A request that is not a finite number, is negative or is above the chain's
  ``max_setpoint_n`` is refused: the previous set-point stays, the reason is returned and the
  health turns WARN until the next accepted set-point (or a fault reset).
* **Zero load de-energises the brake.** At a set-point of 0 N the brake is driven open loop at
  0 V (:meth:`~bearing_rig_sim.rig.loading.LoadingChain.set_manual_voltage`) instead of being
  regulated around zero force: a rope cannot push, so below zero force the loop has no feedback,
  the integrator walks on the load cell's noise and drives the plunger back to its slack stop
  (over 2 mm in 2.6 s at the shipped values); the next set-point then slams the rope taut and
  trips the rate interlock. Any set-point above 0 N returns to closed loop (bumpless, from the
  load cell's reading).
* **Interlocks** (load limit, rate limit, clutch slip; :class:`~bearing_rig_sim.rig.loading.LoadingChain`)
  latch a fault: the brake is de-energised and the health is ERROR with the interlock's reason.
  **A fault is cleared only by** :meth:`AxialLoadOperation.reset_fault` (the node's
  ``reset_fault`` service), and only once its cause is gone: the load cell reads at or below the
  load limit, the clutch no longer slips, and the set-point in force is below the clutch's
  holding force (else it would slip again at once). A set-point given while a fault is latched is
  accepted and stored, and takes effect after the reset; it does not clear the fault by itself
  (a latched interlock wants an explicit acknowledgement).
* **The force on the bearing is watched.** While the loop controls (clutch engaged, no fault,
  set-point above 0 N), a load-cell reading (in series with the bearing) outside
  :func:`settle_band` of the set-point for longer than :func:`settle_time_bound` of that step is
  an ERROR naming the set-point and the bound, until the force is back in the band. A new
  set-point, an engagement or a reset starts the count again from the force at that moment.

* **Set-points stamped ahead** (:meth:`AxialLoadOperation.request_load`): a whole load set-point
  (axial, radial, moment) with the simulation time it takes effect. It is judged on arrival
  (refused as a whole, reported as any refusal, when one part would be) and, accepted, kept until
  the chain's time reaches its stamp: the chain is stepped to the stamp, the set-point applied,
  and the step goes on from there, so it is in force from its stamp exactly, not a sample before
  (a stamp at or before the chain's time, or none, applies it at once). Without real time the
  simulator runs ahead of whoever sends the set-points; stamped with a segment's start and sent
  ahead, a set-point reaches the bearing when the segment starts however late its sender runs.
* **Radial load and moment** (:meth:`AxialLoadOperation.request_radial`): a separate loader,
  not the axial chain (the paper's bench has none; a bench that loads radially states its limits
  in the rig file's ``combined_loading`` section). Its set-point, a :class:`RadialLoad`, is
  applied as given from the next force sample on (the section states no dynamics of the radial
  loader) and travels in force.x/y and torque.x/y of the force on the bearing. One with a
  component that is not a finite number, or a magnitude above
  ``combined_loading.max_radial_setpoint_n`` (force) or ``max_moment_setpoint_n_m`` (moment)
  is refused: the previous one stays and the health turns WARN until the next accepted one. The
  axial chain's interlocks do not act on it.

Units: N, N m, s throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

from typing import TYPE_CHECKING

from bearing_rig_sim.errors import RigError
from bearing_rig_sim.health import Health, HealthLevel
from bearing_rig_sim.rig.loading import ClutchState, LoadChainState, LoadingChain, LoadingChainConfig, SetpointError
from bearing_rig_sim.rig.program import RigLimits

if TYPE_CHECKING:
    from bearing_rig_sim.load_control.settings import LoadControllerSettings


class SetpointSource(str, Enum):
    """Where a set-point request came from; compares equal to its string value."""

    TOPIC = "topic"
    SERVICE = "service"
    PARAMETER = "parameter"


@dataclass(frozen=True)
class Reply:
    """Answer to a request (set-point, fault reset, clutch command)."""

    accepted: bool
    message: str
    """Why it was refused, or what is now in force."""


@dataclass(frozen=True)
class AdvanceResult:
    """What one clock reading did (see :meth:`AxialLoadOperation.advance_to`)."""

    time: float
    """Simulation time now, s."""
    stepped: float
    """Chain time advanced, s (0 for the first reading or a clock that went back)."""
    state: LoadChainState
    """The chain's state after the step."""
    state_due: bool
    """The state message is due (one per ``state_period_s`` of sim time)."""
    diagnostics_due: bool
    """The diagnostics are due: their period of sim time elapsed, or the health changed since
    last reported (the caller publishes them; the health counts as reported)."""
    tripped: str
    """The interlock reason if a fault latched during this step, else empty."""
    clock_note: str
    """Why the clock was not stepped as read (went back, gap capped); empty normally."""
    applied: tuple[Reply, ...] = ()
    """Set-points stamped ahead (:meth:`AxialLoadOperation.request_load`) that took effect during
    this step, in order."""


@dataclass(frozen=True)
class RadialLoad:
    """A radial-load set-point in the bearing's frame (the fields of
    ``/rig/load/setpoint``'s wrench besides the axial force.z).

    The radial force is the magnitude of (``force_x``, ``force_y``) at the azimuth
    atan2(force_y, force_x); the moment across the axis is (``torque_x``, ``torque_y``).
    """

    force_x: float = 0.0
    """Radial force along the bearing frame's x axis, N."""
    force_y: float = 0.0
    """Radial force along the y axis, N."""
    torque_x: float = 0.0
    """Moment about the x axis, N m."""
    torque_y: float = 0.0
    """Moment about the y axis, N m."""

    @property
    def radial_n(self) -> float:
        """The radial force's magnitude, N."""
        return math.hypot(self.force_x, self.force_y)

    @property
    def moment_n_m(self) -> float:
        """The moment's magnitude, N m."""
        return math.hypot(self.torque_x, self.torque_y)


class AxialLoadOperation:
    """Set-point requests, fault latch and reset, and clock-driven stepping of a loading chain.

    Args:
        chain: the loading chain to operate (its clutch is engaged here when ``engage`` is True).
        state_period_s: sim time between two state messages, s (> 0).
        diagnostics_period_s: sim time between two periodic diagnostics, s (> 0).
        max_clock_gap_s: longest clock advance stepped at once, s (> 0).
        sample_period_s: sim time between two force samples of :meth:`follow`, s (> 0).
        engage: engage the clutch at start.
        radial_limits: the rig file's limits of radial-load set-points (``combined_loading``;
            default: the shipped ``config/rig.yaml``'s, 0 N and 0 N m: the paper's bench loads
            only axially).

    The values come from :class:`~bearing_rig_sim.load_control.settings.LoadControllerSettings`
    (``config/load_controller.yaml``); there are no defaults here.

    Raises:
        RigError: a period or gap that is not a finite number > 0.
    """

    def __init__(
        self,
        chain: LoadingChain,
        *,
        state_period_s: float,
        diagnostics_period_s: float,
        max_clock_gap_s: float,
        sample_period_s: float,
        engage: bool,
        radial_limits: RigLimits | None = None,
    ) -> None:
        for name, value in (
            ("state_period_s", state_period_s),
            ("diagnostics_period_s", diagnostics_period_s),
            ("max_clock_gap_s", max_clock_gap_s),
            ("sample_period_s", sample_period_s),
        ):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0.0:
                raise RigError(f"load controller: {name} must be a finite number > 0 s, got {value!r}")
        self.chain = chain
        self.state_period = float(state_period_s)
        self.diagnostics_period = float(diagnostics_period_s)
        self.max_clock_gap = float(max_clock_gap_s)
        self.sample_period_ns = max(1, round(float(sample_period_s) * 1e9))
        self._time: float | None = None
        self._next_state = 0.0
        self._next_diagnostics = 0.0
        self._refusal = ""
        self._reported: Health | None = None
        self._watched: tuple[float, bool, bool] | None = None
        self._off_since: float | None = None
        self._off_bound = 0.0
        self._unmet = ""
        self.radial_limits = radial_limits
        self.radial = RadialLoad()
        """The radial-load set-point in force (:meth:`request_radial`)."""
        self._radial_refusal = ""
        self._pending: list[tuple[int, int, float, RadialLoad, str]] = []
        """Set-points stamped ahead, not in force yet: (stamp in ns, arrival order, axial N,
        radial load, source), sorted."""
        self._arrivals = 0
        if engage:
            chain.engage()
        self._apply_zero_load_rule()

    @classmethod
    def from_config(cls, config: LoadingChainConfig, **options: float | bool) -> AxialLoadOperation:
        """An operation of a new chain built from ``config``, run as the shipped
        ``config/load_controller.yaml`` says, with ``options`` (constructor keywords) overriding."""
        from bearing_rig_sim.load_control.settings import LoadControllerSettings

        settings = LoadControllerSettings.from_yaml()
        values: dict[str, float | bool] = {
            "state_period_s": 1.0 / settings.state_rate_hz,
            "diagnostics_period_s": settings.diagnostics_period_s,
            "max_clock_gap_s": settings.max_clock_gap_s,
            "sample_period_s": 1.0 / settings.force_rate_hz,
            "engage": settings.engage_clutch_on_start,
        }
        values.update(options)
        return cls(LoadingChain(config), **values)  # type: ignore[arg-type]  # keywords checked by the constructor

    @classmethod
    def from_settings(cls, config: LoadingChainConfig, settings: LoadControllerSettings) -> AxialLoadOperation:
        """An operation of a new chain built from ``config``, run as ``settings`` say."""
        return cls(
            LoadingChain(config),
            state_period_s=1.0 / settings.state_rate_hz,
            diagnostics_period_s=settings.diagnostics_period_s,
            max_clock_gap_s=settings.max_clock_gap_s,
            sample_period_s=1.0 / settings.force_rate_hz,
            engage=settings.engage_clutch_on_start,
            radial_limits=RigLimits.from_rig_file(settings.rig_file),
        )

    # -- requests ---------------------------------------------------------------------------------
    @property
    def time(self) -> float | None:
        """Simulation time of the last clock reading, s; None before the first."""
        return self._time

    @property
    def setpoint(self) -> float:
        """Set-point in force, N."""
        return self.chain.setpoint

    def request_setpoint(self, force_n: object, source: SetpointSource | str) -> Reply:
        """Ask for an axial load of ``force_n`` N.

        Returns:
            Accepted (the set-point in force, noting a latched fault), or refused with the reason
            (the previous set-point stays; the health turns WARN until the next accepted one).
        """
        origin = SetpointSource(source).value
        try:
            self.chain.set_setpoint(force_n)  # type: ignore[arg-type]  # any object: the chain validates and refuses it
        except SetpointError as exc:
            self._refusal = f"set-point by {origin} refused: {exc}"
            return Reply(False, self._refusal)
        self._refusal = ""
        self._apply_zero_load_rule()
        message = f"axial-load set-point {self.chain.setpoint:g} N (by {origin})"
        if self.chain.fault:
            message += f"; interlock fault latched ({self.chain.fault_reason}): takes effect after reset_fault"
        return Reply(True, message)

    def check_setpoint(self, force_n: object, source: SetpointSource | str) -> Reply:
        """Whether :meth:`request_setpoint` would accept ``force_n`` N, without applying it: for a
        validation step ahead of the request (a ROS parameter's). A refusal counts as one (the
        health turns WARN with the reason until the next accepted set-point).

        Returns:
            Accepted with an empty message, or refused with the reason.
        """
        origin = SetpointSource(source).value
        try:
            self.chain.check_setpoint(force_n)
        except SetpointError as exc:
            self._refusal = f"set-point by {origin} refused: {exc}"
            return Reply(False, self._refusal)
        return Reply(True, "")

    def request_radial(self, load: RadialLoad, source: SetpointSource | str) -> Reply:
        """Ask for a radial force and a moment (see the module documentation); ``load`` may
        hold anything in its fields (a message's), judged here.

        Returns:
            Accepted (the set-point in force), or refused with the reason naming the rig file's
            limit (the previous one stays; the health turns WARN until the next accepted one).
        """
        origin = SetpointSource(source).value
        reason = self._radial_reason(load)
        if reason:
            self._radial_refusal = f"radial set-point by {origin} refused: {reason}"
            return Reply(False, self._radial_refusal)
        self._radial_refusal = ""
        self.radial = RadialLoad(*(float(v) for v in (load.force_x, load.force_y, load.torque_x, load.torque_y)))
        return Reply(True, f"radial-load set-point {self.radial.radial_n:g} N, moment {self.radial.moment_n_m:g} N m (by {origin})")

    def request_load(self, axial_n: object, radial: RadialLoad, at: float | None, source: SetpointSource | str) -> Reply:
        """Ask for a whole load set-point (``axial_n`` N and ``radial``) in force from the
        simulation time ``at`` (s; None: at once); see the module documentation.

        Returns:
            Refused (as a whole, with the reasons; the health turns WARN as for
            :meth:`request_setpoint` and :meth:`request_radial`), accepted and in force (no stamp,
            or one the chain's time has reached), or accepted and waiting for its stamp.
        """
        origin = SetpointSource(source).value
        reasons = []
        try:
            self.chain.check_setpoint(axial_n)  # any object: the chain validates it
        except SetpointError as exc:
            self._refusal = f"set-point by {origin} refused: {exc}"
            reasons.append(self._refusal)
        radial_reason = self._radial_reason(radial)
        if radial_reason:
            self._radial_refusal = f"radial set-point by {origin} refused: {radial_reason}"
            reasons.append(self._radial_refusal)
        if reasons:
            return Reply(False, "; ".join(reasons))
        axial = float(axial_n)  # type: ignore[arg-type]  # a number: checked above
        stamp_ns = None if at is None else round(at * 1e9)
        if stamp_ns is None or (self._time is not None and stamp_ns <= round(self._time * 1e9)):
            return self._apply_load(axial, radial, origin)
        self._arrivals += 1
        self._pending.append((stamp_ns, self._arrivals, axial, radial, origin))
        self._pending.sort(key=lambda p: (p[0], p[1]))
        return Reply(True, f"load set-point {axial:g} N axial, {radial.radial_n:g} N radial: in force from t = {stamp_ns * 1e-9:.9g} s (by {origin})")

    @property
    def pending(self) -> int:
        """Set-points stamped ahead and not in force yet."""
        return len(self._pending)

    def drop_pending(self) -> int:
        """Forget the set-points stamped ahead (they belong to the run that sent them); returns
        how many there were."""
        count, self._pending = len(self._pending), []
        return count

    def _apply_load(self, axial_n: float, radial: RadialLoad, origin: str) -> Reply:
        """Put a judged load set-point in force: one reply for both parts."""
        axial = self.request_setpoint(axial_n, origin)
        side = self.request_radial(radial, origin)
        if not (axial.accepted and side.accepted):  # pragma: no cover - judged on arrival
            return Reply(False, "; ".join(r.message for r in (axial, side) if not r.accepted))
        return Reply(True, f"{axial.message}; {side.message}" if radial.radial_n or radial.moment_n_m else axial.message)

    def _step_applying(self, start: float, end: float) -> tuple[LoadChainState, tuple[Reply, ...]]:
        """Step the chain from ``start`` to ``end`` (s of sim time), putting each set-point stamped
        within (start, end] in force at its stamp."""
        applied = []
        at = start
        end_ns = round(end * 1e9)
        while self._pending and self._pending[0][0] <= end_ns:
            stamp_ns, _order, axial, radial, origin = self._pending.pop(0)
            when = stamp_ns * 1e-9
            if when > at:
                self.chain.step(when - at)
                at = when
            applied.append(self._apply_load(axial, radial, origin))
        return (self.chain.step(end - at) if end > at else self.chain.state()), tuple(applied)

    def _apply_due(self, now: float) -> tuple[Reply, ...]:
        """Put in force at once every set-point stamped at or before ``now`` (s)."""
        now_ns = round(now * 1e9)
        applied = []
        while self._pending and self._pending[0][0] <= now_ns:
            _stamp, _order, axial, radial, origin = self._pending.pop(0)
            applied.append(self._apply_load(axial, radial, origin))
        return tuple(applied)

    def _radial_reason(self, load: RadialLoad) -> str:
        """Why ``load`` cannot be applied; empty when it can."""
        for name in ("force_x", "force_y", "torque_x", "torque_y"):
            value = getattr(load, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                return f"{name.replace('_', '.')} must be a finite number, got {value!r}"
        if self.radial_limits is None:
            self.radial_limits = RigLimits.from_rig_file()
        limits = self.radial_limits
        for what, size, limit, unit, key in (
            ("radial force", load.radial_n, limits.max_radial_load_n, "N", "max_radial_setpoint_n"),
            ("moment", load.moment_n_m, limits.max_moment_n_m, "N m", "max_moment_setpoint_n_m"),
        ):
            if size > limit:
                return f"{what} {size:g} {unit} is above the rig's limit of {limit:g} {unit} (combined_loading.{key} in {limits.source})"
        return ""

    def _apply_zero_load_rule(self) -> None:
        """Brake de-energised (open loop, 0 V) at a 0 N set-point, closed loop otherwise."""
        self.chain.set_manual_voltage(0.0 if self.chain.setpoint == 0.0 else None)

    def fault_cause_present(self) -> str:
        """Why a latched fault cannot be reset yet; empty when its cause is gone."""
        state = self.chain.state()
        limit = self.chain.config.interlocks.max_force_n
        if state.load_cell_force > limit:
            return f"the load cell still reads {state.load_cell_force:.1f} N > max_force_n {limit:g} N"
        if state.clutch_state is ClutchState.SLIPPING:
            return "the clutch is still slipping"
        holding = self.chain.config.clutch.holding_force_n
        if self.chain.setpoint >= holding:
            return f"the set-point {self.chain.setpoint:g} N would make the clutch slip (holding force {holding:g} N): lower it first"
        return ""

    def reset_fault(self) -> Reply:
        """Clear a latched interlock fault once its cause is gone (see the module documentation).

        Returns:
            Accepted (fault cleared, or none was latched), or refused with what still persists.
        """
        if not self.chain.fault:
            self._refusal = ""
            return Reply(True, "no interlock fault latched")
        cause = self.fault_cause_present()
        if cause:
            return Reply(False, f"fault not reset ({self.chain.fault_reason}): {cause}")
        reason = self.chain.fault_reason
        self.chain.reset_fault()
        self._apply_zero_load_rule()  # a trip leaves the chain's manual mode
        self._refusal = ""
        return Reply(True, f"fault reset ({reason}); set-point {self.chain.setpoint:g} N in force")

    def set_clutch(self, engage: bool) -> Reply:
        """Engage (True) or release (False) the magnet clutch."""
        if engage:
            self.chain.engage()
            return Reply(True, "clutch engaged")
        self.chain.release()
        return Reply(True, "clutch released: no axial load reaches the bearing")

    # -- clock ----------------------------------------------------------------------------------
    def advance_to(self, sim_time: float) -> AdvanceResult:
        """Step the chain to the simulation time ``sim_time`` (s) (see the module documentation).

        Raises:
            RigError: ``sim_time`` is not a finite number >= 0.
        """
        if isinstance(sim_time, bool) or not isinstance(sim_time, (int, float)) or not math.isfinite(sim_time) or sim_time < 0.0:
            raise RigError(f"load controller: clock time must be a finite number >= 0 s, got {sim_time!r}")
        was_faulted = self.chain.fault
        previous = self._time
        note = ""
        stepped = 0.0
        state: LoadChainState | None = None
        applied: tuple[Reply, ...] = ()
        if previous is None:
            self._schedule_from(sim_time)
            applied = self._apply_due(sim_time)
        elif sim_time < previous:
            note = f"clock went back from {previous:.6f} s to {sim_time:.6f} s: restarting the step count"
            self._schedule_from(sim_time)
            applied = self._apply_due(sim_time)
        elif sim_time > previous:
            stepped = sim_time - previous
            if stepped > self.max_clock_gap:
                note = f"clock advanced {stepped:.3f} s at once: stepping {self.max_clock_gap:g} s (max_clock_gap_s)"
                stepped = self.max_clock_gap
                applied = self._apply_due(sim_time)
                state = self.chain.step(stepped)
            else:
                state, applied = self._step_applying(previous, float(sim_time))  # the state after the step
        self._time = float(sim_time)
        if state is None:
            state = self.chain.state()
        self._watch_force(float(sim_time), state)
        state_due = sim_time >= self._next_state - 1e-9
        if state_due:
            self._next_state = _next_multiple(sim_time, self.state_period)
        health = self.health()
        diagnostics_due = sim_time >= self._next_diagnostics - 1e-9 or health != self._reported
        if diagnostics_due:  # the caller publishes them now
            self._next_diagnostics = sim_time + self.diagnostics_period
            self._reported = health
        tripped = state.fault_reason if state.fault and not was_faulted else ""
        return AdvanceResult(float(sim_time), stepped, state, state_due, diagnostics_due, tripped, note, applied)

    def follow(self, sim_time: float) -> list[AdvanceResult]:
        """Step the chain to ``sim_time`` (s) in samples (see the module documentation).

        Returns one result per multiple of ``sample_period_s`` passed since the last reading (in
        order; each stepped from the previous one), or the single result of
        :meth:`advance_to` for the first reading, a clock that went back or a gap longer than
        ``max_clock_gap_s``. Empty when the clock has not reached the next sample.

        Raises:
            RigError: ``sim_time`` is not a finite number >= 0.
        """
        previous = self._time
        if (
            previous is None
            or isinstance(sim_time, bool)
            or not isinstance(sim_time, (int, float))
            or not math.isfinite(sim_time)
            or sim_time < previous
            or sim_time - previous > self.max_clock_gap
        ):
            return [self.advance_to(sim_time)]
        period = self.sample_period_ns
        first = round(previous * 1e9) // period + 1
        last = round(sim_time * 1e9) // period
        return [self.advance_to(k * period * 1e-9) for k in range(first, last + 1)]

    def _settle_bound(self, start_n: float, target_n: float) -> float:
        # a band wider than half the set-point (small set-points) is stated as half of it
        return settle_time_bound(self.chain.config, start_n, target_n, min(settle_band(target_n) / target_n, 0.5))

    def _watch_force(self, now: float, state: LoadChainState) -> None:
        """The settle rule of the module documentation."""
        chain = self.chain
        target = chain.setpoint
        controlling = chain.clutch.engaged and not chain.fault and target > 0.0
        watched = (target, chain.clutch.engaged, chain.fault)
        if not controlling:
            self._watched, self._off_since, self._unmet = watched, None, ""
            return
        band = settle_band(target)
        force = state.load_cell_force
        if watched != self._watched:  # a new target: the step starts now
            self._watched, self._unmet = watched, ""
            self._off_since, self._off_bound = None, 0.0
            if abs(force - target) > band:
                self._off_since = now
                self._off_bound = self._settle_bound(max(force, 0.0), target)
            return
        if abs(force - target) <= band:
            self._off_since, self._unmet = None, ""
            return
        if self._off_since is None:  # left the band: the loop has a step's bound to restore it
            self._off_since = now
            self._off_bound = self._settle_bound(max(force, 0.0), target)
        if now - self._off_since > self._off_bound and not self._unmet:
            self._unmet = (
                f"set-point {target:g} N not reached: the load cell read outside {target:g} +- {band:.3g} N for longer "
                f"than the settle bound {self._off_bound:.3g} s"
            )

    def _schedule_from(self, sim_time: float) -> None:
        self._next_state = sim_time
        self._next_diagnostics = sim_time

    # -- health -----------------------------------------------------------------------------------
    def health(self) -> Health:
        """ERROR while an interlock fault is latched, WARN after a refused set-point, else OK.

        The message changes only with the condition (not with the measured force), so "the
        health changed" means something happened; the live values go beside it."""
        chain = self.chain
        if chain.fault:
            return Health(HealthLevel.ERROR, (f"interlock: {chain.fault_reason}",))
        if self._unmet:
            return Health(HealthLevel.ERROR, (self._unmet,))
        refusals = tuple(r for r in (self._refusal, self._radial_refusal) if r)
        if refusals:
            return Health(HealthLevel.WARN, refusals)
        if chain.clutch.state is ClutchState.RELEASED:
            return Health(HealthLevel.OK, (f"clutch released; set-point {chain.setpoint:g} N",))
        if chain.setpoint == 0.0:
            return Health(HealthLevel.OK, ("set-point 0 N: brake de-energised",))
        return Health(HealthLevel.OK, (f"controlling the axial load; set-point {chain.setpoint:g} N",))

    def mark_reported(self, health: Health | None) -> None:
        """Note that ``health`` was published (diagnostics are due again when it changes;
        None: nothing was, so they are due at once)."""
        self._reported = health

    def health_changed(self) -> bool:
        """The health differs from the one last reported."""
        return self.health() != self._reported


def _next_multiple(t: float, period: float) -> float:
    """The first multiple of ``period`` after ``t``."""
    return (math.floor(t / period + 1e-9) + 1) * period


def closed_loop_time_constant(config: LoadingChainConfig, force_n: float) -> float:
    """Time constant of the closed force loop near ``force_n`` N, s.

    The PI controller with Ti = Kp/Ki = L/R cancels the coil's pole, leaving a first-order loop
    ``tau = (L/R) / (Kp K)``, K the plant gain d(bearing force)/d(voltage) at that force:
    ``K = k_f (1 - (F_b/F_sat)^2) r / R`` (tanh saturation of the brake, lever ratio r; the
    mechanics, some hundred hertz, is much faster and left out).
    """
    brake, controller = config.brake, config.controller
    brake_force = force_n / config.lever.force_ratio
    slope = brake.force_constant_n_per_a * max(0.0, 1.0 - (brake_force / brake.saturation_force_n) ** 2)
    gain = slope * config.lever.force_ratio / brake.resistance_ohm
    return (brake.inductance_h / brake.resistance_ohm) / (controller.proportional_gain_v_per_n * gain)


SETTLE_BAND_FRACTION = 0.02
"""Settled: within 2 % of the set-point (the band :func:`settle_time_bound` uses by default) ..."""
SETTLE_BAND_MIN_N = 5.0
"""... or within 5 N, whichever is wider: five standard deviations of the load cell's noise
(``noise_std_n`` 1 N), so that noise alone never leaves the band."""


def settle_band(target_n: float) -> float:
    """Half-width of the band the force settles into around a set-point of ``target_n`` N, N."""
    return max(SETTLE_BAND_FRACTION * target_n, SETTLE_BAND_MIN_N)


def settle_time_bound(config: LoadingChainConfig, start_n: float, target_n: float, band: float = 0.02) -> float:
    """Longest time for the bearing force to settle within ``band`` (fraction) of ``target_n``
    after a set-point step from a settled ``start_n``, s.

    The set-point ramps at ``setpoint_rate_n_per_s`` (``|target - start| / rate``); a first-order
    loop following a ramp lags by ``rate * tau``, which then decays to ``band * target`` in
    ``tau ln(rate tau / (band target))``; 2 tau more cover what the first-order picture leaves
    out (the coil pole not exactly cancelled away from the working point, the load cell's filter,
    one control period of delay). tau is the slower of the two ends
    (:func:`closed_loop_time_constant`).
    """
    if target_n <= 0.0 or not 0.0 < band < 1.0:
        raise RigError(f"settle_time_bound: need target_n > 0 N and 0 < band < 1, got {target_n!r}, {band!r}")
    rate = config.controller.setpoint_rate_n_per_s
    tau = max(closed_loop_time_constant(config, f) for f in (start_n, target_n))
    return abs(target_n - start_n) / rate + tau * max(0.0, math.log(rate * tau / (band * target_n))) + 2.0 * tau
