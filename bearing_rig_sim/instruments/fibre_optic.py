"""Fibre-optic reflective speed sensors of the bench and the counter that turns their pulses
into speeds (docs/paper.md section 8).

Reflective strips are stuck on a shaft (the motor spindle, which carries the inner ring, or the
cage), equally spaced; a fixed fibre-optic sensor sees one light pulse each time a strip passes.
:class:`FibreOpticSensor` emulates the sensor from the shaft's angle as the dynamics engine
integrates it; :class:`PulseCounter` does what the bench's counter does with the pulses: the
speed over whole revolutions from the time between two passages of the same strip. The counter
never sees the true speed, so it runs unchanged on the real bench's pulses.

Conventions: angles in rad, unwrapped (they keep growing past 2 pi) and increasing for a
forward-turning shaft; times in s on the rig clock; speeds in rad/s.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.instruments.base import SHAFT_ANGLES, InstrumentError, InstrumentSettings, Measurand
from bearing_rig_sim.rig.parameters import bounded

TWO_PI = 2.0 * math.pi

MIN_PULSE_SPACING = 1e-9
"""Smallest time between two emitted pulses, s: the resolution of a ROS time stamp (1 ns), so
that pulse stamps stay strictly increasing on the wire."""

JITTER_CLIP = 4.0
"""Timing jitter is a Gaussian truncated at this many standard deviations (1). Assumption: an
electronic trigger's timing error is bounded; the truncation keeps every pulse within
``4 jitter_std`` of its true crossing time and changes the standard deviation by < 0.1 %."""

MAX_STRIP_COUNT = 65535
"""Largest strip count the pulse message can carry (``uint16 strip_count``)."""


class SensorError(InstrumentError):
    """Bad input to a sensor model or a pulse counter (non-finite, time going backwards, ...)."""


@dataclass(frozen=True)
class Pulse:
    """One light pulse: a reflective strip passed the sensor (fields of FibreOpticPulse.msg)."""

    time: float
    """Time of the strip passage on the rig clock, s (with the sensor's timing jitter)."""
    strip_id: int
    """Index of the strip that passed, 0 .. strip_count - 1."""
    strip_count: int
    """Number of strips on the shaft (1)."""
    revolution: int
    """Whole revolutions of the shaft completed since the sensor's first pulse (1):
    ``pulse_index // strip_count``."""
    pulse_index: int
    """Strip passages since the sensor started, counting dropped pulses (1); a jump in this
    index tells the receiver that pulses were lost."""
    sensor_id: str = ""
    """Which shaft's sensor gave the pulse (``"spindle"`` or ``"cage"``); empty if unknown."""

    def message_fields(self) -> dict[str, float | int | str]:
        """The fields of its FibreOpticPulse message (the stamp is :attr:`time`)."""
        return {
            "header.frame_id": f"{self.sensor_id}_sensor",
            "sensor_id": self.sensor_id,
            "strip_id": self.strip_id,
            "strip_count": self.strip_count,
            "revolution": self.revolution,
            "pulse_index": self.pulse_index,
        }


def _require_finite(owner: str, **values: float) -> None:
    for name, value in values.items():
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value):
            raise SensorError(f"{owner}: {name} must be a finite number, got {value!r}")


