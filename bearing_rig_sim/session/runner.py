"""The program runner's logic: which segment runs, what to command, when it ends (no ROS).

:class:`ProgramRunner` walks a :class:`~bearing_rig_sim.rig.program.TestProgram` on the
simulation clock. The ROS side (:mod:`bearing_rig_sim.session.node`) feeds it the clock, the
monitor's slip statuses, the simulator's ground truth and the load controller's force, and sends
the commands it returns.

Rules (simulation time throughout, s):

* A segment starts when the runner notices the previous one ended (the first at
  :meth:`ProgramRunner.start`); its speed profile starts there from the previous segment's
  target speed; its ramp ends at ``start + ramp duration``
  (:meth:`~bearing_rig_sim.rig.program.Segment.ramp_duration`).
* ``dwell_s``: the segment ends at ``ramp end + dwell``. Its verdict is the monitor's last state
  within the segment (stable, slipping, fault; unknown when no status came).
* ``until_stable``: the segment ends at the first ``STATE_STABLE`` status that speaks for the
  new operating point, by the rule offline analysis also uses
  (:class:`~bearing_rig_sim.monitoring.schedule.TimeToStable`): P(slope >= k) at least 0.95 on
  slip windows that all started after the ramp end (the monitor's ``slope_span_s`` and
  ``min_slope_points`` say how far back its verdict reaches). Verdict "stable", time to stable =
  that status's stamp - ramp end. Without one by ``ramp end + timeout_s``: verdict "timeout".
* Measured slip: the slip rate of the status that decided the verdict (the stable one), else the
  last status of the segment. Truth slip: the mean of the simulator's true slip over the same
  window as that status (``window_revolutions`` cage revolutions ending at its stamp), so the
  two are compared over the same stretch of time. Bearing force: mean of the load controller's
  bearing force once the load has settled (after the ramp end and at least
  :data:`LOAD_SETTLE_S` after the load controller's state first shows the segment's set-point).
  Measured speed: the monitor's inner-ring speed in the deciding status (else the segment's last),
  when it is stamped after the ramp end.
* Conditions: a segment whose measured speed or bearing force is off the commanded one by more
  than the tolerance (:func:`speed_tolerance`, :func:`~bearing_rig_sim.load_control.settle_band`),
  or during which a command, a set-point or the load controller's set-point came from outside
  the session (:meth:`ProgramRunner.observe_disturbance`,
  :meth:`ProgramRunner.observe_axial_setpoint`), is marked: its ``conditions`` say what, and the
  session's exit status says so. Its verdict is what the monitor said, under other conditions.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from enum import Enum

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.config import rad_s_to_rpm
from bearing_rig_sim.load_control import settle_band
from bearing_rig_sim.monitoring.load_sweep import sweep_key
from bearing_rig_sim.monitoring.schedule import TimeToStable, evidence_start, speed_tolerance
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.rig.program import Segment, SegmentSpeed, SpeedProfileKind, TestProgram

__all__ = [
    "ProgramRunner",
    "SegmentOutcome",
    "SegmentPlan",
    "SlipObservation",
    "StatusState",
    "Verdict",
]

TRUTH_HISTORY = 6000
"""True-slip samples kept (60 s at the simulator's 100 Hz): enough for any status window."""

LOAD_SETTLE_S = 0.5
"""Sim time after a segment's start before its load is judged, s: the loading chain's stated
settle bound is under 0.37 s for any step within 0-1000 N (``settle_time_bound``), and a set-point
sent at the start reaches the load controller within this too."""



StatusState = SlipState
"""The ``STATE_*`` constants of SlipStatus.msg: the project's one state enum."""


class Verdict(str, Enum):
    """How a segment ended; compares equal to its string value."""

    STABLE = "stable"
    """Stable slip: ``until_stable`` reached, or the monitor said stable at the end of a dwell."""
    TIMEOUT = "timeout"
    """``until_stable`` without a stable verdict within ``timeout_s``."""
    SLIPPING = "slipping"
    """End of a dwell with the monitor saying the slip still changes."""
    FAULT = "fault"
    """End of a dwell with the monitor reporting a sensor fault."""
    UNKNOWN = "unknown"
    """End of a dwell with no verdict from the monitor (no status, or not enough data)."""
    INTERRUPTED = "interrupted"
    """The session stopped during the segment."""


_DWELL_VERDICTS = {
    StatusState.STABLE: Verdict.STABLE,
    StatusState.SLIPPING: Verdict.SLIPPING,
    StatusState.FAULT: Verdict.FAULT,
    StatusState.UNKNOWN: Verdict.UNKNOWN,
}


@dataclass(frozen=True)
class SlipObservation:
    """One slip status of the monitor, as the runner uses it."""

    time: float
    """Stamp: end of the evaluation window, s of sim time."""
    state: StatusState
    slip_rate: float
    """Measured slip, %."""
    inner_ring_speed: float
    """rad/s."""
    cage_speed: float
    """rad/s."""
    window_revolutions: int
    """Whole cage revolutions in the slip window."""
    confidence: float = 0.0
    """P(slope >= k) of the monitor's verdict (1)."""
    sweep_speed: float = math.nan
    """Spindle speed of the monitor's latest load-sweep verdict, rad/s (NaN: none)."""
    sweep_verdict: str = ""
    """That verdict in words ("stable from 300 N (...)" or "no stable state: ...")."""

    @property
    def window_duration(self) -> float:
        """Time span of the slip window, s (0 when the cage speed does not give one)."""
        if self.cage_speed <= 0.0 or not math.isfinite(self.cage_speed) or self.window_revolutions <= 0:
            return 0.0
        return self.window_revolutions * 2.0 * math.pi / self.cage_speed


@dataclass(frozen=True)
class SegmentPlan:
    """A segment as started: what to command and when it may end."""

    index: int
    """0-based position in the program."""
    segment: Segment
    profile: SegmentSpeed
    """Speed against time from the start (start time, start speed, target...)."""

    @property
    def start_time(self) -> float:
        """s of sim time."""
        return self.profile.start_time

    @property
    def ramp_end(self) -> float:
        """When the target speed is reached, s of sim time."""
        return self.profile.ramp_end

    @property
    def deadline(self) -> float:
        """Latest end: ramp end + dwell, or ramp end + timeout, s of sim time."""
        hold = self.segment.dwell if self.segment.dwell is not None else self.segment.timeout
        assert hold is not None
        return self.ramp_end + hold


@dataclass(frozen=True)
class SegmentOutcome:
    """How a segment went (a row of the summary table); SI units, slip in %."""

    index: int
    name: str
    target_speed: float
    """rad/s."""
    axial_load: float
    """Set-point, N."""
    verdict: Verdict
    start_time: float
    ramp_end: float
    end_time: float
    time_to_stable: float | None
    """Stable stamp - ramp end, s; None without a stable verdict after the ramp."""
    measured_slip: float | None
    """Monitor's slip rate, %."""
    truth_slip: float | None
    """Simulator's true slip over the same window, %."""
    bearing_force: float | None
    """Mean axial force on the bearing once settled (see the module documentation), N."""
    measured_speed: float | None = None
    """Mean inner-ring speed the monitor measured after the ramp end, rad/s."""
    conditions: tuple[str, ...] = ()
    """What was off: speed or load not as commanded, disturbances from outside; empty when the
    segment ran under its own conditions."""

    @property
    def conditions_met(self) -> bool:
        """Nothing was off."""
        return not self.conditions


@dataclass
class _SegmentData:
    plan: SegmentPlan
    stable: SlipObservation | None = None
    last_status: SlipObservation | None = None
    force_sum: float = 0.0
    force_count: int = 0
    force_sum_all: float = 0.0
    force_count_all: int = 0
    statuses: int = field(default=0)
    rule: TimeToStable | None = None
    """The "stable after the ramp" rule, shared with offline analysis."""
    disturbances: list[str] = field(default_factory=list)
    setpoint_seen: float | None = None
    """When the load controller's state first showed the segment's set-point, s of sim time."""


class ProgramRunner:
    """Walks a test program on the simulation clock (see the module documentation).

    Typical use::

        runner = ProgramRunner(program)
        send(runner.start(now))                 # command the first segment
        ...                                     # feed observe_status / observe_truth / observe_load
        for plan in runner.update(now):         # segments started by this update
            send(plan)
        if runner.finished: ...                 # runner.outcomes holds one row per segment
    """

    def __init__(self, program: TestProgram, monitor_settings: MonitorSettings | None = None) -> None:
        self.program = program
        self.monitor_settings = monitor_settings if monitor_settings is not None else MonitorSettings.from_yaml()
        """The monitor's parameters: how far back its verdicts reach (the shipped ones by default)."""
        self.outcomes: list[SegmentOutcome] = []
        self._data: _SegmentData | None = None
        self._truth: deque[tuple[float, float]] = deque(maxlen=TRUTH_HISTORY)
        self._start_speeds = program.start_speeds()
        self._finished = False
        self.latest_status: SlipObservation | None = None
        """The last status received, whatever its segment."""
        self.sweeps: dict[int, str] = {}
        """The monitor's latest load-sweep verdict per spindle speed (rpm, rounded): the paper's
        "stable from N" or the reason there is none (:mod:`bearing_rig_sim.monitoring.load_sweep`)."""

    # -- state ------------------------------------------------------------------------------------
    @property
    def current(self) -> SegmentPlan | None:
        """The segment running, None before :meth:`start` and after the end."""
        return self._data.plan if self._data is not None else None

    @property
    def started(self) -> bool:
        return self._data is not None or self._finished

    @property
    def finished(self) -> bool:
        """Every segment ended (or the run was interrupted)."""
        return self._finished

    @property
    def segment_count(self) -> int:
        return len(self.program.segments)

    # -- driving ----------------------------------------------------------------------------------
    def start(self, now: float) -> SegmentPlan:
        """Start the first segment at ``now`` (s of sim time); returns its plan.

        Raises:
            RuntimeError: already started.
        """
        if self.started:
            raise RuntimeError("the program runner was started already")
        return self._begin(0, now)

    def _begin(self, index: int, now: float) -> SegmentPlan:
        segment = self.program.segments[index]
        plan = SegmentPlan(index, segment, segment.speed_profile(now, self._start_speeds[index]))
        run_up = plan.profile.start_time if plan.profile.kind is SpeedProfileKind.CONSTANT_ACCELERATION and plan.ramp_end > plan.start_time else None
        self._data = _SegmentData(plan, rule=TimeToStable(plan.ramp_end, plan.segment.target_speed, run_up))
        return plan

    def update(self, now: float) -> list[SegmentPlan]:
        """Check the running segment's end condition at ``now`` (s of sim time); end it and start
        the next when it is met. Returns the plans of the segments started (at most one)."""
        data = self._data
        if data is None:
            return []
        plan = data.plan
        verdict: Verdict | None = None
        if plan.segment.until_stable:
            if data.stable is not None:
                verdict = Verdict.STABLE
            elif now >= plan.deadline:
                verdict = Verdict.TIMEOUT
        elif now >= plan.deadline:
            last = data.last_status
            verdict = _DWELL_VERDICTS[last.state] if last is not None else Verdict.UNKNOWN
        if verdict is None:
            return []
        self._end(verdict, now)
        if plan.index + 1 < self.segment_count:
            return [self._begin(plan.index + 1, now)]
        self._finished = True
        return []

    def interrupt(self, now: float) -> SegmentOutcome | None:
        """Stop: the running segment ends as "interrupted" (returned), the program as finished."""
        outcome = self._end(Verdict.INTERRUPTED, now) if self._data is not None else None
        self._finished = True
        return outcome

    def _end(self, verdict: Verdict, now: float) -> SegmentOutcome:
        data = self._data
        assert data is not None
        plan = data.plan
        decisive = data.stable if data.stable is not None else data.last_status
        if data.stable is not None:
            assert data.rule is not None
            time_to_stable: float | None = data.stable.time - data.rule.ramp_end
        else:
            time_to_stable = None
        settled = data.force_count > 0
        if data.force_count:
            force: float | None = data.force_sum / data.force_count
        elif data.force_count_all:
            force = data.force_sum_all / data.force_count_all
        else:
            force = None
        measured_speed = (
            decisive.inner_ring_speed
            if decisive is not None and decisive.time >= plan.ramp_end and math.isfinite(decisive.inner_ring_speed)
            else None
        )
        outcome = SegmentOutcome(
            index=plan.index,
            name=plan.segment.name,
            target_speed=plan.segment.target_speed,
            axial_load=plan.segment.axial_load,
            verdict=verdict,
            start_time=plan.start_time,
            ramp_end=plan.ramp_end,
            end_time=now,
            time_to_stable=time_to_stable,
            measured_slip=decisive.slip_rate if decisive is not None else None,
            truth_slip=self.truth_slip_over(decisive) if decisive is not None else None,
            bearing_force=force,
            measured_speed=measured_speed,
            conditions=_conditions(plan.segment, measured_speed, force if settled else None, data.disturbances, verdict),
        )
        self.outcomes.append(outcome)
        self._data = None
        return outcome

    # -- observations -----------------------------------------------------------------------------
    def observe_status(self, status: SlipObservation) -> None:
        """A slip status of the monitor (any order relative to :meth:`update`)."""
        self.latest_status = status
        if status.sweep_verdict and math.isfinite(status.sweep_speed):
            self.sweeps[sweep_key(status.sweep_speed)] = status.sweep_verdict
        data = self._data
        if data is None or status.time < data.plan.start_time:
            return
        data.last_status = status
        data.statuses += 1
        assert data.rule is not None
        st = self.monitor_settings
        evidence = evidence_start(status.time, status.cage_speed, status.window_revolutions, st.slope_span_s, st.min_slope_points, st.min_window_s)
        if data.rule.observe(status.time, evidence, int(status.state), status.confidence, status.inner_ring_speed):
            data.stable = status

    def observe_truth(self, time: float, slip_rate: float) -> None:
        """The simulator's true slip rate (%) at ``time`` (s of sim time)."""
        if math.isfinite(slip_rate):
            self._truth.append((time, slip_rate))

    def observe_load(self, time: float, bearing_force: float) -> None:
        """The axial force on the bearing (N) at ``time`` (s of sim time)."""
        data = self._data
        if data is None or time < data.plan.start_time or not math.isfinite(bearing_force):
            return
        data.force_sum_all += bearing_force
        data.force_count_all += 1
        seen = data.setpoint_seen
        if seen is not None and time >= max(data.plan.ramp_end, seen + LOAD_SETTLE_S):
            data.force_sum += bearing_force
            data.force_count += 1

    def observe_axial_setpoint(self, time: float, setpoint: float) -> None:
        """The load controller's set-point in force (N) at ``time`` (s of sim time), from its
        state. The segment's own set-point starts the load's settling time (the simulator may run
        ahead of the session, so the set-point can arrive well after the segment's start in sim
        time, the previous one, or the load controller's initial 0 N, still in force); any other
        once the segment's was seen was set from outside."""
        data = self._data
        if data is None or time < data.plan.start_time:
            return
        own = data.plan.segment.axial_load
        if setpoint == own:
            if data.setpoint_seen is None:
                data.setpoint_seen = time
            return
        if data.setpoint_seen is not None:  # before it, an earlier set-point is still in force
            self.observe_disturbance(time, f"the load controller's set-point was {setpoint:g} N, not the program's {own:g} N")

    def observe_disturbance(self, time: float, what: str) -> None:
        """Something from outside the session changed the rig's conditions at ``time`` (s of sim
        time): the running segment is marked (each distinct ``what`` once)."""
        data = self._data
        if data is not None and what not in data.disturbances:
            data.disturbances.append(what)

    def truth_slip_over(self, status: SlipObservation) -> float | None:
        """Mean true slip (%) over the window of ``status``; the last sample at or before its
        stamp when the window holds none; None without any sample."""
        start = status.time - status.window_duration
        inside = [s for t, s in self._truth if start <= t <= status.time]
        if inside:
            return sum(inside) / len(inside)
        before = [s for t, s in self._truth if t <= status.time]
        return before[-1] if before else None


def _conditions(
    segment: Segment, measured_speed: float | None, bearing_force: float | None, disturbances: list[str], verdict: Verdict
) -> tuple[str, ...]:
    """What was off in a segment (see the module documentation). An interrupted segment's speed
    and load are not judged, nor a measurement that is missing (a segment shorter than
    :data:`LOAD_SETTLE_S` has no settled load)."""
    off: list[str] = []
    if verdict is not Verdict.INTERRUPTED:
        target = segment.target_speed
        if measured_speed is not None and abs(measured_speed - target) > speed_tolerance(target):
            off.append(f"speed {rad_s_to_rpm(measured_speed):.0f} rpm measured, {rad_s_to_rpm(target):.0f} rpm commanded")
        load = segment.axial_load
        if bearing_force is not None and abs(bearing_force - load) > settle_band(load):
            off.append(f"load {bearing_force:.1f} N on the bearing, {load:g} N commanded")
    off.extend(f"disturbed: {what}" for what in disturbances)
    return tuple(off)
