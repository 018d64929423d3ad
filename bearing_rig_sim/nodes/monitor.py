"""The monitor node: cage slip and its stability from the fibre-optic pulse topics (a thin shell
around :class:`~bearing_rig_sim.monitoring.SlipMonitor` and the
:class:`~bearing_rig_sim.monitoring.StatusSchedule` that offline analysis runs too).

Subscribes ``/rig/spindle/pulses`` and ``/rig/cage/pulses`` (bearing_rig_msgs/FibreOpticPulse)
and ``/rig/axial_load/force`` (the load cell: the load sweep's abscissa and the loaded contact
angle of the kinematic slip), all best effort with a deep queue (``pulse_reader``), so it runs
unchanged on the bench's topics. Publishes:

* ``/rig/slip_status`` (bearing_rig_msgs/SlipStatus, reliable, transient local): when the
  schedule says (``status_rate_hz`` per second of pulse time, and as each slip window closes),
  stamped at the latest window's end; when the pulses stop, checked on a timer of the steady
  clock at ``status_rate_hz`` that publishes one status per period of *rig time* passed since the
  last one (at most :data:`IDLE_CATCH_UP_STATUSES` at a time), and once the rig is found stopped
  those statuses (speeds 0, no slip) are stamped at the rig time of the check, so that a stopped
  rig's statuses follow its clock at ``status_rate_hz``, however fast it runs;
* ``/diagnostics`` (diagnostic_msgs/DiagnosticArray, reliable): ``diagnostics_rate_hz`` (wall) and
  on every change of level: OK stable, WARN slipping, unknown or pulses lost lately (with the
  counts), ERROR sustained sensor loss or invalid data.

The rig time is the latest stamp of the pulses and the load cell. On a bench without a load cell
it is the pulses' stamps extrapolated by the steady clock while none arrive; the load cell's
stamps (in a session: the simulation clock's, as the load controller steps on ``/clock``) carry it
on through a stop, and no status is then stamped past them. Before any of them has come a status
or a diagnostic is stamped 0 (the simulation clock's origin) while a ``/clock`` is published, the
wall clock only on a bench without one; so in a session on ``/clock`` no message of the monitor
carries the wall clock. With ``use_sim_time`` the node's clock counts as well, and a /clock going
back resets the monitor.

Lifecycle (:class:`~bearing_rig_sim.nodes.shell.ManagedNode`): the settings, the slip monitor,
publishers, subscriptions and timers are made at configure; pulses are taken and statuses
published only while active. A sensor loss or invalid data is a FAULT state on the status and an
ERROR on /diagnostics with the node staying active (it recovers when the pulses return).
"""

from __future__ import annotations

import functools
import gc
import math
import sys
import time
from typing import Any
from collections.abc import Sequence

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from rclpy.clock import Clock, ClockType

from bearing_rig_msgs.msg import FibreOpticPulse, SlipStatus
from bearing_rig_sim.interfaces import CLOCK, DIAGNOSTICS, SLIP_STATUS
from bearing_rig_sim.interfaces import AXIAL_LOAD_FORCE, PULSE_TOPICS
from bearing_rig_sim.monitoring import (
    DIAGNOSTIC_NAME,
    NODE_NAME,
    MonitorSettings,
    MonitorStatus,
    PulseMerger,
    SlipMonitor,
    SlipState,
    StatusSchedule,
    shipped_parameters,
    unstamped,
)
from bearing_rig_sim.nodes.common import (
    ERROR,
    OK,
    PULSE_READER_QOS,
    WARN,
    diagnostic_array,
    diagnostic_status,
    from_stamp,
    qos_profile,
    node_main,
    to_stamp,
)
from bearing_rig_sim.nodes.shell import ManagedNode, declare_described, parameter_values, survives_shutdown
from bearing_rig_sim.nodes.sim_clock import guard_sim_clock
from bearing_rig_sim.instruments.fibre_optic import Pulse

IDLE_CATCH_UP_STATUSES = 100
"""Most idle statuses one status timer publishes to catch up with the rig time (10 s of it at the
shipped 10 Hz), a fiftieth of the status publisher's history (``transient_stream``, 5000), so
that a reliable reader that falls behind for one burst misses none. Only more rig time than that
between two timer calls leaves a gap: a clock that jumps, or a monitor held up that long. At 8
(0.8 s) a monitor whose 10 Hz timer a loaded host held up for 0.3 s of wall time, with the
simulator at four times the wall clock, left statuses 0.3 s of rig time apart."""