class FibreOpticSensor:
    """A fibre-optic reflective sensor watching equally spaced strips on a turning shaft.

    Strip ``k`` passes the sensor whenever the shaft angle equals ``phase + 2 pi (k + m N) / N``
    (``N`` strips, ``m`` any integer). :meth:`update` is called once per integration step with
    the shaft's angle at both ends of the step and returns the passages inside it. The crossing
    time is found by linear interpolation of the angle inside the step: for a shaft with angular
    acceleration ``a`` and a step of ``h`` seconds the time error is at most
    ``|a| h^2 / (8 w)`` (``w`` the mean speed over the step; the chord of a convex angle curve
    lies above it, so the interpolated time is early for an accelerating shaft).

    The sensor is direction-blind in reality; this model is for shafts that turn forward and
    ignores backward motion: after the angle has gone back, no pulse is emitted until the shaft
    has passed its furthest angle again (so a shaft rocking at rest gives no spurious pulses).

    Args:
        sensor_id: which shaft the sensor watches, e.g. ``"spindle"`` or ``"cage"``.
        strip_count: number of equally spaced reflective strips, 1 .. 65535.
        jitter_std: standard deviation of the Gaussian timing jitter, s (truncated at
            :data:`JITTER_CLIP` standard deviations); 0 for an ideal sensor.
        phase: shaft angle at which strip 0 passes the sensor, rad.
        seed: seed of the sensor's own random generator (jitter and drops), for reproducible runs.
        drop_probability: probability that a passage gives no pulse, in [0, 1); used to test the
            receivers' handling of lost pulses. Dropped passages still advance ``pulse_index``.
    """

    def __init__(
        self,
        sensor_id: str,
        strip_count: int,
        jitter_std: float = 0.0,
        phase: float = 0.0,
        seed: int = 0,
        drop_probability: float = 0.0,
    ) -> None:
        if not isinstance(sensor_id, str) or not sensor_id:
            raise SensorError(f"sensor_id must be a non-empty string, got {sensor_id!r}")
        owner = f"sensor {sensor_id!r}"
        if isinstance(strip_count, bool) or not isinstance(strip_count, int) or not 1 <= strip_count <= MAX_STRIP_COUNT:
            raise SensorError(f"{owner}: strip_count must be an integer in 1..{MAX_STRIP_COUNT}, got {strip_count!r}")
        _require_finite(owner, jitter_std=jitter_std, phase=phase, drop_probability=drop_probability)
        if jitter_std < 0.0:
            raise SensorError(f"{owner}: jitter_std must be >= 0 s, got {jitter_std!r}")
        if not 0.0 <= drop_probability < 1.0:
            raise SensorError(f"{owner}: drop_probability must be in [0, 1), got {drop_probability!r}")
        self.sensor_id = sensor_id
        self.strip_count = strip_count
        self.jitter_std = float(jitter_std)
        self.phase = float(phase)
        self.drop_probability = float(drop_probability)
        self._rng = np.random.default_rng(seed)
        self._spacing = TWO_PI / strip_count
        self.reset()

    settings: FibreOpticSettings
    """The settings block it was built from (:meth:`from_settings`)."""

    @classmethod
    def from_settings(cls, settings: FibreOpticSettings) -> FibreOpticSensor:
        """The sensor of a settings block."""
        sensor = cls(
            settings.sensor_id,
            settings.strip_count,
            jitter_std=settings.timing_jitter_std_s,
            phase=settings.phase_rad,
            seed=settings.seed,
            drop_probability=settings.pulse_drop_probability,
        )
        sensor.settings = settings
        return sensor

    def observe(self, t0: float, t1: float, measurand: Measurand) -> list[Pulse]:
        """The pulses of the chunk (t0, t1] from the shaft angle at both ends (:meth:`update`)."""
        return self.update(t0, measurand.at_start(), t1, measurand.at_end())

    def reset(self) -> None:
        """Start afresh (e.g. after a clock jump): the next update starts a new pulse count.

        The random generator is not reseeded, so a reset run does not repeat the same jitter.
        """
        self._first_crossing: int | None = None
        self._next_crossing = 0
        self._last_step_end: float | None = None
        self._last_emitted = -math.inf
        self.pulses_emitted = 0
        """Pulses returned since the last reset (1)."""
        self.pulses_dropped = 0
        """Passages that gave no pulse since the last reset (1)."""

    def _crossing_index(self, angle: float) -> int:
        """Index of the last strip passage at or before ``angle``."""
        return math.floor((angle - self.phase) / self._spacing)

    def update(self, t0: float, angle0: float, t1: float, angle1: float) -> list[Pulse]:
        """Pulses of the strips that passed the sensor in the step (t0, t1], in time order.

        Args:
            t0: start of the step, s; not before the end of the previous step.
            angle0: shaft angle at ``t0``, rad (unwrapped).
            t1: end of the step, s; > ``t0``.
            angle1: shaft angle at ``t1``, rad (unwrapped).

        Raises:
            SensorError: a non-finite input, ``t1 <= t0``, or ``t0`` before the previous step's
                end (call :meth:`reset` after a clock jump).
        """
        owner = f"sensor {self.sensor_id!r}"
        _require_finite(owner, t0=t0, angle0=angle0, t1=t1, angle1=angle1)
        if not t1 > t0:
            raise SensorError(f"{owner}: step end t1={t1!r} s must be after its start t0={t0!r} s")
        if self._last_step_end is not None and t0 < self._last_step_end:
            raise SensorError(
                f"{owner}: step starts at t0={t0!r} s, before the previous step's end {self._last_step_end!r} s; reset the sensor after a clock jump"
            )
        self._last_step_end = t1
        if self._first_crossing is None:
            self._first_crossing = self._crossing_index(angle0) + 1
            self._next_crossing = self._first_crossing
        last = self._crossing_index(angle1)
        pulses: list[Pulse] = []
        sweep = angle1 - angle0
        for crossing in range(self._next_crossing, last + 1):
            if sweep > 0.0:
                fraction = (self.phase + crossing * self._spacing - angle0) / sweep
                fraction = min(max(fraction, 0.0), 1.0)
            else:  # the angle jumped between calls; the passage happened at the step's start
                fraction = 0.0
            pulse = self._emit(crossing, t0 + fraction * (t1 - t0))
            if pulse is not None:
                pulses.append(pulse)
        self._next_crossing = max(self._next_crossing, last + 1)
        return pulses

    def _emit(self, crossing: int, true_time: float) -> Pulse | None:
        """The pulse of one passage (jitter, drop and ordering applied), or None if dropped."""
        assert self._first_crossing is not None
        if self.drop_probability > 0.0 and self._rng.random() < self.drop_probability:
            self.pulses_dropped += 1
            return None
        time = true_time
        if self.jitter_std > 0.0:
            error = float(self._rng.normal(0.0, self.jitter_std))
            limit = JITTER_CLIP * self.jitter_std
            time += min(max(error, -limit), limit)
        time = max(time, self._last_emitted + MIN_PULSE_SPACING)
        self._last_emitted = time
        self.pulses_emitted += 1
        index = crossing - self._first_crossing
        return Pulse(
            time=time,
            strip_id=crossing % self.strip_count,
            strip_count=self.strip_count,
            revolution=index // self.strip_count,
            pulse_index=index,
            sensor_id=self.sensor_id,
        )


