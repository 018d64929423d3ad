"""When the monitor checks and reports, and when a segment counts as stable: one policy for the
monitor node, offline analysis (``bearing-rig analyze``) and the live session summary.

**Schedule** (:class:`StatusSchedule`), on the rig clock of the pulses, so that the node and a
replayed bag give the same statuses: before each pulse, :meth:`SlipMonitor.check` runs at every
tick ``t0 + k / status_rate_hz`` up to the pulse's time (``t0``: the first pulse), each followed
by a status; each closed slip window gives one more status at once. A pulse further back than
``clock_jump_tolerance_s`` restarts the ticks (the monitor resets itself on it). When the pulses
stop, the node calls :meth:`StatusSchedule.idle` with its own estimate of the rig time, so a
silent sensor is still reported; offline the ticks catch up at the next pulse, and
:meth:`StatusSchedule.finish` closes the series.

**Time to stable** (:class:`TimeToStable`): a segment is stable at the first status that is
STABLE *on evidence from after the ramp's end*: its confidence P(slope >= k) is at least the
monitor's ``stable_confidence`` (so the present points, not a state held by hysteresis, say stable)
and every slip window its slope rests on started at or after the ramp's end
(:func:`evidence_start`), at the commanded speed: the status's inner-ring speed within
:func:`speed_tolerance` of the segment's target (a spindle that took the command late, or never
reached it, is not stable at that speed on windows of the speed before). The time to stable is
that status's stamp (its window's end) minus the ramp's end. A run-up (a constant-acceleration
segment) is judged during its acceleration instead, as the paper judges it (section 4.2): from
its start, at whatever speed (:class:`TimeToStable`). The live session summary and ``analyze``
both use it, on the fields a SlipStatus carries, so they agree.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring.monitor import MonitorStatus, SlipMonitor
from bearing_rig_sim.monitoring.windows import pulse_stamp
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim import picklable


@dataclass(frozen=True)
class ScheduledStatus:
    """A status the schedule emits: rig time (s), why ("tick", "window", "idle", "end")."""

    time: float
    reason: str
    status: MonitorStatus


class StatusSchedule:
    """Feeds pulses to a :class:`SlipMonitor` and says when to check and report (module
    docstring)."""

    def __init__(self, monitor: SlipMonitor) -> None:
        self.monitor = monitor
        self.period = 1.0 / monitor.settings.status_rate_hz
        self._origin: float | None = None
        self._tick = 0
        self.clock = -math.inf
        """Latest rig time seen (s)."""

    def on_pulse(self, shaft: str, pulse: Pulse) -> list[ScheduledStatus]:
        """The statuses due up to and at this pulse, in order."""
        out: list[ScheduledStatus] = []
        t = pulse_stamp(pulse)
        if t is not None:
            self._advance(t, out)
        if self.monitor.add_pulse(shaft, pulse):
            out.append(ScheduledStatus(self.clock, "window", self.monitor.status()))
        return out

    def _advance(self, t: float, out: list[ScheduledStatus]) -> None:
        tolerance = self.monitor.settings.clock_jump_tolerance_s
        if self._origin is None or t < self.clock - tolerance:
            self._origin, self._tick, self.clock = t, 0, t
        while (tick := self._origin + self._tick * self.period) <= t:
            self.monitor.check(tick)
            out.append(ScheduledStatus(tick, "tick", self.monitor.status()))
            self._tick += 1
        if t > self.clock:
            self.clock = t

    def advance_to(self, t: float) -> list[ScheduledStatus]:
        """The ticks due up to the rig time ``t`` (s) without a pulse: those the next pulse would
        bring, brought now (offline, where something other than a pulse marks the time, such as
        the start of a program segment); none before the first pulse."""
        out: list[ScheduledStatus] = []
        if self._origin is not None and math.isfinite(t) and t > self.clock:
            self._advance(t, out)
        return out

    def idle(self, now: float) -> ScheduledStatus:
        """No pulse for a while: check at the rig time ``now`` (s) and report."""
        self.monitor.check(now)
        return ScheduledStatus(now, "idle", self.monitor.status())

    def finish(self) -> ScheduledStatus | None:
        """The last check and status after the last pulse (None if no pulse came)."""
        if self._origin is None:
            return None
        self.monitor.check(self.clock)
        return ScheduledStatus(self.clock, "end", self.monitor.status())


def evidence_start(stamp: float, cage_speed: float, window_revolutions: int, slope_span_s: float, min_slope_points: int, min_window_s: float = 0.0) -> float:
    """The earliest time the verdict of a status stamped ``stamp`` (s) can rest on, s.

    Its slope is fitted to the slip windows that ended in the last ``slope_span_s`` (at least the
    last ``min_slope_points`` of them), each ``window_revolutions`` cage revolutions long at
    ``cage_speed`` (rad/s), or the fewest whole revolutions that last ``min_window_s`` (s) if
    more. -inf when the cage speed is unknown.
    """
    if not (math.isfinite(cage_speed) and cage_speed > 0.0 and window_revolutions > 0):
        return -math.inf
    revolutions = max(window_revolutions, math.ceil(min_window_s * cage_speed / (2.0 * math.pi)))
    window = revolutions * 2.0 * math.pi / cage_speed
    return stamp - max(slope_span_s + window, min_slope_points * window)


SPEED_TOLERANCE_FRACTION = 0.01
"""The measured speed may differ from the commanded by 1 % ..."""
SPEED_TOLERANCE_RAD_S = 1.0
"""... or by 1 rad/s (9.5 rpm), whichever is wider: the pulse counter's resolution near rest."""


