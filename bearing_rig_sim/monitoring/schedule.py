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

**Time to stable** (:class:`TimeToStable`): a segment is stable at the first STABLE status whose
slip window starts at or after the ramp's end and, when the segment changes the speed, that
follows a status other than STABLE stamped after the ramp's end (the monitor restarts its series
for a new phase, so a stable verdict carried over from the previous speed does not count). The
time to stable is that status's stamp (its window's end) minus the ramp's end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring.monitor import MonitorStatus, SlipMonitor
from bearing_rig_sim.rig.fibre_optic import Pulse


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
        t = pulse.time
        if isinstance(t, (int, float)) and not isinstance(t, bool) and math.isfinite(t):
            self._advance(float(t), out)
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
        self.clock = max(self.clock, t)

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


class TimeToStable:
    """The one "stable after the ramp" rule (module docstring).

    Args:
        ramp_end: end of the segment's ramp, rig s.
        changes_speed: whether the segment changes the spindle speed.
    """

    def __init__(self, ramp_end: float, changes_speed: bool) -> None:
        self.ramp_end = ramp_end
        self.changes_speed = changes_speed
        self.unsettled = False
        self.stable_at: float | None = None
        """Stamp of the status that made the segment stable, s (None before)."""

    def observe(self, stamp: float, window_start: float, state: int) -> bool:
        """A status stamped ``stamp`` whose slip window started at ``window_start`` (s); returns
        whether this status made the segment stable."""
        if self.stable_at is not None or not stamp >= self.ramp_end:
            return False
        if state != SlipState.STABLE:
            self.unsettled = True
            return False
        if window_start >= self.ramp_end and (self.unsettled or not self.changes_speed):
            self.stable_at = stamp
            return True
        return False

    @property
    def time_to_stable(self) -> float | None:
        """Stable stamp - ramp end, s (None without one)."""
        return None if self.stable_at is None else self.stable_at - self.ramp_end
