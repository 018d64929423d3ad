"""Measured slip windows for the shadow twin: the monitor's own windows and fault handling.

The one place the shadow twin touches the monitor. :class:`MeasuredWindows` wraps the monitor's
ROS-free core (:class:`~bearing_rig_sim.monitoring.SlipMonitor`), so that the windows compared
with the prediction are the monitor's whole-cage-revolution windows, with the monitor's rules for
lost pulses, malformed and out-of-order pulses, clock jumps, sensor loss and a stopped rig. Only
the windows, the active faults and the stop are used; the monitor's verdict is not.

Units: s, rad/s.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from bearing_rig_sim.monitoring import MonitorSettings, SlipMonitor
from bearing_rig_sim.rig.fibre_optic import Pulse


@dataclass(frozen=True)
class MeasuredWindow:
    """One window of whole cage revolutions as the monitor measured it.

    Attributes:
        start_time, end_time: its two cage pulses (same strip), s.
        cage_speed: mean cage speed, rad/s.
        inner_ring_speed: mean spindle speed over the same interval, rad/s.
    """

    start_time: float
    end_time: float
    cage_speed: float
    inner_ring_speed: float


class MeasuredWindows:
    """The monitor's windows and input faults (see the module docstring).

    Args:
        window_revolutions: whole cage revolutions per window.
        monitor_settings: the monitor's other parameters (default: the shipped
            ``config/monitor.yaml``).
    """

    def __init__(self, window_revolutions: int, monitor_settings: MonitorSettings | None = None) -> None:
        base = monitor_settings if monitor_settings is not None else MonitorSettings.from_yaml()
        self.settings = dataclasses.replace(base, window_revolutions=window_revolutions)
        self._monitor = SlipMonitor(self.settings.kinematics(), self.settings)

    @property
    def clock_jump_tolerance_s(self) -> float:
        """A pulse further back than this before its shaft's previous one is a clock jump, s."""
        return self.settings.clock_jump_tolerance_s

    def add_pulse(self, shaft: str, pulse: Pulse) -> list[MeasuredWindow]:
        """Take one pulse of ``"spindle"`` or ``"cage"``; the windows it completes (never raises)."""
        if not self._monitor.add_pulse(shaft, pulse):
            return []
        w = self._monitor.latest_window
        if w is None:  # pragma: no cover - add_pulse returned True
            return []
        return [MeasuredWindow(w.start_time, w.end_time, w.cage_speed, w.inner_ring_speed)]

    def check(self, now: float) -> None:
        """Sensor-loss and stop checks at bench time ``now`` (s)."""
        if math.isfinite(now):
            self._monitor.check(now)

    def faults(self) -> tuple[str, ...]:
        """The input faults active now (lost or malformed pulses, sensor loss)."""
        return self._monitor.faults()

    def stopped(self) -> str:
        """Why the rig is taken to have stopped ("" while it is not)."""
        status = self._monitor.status()
        return status.detail if status.state == 0 and "stopped" in status.detail else ""
