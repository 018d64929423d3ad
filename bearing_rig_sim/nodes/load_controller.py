"""Load controller node: the bench's axial loading chain on the simulation clock.

A thin shell around :class:`~bearing_rig_sim.load_control.AxialLoadOperation` (which holds the
:class:`~bearing_rig_sim.rig.loading.LoadingChain` and every policy below; it is tested without
ROS). Start: ``ros2 run bearing_rig_sim load_controller`` or ``bearing-rig-load-controller``;
parameters from ``config/load_controller.yaml``.

Interfaces (README, interface table):

* follows ``/clock`` (rosgraph_msgs/Clock; ``use_sim_time`` must be true): a timer on the steady
  clock wakes every ``step_period_s`` (10 ms), takes the latest ``/clock`` from a queue no
  callback drains, and steps the chain to it in force samples of ``1 / force_rate_hz`` of sim time
  (:meth:`~bearing_rig_sim.load_control.AxialLoadOperation.follow`), publishing the forces of
  each sample with its stamp. The node wakes 100 times a second instead of once per ``/clock``
  message (rclpy's own time source would dispatch each of the 1000), and keeps up with a
  simulator faster than real time (each wake-up takes whatever sim time passed);
* subscribes ``/rig/axial_load/setpoint`` (std_msgs/Float64, N, reliable), taken by the step
  timer before it steps, so a set-point is in force for every sample published after it came;
* subscribes ``/rig/load/setpoint`` (geometry_msgs/WrenchStamped, reliable): the whole load
  set-point, in force from ``header.stamp`` (sim time; a zero stamp: on arrival). force.z the
  axial load (N), force.x/y the radial force (N, magnitude and azimuth), torque.x/y a moment across
  the axis (N m); torque.z unused. Taken by the step like the axial set-point and judged on
  arrival: refused as a whole (a logged reason and a WARN, the previous one kept) when the axial
  part would be or the radial part is above the rig file's ``max_radial_setpoint_n`` /
  ``max_moment_setpoint_n_m`` (0 for the paper's axially loaded bench). Accepted, it waits until
  the chain's time reaches its stamp and is in force from that instant
  (:meth:`~bearing_rig_sim.load_control.AxialLoadOperation.request_load`): the session stamps each
  segment's set-point with its start and sends it ahead, so it reaches the bearing at the start
  however far the simulator runs ahead of the session. Those still waiting are dropped at
  deactivation. The radial part is applied as given (the
  rig file's ``combined_loading`` states no loader dynamics);
* service ``/rig/axial_load/set`` (bearing_rig_msgs/srv/SetAxialLoad): accepted + message;
* service ``/rig/axial_load/reset_fault`` (std_srvs/srv/Trigger): clears a latched interlock
  fault once its cause is gone (success false, with what persists, otherwise);
* service ``/rig/axial_load/clutch`` (std_srvs/srv/SetBool): engage (true) or release the clutch;
* parameter ``axial_load_setpoint_n`` (N): validated by the parameter validation callback (refused
  with the reason) and applied by the post-set callback once set; it mirrors the set-point in
  force whichever way it was given;
* publishes, stamped with the simulation time of the clock tick:
  ``/rig/bearing/axial_force`` (geometry_msgs/WrenchStamped, force.z = the force that reaches the
  bearing, N, force.x/y and torque.x/y the radial set-point in force (all 0.0 without one), reliable,
  ``force_rate_hz`` of sim time: the simulator's input),
  ``/rig/axial_load/force`` (WrenchStamped, the load cell's reading, N, reliable stream: recorded
  whole, read best effort by the monitor; the same rate),
  ``/rig/axial_load/state`` (bearing_rig_msgs/AxialLoadState, reliable, ``state_rate_hz`` of sim
  time) and ``/diagnostics`` (every ``diagnostics_period_s`` of sim time and at once on a change:
  OK; WARN after a refused set-point, until the next accepted one; ERROR with the interlock's
  reason while a fault is latched; on a rig file with a radial loader, the values
  ``radial_setpoint_n`` and ``moment_setpoint_n_m`` too).

A set-point that is NaN, negative or above the chain's ``max_setpoint_n`` is refused (the
previous one stays) with a logged reason and a WARN on ``/diagnostics``; the node carries on. An
interlock (load limit, rate limit, clutch slip) latches a fault: brake de-energised, ERROR on
``/diagnostics``. **Only the reset_fault service clears it**, and only once its cause is gone:
the load cell reads at or below the load limit, the clutch holds again, and the set-point is
below the clutch's holding force. Set-points given meanwhile are stored and take effect after
the reset. The clutch is engaged at configure (``engage_clutch_on_start``).

Lifecycle (:class:`~bearing_rig_sim.nodes.shell.ManagedNode`): the settings, the chain, the
publishers, the services and the timer are made at configure; stepping and publishing run only
while active. The services answer in every configured state (a set-point given while inactive
takes effect at activation); set-points on the topic are taken by the step, so one given while
inactive waits in the reader's queue and takes effect at activation. An interlock fault does not deactivate the node: the brake is de-energised, and the
node goes on publishing the (falling) force, the ERROR and the state, as the bench's controller
does; only reset_fault clears it.
"""

