"""The program runner's logic: which segment runs, what to command, when it ends (no ROS).

:class:`ProgramRunner` walks a :class:`~bearing_rig_sim.rig.program.TestProgram` on the
simulation clock. The ROS side (:mod:`bearing_rig_sim.session.node`) feeds it the clock, the
monitor's slip statuses, the simulator's ground truth and the load controller's force, and sends
the commands it returns.

Rules (simulation time throughout, s):

* A segment starts where its spindle command is stamped to take effect: the first at
  :meth:`ProgramRunner.start`; one after a ``dwell_s`` segment at that segment's end
  (``ramp end + dwell``, known from its start on); one after an ``until_stable`` segment when the
  runner notices the previous one ended. Its speed profile starts there from the previous
  segment's target speed; its ramp ends at ``start + ramp duration``
  (:meth:`~bearing_rig_sim.rig.program.Segment.ramp_duration`).
* **Commands ahead of time** (:meth:`ProgramRunner.commands_due`): the command of a segment whose
  start is fixed (every segment before it a dwell segment) is sent up to :data:`COMMAND_LEAD_S`
  (in real time :data:`REALTIME_COMMAND_LEAD_S`) before that start, stamped with it; the
  simulator queues it and applies it exactly then. Without real time the simulator runs ahead of the session's clock (up
  to its ``SESSION_LEAD_S``, 2 s of sim time, past the session's ``/rig/session/progress``),
  and a command stamped with the session's own, older, clock takes effect when it arrives: the spindle's ramp then starts and ends late, the segment's speed is judged against a
  plan the spindle does not follow (a stop still turning at its "ramp end"), and a run-up's time
  to stable counts from a start that was not the spindle's. Stamped ahead, the plan, the
  spindle and the recorded command (``analyze`` times segments by its stamp) agree.
* ``dwell_s``: the segment ends at ``ramp end + dwell``. Its verdict is the monitor's last state
  within the segment (stable, slipping, fault; unknown when no status came).
* ``until_stable``: the segment ends at the first ``STATE_STABLE`` status that speaks for the
  new operating point, by the rule offline analysis also uses
  (:class:`~bearing_rig_sim.monitoring.schedule.TimeToStable`): P(slope >= k) at least the monitor's ``stable_confidence`` (0.6) on
  slip windows that all started after the ramp end (the monitor's ``slope_span_s`` and
  ``min_slope_points`` say how far back its verdict reaches). Verdict "stable", time to stable =
  that status's stamp - ramp end. Without one by ``ramp end + timeout_s``: verdict "timeout".
* A **run-up** (a constant-acceleration segment) is judged during its acceleration, as the paper
  judges it (section 4.2, Table 7): its time to stable counts from the run-up's start, and the
  stable status may come before the target speed (the summary says at which speed).
* Measured slip: the slip rate of the status that decided the verdict (the stable one), else of
  the last status of the segment when its window began after the ramp end (none otherwise: a
  stop's last windows are the deceleration's). Truth slip: the mean of the simulator's true slip over the same
  window as that status (``window_revolutions`` cage revolutions ending at its stamp), so the
  two are compared over the same stretch of time; none when that status has no window (a stop
  that stopped: the monitor reports the rig stopped, and neither slip is defined). Bearing force: mean of the load controller's
  bearing force once the load has settled (after the ramp end and at least
  :data:`LOAD_SETTLE_S` after the load controller's state first shows the segment's set-point).
  Measured speed: the monitor's inner-ring speed in the segment's last status, when it is stamped
  after the ramp end: the speed held at the end, not that of the status that decided the verdict
  (a run-up is judged stable during its acceleration). A window closes only at a spindle pulse
  at or after its end, so a stop that stopped has none after its ramp (its last window closes
  during the ramp, and is not judged), and a stop whose spindle still turns is measured turning.
* **Statuses through the end** (with ``monitor_guard_s``, as a session runs it): a segment that
  ends at its deadline (a dwell's end, an ``until_stable`` timeout) ends only once a status
  stamped at or after that deadline has come, so its verdict and slip rest on every status of
  the segment however far the monitor lags the clock; after ``monitor_guard_s`` of wall time
  without one it ends anyway, named in :attr:`ProgramRunner.unconfirmed`.
* Observations stamped at or after the end of a dwell segment belong to the next segment (the
  simulator may be there already, its command having been sent ahead): they are kept until the
  runner starts it.
* **Set-points ahead of time** (:meth:`ProgramRunner.setpoints_due`): each segment's load
  set-point, stamped with the segment's start, is sent as soon as that start is fixed (without
  real time every set-point of a run of dwell segments at once; in real time
  :data:`REALTIME_COMMAND_LEAD_S` ahead, as a command) and at the start otherwise; the load
  controller keeps it until its stamp. The first segment's goes out before the program's clock
  starts: the session starts the runner once the load controller shows it in force
  (``start(..., setpoint_sent=True)``). A lead like the commands' 9 s was not enough: under four
  busy loops on two cores the simulator ran more than 9 s ahead of the session (its recorder's
  readers acknowledge from the middleware's thread, so the session's Python may lag far behind),
  and four of 40 load-sweep segments began on the previous set-point.
* **The load is judged sample by sample**: every bearing force of the load controller's state
  from :data:`LOAD_SETTLE_S` after the segment's start (after a fixed start, whose set-point was
  sent ahead and is in force from the start), or after the load controller's state first showed
  the set-point (the first segment, and one after an ``until_stable`` segment, whose set-point
  leaves when the session notices the start and may reach a load controller running ahead of it
  later in sim time), to the segment's end must lie within
  :func:`~bearing_rig_sim.load_control.settle_band` of the set-point; so must the axial load the
  simulator applied (its ground truth, where there is one: what the bearing carried) and, in a
  program that loads radially, the radial force on the bearing (force.x/y of the load
  controller's force on the bearing, against the segment's, within the band of its magnitude).
  The worst sample outside names the segment's condition; a set-point the load controller never
  showed during a segment longer than :data:`LOAD_SETTLE_S` does too.
* Conditions: a segment whose measured speed is off the commanded one by more than the tolerance
  (:func:`speed_tolerance`), whose load is off (above), or during which a command, a set-point or the load controller's set-point came from outside
  the session (:meth:`ProgramRunner.observe_disturbance`,
  :meth:`ProgramRunner.observe_axial_setpoint`), is marked: its ``conditions`` say what, and the
  session's exit status says so. Its verdict is what the monitor said, under other conditions.
"""

