"""The bench's measured inputs as the engine needs them: inner-ring speed points from the spindle
pulses and a smoothed axial force from the load cell (no ROS).

**Speed points.** Each spindle pulse closes one whole revolution with the pulse of the same strip
``strip_count`` indices earlier (when both were received). Its mean speed ``2 pi / (t_k -
t_(k-n))`` is the speed at the interval's time midpoint exactly under constant acceleration, and
is free of the strips' spacing errors (same strip to same strip), so the point is ``((t_k +
t_(k-n)) / 2, 2 pi / (t_k - t_(k-n)))``. With 4 strips a point comes every quarter revolution;
the engine follows the straight line between consecutive points and so runs half a revolution
behind the latest pulse. A lost pulse costs the points that needed it, nothing else.

**Axial force.** The mean of the load-cell samples of the last ``average_s`` seconds (the load
cell's noise averaged), held when no sample comes; :meth:`LoadCellTrack.silent_for` tells a
dropout.

Units: s, rad/s, N.
"""

from __future__ import annotations

import math
from collections import deque
from typing import NamedTuple

from bearing_rig_sim.instruments.fibre_optic import TWO_PI, Pulse


class SpeedPoint(NamedTuple):
    """Mean spindle speed over one whole revolution, at the revolution's time midpoint.

    Attributes:
        time: the midpoint, s (bench clock).
        speed: rad/s.
        span: the revolution's duration, s.
    """

    time: float
    speed: float
    span: float


class SpindleSpeedTrack:
    """Whole-revolution speed points from the spindle pulses (see the module docstring).

    Args:
        clock_jump_tolerance_s: a pulse further back than this before the previous one is a clock
            jump (:attr:`jumps` counts them; the track restarts), s.
    """

    def __init__(self, clock_jump_tolerance_s: float = 0.1) -> None:
        self.clock_jump_tolerance_s = clock_jump_tolerance_s
        self.jumps = 0
        """Clock jumps back seen (1)."""
        self.reset()

    def reset(self) -> None:
        """Forget every pulse."""
        self._times: dict[int, float] = {}
        self._order: deque[int] = deque()
        self._last: tuple[int, float] | None = None
        self._strips: int | None = None

    def add(self, pulse: Pulse) -> SpeedPoint | None:
        """Take one spindle pulse; the speed point it completes, if any.

        Malformed, repeated and out-of-order pulses are ignored; a clock jump back restarts the
        track (the caller learns it from :attr:`jumps`).
        """
        t, index, n = pulse.time, pulse.pulse_index, pulse.strip_count
        if not math.isfinite(t) or n < 1:
            return None
        if self._last is not None:
            last_index, last_time = self._last
            if t < last_time - self.clock_jump_tolerance_s:
                self.jumps += 1
                self.reset()
            elif t <= last_time or index <= last_index:
                return None
        if self._strips != n:
            self.reset()
            self._strips = n
        self._last = (index, t)
        self._times[index] = t
        self._order.append(index)
        while self._order and self._order[0] < index - n:
            del self._times[self._order.popleft()]
        earlier = self._times.get(index - n)
        if earlier is None or t <= earlier:
            return None
        span = t - earlier
        return SpeedPoint(0.5 * (t + earlier), TWO_PI / span, span)


class LoadCellTrack:
    """The load-cell force averaged over the last ``average_s`` seconds.

    Args:
        average_s: averaging time, s (> 0).
    """

    def __init__(self, average_s: float) -> None:
        self.average_s = average_s
        self._samples: deque[tuple[float, float]] = deque()
        self._sum = 0.0
        self.last_time: float | None = None
        """Stamp of the latest sample, s (None before any)."""
        self.held = math.nan
        """The latest average, N (NaN before any sample)."""

    def reset(self) -> None:
        """Forget every sample."""
        self._samples.clear()
        self._sum = 0.0
        self.last_time = None
        self.held = math.nan

    def add(self, time: float, force: float) -> bool:
        """Take one sample (s, N); False (ignored) if either is not finite or it is older than the
        latest sample."""
        if not (math.isfinite(time) and math.isfinite(force)):
            return False
        if self.last_time is not None and time < self.last_time:
            return False
        self._samples.append((time, force))
        self._sum += force
        self.last_time = time
        return True

    def force_at(self, time: float) -> float:
        """The mean force of the samples in ``(time - average_s, time]``, N; the last mean when
        there are none (NaN before any sample). Samples older than the window are dropped, so
        call with non-decreasing times."""
        samples = self._samples
        while samples and samples[0][0] <= time - self.average_s:
            self._sum -= samples.popleft()[1]
        inside = self._sum
        count = len(samples)
        # samples after ``time`` (the load cell runs ahead of the engine) are not yet used
        for t, f in reversed(samples):
            if t <= time:
                break
            inside -= f
            count -= 1
        if count > 0:
            self.held = inside / count
        if not samples:
            self._sum = 0.0
        return self.held

    def silent_for(self, time: float) -> float:
        """Seconds since the latest sample at ``time`` (infinite before any)."""
        return math.inf if self.last_time is None else time - self.last_time