LEVELS = {SlipState.STABLE: OK, SlipState.SLIPPING: WARN, SlipState.UNKNOWN: WARN, SlipState.FAULT: ERROR}
"""Diagnostics level of each monitor state (recent lost pulses raise OK to WARN)."""


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
        self.schedule = StatusSchedule(self.monitor)
        self.merger = PulseMerger()
        self._last_clock: float | None = None
        self._last_pulse_wall: float | None = None
        self._last_idle: float | None = None
        """Rig time of the latest idle status while the pulses have stopped, s (None while they drive)."""
        self._last_load_stamp: float | None = None
        """Stamp of the latest load-cell sample, s (None before the first)."""
        self._last_state: SlipState | None = None
        self._last_level: bytes | None = None
        self._received = {"spindle": 0, "cage": 0}
        # Time base: the pulse stamps (rig time), extrapolated by the steady clock between
        # pulses. With use_sim_time the node's /clock also counts, and a jump back resets.
        self._sim_time = bool(self.get_parameter("use_sim_time").value)

        self._status_pub = self.publisher(SlipStatus, SLIP_STATUS.name, qos_profile(SLIP_STATUS))
        self._diag_pub = self.publisher(DiagnosticArray, DIAGNOSTICS.name, qos_profile(DIAGNOSTICS))
        for shaft, topic in PULSE_TOPICS.items():
            self.subscription(FibreOpticPulse, topic.name, functools.partial(self._on_pulse, shaft), PULSE_READER_QOS)
        # the load cell: the load sweep's abscissa and the loaded contact angle of the kinematic slip
        self.subscription(WrenchStamped, AXIAL_LOAD_FORCE.name, self._on_load, PULSE_READER_QOS)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.timer(1.0 / self.settings.status_rate_hz, self._on_status_timer, clock=steady)
        self.timer(1.0 / self.settings.diagnostics_rate_hz, self._on_diagnostics_timer, clock=steady)
        kin = self.monitor.kinematics
        self.get_logger().info(
            f"monitoring cage slip over {self.settings.window_revolutions} cage revolution(s) per window "
            f"(epicyclic ratio {kin.epicyclic_ratio():.6g} at {math.degrees(kin.contact_angle):g} deg)"
        )
        # What was built to get here (rclpy, numpy, the bearing's tables: some hundred thousand
        # objects) lives as long as the node: out of the cyclic collector's sight, whose full
        # passes over it took 50-90 ms, once a minute or so, inside a pulse's callback.
        gc.collect()
        gc.freeze()

    def activate(self) -> None:
        """Report the state at once on activation (the first status, then the timers)."""
        self._last_state = None
        self._last_level = None

    def delivery_stamp(self) -> Any:
        """The rig time (see the module docstring)."""
        return to_stamp(max(self._stamp_now(), 0.0))

    # -- inputs --------------------------------------------------------------------------------
    @survives_shutdown
    def _on_pulse(self, shaft: str, msg: FibreOpticPulse) -> None:
        try:
            stamp = from_stamp(msg.header.stamp)
            if stamp == 0.0 and unstamped(stamp, received := self._clock_now()):  # (the clock is read only for a zero stamp)
                stamp = received
                self.get_logger().warning(
                    f"{shaft} pulses with a zero header stamp: their reception times are used, whose delivery jitter scatters the slip",
                    once=True,
                )
            pulse = Pulse(
                time=stamp,
                strip_id=int(msg.strip_id),
                strip_count=int(msg.strip_count),
                revolution=int(msg.revolution),
                pulse_index=int(msg.pulse_index),
                sensor_id=msg.sensor_id,
            )
            self._last_pulse_wall = time.monotonic()
            self._received[shaft] += 1
            self._feed(self.merger.push(shaft, pulse, time.monotonic()))
        except Exception as exc:
            if not self.context.ok():
                raise
            self.get_logger().error(f"{shaft} pulse not processed: {exc}", throttle_duration_sec=1.0)

    def _feed(self, pulses: list[tuple[str, Pulse]]) -> None:
        """Pulses back in time order (:class:`PulseMerger`) through the shared schedule."""
        for shaft, pulse in pulses:
            for scheduled in self.schedule.on_pulse(shaft, pulse):
                self._publish(scheduled.status)

    @survives_shutdown
    def _on_load(self, msg: WrenchStamped) -> None:
        stamp = from_stamp(msg.header.stamp)
        if stamp > 0.0:
            self._last_load_stamp = max(stamp, self._last_load_stamp or 0.0)
        self.monitor.add_load(stamp, float(msg.wrench.force.z))

    def _clock_now(self) -> float:
        return self.get_clock().now().nanoseconds * 1e-9

    def _rig_now(self, clock_now: float) -> float | None:
        """Rig time now (see the module docstring): the latest stamp of the pulses and the load
        cell; without a load cell the latest pulse extrapolated by the steady clock; with
        use_sim_time, the later of that and the node's clock. None before any stamp without sim
        time."""
        last = self.monitor.last_pulse_time() if self._last_pulse_wall is not None else None
        stamps = [t for t in (last, self._last_load_stamp) if t is not None]
        if self._sim_time:
            return max([clock_now, *stamps])
        if not stamps:
            return None
        if self._last_load_stamp is None and last is not None and self._last_pulse_wall is not None:
            return last + (time.monotonic() - self._last_pulse_wall)
        return max(stamps)

    def _stamp_now(self) -> float:
        """The stamp of a message that has no rig time of its own, s: the rig time when known;
        before it, 0 while a ``/clock`` is published (a session on simulation time), else the
        node's clock (the wall clock on a bench)."""
        clock_now = self._clock_now()
        now = self._rig_now(clock_now)
        if now is not None:
            return now
        return 0.0 if self.count_publishers(CLOCK.name) > 0 else clock_now

    # -- periodic ------------------------------------------------------------------------------
    @survives_shutdown
    def _on_status_timer(self) -> None:
        clock_now = self._clock_now()
        tolerance = self.settings.clock_jump_tolerance_s
        if self._sim_time and self._last_clock is not None and clock_now < self._last_clock - tolerance:
            self.get_logger().warning(f"rig clock jumped back from {self._last_clock:.6g} s to {clock_now:.6g} s: reset")
            self.monitor.clock_jump(self._last_clock, clock_now)
            self._last_pulse_wall = None
            self._last_idle = None
        self._last_clock = clock_now
        self._feed(self.merger.expire(time.monotonic()))
        period = 1.0 / self.settings.status_rate_hz
        if self._last_pulse_wall is not None and time.monotonic() - self._last_pulse_wall < 2.0 * period:
            self._last_idle = None
            return  # the pulses drive the schedule
        now = self._rig_now(clock_now)
        if now is None:
            self._publish(self.monitor.status())
            return
        # One status per period of rig time since the last one (the latest pulse's, or the last
        # idle status), not per period of the steady clock: a rig time running faster than the
        # wall clock (a session without real time) is reported at status_rate_hz as well.
        since = self._last_idle if self._last_idle is not None else self.schedule.clock
        if math.isfinite(since) and now > since:
            since = max(since, now - IDLE_CATCH_UP_STATUSES * period)
            for k in range(1, IDLE_CATCH_UP_STATUSES + 1):
                if since + k * period >= now:
                    break
                self._publish(self.schedule.idle(since + k * period).status, since + k * period)
        self._publish(self.schedule.idle(now).status, now)
        self._last_idle = now

    @survives_shutdown
    def _on_diagnostics_timer(self) -> None:
        self._publish_diagnostics(self.monitor.status())

    # -- outputs -------------------------------------------------------------------------------
    def _publish(self, status: MonitorStatus, checked_at: float | None = None) -> None:
        """Publish a status; one with no window of its own (a stopped rig) is stamped at
        ``checked_at`` (the rig time of its check, s), or else at the rig time now."""
        if status.state != self._last_state:
            self.get_logger().info(f"state {status.state.label}: {status.detail}")
        self._last_state = status.state
        self._status_pub.publish(self._status_message(status, checked_at))
        if _level(status) != self._last_level:
            self._publish_diagnostics(status)

    def _status_message(self, status: MonitorStatus, checked_at: float | None = None) -> SlipStatus:
        msg = SlipStatus(**status.message_fields())
        stamp = status.time if status.time is not None else checked_at if checked_at is not None else self._stamp_now()
        msg.header.stamp = to_stamp(max(stamp, 0.0))
        msg.header.frame_id = "bearing"
        return msg

    def _publish_diagnostics(self, status: MonitorStatus) -> None:
        level = _level(status)
        self._last_level = level
        values = {
            "state": status.state.label,
            "slip_rate_pct": f"{status.slip_rate:.6g}",
            "inner_ring_speed_rad_s": f"{status.inner_ring_speed:.6g}",
            "cage_speed_rad_s": f"{status.cage_speed:.6g}",
            f"fitted_slope_pct_per_{_X_UNIT[status.criterion]}": f"{status.fitted_slope:.4g}",
            f"critical_slope_pct_per_{_X_UNIT[status.criterion]}": f"{status.critical_slope:g}",
            "confidence": f"{status.confidence:.3f}",
            "windows": status.windows,
            "spindle_pulses_received": self._received["spindle"],
            "cage_pulses_received": self._received["cage"],
            "spindle_pulses_lost": status.lost[0],
            "cage_pulses_lost": status.lost[1],
            "cage_windows_skipped": status.windows_skipped,
            "spindle_pulses_duplicated": status.duplicates[0],
            "cage_pulses_duplicated": status.duplicates[1],
            "faults": " | ".join(status.faults),
            "warnings": " | ".join(status.warnings),
            **self.settings.published_parameters(),  # what judging these statuses takes: the running values
        }
        message = f"{status.state.label}: {status.detail}"
        array = diagnostic_array(to_stamp(max(self._stamp_now(), 0.0)), [diagnostic_status(DIAGNOSTIC_NAME, level, message, values)])
        self._diag_pub.publish(array)


_X_UNIT = {"time": "s", "axial_load": "n"}


def _level(status: MonitorStatus) -> bytes:
    """Diagnostics level: the state's, raised to WARN while lost pulses are recent."""
    level = LEVELS[status.state]
    return WARN if level == OK and status.warnings else level


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``monitor`` / ``bearing-rig-monitor``: spin the node until Ctrl-C.

    ROS arguments (``--ros-args -p name:=value``, ``--params-file``) set the parameters of
    ``config/monitor.yaml``.
    """
    return node_main(NODE_NAME, MonitorNode, argv)


if __name__ == "__main__":
    sys.exit(main())