class PulseCounter:
    """The bench's counter: shaft speed from the pulses of one sensor, over whole revolutions.

    For each pulse, the speed is ``2 pi R / (t - t_ref)``, with ``t_ref`` the time the same
    strip passed ``R`` revolutions earlier (``R = revolutions_per_window``). Using the same strip
    cancels any error in the strips' spacing; a longer window divides the timing-jitter error by
    ``R``. Dropped pulses are detected as a jump in ``pulse_index`` (:attr:`gap_detected`); an
    estimate is still given when the reference passage itself was received.

    Args:
        strip_count: number of strips on the shaft, must match the pulses' ``strip_count``.
        revolutions_per_window: whole revolutions per speed estimate, >= 1.
    """

    def __init__(self, strip_count: int, revolutions_per_window: int = 1) -> None:
        for name, value, upper in (
            ("strip_count", strip_count, MAX_STRIP_COUNT),
            ("revolutions_per_window", revolutions_per_window, 1_000_000),
        ):
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= upper:
                raise SensorError(f"pulse counter: {name} must be an integer in 1..{upper}, got {value!r}")
        self.strip_count = strip_count
        self.revolutions_per_window = revolutions_per_window
        self._span = strip_count * revolutions_per_window
        self.reset()

    def reset(self) -> None:
        """Forget all pulses (e.g. after a clock jump or a sensor restart)."""
        self._times: dict[int, tuple[float, int]] = {}
        self._order: deque[int] = deque()
        self._last_index: int | None = None
        self._last_time: float | None = None
        self._speed: float | None = None
        self._gap = False
        self.lost_pulses = 0
        """Pulses missing from the index sequence since the last reset (1)."""

    @property
    def speed(self) -> float | None:
        """Latest speed estimate, rad/s; None until a whole window has been seen."""
        return self._speed

    @property
    def gap_detected(self) -> bool:
        """True once a jump in ``pulse_index`` (lost pulses) has been seen since the last reset."""
        return self._gap

    @property
    def last_pulse_time(self) -> float | None:
        """Time of the latest pulse, s; None before the first."""
        return self._last_time

    def add(self, pulse: Pulse) -> float | None:
        """Take one pulse; return the new speed estimate (rad/s) if this pulse completes a window.

        Raises:
            SensorError: the pulse has another strip count, a non-finite time, an index or time
                that does not increase, or a strip id inconsistent with its index.
        """
        _require_finite("pulse counter", time=pulse.time)
        if pulse.strip_count != self.strip_count:
            raise SensorError(f"pulse counter: pulse has strip_count {pulse.strip_count}, counter expects {self.strip_count}")
        if self._last_index is not None and self._last_time is not None:
            if pulse.pulse_index <= self._last_index:
                raise SensorError(f"pulse counter: pulse_index {pulse.pulse_index} does not follow {self._last_index}")
            if pulse.time <= self._last_time:
                raise SensorError(f"pulse counter: pulse time {pulse.time!r} s is not after the previous {self._last_time!r} s")
            if pulse.pulse_index > self._last_index + 1:
                self._gap = True
                self.lost_pulses += pulse.pulse_index - self._last_index - 1
        self._last_index = pulse.pulse_index
        self._last_time = pulse.time
        reference_index = pulse.pulse_index - self._span
        while self._order and self._order[0] <= reference_index - 1:
            del self._times[self._order.popleft()]
        self._times[pulse.pulse_index] = (pulse.time, pulse.strip_id)
        self._order.append(pulse.pulse_index)
        reference = self._times.get(reference_index)
        if reference is None:
            return None
        reference_time, reference_strip = reference
        if reference_strip != pulse.strip_id:
            raise SensorError(
                f"pulse counter: strip {pulse.strip_id} at index {pulse.pulse_index} but strip {reference_strip} "
                f"{self._span} pulses earlier; the strip count or the indices are wrong"
            )
        self._speed = TWO_PI * self.revolutions_per_window / (pulse.time - reference_time)
        return self._speed

    def is_stale(self, now: float, max_period: float) -> bool:
        """True if no pulse came within ``max_period`` s before ``now`` (or none yet): sensor loss,
        or a shaft turning slower than one strip per ``max_period``.

        Raises:
            SensorError: ``now`` not finite, or ``max_period`` not finite and > 0.
        """
        _require_finite("pulse counter", now=now, max_period=max_period)
        if max_period <= 0.0:
            raise SensorError(f"pulse counter: max_period must be > 0 s, got {max_period!r}")
        return self._last_time is None or now - self._last_time > max_period


