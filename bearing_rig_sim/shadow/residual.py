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

Units: s; slip, residual and band in percentage points.
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

    def add(self, start: float, end: float, residual: float | None, band: float) -> AnomalyState:
        """One window ``[start, end]`` (s) with its residual (None: not compared) and band (pp)."""
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
            detail = (
                f"residual {mean:+.3f} pp outside its band (+-{band:.3f} pp) for {outside:.2f} s "
                f"(limit {self.warn_after_s if level == HealthLevel.WARN else self.error_after_s:g} s): {likely_cause(mean)}"
            )
        self.state = AnomalyState(level, outside, detail)
        return self.state
