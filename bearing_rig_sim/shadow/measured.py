"""Measured slip windows for the shadow twin: the monitor's own windows and fault handling.

The one place the shadow twin touches the monitor. :class:`MeasuredWindows` wraps the monitor's
whole-revolution windows and loss books (:class:`~bearing_rig_sim.monitoring.SlipWindows`), with
the monitor's parameters (``config/monitor.yaml``: loss rules, clock-jump tolerance, fault hold),
so that the windows compared with the prediction are the monitor's, and the monitor's rules decide
what is a fault:

* an isolated lost pulse costs nothing (a window whose closing cage pulse was lost is skipped by
  the counter; a spindle gap only widens the interpolation): no fault;
* sustained loss or silence (the counter's rules, stated in revolutions) is a fault while it lasts;
* a malformed pulse is a fault held ``fault_hold_s`` of bench time, as the monitor holds it;
* a clock jump back restarts the counting; a stopped rig is reported, not a fault.

Units: s, rad/s.
"""

from __future__ import annotations

import math

from bearing_rig_sim.monitoring import MonitorSettings, SlipWindow, SlipWindows
from bearing_rig_sim.instruments.fibre_optic import Pulse


MeasuredWindow = SlipWindow
"""One window of whole cage revolutions as the monitor measured it (the monitor's own type)."""


class MeasuredWindows:
    """The monitor's windows and input faults (see the module docstring).

    Args:
        window_revolutions: whole cage revolutions per window.
        monitor_settings: the monitor's other parameters (default: the shipped
            ``config/monitor.yaml``).
    """

    def __init__(self, window_revolutions: int, monitor_settings: MonitorSettings | None = None) -> None:
        base = monitor_settings if monitor_settings is not None else MonitorSettings.from_yaml()
        # The shadow compares the bench with the twin window by window over exactly
        # ``window_revolutions`` (config/shadow.yaml): no minimum duration stretches a window.
        self.settings = base.replace(window_revolutions=window_revolutions, min_window_s=0.0)
        self._counter = SlipWindows(window_revolutions, self.settings.loss_rules(), self.settings.clock_jump_tolerance_s, self.settings.min_window_s)
        self._invalid: dict[str, tuple[float | None, str]] = {}

    @property
    def clock_jump_tolerance_s(self) -> float:
        """A pulse further back than this before its shaft's previous one is a clock jump, s."""
        return self.settings.clock_jump_tolerance_s

    def add_pulse(self, shaft: str, pulse: Pulse) -> list[MeasuredWindow]:
        """Take one pulse of ``"spindle"`` or ``"cage"``; the windows it completes (never raises)."""
        done = self._counter.add_pulse(shaft, pulse)
        for kind, when, text in self._counter.events:
            if kind == "invalid":
                self._invalid[text.split(":", 1)[0]] = (when, text)
            elif kind == "reset":
                self._invalid.clear()
        self._counter.events.clear()
        return list(done)

    def check(self, now: float) -> None:
        """Sensor-loss and stop checks at bench time ``now`` (s); held faults expire."""
        if not math.isfinite(now):
            return
        self._counter.check(now)
        for key, (when, reason) in list(self._invalid.items()):
            if when is None:
                self._invalid[key] = (now, reason)
            elif now - when > self.settings.fault_hold_s:
                del self._invalid[key]

    def faults(self) -> tuple[str, ...]:
        """The input faults active now (sustained loss or silence, malformed pulses)."""
        return tuple(self._counter.faults().values()) + tuple(text for _, text in self._invalid.values())

    def stopped(self) -> str:
        """Why the rig is taken to have stopped ("" while it is not)."""
        return self._counter.stopped
