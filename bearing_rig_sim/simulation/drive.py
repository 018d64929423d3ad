"""The spindle drive: the speed command of the rig's motor, followed chunk by chunk.

The dynamics engine takes the inner-ring motion as a constant angular acceleration per call of
``advance`` (one chunk). :class:`SpindleDrive` holds the current speed command, a
:class:`~bearing_rig_sim.rig.speed_profile.SegmentSpeed` that starts from the speed the spindle had
when the command took effect, and gives for a chunk ``[t, t + h]`` the constant acceleration
``(w(t + h) - w_now) / h`` that brings the inner ring from its present speed ``w_now`` to the
profile's speed at the chunk's end. The engine's speed therefore equals the profile at every
chunk boundary (whatever small drift it had is corrected in the next chunk), and within a chunk
it is the chord of the profile:

* STEP ramp (the paper's drive function, docs/paper.md section 5): ``w`` is
  :func:`~bearing_rig_sim.rig.speed_profile.step_ramp`; its slope is zero at both ends, so the first
  and last chunks of a ramp accelerate gently. A ramp time of 0 is a jump, spread over one
  chunk (a motor cannot jump; one chunk is 1 ms by default).
* Constant acceleration: ``|a|`` towards the target until the target is reached, then 0; the
  chunk in which the target is reached gets the mean acceleration that ends exactly on it.

A command may carry the rig-clock time at which it takes effect; a time in the past (or none)
means now. Commands in the future wait in a queue and take effect at the first chunk boundary
at or after their time, from the speed the spindle has then.

Invalid commands (non-finite or negative target speed, non-positive acceleration, a speed or
acceleration beyond the rig's limits, a negative ramp time, a time too far ahead) raise
:class:`SpindleCommandError` and leave the drive on its last valid command.

Units: rad/s, rad/s^2, s.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.speed_profile import SegmentSpeed, SpeedProfileKind


class SpindleCommandError(RigError):
    """A spindle command the drive refuses; the message says which field and why."""


@dataclass(frozen=True)
class SpindleCommand:
    """One speed command for the spindle (the fields of SpindleCommand.msg, SI units).

    Attributes:
        target_speed: inner-ring speed to reach, rad/s (finite, >= 0).
        profile: STEP ramp over ``ramp_time`` or constant ``acceleration``.
        ramp_time: duration of the STEP ramp, s (>= 0; 0 = jump). Ignored for constant
            acceleration.
        acceleration: magnitude of the angular acceleration, rad/s^2 (> 0). Ignored for STEP.
        time: rig-clock time at which the command takes effect, s; None (or a time already
            past) = at once.
    """

    target_speed: float
    profile: SpeedProfileKind = SpeedProfileKind.STEP
    ramp_time: float = 0.0
    acceleration: float = 0.0
    time: float | None = None


def profile_from_code(code: int) -> SpeedProfileKind:
    """The profile of a ``SpindleCommand.msg`` ``PROFILE_*`` code (0 STEP, 1 constant acceleration).

    Raises:
        SpindleCommandError: any other code.
    """
    for kind in SpeedProfileKind:
        if kind.message_code == code:
            return kind
    raise SpindleCommandError(f"profile: unknown code {code!r}; expected 0 (STEP) or 1 (constant acceleration)")


def _finite(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SpindleCommandError(f"{name}: must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise SpindleCommandError(f"{name}: must be finite, got {value!r}")
    return x


class SpindleDrive:
    """The spindle's speed command and the per-chunk acceleration that follows it.

    Args:
        initial_speed: spindle speed before any command, rad/s (>= 0); held until the first
            command.
        start_time: rig-clock time of the start, s.
        max_speed: highest target speed the rig's motor accepts, rad/s (> 0).
        max_acceleration: highest constant acceleration accepted, rad/s^2 (> 0).
        max_lead: how far ahead of the rig clock a command's time may lie, s (>= 0); a time
            further ahead is refused (it is most likely on another clock).

    Raises:
        SpindleCommandError: a non-finite or out-of-range argument.
    """

    def __init__(
        self,
        initial_speed: float,
        start_time: float = 0.0,
        *,
        max_speed: float,
        max_acceleration: float,
        max_lead: float,
    ) -> None:
        for name, value in (("max_speed", max_speed), ("max_acceleration", max_acceleration)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value) or not value > 0.0:
                raise SpindleCommandError(f"{name}: must be > 0, got {value!r}")
        if isinstance(max_lead, bool) or not isinstance(max_lead, (int, float)) or math.isnan(max_lead) or max_lead < 0.0:
            raise SpindleCommandError(f"max_lead: must be >= 0 s, got {max_lead!r}")
        self.max_speed = float(max_speed)
        self.max_acceleration = float(max_acceleration)
        self.max_lead = float(max_lead)
        speed = self._check_target(initial_speed, "initial_speed")
        start = _finite("start_time", start_time)
        self._profile = SegmentSpeed(start, speed, speed, SpeedProfileKind.STEP, 0.0, 0.0)
        self._command = SpindleCommand(speed, SpeedProfileKind.STEP, 0.0, 0.0, start)
        self._pending: list[tuple[float, int, SpindleCommand]] = []
        self._sequence = 0

    # -- state ---------------------------------------------------------------------------------
    @property
    def profile(self) -> SegmentSpeed:
        """The speed profile in force (start time and speed, target, kind, ramp, acceleration)."""
        return self._profile

    @property
    def command(self) -> SpindleCommand:
        """The last command that took effect (with the time it did)."""
        return self._command

    @property
    def pending(self) -> tuple[SpindleCommand, ...]:
        """Accepted commands waiting for their time, earliest first."""
        return tuple(c for _, _, c in self._pending)

    def speed_at(self, t: float) -> float:
        """The profile's inner-ring speed at time ``t`` (s), rad/s (queued commands not included)."""
        return self._profile.at(t)[0]

    # -- commands ------------------------------------------------------------------------------
    def submit(self, command: SpindleCommand, now: float, current_speed: float) -> None:
        """Accept a command: at once if its time is None or not after ``now``, else queued.

        Args:
            command: the command.
            now: the rig clock, s.
            current_speed: the spindle's speed now, rad/s (the start of an immediate profile).

        Raises:
            SpindleCommandError: the command is invalid (see the module docstring); the drive
                keeps its previous command and queue.
        """
        checked = self.validate(command, now)
        if checked.time is None or checked.time <= now:
            self._activate(checked, now, current_speed)
            return
        self._sequence += 1
        bisect.insort(self._pending, (checked.time, self._sequence, checked))

    def validate(self, command: SpindleCommand, now: float) -> SpindleCommand:
        """The command with its numbers as floats, checked against the rig's limits.

        Raises:
            SpindleCommandError: naming the field and the allowed range.
        """
        if not isinstance(command.profile, SpeedProfileKind):
            raise SpindleCommandError(f"profile: must be a SpeedProfileKind, got {command.profile!r}")
        target = self._check_target(command.target_speed, "target_speed")
        ramp, accel = 0.0, 0.0
        if command.profile is SpeedProfileKind.STEP:
            ramp = _finite("ramp_time", command.ramp_time)
            if ramp < 0.0:
                raise SpindleCommandError(f"ramp_time: must be >= 0 s, got {command.ramp_time!r}")
        else:
            accel = _finite("acceleration", command.acceleration)
            if not accel > 0.0:
                raise SpindleCommandError(f"acceleration: must be > 0 rad/s^2, got {command.acceleration!r}")
            if accel > self.max_acceleration:
                raise SpindleCommandError(f"acceleration: {accel!r} rad/s^2 is above the rig's limit of {self.max_acceleration!r} rad/s^2")
        time = None
        if command.time is not None:
            time = _finite("time", command.time)
            if time - now > self.max_lead:
                raise SpindleCommandError(
                    f"time: {time!r} s is {time - now:.6g} s ahead of the rig clock ({now!r} s), more than the "
                    f"{self.max_lead!r} s allowed; is the command stamped on another clock?"
                )
        return SpindleCommand(target, command.profile, ramp, accel, time)

    def _check_target(self, value: object, name: str) -> float:
        target = _finite(name, value)
        if target < 0.0:
            raise SpindleCommandError(f"{name}: must be >= 0 rad/s, got {value!r}")
        if target > self.max_speed:
            raise SpindleCommandError(f"{name}: {target!r} rad/s is above the rig's limit of {self.max_speed!r} rad/s")
        return target

    def _activate(self, command: SpindleCommand, t: float, speed: float) -> None:
        start_speed = max(float(speed), 0.0)
        self._profile = SegmentSpeed(t, start_speed, command.target_speed, command.profile, command.ramp_time, command.acceleration)
        self._command = SpindleCommand(command.target_speed, command.profile, command.ramp_time, command.acceleration, t)

    def clear_pending(self) -> None:
        """Drop the queued commands (e.g. after a restart of the rig clock)."""
        self._pending.clear()

    # -- per chunk -----------------------------------------------------------------------------
    def chunk_acceleration(self, t: float, h: float, current_speed: float | None = None) -> float:
        """The constant inner-ring acceleration for the chunk ``[t, t + h]``, rad/s^2.

        Queued commands whose time is at or before ``t`` take effect first, from
        ``current_speed`` (or the profile's speed at ``t``).

        Args:
            t: start of the chunk, s.
            h: chunk length, s (> 0).
            current_speed: the spindle's speed at ``t``, rad/s; None: the profile's.

        Returns:
            ``(w(t + h) - w_start) / h``: the profile's speed is reached exactly at ``t + h``.

        Raises:
            SpindleCommandError: ``t`` or ``current_speed`` non-finite, or ``h`` not > 0.
        """
        t = _finite("t", t)
        h = _finite("h", h)
        if not h > 0.0:
            raise SpindleCommandError(f"h: the chunk length must be > 0 s, got {h!r}")
        start = self.speed_at(t) if current_speed is None else _finite("current_speed", current_speed)
        while self._pending and self._pending[0][0] <= t:
            _, _, command = self._pending.pop(0)
            self._activate(command, t, start)
        return (self.speed_at(t + h) - start) / h