from __future__ import annotations

import struct
import sys
from collections.abc import Sequence
from typing import Any

from bearing_rig_msgs.msg import AxialLoadState
from bearing_rig_msgs.srv import SetAxialLoad
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from rcl_interfaces.msg import SetParametersResult
from rclpy.clock import Clock as RosClock
from rclpy.clock import ClockType, ROSClock
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.time import Time as RosTime
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64
from std_srvs.srv import SetBool, Trigger

from bearing_rig_sim.interfaces import (
    AXIAL_LOAD_CLUTCH,
    AXIAL_LOAD_FORCE,
    AXIAL_LOAD_RESET_FAULT,
    AXIAL_LOAD_SET,
    AXIAL_LOAD_SETPOINT,
    AXIAL_LOAD_STATE,
    BEARING_AXIAL_FORCE,
    CLOCK,
    DIAGNOSTICS,
    LOAD_SETPOINT,
)
from bearing_rig_sim.clock_guard import ClockGuard
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.load_control import AxialLoadOperation, HealthLevel, LoadControllerSettings, RadialLoad, Reply, SetpointSource
from bearing_rig_sim.load_control.settings import NODE_NAME, shipped_parameters
from bearing_rig_sim.nodes.common import (
    ERROR,
    OK,
    RELIABLE_QOS,
    WARN,
    diagnostic_array,
    diagnostic_status,
    drain,
    from_stamp,
    node_main,
    qos_profile,
    to_stamp,
    unspun_reader,
)
from bearing_rig_sim.nodes.shell import ManagedNode, declare_described, parameter_values, survives_shutdown
from bearing_rig_sim.rig.loading import LoadChainState, LoadingChainConfig

SETPOINT_PARAMETER = "axial_load_setpoint_n"
DIAGNOSTIC_NAME = "load_controller: axial load"
CLOCK_QOS = qos_profile("clock_reader")
"""The /clock reader's QoS: every tick of a step period kept (100 ms of a 1 kHz clock), so that
the clock guard sees the stamps in a row it needs to confirm a restarted clock."""

_LEVELS = {HealthLevel.OK: OK, HealthLevel.WARN: WARN, HealthLevel.ERROR: ERROR}


def clock_stamp(raw: bytes) -> tuple[int, int]:
    """``(sec, nanosec)`` of a serialized ``rosgraph_msgs/Clock``: the CDR encapsulation header
    (its second byte 1 for little endian), then ``int32 sec`` and ``uint32 nanosec``."""
    sec, nanosec = struct.unpack_from("<iI" if raw[1] == 1 else ">iI", raw, 4)
    return int(sec), int(nanosec)