def speed_tolerance(target_speed: float) -> float:
    """Largest difference between measured and commanded inner-ring speed at which a segment is
    at its commanded speed, rad/s."""
    return max(SPEED_TOLERANCE_FRACTION * target_speed, SPEED_TOLERANCE_RAD_S)


class TimeToStable:
    """The one "stable after the ramp" rule (module docstring).

    A **run-up** (a constant-acceleration segment, ``run_up_start`` given) is judged as the paper
    judges it (section 4.2): the slope of slip against time during the acceleration itself, so
    its time to stable counts from the start of the run-up (the paper's t = 0 of Table 7) to the
    first stable status on evidence from after that start, at whatever speed it comes.

    Args:
        ramp_end: end of the segment's ramp, rig s.
        target_speed: the commanded inner-ring speed, rad/s; None: not checked.
        run_up_start: start of a run-up, rig s; None for any other segment.
        min_confidence: least P(slope >= k) of the status that makes it stable (1): the running
            monitor's ``stable_confidence`` (live: as it publishes them on its /diagnostics,
            ``MonitorSettings.published_parameters``; offline: the same, recorded in the bag), no default of its own.
    """

    def __init__(self, ramp_end: float, target_speed: float | None = None, run_up_start: float | None = None, *, min_confidence: float) -> None:
        self.min_confidence = min_confidence
        self.run_up_start = run_up_start
        self.ramp_end = ramp_end if run_up_start is None else run_up_start
        """The origin of the time to stable: the ramp's end, or the run-up's start, rig s."""
        self.target_speed = target_speed if run_up_start is None else None
        self.stable_at: float | None = None
        """Stamp of the status that made the segment stable, s (None before)."""

    def observe(self, stamp: float, evidence_from: float, state: int, confidence: float, inner_ring_speed: float = math.nan) -> bool:
        """A status stamped ``stamp`` whose verdict rests on data from ``evidence_from`` on (s,
        :func:`evidence_start`), measured at ``inner_ring_speed`` (rad/s); returns whether this
        status made the segment stable."""
        if self.stable_at is not None or state != SlipState.STABLE or not confidence >= self.min_confidence:
            return False
        target = self.target_speed
        if target is not None and not abs(inner_ring_speed - target) <= speed_tolerance(target):
            return False
        if evidence_from >= self.ramp_end:
            self.stable_at = stamp
            return True
        return False

    @property
    def time_to_stable(self) -> float | None:
        """Stable stamp - ramp end, s (None without one)."""
        return None if self.stable_at is None else self.stable_at - self.ramp_end


class PulseMerger:
    """Puts the two pulse topics back in time order before the schedule (the node's use).

    A subscriber gets each topic from its own queue; after a hold-up the backlogs come one
    message per topic in turn, so the sparser cage pulses run ahead in time of the spindle's (0.7 s
    was seen), and a check on that clock finds the spindle silent. A bag's log order is the
    recorder's reception order, held up the same way: ``analyze`` uses :class:`StampOrder`. Rule: a pulse goes on once it is no later than the other
    shaft's latest pulse plus twice that shaft's last pulse interval (the other's next pulse is
    due by then), or the other shaft has not been heard of for ``max_wait_s`` of the steady
    clock (silent, which the schedule's checks then judge); pulses go on in time order.

    Args:
        max_wait_s: longest hold while the other shaft is silent, wall s.
    """

    def __init__(self, max_wait_s: float = 0.2) -> None:
        self.max_wait_s = max_wait_s
        self._held: dict[str, deque[Pulse]] = {"spindle": deque(), "cage": deque()}
        self._latest: dict[str, float] = {"spindle": -math.inf, "cage": -math.inf}
        self._interval: dict[str, float] = {"spindle": math.inf, "cage": math.inf}
        self._heard: dict[str, float] = {"spindle": -math.inf, "cage": -math.inf}

    def push(self, shaft: str, pulse: Pulse, wall_now: float) -> list[tuple[str, Pulse]]:
        """Take one received pulse; the pulses (of either shaft) that may go on now, in order."""
        t = pulse_stamp(pulse)
        if shaft not in self._held or t is None:
            return [(shaft, pulse)]  # the monitor reports what is wrong with it
        if t > self._latest[shaft]:
            if math.isfinite(self._latest[shaft]):
                self._interval[shaft] = t - self._latest[shaft]
            self._latest[shaft] = t
        self._heard[shaft] = wall_now
        self._held[shaft].append(pulse)
        return self._release(wall_now)

    def expire(self, wall_now: float) -> list[tuple[str, Pulse]]:
        """The held pulses that may go on because the other shaft has been silent too long."""
        return self._release(wall_now)

    def _release(self, wall_now: float) -> list[tuple[str, Pulse]]:
        out: list[tuple[str, Pulse]] = []
        while True:
            heads = [(q[0].time, name) for name, q in self._held.items() if q]
            if not heads:
                return out
            t, name = min(heads)
            other = "cage" if name == "spindle" else "spindle"
            due = self._latest[other] + 2.0 * self._interval[other]
            silent = wall_now - self._heard[other] > self.max_wait_s
            if not (self._held[other] or t <= due or silent):
                return out
            out.append((name, self._held[name].popleft()))


