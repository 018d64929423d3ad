"""The load sweep as the paper judges it (section 4.1; docs/method.md): per spindle speed, the
settled slip of each load point, a Gaussian sum fitted to slip against load, and the load from
which the fitted slope is at or above k1. One collector for the monitor node, ``analyze`` and the
session summary (which reads the verdicts off the statuses).

**Load points** from the slip windows (each with its mean measured axial load and mean spindle
speed): a *hold* is a run of consecutive windows whose load stays within ``load_step_n / 2`` and
whose speed stays within :data:`SPEED_TOLERANCE` of the hold's first window. A hold gives one
load point once it has lasted ``settle_s + average_s``: the mean slip (and load) of its windows
that start at least ``settle_s`` after the hold's first window and end within ``settle_s +
average_s`` of it. The point is therefore fixed by the windows alone, whenever the run ends, so
the node, a replayed bag and the session agree on it. Shorter holds (a load or speed ramp) give
no point.

**Speeds**: consecutive points whose speeds are within :data:`SPEED_TOLERANCE` of the first
point's make one sweep; a point at another speed closes it and starts the next. Each new point of
a sweep with at least :data:`~bearing_rig_sim.analysis.stability.SWEEP_MIN_POINTS` points makes a
new :class:`~bearing_rig_sim.analysis.stability.LoadSweepVerdict` (the last one, after the last
load of a speed, is that speed's verdict).

Units: s, rad/s, N; slip in percent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from bearing_rig_sim.analysis.stability import SWEEP_MIN_POINTS, LoadSweepVerdict, load_sweep_verdict

SPEED_TOLERANCE = 0.01
"""Windows (and points) whose spindle speeds differ by more than this fraction are at different
speeds (1); a jittered hold's windows differ by about 1e-4, a step of the paper's sweep by 0.4."""


def sweep_key(speed: float) -> int:
    """The key of a load sweep's spindle speed (rad/s) in summaries: rpm rounded to 10 rpm (the
    points of one sweep differ by far less, the paper's speeds by 2000 rpm)."""
    return int(round(speed * 30.0 / math.pi / 10.0)) * 10


@dataclass(frozen=True)
class LoadPoint:
    """One settled load point: mean axial load (N), slip (%) and spindle speed (rad/s) of the
    windows averaged, the rig time of its last window (s) and how many windows it averages."""

    axial_load: float
    slip_rate: float
    inner_ring_speed: float
    time: float
    windows: int


@dataclass
class _Hold:
    start: float
    load: float
    speed: float
    sums: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0, 0.0])  # load, slip, speed, count
    done: bool = False


class LoadSweep:
    """Collects load points and judges each speed's sweep (module docstring).

    Args:
        critical_slope: k1, %/N.
        load_step_n: loads within half of this are one hold, N.
        settle_s: time after a hold's first window before its windows count, s.
        average_s: time over which they are averaged, s.
    """

    def __init__(self, critical_slope: float, load_step_n: float, settle_s: float, average_s: float) -> None:
        self.critical_slope = critical_slope
        self.load_step_n = load_step_n
        self.settle_s = settle_s
        self.average_s = average_s
        self.reset()

    def reset(self) -> None:
        """Forget every hold, point and verdict."""
        self._hold: _Hold | None = None
        self.points: list[LoadPoint] = []
        """The current speed's load points, in order."""
        self.verdicts: list[LoadSweepVerdict] = []
        """The latest verdict of each speed, in order (the last may still change)."""
        self._speed_closed = True

    @property
    def latest(self) -> LoadSweepVerdict | None:
        """The latest verdict (None before the first)."""
        return self.verdicts[-1] if self.verdicts else None

    def add_window(self, start: float, end: float, axial_load: float, slip_rate: float, inner_ring_speed: float) -> LoadSweepVerdict | None:
        """One slip window (rig s, N, %, rad/s); returns a new verdict when it completed a load
        point of a sweep with enough points, else None. A window without a spindle speed ends the
        current hold; one without a load (no load-cell sample in it) or slip is skipped."""
        if not (math.isfinite(inner_ring_speed) and inner_ring_speed > 0.0):
            self._hold = None
            return None
        if not (math.isfinite(axial_load) and math.isfinite(slip_rate)):
            return None
        hold = self._hold
        if hold is None or abs(axial_load - hold.load) > 0.5 * self.load_step_n or abs(inner_ring_speed - hold.speed) > SPEED_TOLERANCE * hold.speed:
            hold = self._hold = _Hold(start, axial_load, inner_ring_speed)
        if hold.done:
            return None
        begin, finish = hold.start + self.settle_s, hold.start + self.settle_s + self.average_s
        if start >= begin and end <= finish:
            for i, value in enumerate((axial_load, slip_rate, inner_ring_speed, 1.0)):
                hold.sums[i] += value
        if end + (end - start) <= finish:  # the next window may still fall inside
            return None
        hold.done = True
        load, slip, speed, count = hold.sums
        if not count:
            return None
        return self._add_point(LoadPoint(load / count, slip / count, speed / count, end, int(count)))

    def _add_point(self, point: LoadPoint) -> LoadSweepVerdict | None:
        if self.points and abs(point.inner_ring_speed - self.points[0].inner_ring_speed) > SPEED_TOLERANCE * self.points[0].inner_ring_speed:
            self.points = []
            self._speed_closed = True
        self.points.append(point)
        if len(self.points) < SWEEP_MIN_POINTS:
            return None
        speed = sum(p.inner_ring_speed for p in self.points) / len(self.points)
        verdict = load_sweep_verdict([p.axial_load for p in self.points], [p.slip_rate for p in self.points], self.critical_slope, speed)
        if self._speed_closed:
            self.verdicts.append(verdict)
            self._speed_closed = False
        else:
            self.verdicts[-1] = verdict
        return verdict