class LoadControllerNode(ManagedNode):
    """The load controller (see the module documentation).

    Raises:
        RigError: a parameter given at start out of its range.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(NODE_NAME, **kwargs)
        self._defaults = shipped_parameters()
        declare_described(self, NODE_NAME, self._defaults)
        self._mirroring = False
        self.operation: AxialLoadOperation | None = None
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.add_post_set_parameters_callback(self._on_parameters_set)
        # The clock is read by the step timer from a queue of its own (see the module
        # documentation): rclpy's time source would wake the executor for every tick.
        if self.get_parameter("use_sim_time").value:
            self._time_source.detach_node()
        self._clock_tap: Node | None = None
        self.clock_guard = ClockGuard(name=f"{NODE_NAME}: {CLOCK.name}")
        """Negative and far-jumping /clock stamps are refused (see :mod:`bearing_rig_sim.clock_guard`)."""

    def configure(self) -> None:
        """Validate the parameters; build the chain, publishers, services and the step timer."""
        settings = LoadControllerSettings.from_values(parameter_values(self, {**self._defaults, "use_sim_time": True}), f"{NODE_NAME} parameters")
        self.settings = settings
        config = LoadingChainConfig.from_yaml(settings.rig_file)
        operation = AxialLoadOperation.from_settings(config, settings)
        reply = operation.request_setpoint(settings.axial_load_setpoint_n, SetpointSource.PARAMETER)
        if not reply.accepted:
            raise RigError(f"{NODE_NAME}: {reply.message}")
        self.operation = operation

        # No QoS-event handlers on our own endpoints: each is a waitable that rclpy's executor
        # walks on every wake-up; an incompatible QoS goes unlogged.
        quiet = PublisherEventCallbacks(use_default_callbacks=False)
        self._force_pub = self.publisher(WrenchStamped, BEARING_AXIAL_FORCE.name, qos_profile(BEARING_AXIAL_FORCE), event_callbacks=quiet)
        self._load_cell_pub = self.publisher(WrenchStamped, AXIAL_LOAD_FORCE.name, qos_profile(AXIAL_LOAD_FORCE), event_callbacks=quiet)
        self._state_pub = self.publisher(AxialLoadState, AXIAL_LOAD_STATE.name, qos_profile(AXIAL_LOAD_STATE), event_callbacks=quiet)
        self._diagnostics_pub = self.publisher(DiagnosticArray, DIAGNOSTICS.name, qos_profile(DIAGNOSTICS), event_callbacks=quiet)
        self._rig_services = [
            self.create_service(SetAxialLoad, AXIAL_LOAD_SET.name, self._on_set_service),
            self.create_service(Trigger, AXIAL_LOAD_RESET_FAULT.name, self._on_reset_fault),
            self.create_service(SetBool, AXIAL_LOAD_CLUTCH.name, self._on_clutch),
        ]
        self._clock_tap = Node(f"{NODE_NAME}_inputs", context=self.context)
        self._clock_sub = unspun_reader(self._clock_tap, Clock, CLOCK.name, CLOCK_QOS)
        # The set-points too are taken by the step, before it steps: one that came since the
        # last step is in force for every sample this step publishes (a callback of its own
        # could run after the step and leave a lagging node's samples on the old set-point).
        self._setpoint_sub = unspun_reader(self._clock_tap, Float64, AXIAL_LOAD_SETPOINT.name, RELIABLE_QOS)
        self._load_sub = unspun_reader(self._clock_tap, WrenchStamped, LOAD_SETPOINT.name, qos_profile(LOAD_SETPOINT))
        self.timer(settings.step_period_s, self._on_step, clock=RosClock(clock_type=ClockType.STEADY_TIME))
        self._bearing_msg = WrenchStamped()
        self._bearing_msg.header.frame_id = "bearing"
        self._load_cell_msg = WrenchStamped()
        self._load_cell_msg.header.frame_id = "load_cell"
        self._mirror_setpoint()
        self.get_logger().info(
            f"loading chain from {settings.rig_file}; clutch {'engaged' if settings.engage_clutch_on_start else 'released'}; "
            f"set-point {operation.setpoint:g} N; stepping on {CLOCK.name} every {settings.step_period_s * 1e3:g} ms"
        )

    def activate(self) -> None:
        """Report the health at once on activation."""
        if self.operation is not None:
            self.operation.mark_reported(None)

    def deactivate(self) -> None:
        """Forget the set-points stamped ahead: a run that stops its nodes leaves none to take
        effect at a later activation."""
        if self.operation is not None and self.operation.pending:
            self.get_logger().info(f"deactivated: {self.operation.drop_pending()} set-point(s) stamped ahead dropped")

    def delivery_stamp(self) -> Any:
        """The chain's time (its last /clock), s; 0 before any."""
        return to_stamp((self.operation.time if self.operation is not None else None) or 0.0)

    def cleanup(self) -> None:
        """Drop the chain, the services and the clock reader."""
        for service in getattr(self, "_rig_services", []):
            self.destroy_service(service)
        self._rig_services = []
        if self._clock_tap is not None:
            self._clock_tap.destroy_node()
            self._clock_tap = None
        self.operation = None

    # -- clock ------------------------------------------------------------------------------------
    def _latest_clock(self) -> Time | None:
        """The latest /clock stamp queued since the last call that the clock guard accepts
        (None when none came): negative and far-jumping stamps are refused and logged."""
        latest = None
        guard = self.clock_guard
        # Taken serialized and read in place (a hundred a wake-up): no message objects.
        for raw, _info in drain(self._clock_sub, Clock):
            sec, nanosec = clock_stamp(raw)
            verdict = guard.check(sec * 1_000_000_000 + nanosec)
            if verdict.note:
                self.get_logger().warning(f"{verdict.note} ({guard.refused} refused so far)", throttle_duration_sec=1.0)
            if verdict.accepted:
                latest = (sec, nanosec)
        return None if latest is None else Time(sec=latest[0], nanosec=latest[1])

    @survives_shutdown
    def _on_step(self) -> None:
        """Apply the set-points that came, step the chain to the latest /clock in force samples
        and publish them."""
        for setpoint, _info in drain(self._setpoint_sub, Float64, serialized=False):
            self._on_setpoint(setpoint)
        for load, _info in drain(self._load_sub, WrenchStamped, serialized=False):
            self._on_load_setpoint(load)
        operation = self.operation
        stamp = self._latest_clock()
        if operation is None or stamp is None:
            return
        clock = self.get_clock()
        if isinstance(clock, ROSClock):  # the node's clock follows the /clock it steps on
            clock.set_ros_time_override(RosTime.from_msg(stamp))
        for result in operation.follow(stamp.sec + stamp.nanosec * 1e-9):
            sample = to_stamp(result.time)
            if result.clock_note:
                self.get_logger().warning(result.clock_note)
            for reply in result.applied:  # stamped set-points that took effect in this sample
                self.get_logger().info(f"at t = {result.time:.6g} s: {reply.message}")
                self._mirror_setpoint()
            if result.tripped:
                self.get_logger().error(f"interlock tripped: {result.tripped}; brake de-energised, call reset_fault once clear")
            self._publish_forces(sample, result.state)
            if result.state_due:
                self._state_pub.publish(self._state_message(sample, result.state))
            if result.diagnostics_due:
                self._publish_diagnostics()

    def _publish_forces(self, stamp: object, state: LoadChainState) -> None:
        bearing, cell = self._bearing_msg, self._load_cell_msg
        bearing.header.stamp = stamp
        bearing.wrench.force.z = state.bearing_force
        if self.operation is not None:
            radial = self.operation.radial
            force, torque = bearing.wrench.force, bearing.wrench.torque
            force.x, force.y, torque.x, torque.y = radial.force_x, radial.force_y, radial.torque_x, radial.torque_y
        self._force_pub.publish(bearing)
        cell.header.stamp = stamp
        cell.wrench.force.z = state.load_cell_force
        self._load_cell_pub.publish(cell)

    @staticmethod
    def _state_message(stamp: object, state: LoadChainState) -> AxialLoadState:
        msg = AxialLoadState()
        msg.header.stamp = stamp
        msg.header.frame_id = "loading_chain"
        msg.setpoint = state.setpoint
        msg.load_cell_force = state.load_cell_force
        msg.bearing_force = state.bearing_force
        msg.brake_current = state.brake_current
        msg.brake_force = state.brake_force
        msg.rope_tension = state.rope_tension
        msg.clutch_state = state.clutch_state.message_code
        msg.fault = state.fault
        msg.fault_reason = state.fault_reason
        return msg

    def _publish_diagnostics(self) -> None:
        if self.operation is None:
            return
        health = self.operation.health()
        state = self.operation.chain.state()
        now = self.operation.time or 0.0
        values = {
            "setpoint_n": f"{state.setpoint:g}",
            "bearing_force_n": f"{state.bearing_force:.2f}",
            "load_cell_force_n": f"{state.load_cell_force:.2f}",
            "clutch": state.clutch_state.value,
            "fault_reason": state.fault_reason,
            "sim_time_s": f"{now:.3f}",
        }
        limits = self.operation.radial_limits
        if limits is not None and (limits.max_radial_load_n > 0.0 or limits.max_moment_n_m > 0.0):  # a rig with a radial loader
            values["radial_setpoint_n"] = f"{self.operation.radial.radial_n:g}"
            values["moment_setpoint_n_m"] = f"{self.operation.radial.moment_n_m:g}"
        status = diagnostic_status(DIAGNOSTIC_NAME, _LEVELS[health.level], health.message, values)
        self._diagnostics_pub.publish(diagnostic_array(to_stamp(now), [status]))
        self.operation.mark_reported(health)

    # -- requests ---------------------------------------------------------------------------------
    def _apply(self, reply: Reply) -> Reply:
        """Log a reply, mirror the set-point parameter, publish diagnostics on a change."""
        if reply.accepted:
            self.get_logger().info(reply.message)
        else:
            self.get_logger().warning(reply.message)
        if self.active and self.operation is not None and self.operation.health_changed():
            self._publish_diagnostics()
        return reply

    def _mirror_setpoint(self) -> None:
        """Keep the parameter equal to the set-point in force."""
        if self.operation is None:
            return
        current = self.get_parameter(SETPOINT_PARAMETER).value
        if current == self.operation.setpoint and isinstance(current, float):
            return
        self._mirroring = True
        try:
            self.set_parameters([Parameter(SETPOINT_PARAMETER, Parameter.Type.DOUBLE, float(self.operation.setpoint))])
        finally:
            self._mirroring = False

    def _on_setpoint(self, msg: Float64) -> None:
        assert self.operation is not None  # taken by the step, which runs from activate to deactivate
        if self._apply(self.operation.request_setpoint(msg.data, SetpointSource.TOPIC)).accepted:
            self._mirror_setpoint()

    def _on_load_setpoint(self, msg: WrenchStamped) -> None:
        assert self.operation is not None  # taken by the step, which runs from activate to deactivate
        force, torque = msg.wrench.force, msg.wrench.torque
        stamp = from_stamp(msg.header.stamp)
        reply = self._apply(
            self.operation.request_load(force.z, RadialLoad(force.x, force.y, torque.x, torque.y), stamp if stamp > 0.0 else None, SetpointSource.TOPIC)
        )
        if reply.accepted:
            self._mirror_setpoint()

    def _on_set_service(self, request: SetAxialLoad.Request, response: SetAxialLoad.Response) -> SetAxialLoad.Response:
        assert self.operation is not None  # the service lives from configure to cleanup
        reply = self._apply(self.operation.request_setpoint(request.axial_load, SetpointSource.SERVICE))
        if reply.accepted:
            self._mirror_setpoint()
        response.accepted = reply.accepted
        response.message = reply.message
        return response

    def _on_reset_fault(self, _request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        assert self.operation is not None
        reply = self._apply(self.operation.reset_fault())
        response.success = reply.accepted
        response.message = reply.message
        return response

    def _on_clutch(self, request: SetBool.Request, response: SetBool.Response) -> SetBool.Response:
        assert self.operation is not None
        reply = self._apply(self.operation.set_clutch(bool(request.data)))
        response.success = reply.accepted
        response.message = reply.message
        return response

    def _on_set_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        """Validate ``axial_load_setpoint_n`` (any type reaches here: dynamic typing) without
        applying it; refuse with the chain's reason. It is applied once set
        (:meth:`_on_parameters_set`)."""
        for parameter in parameters:
            if parameter.name != SETPOINT_PARAMETER or self._mirroring:
                continue
            value = _as_number(parameter.value)
            if self.operation is None:  # not configured: validated at configure
                reason = LoadControllerSettings.check_value(SETPOINT_PARAMETER, value)
                if reason:
                    return SetParametersResult(successful=False, reason=reason)
                continue
            reply = self.operation.check_setpoint(value, SetpointSource.PARAMETER)
            if not reply.accepted:
                self._apply(reply)
                return SetParametersResult(successful=False, reason=reply.message)
        return SetParametersResult(successful=True)

    def _on_parameters_set(self, parameters: list[Parameter]) -> None:
        """Apply a set-point given as the parameter, once it is set (validated above)."""
        for parameter in parameters:
            if parameter.name == SETPOINT_PARAMETER and not self._mirroring and self.operation is not None:
                self._apply(self.operation.request_setpoint(_as_number(parameter.value), SetpointSource.PARAMETER))


def _as_number(value: object) -> object:
    """An integer parameter as a float (``ros2 param set ... 100`` gives an integer); anything else
    unchanged, for the chain to judge."""
    if isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value


def main(argv: Sequence[str] | None = None) -> int:
    """Console script ``load_controller`` / ``bearing-rig-load-controller``: the node starts
    unconfigured (``lifecycle_msgs`` services); ``--autostart`` configures and activates it."""
    return node_main(NODE_NAME, LoadControllerNode, argv)


if __name__ == "__main__":
    sys.exit(main())