from __future__ import annotations

import math
from time import monotonic
from collections import deque
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

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

COMMAND_LEAD_S = 9.0
"""How long before a segment's fixed start its spindle command is sent without real time, s of
sim time: more than the simulator runs ahead of the session, which it bounds by its
``SESSION_LEAD_S`` (2 s) past the session's progress (before that bound, 1.4 s in the runs that
failed before commands were sent ahead, and over 9 s under six busy loops, where a stop command
arrived 1.1 s late), and under the simulator's ``max_command_lead_s`` (10 s), which it counts
from its own clock, later than the session's. In the acceleration program a run-up's
command goes out 6-9 s ahead (from the start of the run-up before the stop that precedes it)."""

REALTIME_COMMAND_LEAD_S = 1.0
"""The same in real time, s: the rig's clock is the wall clock's, and a command queued in the
drive outlives an interrupted session by at most this."""

LOAD_SETTLE_S = 0.5
"""Sim time after a segment's start before its load is judged, s: the loading chain's stated
settle bound is under 0.37 s for any step within 0-1000 N (``settle_time_bound``), and the
simulator applies the force on the bearing within its ``FORCE_LEAD_S`` (0.1 s) of it."""

STAMP_RESOLUTION_S = 1e-6
"""Observations stamped this close before a dwell segment's end belong to the next segment, s:
stamps are whole nanoseconds and a segment's end a sum of floats, so a sample stamped at the end
(the next set-point in force from it) may read a hair before it."""


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

    @property
    def window_start(self) -> float:
        """Start of the slip window, s (the stamp when there is no window)."""
        return self.time - self.window_duration


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
    """Stable stamp - ramp end (a run-up's: - its start), s; None without a stable verdict."""
    measured_slip: float | None
    """Monitor's slip rate, %: of the status that made the segment stable, else of its last status
    if that one's window began after the ramp's end; None otherwise (a stop: its last windows
    are the deceleration's)."""
    truth_slip: float | None
    """Simulator's true slip over the same window, %."""
    bearing_force: float | None
    """Mean axial force on the bearing once settled (see the module documentation), N."""
    measured_speed: float | None = None
    """Inner-ring speed of the segment's last status, when stamped after the ramp end, rad/s."""
    conditions: tuple[str, ...] = ()
    """What was off: speed or load not as commanded, disturbances from outside; empty when the
    segment ran under its own conditions."""
    run_up: bool = False
    """A constant-acceleration run-up: judged during its acceleration, as the paper judges it
    (section 4.2), so its time to stable counts from its start, and its measured slip is that of
    the stable status, at the speed of ``stable_speed``."""
    stable_speed: float | None = None
    """Inner-ring speed of the status that made the segment stable, rad/s (None without one)."""

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
    setpoint_states: int = 0
    """States of the load controller seen during the segment."""
    fixed_start: bool = False
    """The segment's start was known ahead (it follows a dwell segment): its set-point was sent
    ahead, stamped with it, and is judged from the start."""
    worst: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    """Per judged load (see the module documentation): the sample furthest outside its band as
    (excess over the band N, value N, time s)."""


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

    def __init__(
        self,
        program: TestProgram,
        monitor_settings: MonitorSettings | None = None,
        command_lead_s: float = COMMAND_LEAD_S,
        setpoint_lead_s: float = math.inf,
        monitor_guard_s: float | None = None,
        wall_clock: Callable[[], float] = monotonic,
    ) -> None:
        self.program = program
        self.monitor_guard_s = monitor_guard_s
        """A segment that ends at its deadline waits for a status stamped at or after it (every
        status of the segment taken: the monitor publishes in order) up to this much wall time, s;
        None: it does not wait (the module documentation, "Statuses through the end")."""
        self._wall_clock = wall_clock
        self.status_through = -math.inf
        """The latest stamp of a status taken, s of sim time."""
        self.unconfirmed: list[str] = []
        """Segments ended without the monitor's statuses through their end (the guard ran out)."""
        self._waiting_since: float | None = None
        self.command_lead_s = command_lead_s
        """How long before a segment's fixed start its command is sent, s (:meth:`commands_due`)."""
        self.setpoint_lead_s = setpoint_lead_s
        """How long before a segment's fixed start its load set-point is sent, s (:meth:`setpoints_due`)."""
        self.monitor_settings = monitor_settings if monitor_settings is not None else MonitorSettings.from_yaml()
        """The monitor's parameters: how far back its verdicts reach and at what confidence a
        STABLE counts (the shipped ones until the running monitor publishes its own,
        :meth:`observe_monitor_parameters`)."""
        self.outcomes: list[SegmentOutcome] = []
        self._data: _SegmentData | None = None
        self._truth: deque[tuple[float, float]] = deque(maxlen=TRUTH_HISTORY)
        self._start_speeds = program.start_speeds()
        self._finished = False
        self._ahead: dict[int, SegmentPlan] = {}
        """Plans of segments not started yet whose start is fixed (see :meth:`commands_due`)."""
        self._commanded = -1
        """Highest segment index whose command :meth:`commands_due` gave."""
        self._setpoints_sent = -1
        """Highest segment index whose set-point :meth:`setpoints_due` gave."""
        self._early: list[tuple[Callable[..., None], tuple[Any, ...]]] = []
        """Observations stamped after the running segment's end, for the next one (in order)."""
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

    @property
    def loads_radially(self) -> bool:
        """Some segment asks for a radial load or a moment: the session then sends every
        segment's radial set-point (0 included); a program that loads only axially sends none,
        as the paper's bench has no radial loader to send it to."""
        return any(seg.radial_load != 0.0 or seg.moment != 0.0 for seg in self.program.segments)

    # -- driving ----------------------------------------------------------------------------------
    def start(self, now: float, setpoint_sent: bool = False) -> SegmentPlan:
        """Start the first segment at ``now`` (s of sim time); returns its plan.
        ``setpoint_sent``: its load set-point went out before (the session loads the bearing up
        before the program's clock starts), so :meth:`setpoints_due` does not give it again.

        Raises:
            RuntimeError: already started.
        """
        if self.started:
            raise RuntimeError("the program runner was started already")
        if setpoint_sent:
            self._setpoints_sent = 0
        return self._begin(0, now)

    def _plan(self, index: int, start: float) -> SegmentPlan:
        segment = self.program.segments[index]
        return SegmentPlan(index, segment, segment.speed_profile(start, self._start_speeds[index]))

    def _begin(self, index: int, start: float) -> SegmentPlan:
        """Start segment ``index`` at ``start`` (s of sim time), or as planned ahead."""
        plan = self._ahead.pop(index, None) or self._plan(index, start)
        run_up = plan.profile.start_time if plan.profile.kind is SpeedProfileKind.CONSTANT_ACCELERATION and plan.ramp_end > plan.start_time else None
        fixed = index > 0 and self.program.segments[index - 1].dwell is not None
        self._data = _SegmentData(
            plan, rule=TimeToStable(plan.ramp_end, plan.segment.target_speed, run_up, min_confidence=self.monitor_settings.stable_confidence), fixed_start=fixed
        )
        early, self._early = self._early, []
        for observe, args in early:  # stamped within this segment, or beyond it (kept again)
            observe(*args)
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
        at_deadline = plan.segment.dwell is not None or verdict is Verdict.TIMEOUT
        if at_deadline and self.monitor_guard_s is not None and self.status_through < plan.deadline - STAMP_RESOLUTION_S:
            wall = self._wall_clock()
            self._waiting_since = wall if self._waiting_since is None else self._waiting_since
            if wall - self._waiting_since < self.monitor_guard_s:
                return []
            self.unconfirmed.append(f"{plan.segment.name}: the monitor's statuses end at {self.status_through:.3f} s, the segment at {plan.deadline:.3f} s")
        self._waiting_since = None
        self._end(verdict, now)
        if plan.index + 1 < self.segment_count:
            # after a dwell segment the next one starts at its end, where its command is stamped
            return [self._begin(plan.index + 1, plan.deadline if plan.segment.dwell is not None else now)]
        self._finished = True
        return []

    def commands_due(self, now: float) -> list[SegmentPlan]:
        """The plans whose spindle command is to be sent at ``now`` (s of sim time), each once, in
        order: the running segment's (unless given before), and that of each following segment
        whose start is fixed, the end of a dwell segment, and at most :attr:`command_lead_s`
        ahead of ``now``. Each command is stamped with its plan's start
        (:attr:`SegmentPlan.start_time`). An ``until_stable`` segment's end is not known ahead, so
        the segment after it is commanded when it starts."""
        due, self._commanded = self._due(now, self.command_lead_s, self._commanded)
        return due

    def setpoints_due(self, now: float) -> list[SegmentPlan]:
        """The plans whose load set-point is to be sent at ``now`` (s of sim time): as
        :meth:`commands_due`, up to :attr:`setpoint_lead_s` ahead (by default every fixed start
        at once: the load controller keeps them until their stamps, and, unlike a command, a
        set-point has no lead limit at its receiver)."""
        due, self._setpoints_sent = self._due(now, self.setpoint_lead_s, self._setpoints_sent)
        return due

    def _due(self, now: float, lead: float, sent: int) -> tuple[list[SegmentPlan], int]:
        """The plans due within ``lead`` of ``now`` after the one of index ``sent``, and the new
        highest index given (see :meth:`commands_due`)."""
        plan = self.current
        if plan is None:
            return [], sent
        due = []
        if sent < plan.index:
            due.append(plan)
            sent = plan.index
        while plan.segment.dwell is not None and plan.index + 1 < self.segment_count and plan.deadline - now <= lead:
            following = self._ahead.get(plan.index + 1)
            if following is None:
                following = self._ahead[plan.index + 1] = self._plan(plan.index + 1, plan.deadline)
            if sent < following.index:
                due.append(following)
                sent = following.index
            plan = following
        return due, sent

    def interrupt(self, now: float) -> SegmentOutcome | None:
        """Stop: the running segment ends as "interrupted" (returned), the program as finished."""
        outcome = self._end(Verdict.INTERRUPTED, now) if self._data is not None else None
        self._finished = True
        return outcome

    def _end(self, verdict: Verdict, now: float) -> SegmentOutcome:
        data = self._data
        assert data is not None
        plan = data.plan
        decisive = data.stable
        if decisive is None and data.last_status is not None and _window_after(data.last_status, plan.ramp_end):
            decisive = data.last_status  # else its slip is the ramp's (a stop's: the deceleration's), not the segment's speed's
        if data.stable is not None:
            assert data.rule is not None
            time_to_stable: float | None = data.stable.time - data.rule.ramp_end
        else:
            time_to_stable = None
        if data.force_count:
            force: float | None = data.force_sum / data.force_count
        elif data.force_count_all:
            force = data.force_sum_all / data.force_count_all
        else:
            force = None
        last = data.last_status
        measured_speed = last.inner_ring_speed if last is not None and last.time >= plan.ramp_end and math.isfinite(last.inner_ring_speed) else None
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
            conditions=_conditions(plan.segment, measured_speed, _load_conditions(data, now), data.disturbances, verdict),
            run_up=data.rule is not None and data.rule.run_up_start is not None,
            stable_speed=data.stable.inner_ring_speed if data.stable is not None and math.isfinite(data.stable.inner_ring_speed) else None,
        )
        self.outcomes.append(outcome)
        self._data = None
        return outcome

    # -- observations -----------------------------------------------------------------------------
    def observe_monitor_parameters(self, values: Mapping[str, str]) -> str:
        """The running monitor's parameters as its ``/diagnostics`` status publishes them
        (:meth:`~bearing_rig_sim.monitoring.MonitorSettings.published_parameters`): the time to
        stable judges its statuses by them from now on, the running segment's included. Returns
        a problem with a value ("" when none)."""
        self.monitor_settings, problem = self.monitor_settings.with_published(values)
        if self._data is not None and self._data.rule is not None:
            self._data.rule.min_confidence = self.monitor_settings.stable_confidence
        return problem

    def observe_status(self, status: SlipObservation) -> None:
        """A slip status of the monitor (any order relative to :meth:`update`)."""
        self.latest_status = status
        self.status_through = max(self.status_through, status.time)
        if status.sweep_verdict and math.isfinite(status.sweep_speed):
            self.sweeps[sweep_key(status.sweep_speed)] = status.sweep_verdict
        data = self._data
        if data is None or status.time < data.plan.start_time or self._ahead_of_segment(status.time, self.observe_status, status):
            return
        data.last_status = status
        data.statuses += 1
        assert data.rule is not None
        st = self.monitor_settings
        evidence = evidence_start(status.time, status.cage_speed, status.window_revolutions, st.slope_span_s, st.min_slope_points, st.min_window_s)
        if data.rule.observe(status.time, evidence, int(status.state), status.confidence, status.inner_ring_speed):
            data.stable = status

    def _ahead_of_segment(self, time: float, observe: Callable[..., None], *args: Any) -> bool:
        """Whether an observation stamped ``time`` (s of sim time) belongs to a later segment: one
        at or after the end of the running dwell segment, whose successor's command was sent ahead
        (:meth:`commands_due`), so the simulator, running ahead of the session, may already be in
        it. It is kept and given to the next segment when that starts (True); False otherwise."""
        data = self._data
        if data is None or data.plan.segment.dwell is None or time < data.plan.deadline - STAMP_RESOLUTION_S:
            return False
        self._early.append((observe, args))
        return True

    def observe_truth(self, time: float, slip_rate: float, axial_load: float = math.nan) -> None:
        """The simulator's true slip rate (%) and the axial load it applied (N; NaN: not given) at
        ``time`` (s of sim time)."""
        if math.isfinite(slip_rate):
            self._truth.append((time, slip_rate))
        if math.isfinite(axial_load):
            self._judge_load("axial load on the simulated bearing", time, axial_load, self.observe_truth, slip_rate, axial_load)

    def observe_radial(self, time: float, force_x: float, force_y: float) -> None:
        """The radial force on the bearing (N, bearing frame) at ``time`` (s of sim time), from
        the load controller's force on the bearing."""
        data = self._data
        if data is None or time < data.plan.start_time or self._ahead_of_segment(time, self.observe_radial, time, force_x, force_y):
            return
        want_x, want_y = data.plan.segment.radial_components
        self._judge(
            data,
            "radial force on the bearing",
            time,
            math.hypot(force_x - want_x, force_y - want_y),
            math.hypot(force_x, force_y),
            data.plan.segment.radial_load,
        )

    def _judge_load(self, what: str, time: float, value: float, observe: Callable[..., None], *args: Any) -> None:
        """Judge an axial load sample (see the module documentation)."""
        data = self._data
        if data is None or time < data.plan.start_time or self._ahead_of_segment(time, observe, time, *args):
            return
        target = data.plan.segment.axial_load
        self._judge(data, what, time, abs(value - target), value, target)

    @staticmethod
    def _judge(data: _SegmentData, what: str, time: float, deviation: float, value: float, target: float) -> None:
        """Keep the sample furthest outside :func:`settle_band` of ``target`` once the load is judged."""
        judged_from = data.plan.start_time if data.fixed_start else data.setpoint_seen
        if judged_from is None or time < judged_from + LOAD_SETTLE_S or not math.isfinite(deviation):
            return
        excess = deviation - settle_band(target)
        if excess > 0.0 and excess > data.worst.get(what, (0.0, 0.0, 0.0))[0]:
            data.worst[what] = (excess, value, time)

    def observe_load(self, time: float, bearing_force: float) -> None:
        """The axial force on the bearing (N) at ``time`` (s of sim time)."""
        data = self._data
        if data is None or time < data.plan.start_time or not math.isfinite(bearing_force):
            return
        if self._ahead_of_segment(time, self.observe_load, time, bearing_force):
            return
        data.force_sum_all += bearing_force
        data.force_count_all += 1
        self._judge(data, "bearing force", time, abs(bearing_force - data.plan.segment.axial_load), bearing_force, data.plan.segment.axial_load)
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
        if data is None or time < data.plan.start_time or self._ahead_of_segment(time, self.observe_axial_setpoint, time, setpoint):
            return
        data.setpoint_states += 1
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
        stamp when the window holds none; None without any sample, and None when the status has
        no window (a rig found stopped: its cage speed 0, its slip undefined; the truth's slip near
        standstill, 1 - cage / (ratio x inner) of vanishing speeds, compares with nothing)."""
        if status.window_duration <= 0.0:
            return None
        start = status.window_start
        inside = [s for t, s in self._truth if start <= t <= status.time]
        if inside:
            return sum(inside) / len(inside)
        before = [s for t, s in self._truth if t <= status.time]
        return before[-1] if before else None


def _window_after(status: SlipObservation, ramp_end: float) -> bool:
    """Whether the slip window of ``status`` began at or after ``ramp_end`` (s), so that its slip
    is one of the segment's commanded speed (the rule the offline analysis applies to its means,
    :mod:`bearing_rig_sim.offline.segments`); False for a status without a window."""
    return status.window_duration > 0.0 and status.window_start >= ramp_end


def _load_conditions(data: _SegmentData, now: float) -> list[str]:
    """What was off in a segment's load (see the module documentation), the segment ending at
    ``now`` (s of sim time) or, a dwell, at its deadline: the session may notice the end later,
    and what is stamped after the deadline belongs to the next segment."""
    segment = data.plan.segment
    end = min(now, data.plan.deadline) if segment.dwell is not None else now
    off = []
    for what, (_excess, value, time) in data.worst.items():
        target = segment.radial_load if what.startswith("radial") else segment.axial_load
        off.append(f"{what} {value:.1f} N at t = {time:.3f} s, {target:g} N commanded (+- {settle_band(target):.3g} N)")
    if data.setpoint_seen is None and data.setpoint_states > 0 and end - data.plan.start_time > LOAD_SETTLE_S:
        off.append(f"the load controller never showed the set-point {segment.axial_load:g} N during the segment")
    return off


def _conditions(segment: Segment, measured_speed: float | None, load: list[str], disturbances: list[str], verdict: Verdict) -> tuple[str, ...]:
    """What was off in a segment (see the module documentation). An interrupted segment's speed
    and load are not judged, nor a measurement that is missing."""
    off: list[str] = []
    if verdict is not Verdict.INTERRUPTED:
        target = segment.target_speed
        if measured_speed is not None and abs(measured_speed - target) > speed_tolerance(target):
            off.append(f"speed {rad_s_to_rpm(measured_speed):.0f} rpm measured, {rad_s_to_rpm(target):.0f} rpm commanded")
        off.extend(f"load off: {line}" for line in load)
    off.extend(f"disturbed: {what}" for what in disturbances)
    return tuple(off)
