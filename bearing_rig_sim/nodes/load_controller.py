"""Load controller node: the bench's axial loading chain on the simulation clock.

A thin shell around :class:`~bearing_rig_sim.load_control.AxialLoadOperation` (which holds the
:class:`~bearing_rig_sim.rig.loading.LoadingChain` and every policy below; it is tested without
ROS). Start: ``ros2 run bearing_rig_sim load_controller`` or ``bearing-rig-load-controller``;
parameters from ``config/load_controller.yaml``.

Interfaces (README, interface table):

* follows ``/clock`` (rosgraph_msgs/Clock) through the node's own sim-time clock
  (``use_sim_time`` must be true): a jump handler on that clock steps the chain at each advance
  by the sim time elapsed, in sub-steps of at most 1 ms. rclpy's time source keeps only the
  latest tick (best effort, depth 1), so ticks that came while the node was busy are taken
  together and the node keeps up with a simulator faster than real time; and ``/clock`` is
  dispatched once per tick, not twice (the time source's and a subscription of our own);
* subscribes ``/rig/axial_load/setpoint`` (std_msgs/Float64, N, reliable);
* service ``/rig/axial_load/set`` (bearing_rig_msgs/srv/SetAxialLoad): accepted + message;
* service ``/rig/axial_load/reset_fault`` (std_srvs/srv/Trigger): clears a latched interlock
  fault once its cause is gone (success false, with what persists, otherwise);
* service ``/rig/axial_load/clutch`` (std_srvs/srv/SetBool): engage (true) or release the clutch;
* parameter ``axial_load_setpoint_n`` (N): validated by a parameter callback, refused with the
  reason; it mirrors the set-point in force whichever way it was given;
* publishes, stamped with the simulation time of the clock tick:
  ``/rig/bearing/axial_force`` (geometry_msgs/WrenchStamped, force.z = the force that reaches the
  bearing, N, reliable, every clock advance: the simulator's input), ``/rig/axial_load/force``
  (WrenchStamped, the load cell's reading, N, sensor data, every clock advance),
  ``/rig/axial_load/state`` (bearing_rig_msgs/AxialLoadState, reliable, ``state_rate_hz`` of sim
  time) and ``/diagnostics`` (every ``diagnostics_period_s`` of sim time and at once on a change:
  OK; WARN after a refused set-point, until the next accepted one; ERROR with the interlock's
  reason while a fault is latched).

A set-point that is NaN, negative or above the chain's ``max_setpoint_n`` is refused (the
previous one stays) with a logged reason and a WARN on ``/diagnostics``; the node carries on. An
interlock (load limit, rate limit, clutch slip) latches a fault: brake de-energised, ERROR on
``/diagnostics``. **Only the reset_fault service clears it**, and only once its cause is gone:
the load cell reads at or below the load limit, the clutch holds again, and the set-point is
below the clutch's holding force. Set-points given meanwhile are stored and take effect after
the reset. The clutch is engaged at start (``engage_clutch_on_start``).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from collections.abc import Sequence

from bearing_rig_msgs.msg import AxialLoadState
from bearing_rig_msgs.srv import SetAxialLoad
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.clock import JumpThreshold
from rclpy.duration import Duration
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float64
from std_srvs.srv import SetBool, Trigger

from bearing_rig_sim.config import config_path
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.load_control import AxialLoadOperation, HealthLevel, Reply, SetpointSource
from bearing_rig_sim.nodes.common import (
    ERROR,
    OK,
    RELIABLE_QOS,
    RELIABLE_STREAM_QOS,
    SENSOR_QOS,
    WARN,
    diagnostic_array,
    diagnostic_status,
    run_node,
    to_stamp,
)
from bearing_rig_sim.nodes.sim_clock import guard_sim_clock
from bearing_rig_sim.rig.loading import LoadChainState, LoadingChainConfig

NODE_NAME = "load_controller"
SETPOINT_PARAMETER = "axial_load_setpoint_n"
DIAGNOSTIC_NAME = "load_controller: axial load"

_LEVELS = {HealthLevel.OK: OK, HealthLevel.WARN: WARN, HealthLevel.ERROR: ERROR}


class LoadControllerNode(Node):
    """The load controller (see the module documentation).

    Raises:
        ConfigError: the rig file (parameter ``rig_file``) is missing or invalid.
        RigError: a rate or period parameter out of range.
    """

    def __init__(self, **kwargs: object) -> None:
        super().__init__(NODE_NAME, **kwargs)  # type: ignore[arg-type]
        read_only = ParameterDescriptor(read_only=True)
        rig_file = str(self.declare_parameter("rig_file", "", read_only).value)
        engage = bool(self.declare_parameter("engage_clutch_on_start", True, read_only).value)
        state_rate = float(self.declare_parameter("state_rate_hz", 100.0, read_only).value)
        diagnostics_period = float(self.declare_parameter("diagnostics_period_s", 1.0, read_only).value)
        max_gap = float(self.declare_parameter("max_clock_gap_s", 5.0, read_only).value)
        if not (math.isfinite(state_rate) and state_rate > 0.0):
            raise RigError(f"{NODE_NAME}: state_rate_hz must be a finite number > 0 Hz, got {state_rate!r}")
        rig_path = Path(rig_file) if rig_file else config_path("rig.yaml")
        config = LoadingChainConfig.from_yaml(rig_path)
        self.operation = AxialLoadOperation.from_config(
            config,
            state_period_s=1.0 / state_rate,
            diagnostics_period_s=diagnostics_period,
            max_clock_gap_s=max_gap,
            engage=engage,
        )
        self._mirroring = False

        # No QoS-event handlers on our own endpoints: each is a waitable that rclpy's executor
        # walks on every wake-up (about 1000 a second here); an incompatible QoS goes unlogged.
        quiet = PublisherEventCallbacks(use_default_callbacks=False)
        self._force_pub = self.create_publisher(WrenchStamped, "/rig/bearing/axial_force", RELIABLE_STREAM_QOS, event_callbacks=quiet)
        self._load_cell_pub = self.create_publisher(WrenchStamped, "/rig/axial_load/force", SENSOR_QOS, event_callbacks=quiet)
        self._state_pub = self.create_publisher(AxialLoadState, "/rig/axial_load/state", RELIABLE_QOS, event_callbacks=quiet)
        self._diagnostics_pub = self.create_publisher(DiagnosticArray, "/diagnostics", RELIABLE_QOS, event_callbacks=quiet)

        descriptor = ParameterDescriptor(
            description="axial-load set-point, N (finite, >= 0, <= max_setpoint_n of the rig file)",
            dynamic_typing=True,
        )
        initial = self.declare_parameter(SETPOINT_PARAMETER, 0.0, descriptor).value
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self._apply(self.operation.request_setpoint(_as_number(initial), SetpointSource.PARAMETER))
        self._mirror_setpoint()

        if not self.get_parameter("use_sim_time").value:
            raise RigError(f"{NODE_NAME}: steps the loading chain on the simulation clock: use_sim_time must be true")
        self.clock_guard = guard_sim_clock(self)  # negative and far-jumping /clock stamps refused
        self._bearing_msg = WrenchStamped()
        self._bearing_msg.header.frame_id = "bearing"
        self._load_cell_msg = WrenchStamped()
        self._load_cell_msg.header.frame_id = "load_cell"
        self._jump_handle = self.get_clock().create_jump_callback(
            JumpThreshold(min_forward=Duration(nanoseconds=1), min_backward=Duration(nanoseconds=-1)),
            post_callback=self._on_clock,
        )
        self.create_subscription(
            Float64, "/rig/axial_load/setpoint", self._on_setpoint, RELIABLE_QOS,
            event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False),
        )
        self.create_service(SetAxialLoad, "/rig/axial_load/set", self._on_set_service)
        self.create_service(Trigger, "/rig/axial_load/reset_fault", self._on_reset_fault)
        self.create_service(SetBool, "/rig/axial_load/clutch", self._on_clutch)
        self.get_logger().info(
            f"loading chain from {rig_path}; clutch {'engaged' if engage else 'released'}; "
            f"set-point {self.operation.setpoint:g} N; stepping on /clock"
        )

    # -- clock ------------------------------------------------------------------------------------
    def _on_clock(self, _jump: object = None) -> None:
        """The sim-time clock moved (forward or back): step the chain to it and publish."""
        stamp = self.get_clock().now().to_msg()
        result = self.operation.advance_to(stamp.sec + stamp.nanosec * 1e-9)
        if result.clock_note:
            self.get_logger().warning(result.clock_note)
        if result.tripped:
            self.get_logger().error(f"interlock tripped: {result.tripped}; brake de-energised, call reset_fault once clear")
        self._publish_forces(stamp, result.state)
        if result.state_due:
            self._state_pub.publish(self._state_message(stamp, result.state))
        if result.diagnostics_due:
            self._publish_diagnostics()

    def _publish_forces(self, stamp: object, state: LoadChainState) -> None:
        bearing, cell = self._bearing_msg, self._load_cell_msg
        bearing.header.stamp = stamp
        bearing.wrench.force.z = state.bearing_force
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
        if self.operation.health_changed():
            self._publish_diagnostics()
        return reply

    def _mirror_setpoint(self) -> None:
        """Keep the parameter equal to the set-point in force."""
        current = self.get_parameter(SETPOINT_PARAMETER).value
        if current == self.operation.setpoint and isinstance(current, float):
            return
        self._mirroring = True
        try:
            self.set_parameters([Parameter(SETPOINT_PARAMETER, Parameter.Type.DOUBLE, float(self.operation.setpoint))])
        finally:
            self._mirroring = False

    def _on_setpoint(self, msg: Float64) -> None:
        if self._apply(self.operation.request_setpoint(msg.data, SetpointSource.TOPIC)).accepted:
            self._mirror_setpoint()

    def _on_set_service(self, request: SetAxialLoad.Request, response: SetAxialLoad.Response) -> SetAxialLoad.Response:
        reply = self._apply(self.operation.request_setpoint(request.axial_load, SetpointSource.SERVICE))
        if reply.accepted:
            self._mirror_setpoint()
        response.accepted = reply.accepted
        response.message = reply.message
        return response

    def _on_reset_fault(self, _request: Trigger.Request, response: Trigger.Response) -> Trigger.Response:
        reply = self._apply(self.operation.reset_fault())
        response.success = reply.accepted
        response.message = reply.message
        return response

    def _on_clutch(self, request: SetBool.Request, response: SetBool.Response) -> SetBool.Response:
        reply = self._apply(self.operation.set_clutch(bool(request.data)))
        response.success = reply.accepted
        response.message = reply.message
        return response

    def _on_set_parameters(self, parameters: list[Parameter]) -> SetParametersResult:
        """Validate ``axial_load_setpoint_n`` (any type reaches here: dynamic typing); refuse
        with the chain's reason."""
        for parameter in parameters:
            if parameter.name != SETPOINT_PARAMETER or self._mirroring:
                continue
            reply = self._apply(self.operation.request_setpoint(_as_number(parameter.value), SetpointSource.PARAMETER))
            if not reply.accepted:
                return SetParametersResult(successful=False, reason=reply.message)
        return SetParametersResult(successful=True)


def _as_number(value: object) -> object:
    """An integer parameter as a float (``ros2 param set ... 100`` gives an integer); anything else
    unchanged, for the chain to judge."""
    if isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value


def main(argv: Sequence[str] | None = None) -> int:
    """Console script ``load_controller`` / ``bearing-rig-load-controller``."""
    try:
        return run_node(NODE_NAME, LoadControllerNode, argv)
    except RigError as exc:
        print(f"{NODE_NAME}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
