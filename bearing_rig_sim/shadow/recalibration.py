"""Online re-calibration: one calibration parameter tracked from the bench's steady windows.

A second engine (the *probe*) follows the same measured inputs as the shadow's engine, with the
tracked parameter at a trial value ``theta_p``. For a steady, compared window the shadow's engine
(calibrated value ``theta_0``) predicts ``s_0``, the probe ``s_p``, the bench measures ``s_m``. The
secant ``g = (s_p - s_0) / (theta_p - theta_0)`` linearises the slip around the calibration, and
``s_m - s_0 = g (theta - theta_0)`` is one observation of ``theta``. A scalar recursive least
squares with forgetting factor ``lambda`` (Ljung and Soederstroem, *Theory and Practice of
Recursive Identification*, 1983, ch. 2) updates the estimate:

    K = P g / (lambda + g^2 P);   d += K (y - g d);   P = (1 - K g) P / lambda

with ``d = theta - theta_0``. Whenever the estimate has moved more than :data:`PROBE_MOVE_FRACTION`
of ``theta_0`` from the probe's value, the probe goes on at the estimate (its state kept), so the
secant is taken ever closer to the answer (a secant iteration): the estimate converges to the
value that makes the engine reproduce the bench, not to its linearisation.

The estimate's standard uncertainty is ``sqrt(P s_e^2)``, ``s_e^2`` the forgetting-weighted
mean square of the innovations ``y - g d``. Nothing is ever written to the calibration file here;
:meth:`OnlineCalibration.estimate` only reports.

The tracked parameter is one entry of the calibration file's ``parameters:`` (e.g.
``lubricant.yield_stress_pa``), laid over the bearing file as the calibration itself is
(:class:`CalibrationParameter`), so whatever the physics behind it, the probe is the same twin with
that one value changed. The estimate is checked against the entry's stated plausible range.

Units: the parameter's own; slip in percentage points.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from bearing_rig_sim.config import ConfigError, read_mapping
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.dynamics.parameters import overlay_calibration
from bearing_rig_sim.settings_model import read_file
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.shadow.inputs import SpeedPoint
from bearing_rig_sim.shadow.predictor import MeasuredDrive

PROBE_MOVE_FRACTION = 0.02
"""The probe moves to the estimate once they differ by more than this fraction of the calibrated
value (1)."""

MIN_SECANT_PCT = 1e-4
"""Windows where the probe and the shadow's engine differ by less than this (pp) carry no
information on the parameter and are skipped."""


class RecalibrationError(RigError):
    """The tracked parameter is not in the calibration file, or is zero."""


class CalibrationParameter:
    """One parameter of a calibration file, and the bearing with it set to any value.

    Args:
        bearing_file: the bearing data.
        calibration_file: the calibration laid over it.
        name: a key of the calibration's ``parameters:``; "" for the first one it fitted (its
            ``calibration.fitted``; a file that names none: its first parameter).

    Raises:
        RecalibrationError: no such parameter, or its value is not a non-zero number.
        ConfigError: a file is malformed.
    """

    def __init__(self, bearing_file: Path, calibration_file: Path, name: str) -> None:
        self._bearing, self._bearing_source = read_mapping(bearing_file), str(bearing_file)
        calibration = read_file(CalibrationFile, calibration_file)
        raw = read_mapping(calibration_file)
        entries = raw["parameters"]  # as written: a number or a quantity with unit and range
        fitted = [k for k in (raw.get("calibration") or {}).get("fitted") or [] if k in entries]
        key = name or next(iter(fitted or entries), "")
        if key not in entries:
            raise RecalibrationError(f"recalibrate_parameter: {name!r} is not a parameter of {calibration_file} (it has {', '.join(entries) or 'none'})")
        entry = entries[key]
        value = entry.get("value") if isinstance(entry, dict) else entry
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value == 0.0:
            raise RecalibrationError(f"recalibrate_parameter: {key} of {calibration_file} is not a non-zero number ({value!r})")
        self.name = key
        self.calibrated = float(value)
        self.unit = str(entry.get("unit", "")) if isinstance(entry, dict) else ""
        bounds = entry.get("range") if isinstance(entry, dict) else None
        self.range: tuple[float, float] | None = (float(bounds[0]), float(bounds[1])) if isinstance(bounds, list) and len(bounds) == 2 else None
        self._calibration, self._calibration_source = calibration, str(calibration_file)

    def params(self, value: float) -> BearingParameters:
        """The bearing with this parameter at ``value`` (its other calibrated values kept).

        Raises:
            ConfigError: the bearing file refuses the value (outside its hard limits).
        """
        calibration = self._calibration.model_copy(update={"parameters": {**self._calibration.parameters, self.name: float(value)}})
        source = f"{self._bearing_source} + {self._calibration_source} ({self.name}={value:.6g})"
        return BearingParameters.from_mapping(overlay_calibration(self._bearing, calibration), source)


@dataclass(frozen=True)
class ParameterEstimate:
    """The tracked parameter's estimate.

    Attributes:
        name: the calibration parameter (``section.key``).
        calibrated: its value in the calibration, parameter units.
        value: the estimate.
        std: the estimate's standard uncertainty (NaN before the first update).
        updates: steady windows used (1).
        range: the calibration's stated plausible range, or None.
    """

    name: str
    calibrated: float
    value: float
    std: float
    updates: int
    range: tuple[float, float] | None = None

    @property
    def in_range(self) -> bool:
        """Whether the estimate lies in the stated plausible range (True when none is stated)."""
        return self.range is None or self.range[0] <= self.value <= self.range[1]

    @property
    def ratio(self) -> float:
        """Estimate over the calibrated value (1)."""
        return self.value / self.calibrated


class OnlineCalibration:
    """Recursive least squares on one calibration parameter (see the module docstring).

    Args:
        parameter: the calibration parameter tracked.
        forgetting_factor: lambda, per update (0.5-1].
        probe_step_fraction: the probe starts at ``theta_0 (1 + this)``.
        make_drive: builds a :class:`MeasuredDrive` for given parameters (the shadow's settings).
    """

    def __init__(
        self,
        parameter: CalibrationParameter,
        *,
        forgetting_factor: float,
        probe_step_fraction: float,
        make_drive: Callable[[BearingParameters], MeasuredDrive],
    ) -> None:
        self.parameter = parameter
        self.name = parameter.name
        self.calibrated = parameter.calibrated
        self.forgetting_factor = forgetting_factor
        self.probe_value = self.calibrated * (1.0 + probe_step_fraction)
        self.probe = make_drive(parameter.params(self.probe_value))
        self._d = 0.0
        self._p = 1e6 * self.calibrated**2
        self._e2 = math.nan
        self.updates = 0

    def follow(self, point: SpeedPoint) -> None:
        """The probe follows the same speed point as the shadow's engine."""
        self.probe.follow(point)

    def jump_back(self) -> None:
        """The bench clock went back."""
        self.probe.jump_back()

    def update(self, start: float, end: float, measured_pct: float, predicted_pct: float, slip_of: Callable[[float, float], float]) -> bool:
        """One steady compared window: bench slip ``measured_pct``, the shadow's ``predicted_pct``;
        ``slip_of(cage, inner)`` turns the probe's mean speeds into slip. Whether it was used."""
        probe = self.probe.predict(start, end)
        if probe is None or probe.inner_ring_speed <= 0.0:
            return False
        secant = slip_of(probe.cage_speed, probe.inner_ring_speed) - predicted_pct
        if not math.isfinite(secant) or abs(secant) < MIN_SECANT_PCT:
            return False
        g = secant / (self.probe_value - self.calibrated)
        y = measured_pct - predicted_pct
        lam = self.forgetting_factor
        innovation = y - g * self._d
        k = self._p * g / (lam + g * g * self._p)
        self._d += k * innovation
        self._p = (1.0 - k * g) * self._p / lam
        self._e2 = innovation**2 if not math.isfinite(self._e2) else lam * self._e2 + (1.0 - lam) * innovation**2
        self.updates += 1
        estimate = self.calibrated + self._d
        if abs(estimate - self.probe_value) > PROBE_MOVE_FRACTION * abs(self.calibrated) and abs(self._d) > PROBE_MOVE_FRACTION * abs(self.calibrated):
            try:
                params = self.parameter.params(estimate)
            except ConfigError:
                return True  # beyond what the bearing file accepts: the probe stays where it is
            self.probe_value = estimate
            self.probe.swap_parameters(params)
        return True

    def forget_before(self, time: float) -> None:
        """Drop the probe's integrals before ``time`` (s)."""
        self.probe.forget_before(time)

    def estimate(self) -> ParameterEstimate:
        """The present estimate with its standard uncertainty."""
        std = math.sqrt(self._p * self._e2) if self.updates and math.isfinite(self._e2) else math.nan
        return ParameterEstimate(self.name, self.calibrated, self.calibrated + self._d, std, self.updates, self.parameter.range)
