"""Sensors a bench has for heat and friction: an outer-ring thermocouple and a housing torque meter.

* :class:`Thermocouple`: a thermocouple cemented on the outer ring's face, read through its own
  first-order lag (time constant tau) with white measurement noise: exactly,
  y(t + h) = x + (y(t) - x) exp(-h / tau) for the true temperature x held over the step, plus
  N(0, sigma^2).
* :class:`TorqueMeter`: the reaction torque on the housing (a free-floating housing on a
  torque arm and load cell, or an in-line torque flange), the bearing's friction torque
  through a first-order lag (the arm's and amplifier's bandwidth) with noise.

Defaults and their sources: :data:`THERMOCOUPLE_TIME_CONSTANT_S` etc. Both are seeded, so a
run is repeatable.
"""

from __future__ import annotations

import math

import numpy as np

THERMOCOUPLE_TIME_CONSTANT_S = 2.0
"""Time constant of a 0.25-0.5 mm sheathed or exposed type K junction cemented on a steel face,
s (thermocouple makers' response tables: 0.5-5 s in still air)."""
THERMOCOUPLE_NOISE_K = 0.05
"""RMS noise of a thermocouple amplifier reading, K (16-24 bit amplifiers: 0.02-0.1 K); its
accuracy class (IEC 60584-1 class 1: +-1.5 K) is an offset, not modelled."""
THERMOCOUPLE_RATE_HZ = 10.0
"""How often the thermocouple is read, Hz (simulated time)."""
TORQUE_METER_TIME_CONSTANT_S = 0.01
"""First-order lag of the torque arm and its amplifier, s (bandwidth about 16 Hz)."""
TORQUE_METER_NOISE_NM = 2e-4
"""RMS noise of the torque reading, N m (0.1 % of a 0.2 N m range)."""
TORQUE_METER_RATE_HZ = 100.0
"""How often the torque meter is read, Hz (simulated time)."""


class _FirstOrderSensor:
    """A first-order lag with white noise, updated exactly over each step."""

    def __init__(self, time_constant: float, noise: float, seed: int | None) -> None:
        if not time_constant > 0.0 or not math.isfinite(time_constant):
            raise ValueError(f"time constant must be > 0 s, got {time_constant!r}")
        if not noise >= 0.0:
            raise ValueError(f"noise must be >= 0, got {noise!r}")
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


class Thermocouple(_FirstOrderSensor):
    """The outer-ring thermocouple (degC in, degC out)."""

    def __init__(self, time_constant: float = THERMOCOUPLE_TIME_CONSTANT_S, noise: float = THERMOCOUPLE_NOISE_K, seed: int | None = 0) -> None:
        super().__init__(time_constant, noise, seed)


class TorqueMeter(_FirstOrderSensor):
    """The housing's torque meter (N m in, N m out)."""

    def __init__(self, time_constant: float = TORQUE_METER_TIME_CONSTANT_S, noise: float = TORQUE_METER_NOISE_NM, seed: int | None = 1) -> None:
        super().__init__(time_constant, noise, seed)