ORDER_MAX_LEAD_S = 5.0
""":class:`StampOrder` holds a pulse until the other shaft's stamps reach it, or its own shaft's
run this far past it (the other is then silent), rig s: well beyond the 0.7 s by which one topic
was seen to run ahead of the other after a hold-up, and a few thousand pulses at most."""


class StampOrder:
    """Puts the two pulse streams of a recording (each in its own order) into one order by their
    stamps alone, so that what is computed from them depends on the data, not on when it was
    received (``analyze``'s use).

    A bag is in log-time order, the order the recorder received the messages in; after a hold-up
    its subscriber, like the monitor's, gets the two topics' backlogs one message per topic in
    turn, and the sparse cage pulses run ahead of the spindle's (0.7 s was seen). Replayed in that
    order, the schedule's checks found the spindle silent for that long, a FAULT the live
    monitor, whose :class:`PulseMerger` reorders, never reported. Rule: a pulse goes on once the
    other shaft has a pulse stamped at or after it, or its own shaft has run more than
    :data:`ORDER_MAX_LEAD_S` past it (the other is silent, which the schedule's checks then judge
    on the same stamps); pulses go on in stamp order, each shaft's in its own order. Unlike
    :class:`PulseMerger` it waits for the other shaft's next pulse, which costs latency live but
    nothing offline. Pulses without a finite stamp go on at once (the monitor reports them).

    Args:
        max_lead_s: the silence after which a shaft's pulses no longer wait for the other's, rig s.
    """

    def __init__(self, max_lead_s: float = ORDER_MAX_LEAD_S) -> None:
        self.max_lead_s = max_lead_s
        self._held: dict[str, deque[tuple[float, Pulse]]] = {"spindle": deque(), "cage": deque()}  # (stamp, pulse)
        self._latest: dict[str, float] = {"spindle": -math.inf, "cage": -math.inf}

    def push(self, shaft: str, pulse: Pulse) -> list[tuple[str, Pulse]]:
        """Take one pulse of ``shaft``, in the order received; the pulses that may go on now."""
        t = pulse_stamp(pulse)
        held = self._held.get(shaft)
        if held is None or t is None:
            return [(shaft, pulse)]
        latest = self._latest
        if t > latest[shaft]:
            latest[shaft] = t
        held.append((t, pulse))
        return self._release(-math.inf)

    @property
    def clock(self) -> float:
        """The latest stamp received, held or not, rig s (-inf before any)."""
        return max(self._latest.values())

    def release_until(self, until: float) -> list[tuple[str, Pulse]]:
        """The pulses that may go on now, and every held one stamped at or before ``until`` (rig
        s: something else, such as a program segment's start, marks the time there)."""
        return self._release(until)

    def flush(self) -> list[tuple[str, Pulse]]:
        """Every held pulse, in order (the end of the recording)."""
        return self._release(math.inf)

    def _release(self, until: float) -> list[tuple[str, Pulse]]:
        """The held pulses that may go on, in stamp order (the cage's first at equal stamps)."""
        out: list[tuple[str, Pulse]] = []
        spindle, cage = self._held["spindle"], self._held["cage"]
        latest = self._latest
        lead = self.max_lead_s
        while spindle or cage:
            if cage and (not spindle or cage[0][0] <= spindle[0][0]):
                name, other, queue = "cage", "spindle", cage
            else:
                name, other, queue = "spindle", "cage", spindle
            t = queue[0][0]
            if not (t <= until or latest[other] >= t or latest[name] - t > lead):
                break
            out.append((name, queue.popleft()[1]))
        return out


picklable.by_fields(ScheduledStatus)
