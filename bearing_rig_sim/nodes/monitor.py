"""The monitor node: cage slip and its stability from the fibre-optic pulse topics (a thin shell
around :class:`~bearing_rig_sim.monitoring.SlipMonitor`).

Subscribes only ``/rig/spindle/pulses`` and ``/rig/cage/pulses`` (bearing_rig_msgs/FibreOpticPulse,
sensor data), so it runs unchanged on the bench's topics. Publishes:

* ``/rig/slip_status`` (bearing_rig_msgs/SlipStatus, reliable, transient local): ``status_rate_hz``
  (wall clock) and at once on every change of state;
* ``/diagnostics`` (diagnostic_msgs/DiagnosticArray, reliable): ``diagnostics_rate_hz`` (wall) and
  on every change of level: OK stable, WARN slipping or unknown, ERROR sensor loss or invalid data.

The rig clock is the node's clock: ``use_sim_time: true`` in ``config/monitor.yaml`` (the
simulator's /clock), the system clock on the bench (``-p use_sim_time:=false``). A clock going
back resets the monitor. Timers run on the steady clock, so a source that stops (and takes
/clock with it) is still noticed: the rig time used for the sensor-loss check is the later of the
node's clock and the latest pulse's time plus the wall time since it arrived.

Lifecycle (:class:`~bearing_rig_sim.nodes.shell.ManagedNode`): the settings, the slip monitor,
publishers, subscriptions and timers are made at configure; pulses are taken and statuses
published only while active. A sensor loss or invalid data is a FAULT state on the status and an
ERROR on /diagnostics with the node staying active (it recovers when the pulses return).
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any
from collections.abc import Sequence

from diagnostic_msgs.msg import DiagnosticArray
from rclpy.clock import Clock, ClockType

from bearing_rig_msgs.msg import FibreOpticPulse, SlipStatus
from bearing_rig_sim.interfaces import CAGE_PULSES, DIAGNOSTICS, SLIP_STATUS, SPINDLE_PULSES
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.monitoring import (
    NODE_NAME,
    MonitorSettings,
    MonitorState,
    MonitorStatus,
    SlipMonitor,
    shipped_parameters,
)
from bearing_rig_sim.nodes.common import (
    ERROR,
    OK,
    PULSE_READER_QOS,
    RELIABLE_QOS,
    STATUS_QOS,
    WARN,
    diagnostic_array,
    diagnostic_status,
    from_stamp,
    run_node,
    to_stamp,
)
from bearing_rig_sim.nodes.shell import ManagedNode, declare_described, parameter_values, survives_shutdown
from bearing_rig_sim.nodes.sim_clock import guard_sim_clock
from bearing_rig_sim.rig.fibre_optic import Pulse

LEVELS = {MonitorState.STABLE: OK, MonitorState.SLIPPING: WARN, MonitorState.UNKNOWN: WARN, MonitorState.FAULT: ERROR}
"""Diagnostics level of each monitor state."""


class MonitorNode(ManagedNode):
    """The monitor node (see the module docstring).

    Raises:
        ConfigError: a parameter or the bearing file is malformed.
    """

    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        self._defaults = shipped_parameters()
        declare_described(self, NODE_NAME, self._defaults)
        self.clock_guard = guard_sim_clock(self)  # negative and far-jumping /clock stamps refused

    def configure(self) -> None:
        """Validate the parameters; build the slip monitor, publishers, subscriptions, timers."""
        self.settings = MonitorSettings.from_values(parameter_values(self, self._defaults), f"{NODE_NAME} parameters")
        self.monitor = SlipMonitor(self.settings.kinematics(), self.settings)
        self._last_clock: float | None = None
        self._last_pulse_wall: float | None = None
        self._last_state: MonitorState | None = None
        self._last_level: bytes | None = None
        self._received = {"spindle": 0, "cage": 0}
        # Time base: the pulse stamps (rig time), extrapolated by the steady clock between
        # pulses. With use_sim_time the node's /clock also counts, and a jump back resets.
        self._sim_time = bool(self.get_parameter("use_sim_time").value)

        self._status_pub = self.publisher(SlipStatus, SLIP_STATUS.name, STATUS_QOS)
        self._diag_pub = self.publisher(DiagnosticArray, DIAGNOSTICS.name, RELIABLE_QOS)
        self.subscription(FibreOpticPulse, SPINDLE_PULSES.name, lambda m: self._on_pulse("spindle", m), PULSE_READER_QOS)
        self.subscription(FibreOpticPulse, CAGE_PULSES.name, lambda m: self._on_pulse("cage", m), PULSE_READER_QOS)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.timer(1.0 / self.settings.status_rate_hz, self._on_status_timer, clock=steady)
        self.timer(1.0 / self.settings.diagnostics_rate_hz, self._on_diagnostics_timer, clock=steady)
        kin = self.monitor.kinematics
        self.get_logger().info(
            f"monitoring cage slip over {self.settings.window_revolutions} cage revolution(s) per window "
            f"(epicyclic ratio {kin.epicyclic_ratio():.6g} at {math.degrees(kin.contact_angle):g} deg)"
        )

    def activate(self) -> None:
        """Report the state at once on activation (the first status, then the timers)."""
        self._last_state = None
        self._last_level = None

    # -- inputs --------------------------------------------------------------------------------
    @survives_shutdown
    def _on_pulse(self, shaft: str, msg: FibreOpticPulse) -> None:
        try:
            pulse = Pulse(
                time=from_stamp(msg.header.stamp),
                strip_id=int(msg.strip_id),
                strip_count=int(msg.strip_count),
                revolution=int(msg.revolution),
                pulse_index=int(msg.pulse_index),
                sensor_id=msg.sensor_id,
            )
            self._last_pulse_wall = time.monotonic()
            self._received[shaft] += 1
            if self.monitor.add_pulse(shaft, pulse):
                # A slip window just closed: publish its status now rather than at the next
                # timer tick, so the status follows the pulse within the processing time.
                self._publish(self.monitor.status())
        except Exception as exc:
            if not self.context.ok():
                raise
            self.get_logger().error(f"{shaft} pulse not processed: {exc}", throttle_duration_sec=1.0)

    def _clock_now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _rig_now(self, clock_now: float) -> float | None:
        """Rig time now: the latest pulse extrapolated by the steady clock; with use_sim_time,
        the later of that and the node's clock. None before any pulse without sim time."""
        last = self.monitor.last_pulse_time()
        if last is None or self._last_pulse_wall is None:
            return clock_now if self._sim_time else None
        extrapolated = last + (time.monotonic() - self._last_pulse_wall)
        return max(clock_now, extrapolated) if self._sim_time else extrapolated

    # -- periodic ------------------------------------------------------------------------------
    @survives_shutdown
    def _on_status_timer(self) -> None:
        clock_now = self._clock_now()
        tolerance = self.settings.clock_jump_tolerance_s
        if self._sim_time and self._last_clock is not None and clock_now < self._last_clock - tolerance:
            self.get_logger().warning(f"rig clock jumped back from {self._last_clock:.6g} s to {clock_now:.6g} s: reset")
            self.monitor.clock_jump(self._last_clock, clock_now)
            self._last_pulse_wall = None
        self._last_clock = clock_now
        now = self._rig_now(clock_now)
        if now is not None:
            self.monitor.check(now)
        self._publish(self.monitor.status())

    @survives_shutdown
    def _on_diagnostics_timer(self) -> None:
        self._publish_diagnostics(self.monitor.status())

    # -- outputs -------------------------------------------------------------------------------
    def _publish(self, status: MonitorStatus) -> None:
        if status.state != self._last_state:
            self.get_logger().info(f"state {status.state.name.lower()}: {status.detail}")
        self._last_state = status.state
        self._status_pub.publish(self._status_message(status))
        if LEVELS[status.state] != self._last_level:
            self._publish_diagnostics(status)

    def _status_message(self, status: MonitorStatus) -> SlipStatus:
        msg = SlipStatus(**status.message_fields())
        stamp = status.time if status.time is not None else self._clock_now()
        msg.header.stamp = to_stamp(max(stamp, 0.0))
        msg.header.frame_id = "bearing"
        return msg

    def _publish_diagnostics(self, status: MonitorStatus) -> None:
        level = LEVELS[status.state]
        self._last_level = level
        values = {
            "state": status.state.name.lower(),
            "slip_rate_pct": f"{status.slip_rate:.6g}",
            "inner_ring_speed_rad_s": f"{status.inner_ring_speed:.6g}",
            "cage_speed_rad_s": f"{status.cage_speed:.6g}",
            "fitted_slope_pct_per_s": f"{status.fitted_slope:.4g}",
            "critical_slope_pct_per_s": f"{status.critical_slope:g}",
            "confidence": f"{status.confidence:.3f}",
            "windows": status.windows,
            "spindle_pulses_received": self._received["spindle"],
            "cage_pulses_received": self._received["cage"],
            "faults": " | ".join(status.faults),
        }
        message = f"{status.state.name.lower()}: {status.detail}"
        array = diagnostic_array(to_stamp(max(self._clock_now(), 0.0)), [diagnostic_status(f"{NODE_NAME}: cage slip", level, message, values)])
        self._diag_pub.publish(array)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``monitor`` / ``bearing-rig-monitor``: spin the node until Ctrl-C.

    ROS arguments (``--ros-args -p name:=value``, ``--params-file``) set the parameters of
    ``config/monitor.yaml``.
    """
    try:
        return run_node(NODE_NAME, MonitorNode, list(sys.argv if argv is None else argv))
    except RigError as exc:
        print(f"{NODE_NAME}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
