"""The residual's band and the anomaly rule (no ROS).

**Band.** The model's stated uncertainty of one window's residual, in percentage points:

    u = sqrt(rms_cal^2 + u_sensor^2),   u_sensor = 100 * 2 sigma_t / T_window,   band = k u

``rms_cal`` is the calibration's RMS slip error against the bench data it was fitted to (the
calibration file's ``rms_slip_pct``); ``u_sensor`` the sensor resolution at the present speed: a
window's slip comes from two cage pulse times and the spindle angle interpolated at the same two
times, each carrying one pulse-timing jitter ``sigma_t``, so the relative error of each mean
speed is at most ``2 sigma_t / T_window`` (taken whole, not in quadrature, to stay on the safe
side). ``k`` is the coverage factor (2: about 95 % of a normal scatter).

**Anomaly.** A compared window whose residual lies outside its band starts (or continues) an
excursion; a compared window inside the band ends it. An excursion lasting longer than
``warn_after_s`` (from the start of its first window to the end of the latest) is a WARN, longer
than ``error_after_s`` an ERROR. A window that cannot be compared (input fault, engine settling,
spindle below the minimum speed) ends the excursion too: a fault never builds up to an anomaly.
The sign names the likely class (see :func:`likely_cause`).

**Temperature and torque bands** (beside the slip's; the same coverage factor ``k``):

    u_T = sqrt((f_T (T_pred - T_start))^2 + u_tc^2),     band_T = k u_T   (K)
    u_M = sqrt((f_M M_pred)^2 + sigma_M^2 / n),          band_M = k u_M   (N m)

``f_T`` is the thermal network's relative uncertainty of the outer ring's rise since the
network's start ``T_start`` (the bench thermocouple's first reading, or ambient; its
conductances: convection films and contact conductances are known to about +-30 %), ``u_tc``
the thermocouple's standard uncertainty (its accuracy class); ``f_M`` the friction torque's
relative uncertainty propagated from the calibration's covariance and its load uncertainty (about
3 %), ``sigma_M`` the torque meter's noise averaged over its ``n`` samples in the
window. The settings carry the values and their sources (``config/shadow.yaml``).

Units: s; slip, residual and band in percentage points; temperature in K, torque in N m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bearing_rig_sim.health import HealthLevel

HIGHER = (
    "slip higher than predicted: more drag or less traction than calibrated (lubricant more "
    "viscous, more of it, or colder; cage rubbing on its land or pockets; less axial load on the "
    "bearing than the load cell reads)"
)
LOWER = (
    "slip lower than predicted: less drag or more traction than calibrated (lubricant thinner, "
    "starved or warmer; more axial load on the bearing than the load cell reads)"
)


def likely_cause(residual_pct: float) -> str:
    """The likely class of a residual's sign (measured minus predicted slip)."""
    return HIGHER if residual_pct > 0.0 else LOWER


def band_pct(duration_s: float, *, calibration_rms_pct: float, jitter_std_s: float, coverage: float) -> float:
    """Half-width of the residual's band for a window of ``duration_s`` seconds, pp (see the
    module docstring)."""
    sensor = 100.0 * 2.0 * jitter_std_s / duration_s if duration_s > 0.0 else math.inf
    return coverage * math.hypot(calibration_rms_pct, sensor)


def temperature_band_k(predicted_c: float, start_c: float, *, model_fraction: float, sensor_k: float, coverage: float) -> float:
    """Half-width of the outer-ring temperature residual's band, K (module docstring): the
    prediction ``predicted_c`` and the network's start ``start_c``, degC; NaN without a
    prediction."""
    if not (math.isfinite(predicted_c) and math.isfinite(start_c)):
        return math.nan
    return coverage * math.hypot(model_fraction * (predicted_c - start_c), sensor_k)


def torque_band_nm(predicted_nm: float, samples: int, *, model_fraction: float, noise_nm: float, coverage: float) -> float:
    """Half-width of the housing torque residual's band, N m (module docstring); NaN without a
    prediction."""
    if not math.isfinite(predicted_nm):
        return math.nan
    averaged = noise_nm / math.sqrt(samples) if samples > 0 else noise_nm
    return coverage * math.hypot(model_fraction * predicted_nm, averaged)


@dataclass(frozen=True)
class AnomalyState:
    """Where the anomaly rule stands after a window.

    Attributes:
        level: OK, WARN (outside the band longer than ``warn_after_s``) or ERROR.
        outside_for: duration of the present excursion, s (0 when inside).
        detail: the reason, with the likely class; empty at OK.
    """

    level: HealthLevel
    outside_for: float
    detail: str


class AnomalyRule:
    """Residual outside its band for longer than a stated time: WARN, then ERROR.

    Args:
        warn_after_s: s.
        error_after_s: s (> ``warn_after_s``).
    """

    def __init__(self, warn_after_s: float, error_after_s: float) -> None:
        self.warn_after_s = warn_after_s
        self.error_after_s = error_after_s
        self.state = AnomalyState(HealthLevel.OK, 0.0, "")
        self._since: float | None = None
        self._sum = 0.0
        self._count = 0

    def reset(self) -> None:
        """End any excursion."""
        self._since, self._sum, self._count = None, 0.0, 0
        self.state = AnomalyState(HealthLevel.OK, 0.0, "")

    def add(self, start: float, end: float, residual: float | None, band: float, *, unit: str = "pp") -> AnomalyState:
        """One window ``[start, end]`` (s) with its residual (None: not compared) and band, in
        ``unit`` (pp for the slip, whose sign names the likely class)."""
        if residual is None or not math.isfinite(residual) or abs(residual) <= band:
            self.reset()
            return self.state
        if self._since is None or (self._count and math.copysign(1.0, residual) != math.copysign(1.0, self._sum)):
            self._since, self._sum, self._count = start, 0.0, 0
        self._sum += residual
        self._count += 1
        outside = end - self._since
        mean = self._sum / self._count
        if outside > self.error_after_s:
            level = HealthLevel.ERROR
        elif outside > self.warn_after_s:
            level = HealthLevel.WARN
        else:
            level = HealthLevel.OK
        detail = ""
        if level != HealthLevel.OK:
            fmt = ".3f" if unit == "pp" else ".3g"
            detail = (
                f"residual {mean:+{fmt}} {unit} outside its band (+-{band:{fmt}} {unit}) for {outside:.2f} s "
                f"(limit {self.warn_after_s if level == HealthLevel.WARN else self.error_after_s:g} s)"
            )
            if unit == "pp":
                detail += f": {likely_cause(mean)}"
        self.state = AnomalyState(level, outside, detail)
        return self.state
