"""Measurement and control of the axial load: the load cell (noise, low-pass) and the PI(D)
force controller that drives the linear brake's voltage (docs/paper.md section 8).

Units: N, s, V. Parameter values and their sources: ``config/rig.yaml``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bearing_rig_sim.rig.loading_elements import check_time_step, clip
from bearing_rig_sim.rig.parameters import ParameterRecord, bounded


@dataclass(frozen=True)
class LoadCellParams(ParameterRecord):
    """Load cell under the housing.

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.load_cell``.
    """

    noise_std_n: float = bounded(ge=0.0)
    """Standard deviation of the Gaussian noise of each sample, N."""
    cutoff_hz: float = bounded(ge=0.0)
    """Cut-off of the first-order low-pass filter, Hz; 0 = no filter."""
    seed: int = bounded(ge=0)
    """Seed of the noise generator (1)."""


class LoadCell:
    """Measures the housing force with Gaussian noise and an optional first-order low-pass."""

    def __init__(self, params: LoadCellParams) -> None:
        self.params = params
        self._rng = np.random.default_rng(params.seed)
        self.value = 0.0
        """Latest (noisy, filtered) reading, N."""
        self._primed = False

    def measure(self, force: float, dt: float) -> float:
        """Sample ``force`` (N) after ``dt`` s; return the reading, N."""
        dt = check_time_step(dt)
        sample = force
        if self.params.noise_std_n > 0.0:
            sample += float(self._rng.normal(0.0, self.params.noise_std_n))
        if self.params.cutoff_hz > 0.0 and self._primed:
            gain = 1.0 - math.exp(-2.0 * math.pi * self.params.cutoff_hz * dt)
            self.value += gain * (sample - self.value)
        else:
            self.value = sample
        self._primed = True
        return self.value

    def reset(self) -> None:
        """Forget the filter state (the noise generator continues)."""
        self.value = 0.0
        self._primed = False


@dataclass(frozen=True)
class ForceControllerParams(ParameterRecord):
    """PI(D) force controller driving the brake voltage.

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.controller``.
    """

    proportional_gain_v_per_n: float = bounded(ge=0.0)
    """Kp, V/N."""
    integral_gain_v_per_n_s: float = bounded(ge=0.0)
    """Ki, V/(N s)."""
    derivative_gain_v_s_per_n: float = bounded(ge=0.0)
    """Kd on the measurement (not the error, so set-point changes give no kick), V s/N."""
    derivative_filter_s: float = bounded(gt=0.0)
    """Time constant of the first-order filter on the derivative, s."""
    output_min_v: float = bounded(le=0.0)
    """Lowest voltage command, V (negative drives the brake backwards to unload faster)."""
    output_max_v: float = bounded(gt=0.0)
    """Highest voltage command, V."""
    setpoint_rate_n_per_s: float = bounded(gt=0.0)
    """Largest rate of change of the set-point seen by the loop, N/s."""


class ForceController:
    """PI(D) on the load-cell force with set-point rate limiting, output saturation and
    anti-windup by conditional integration (the integrator holds while the output is saturated
    and the error would drive it further into saturation)."""

    def __init__(self, params: ForceControllerParams) -> None:
        self.params = params
        self.reset(0.0)

    def reset(self, measured: float) -> None:
        """Restart from a measured force (N): integrator empty, set-point ramp starting there."""
        self.integral = 0.0
        """Integrator state, V."""
        self.ramped_setpoint = measured
        """Set-point after rate limiting, N."""
        self._derivative = 0.0
        self._last_measured: float | None = None

    def update(self, setpoint: float, measured: float, dt: float) -> float:
        """One control period: the voltage command (V) for a set-point and a measurement (N)."""
        p = self.params
        dt = check_time_step(dt)
        max_change = p.setpoint_rate_n_per_s * dt
        self.ramped_setpoint += clip(setpoint - self.ramped_setpoint, -max_change, max_change)
        error = self.ramped_setpoint - measured
        if p.derivative_gain_v_s_per_n > 0.0 and self._last_measured is not None:
            raw = (measured - self._last_measured) / dt
            self._derivative += (raw - self._derivative) * (1.0 - math.exp(-dt / p.derivative_filter_s))
        self._last_measured = measured
        integral = self.integral + p.integral_gain_v_per_n_s * error * dt
        unsaturated = p.proportional_gain_v_per_n * error + integral - p.derivative_gain_v_s_per_n * self._derivative
        command = clip(unsaturated, p.output_min_v, p.output_max_v)
        winding_up = (unsaturated > p.output_max_v and error > 0.0) or (unsaturated < p.output_min_v and error < 0.0)
        if not winding_up:
            self.integral = integral
        return command
