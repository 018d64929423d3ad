"""The inner-ring speed of one program segment against time: the paper's STEP drive function
(docs/paper.md section 5, paper Eq. 10, with its typo corrected: ``D = (t - t0) / (t1 - t0)``) or a
constant angular acceleration. SI throughout (rad/s, rad/s^2, s).

The program parser (:mod:`bearing_rig_sim.rig.program`) builds a :class:`SegmentSpeed` for each
segment; the simulator's spindle drive (:mod:`bearing_rig_sim.simulation.drive`) follows it. No
YAML and no configuration in here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

__all__ = ["SegmentSpeed", "SpeedProfileKind", "step_ramp", "step_ramp_rate"]


# ---------------------------------------------------------------------------------------------
# The STEP drive function
# ---------------------------------------------------------------------------------------------
def _step_fraction(t: float, t0: float, t1: float) -> float | None:
    """D = (t - t0)/(t1 - t0) inside the ramp, None outside it."""
    if not (math.isfinite(t) and math.isfinite(t0) and math.isfinite(t1)):
        raise ValueError(f"STEP: times must be finite, got t={t!r}, t0={t0!r}, t1={t1!r}")
    if t1 < t0:
        raise ValueError(f"STEP: t1={t1!r} must not be before t0={t0!r}")
    if t <= t0 or t >= t1:
        return None
    return (t - t0) / (t1 - t0)


def step_ramp(t: float, t0: float, x0: float, t1: float, x1: float) -> float:
    """The paper's STEP drive function (docs/paper.md section 5, Eq. 10, typo corrected).

    ``x0`` for ``t <= t0``; ``x1`` for ``t >= t1``; between, the cubic
    ``x0 + (x1 - x0) D^2 (3 - 2 D)`` with ``D = (t - t0)/(t1 - t0)``: monotonic, with zero slope
    at both ends. ``t0 == t1`` is a jump at ``t0`` (``x1`` from ``t0`` on).

    Raises:
        ValueError: a non-finite time, or ``t1 < t0``.
    """
    d = _step_fraction(t, t0, t1)
    if d is None:
        return x0 if t < t0 or (t == t0 and t1 > t0) else x1
    return x0 + (x1 - x0) * d * d * (3.0 - 2.0 * d)


def step_ramp_rate(t: float, t0: float, x0: float, t1: float, x1: float) -> float:
    """Time derivative of :func:`step_ramp`: ``6 (x1 - x0) D (1 - D) / (t1 - t0)``, 0 outside
    the ramp (and 0 for a jump, whose impulse is not represented)."""
    d = _step_fraction(t, t0, t1)
    if d is None:
        return 0.0
    return 6.0 * (x1 - x0) * d * (1.0 - d) / (t1 - t0)


class SpeedProfileKind(str, Enum):
    """How a segment changes the inner-ring speed; compares equal to its string value."""

    STEP = "step"
    """Cubic STEP ramp over ``ramp_time`` (0 = jump)."""
    CONSTANT_ACCELERATION = "constant_acceleration"
    """Constant angular acceleration until the target speed."""

    @property
    def message_code(self) -> int:
        """The ``PROFILE_*`` constant of SpindleCommand.msg for this kind."""
        return 0 if self is SpeedProfileKind.STEP else 1


@dataclass(frozen=True)
class SegmentSpeed:
    """The inner-ring speed of one segment as a function of time.

    Args (fields):
        start_time: when the segment starts, s.
        start_speed: inner-ring speed at the start, rad/s.
        target_speed: speed to reach, rad/s.
        kind: STEP ramp or constant acceleration.
        ramp_time: STEP ramp duration, s (STEP only).
        acceleration: magnitude of the angular acceleration, rad/s^2 (constant acceleration only).
    """

    start_time: float
    start_speed: float
    target_speed: float
    kind: SpeedProfileKind
    ramp_time: float = 0.0
    acceleration: float = 0.0

    @property
    def ramp_end(self) -> float:
        """Time at which the target speed is reached, s."""
        if self.kind is SpeedProfileKind.STEP:
            return self.start_time + self.ramp_time
        return self.start_time + abs(self.target_speed - self.start_speed) / self.acceleration

    def at(self, t: float) -> tuple[float, float]:
        """Inner-ring (speed in rad/s, angular acceleration in rad/s^2) at time ``t`` (s).

        Before the segment's start: the start speed; after the ramp: the target speed.
        """
        if self.kind is SpeedProfileKind.STEP:
            args = (t, self.start_time, self.start_speed, self.start_time + self.ramp_time, self.target_speed)
            return step_ramp(*args), step_ramp_rate(*args)
        change = self.target_speed - self.start_speed
        if t <= self.start_time or change == 0.0:
            return (self.start_speed if t <= self.start_time else self.target_speed), 0.0
        if t >= self.ramp_end:
            return self.target_speed, 0.0
        signed = math.copysign(self.acceleration, change)
        return self.start_speed + signed * (t - self.start_time), signed
