"""Instruments a bench has for heat and friction: an outer-ring thermocouple and a housing torque
meter, each a first-order lag with white noise, read at a fixed rate.

* :class:`Thermocouple`: a thermocouple cemented on a ring's face, read through its own
  first-order lag (time constant tau) with white measurement noise: exactly,
  y(t + h) = x + (y(t) - x) exp(-h / tau) for the true temperature x held over the step, plus
  N(0, sigma^2). Published as ``sensor_msgs/Temperature`` (degC, variance sigma^2 in K^2).
* :class:`TorqueMeter`: the reaction torque on the housing (a free-floating housing on a torque
  arm and load cell, or an in-line torque flange), the bearing's friction torque through a
  first-order lag (the arm's and amplifier's bandwidth) with noise. Published as
  ``geometry_msgs/WrenchStamped`` (torque.z, N m).

Their time constants, noise and rates are in the rig file's ``sensors`` section, each with its
source (config/rig.yaml). Both are seeded, so a run is repeatable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from bearing_rig_sim.instruments.base import InstrumentError, InstrumentSettings, Measurand, Reading, Sample
from bearing_rig_sim.rig.parameters import bounded

PERIOD_TOLERANCE = 1e-9
"""A reading is due once this fraction short of a whole period has passed since the last (the
chunk ends sum to the period up to rounding)."""


class FirstOrderLag:
    """A first-order lag with white noise, updated exactly over each step.

    Args:
        time_constant: the lag's time constant, s (> 0).
        noise: RMS of the white noise added to each reading, in the measured quantity's unit
            (>= 0).
        seed: seed of its own random generator.
    """

    def __init__(self, time_constant: float, noise: float, seed: int | None) -> None:
        if not time_constant > 0.0 or not math.isfinite(time_constant):
            raise InstrumentError(f"time constant must be > 0 s, got {time_constant!r}")
        if not noise >= 0.0:
            raise InstrumentError(f"noise must be >= 0, got {noise!r}")
        self.time_constant = float(time_constant)
        self.noise = float(noise)
        self._rng = np.random.default_rng(seed)
        self.state: float | None = None
        """The sensing element's value (without noise), or None before the first update."""

    def update(self, true_value: float, h: float) -> float:
        """Advance by ``h`` seconds with the measured quantity at ``true_value``; return the
        reading (the element's value plus noise)."""
        if self.state is None:
            self.state = float(true_value)
        else:
            self.state = true_value + (self.state - true_value) * math.exp(-h / self.time_constant)
        return self.state + (float(self._rng.normal(0.0, self.noise)) if self.noise > 0.0 else 0.0)


@dataclass(frozen=True)
class SampledSettings(InstrumentSettings):
    """The keys of a first-order instrument read at a fixed rate; each model adds its noise."""

    frame_id: str
    """Where it sits (the message's ``header.frame_id``), e.g. ``outer_ring``."""
    rate_hz: float = bounded(gt=0.0, le=10000.0, unit="Hz")
    """How often it is read, Hz (simulated time)."""
    time_constant_s: float = bounded(gt=0.0, le=60.0, unit="s")
    """Time constant of its first-order lag, s."""
    seed: int = bounded(ge=0)
    """Seed of its noise generator (1)."""


@dataclass(frozen=True)
class ThermocoupleSettings(SampledSettings):
    """A thermocouple's block in the rig file's ``sensors`` section (its time constant: the
    junction's on its face)."""

    MSGTYPE: ClassVar[str] = "sensor_msgs/msg/Temperature"

    noise_std_k: float = bounded(ge=0.0, le=1.0, unit="K")
    """RMS noise of the amplifier's reading, K."""


@dataclass(frozen=True)
class TorqueMeterSettings(SampledSettings):
    """A torque meter's block in the rig file's ``sensors`` section (its time constant: the
    torque arm's and amplifier's)."""

    MSGTYPE: ClassVar[str] = "geometry_msgs/msg/WrenchStamped"

    noise_std_n_m: float = bounded(ge=0.0, le=0.1, unit="N m")
    """RMS noise of the torque reading, N m."""


class _SampledInstrument:
    """A first-order instrument read every ``1 / rate_hz`` s of simulated time: each reading
    lags the measured quantity (its value at the chunk's end, held over the time since the
    previous reading)."""

    def __init__(self, rate_hz: float, lag: FirstOrderLag) -> None:
        self.period = 1.0 / rate_hz
        """Time between readings, s."""
        self.lag = lag
        self._last: float | None = None

    def reset(self) -> None:
        """Start afresh: the next reading is one period after the next chunk's start."""
        self._last = None
        self.lag.state = None

    def observe(self, t0: float, t1: float, measurand: Measurand) -> list[Reading]:
        """A reading at the chunk's end if a period has passed since the previous one (the
        first: since the first chunk's start), else none."""
        if self._last is None:
            self._last = t0
        h = t1 - self._last
        if h < self.period * (1.0 - PERIOD_TOLERANCE):
            return []
        self._last = t1
        return [Sample(t1, self.fields(self.lag.update(measurand.at_end(), h)))]

    def fields(self, value: float) -> dict[str, float | int | str]:
        """The message fields of a reading of ``value``."""
        raise NotImplementedError


class Thermocouple(_SampledInstrument):
    """A thermocouple (degC in, degC out; see the module documentation)."""

    def __init__(self, settings: ThermocoupleSettings) -> None:
        super().__init__(settings.rate_hz, FirstOrderLag(settings.time_constant_s, settings.noise_std_k, settings.seed))
        self.settings = settings

    def fields(self, value: float) -> dict[str, float | int | str]:
        """``temperature`` degC and its ``variance``, K^2 (the noise's)."""
        return {"header.frame_id": self.settings.frame_id, "temperature": value, "variance": self.settings.noise_std_k**2}


class TorqueMeter(_SampledInstrument):
    """A torque meter about the spindle axis (N m in, N m out)."""

    def __init__(self, settings: TorqueMeterSettings) -> None:
        super().__init__(settings.rate_hz, FirstOrderLag(settings.time_constant_s, settings.noise_std_n_m, settings.seed))
        self.settings = settings

    def fields(self, value: float) -> dict[str, float | int | str]:
        """``wrench.torque.z``, N m."""
        return {"header.frame_id": self.settings.frame_id, "wrench.torque.z": value}