@dataclass(frozen=True)
class FibreOpticSettings(InstrumentSettings):
    """One fibre-optic sensor's block in the rig file's ``sensors`` section (measuring a shaft
    angle) and the bench counter that turns its pulses into a speed."""

    MSGTYPE: ClassVar[str] = "bearing_rig_msgs/msg/FibreOpticPulse"

    sensor_id: str
    """Which shaft's sensor it is, as its pulses name it (``"spindle"``, ``"cage"``); the
    pulse's frame is ``<sensor_id>_sensor``."""
    strip_count: int = bounded(ge=1, le=MAX_STRIP_COUNT)
    """Reflective strips on the shaft (1)."""
    phase_rad: float = bounded(ge=0.0, lt=TWO_PI, unit="rad")
    """Shaft angle at which strip 0 passes the sensor, rad."""
    timing_jitter_std_s: float = bounded(ge=0.0, le=1e-3, unit="s")
    """Standard deviation of the pulse timing jitter, s."""
    pulse_drop_probability: float = bounded(ge=0.0, lt=1.0, unit="1")
    """Probability that a strip passage gives no pulse (1); 0 on a healthy bench."""
    counter_revolutions_per_window: int = bounded(ge=1, le=1000)
    """Whole revolutions per speed estimate of the sensor's counter (1)."""
    seed: int = bounded(ge=0)
    """Seed of this sensor's random generator (jitter, drops) (1)."""

    def check_consistency(self, error: Callable[[str, str], ConfigError]) -> None:
        """The common checks; the measurand is a shaft angle."""
        super().check_consistency(error)
        if self.measures not in SHAFT_ANGLES:
            raise error("measures", f"a fibre-optic sensor watches a shaft: must be one of {', '.join(SHAFT_ANGLES)}, got {self.measures!r}")

    def counter(self) -> PulseCounter:
        """A pulse counter matching this sensor."""
        return PulseCounter(self.strip_count, self.counter_revolutions_per_window)
