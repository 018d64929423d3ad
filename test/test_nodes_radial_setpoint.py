"""A program's radial load and moment reach the twin: session -> load controller -> simulator.

The session node sends a segment's set-point as a session does (``SessionNode.send_setpoint``)
on ``/rig/load/setpoint``: force.z the axial load, force.x/y the radial load at the segment's
``radial_azimuth_deg`` (90 deg here: along the bearing frame's y axis, so force.y = 500 N and
force.x = 500 cos 90 deg = 0 N to rounding), torque.y the moment. The load controller, on a rig
file whose ``combined_loading`` section states a radial loader (800 N, 5 N m), applies it in
force.x/y and torque.y of the force on the bearing, which the simulator applies. The load controller and the simulator run as processes with the test's rig file on the
test's isolated domain (the simulator without real time); the session node records every topic
into memory; every wait is for a message, bounded.

Expected values, independent of the code: the bearing is axisymmetric, so under a radial load
the cage is pushed off the axis (whirl radius above 0, as under a pure axial load it is exactly
0: test_nodes_simulator_loads) and the balls outside the load zone are unloaded, so the largest
ball load is well above the mean (Sjovall's integral); with
a moment applied the inner ring's tilts are free, so at equilibrium the balls' moment on the ring
balances the applied one (1 N m about y, torque.y). The shipped rig file (0 N, 0 N m) refuses the
same program naming the segment and the limit; a set-point above the test rig's limit, sent on the
topic, is refused on the load controller's status and the one in force stays.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.ros
rclpy = pytest.importorskip("rclpy")

from diagnostic_msgs.msg import DiagnosticStatus  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from rclpy.serialization import deserialize_message  # noqa: E402

from bearing_rig_sim.config import ConfigError  # noqa: E402
from bearing_rig_sim.interfaces import BEARING_AXIAL_FORCE, DIAGNOSTICS, LOAD_SETPOINT, TRUTH  # noqa: E402
from bearing_rig_sim.nodes.common import from_stamp, qos_profile  # noqa: E402
from bearing_rig_sim.rig.program import RigLimits, load_program  # noqa: E402
from bearing_rig_sim.session.node import MESSAGE_TYPES, SessionNode  # noqa: E402
from bearing_rig_sim.session.recorder import SessionRecorder  # noqa: E402
from bearing_rig_sim.session.runner import ProgramRunner  # noqa: E402
from test_nodes_simulator_loads import radial_rig_file  # noqa: E402

WAIT = 90.0
"""Longest wait for any one condition, wall s (two nodes start, the chain settles)."""

AXIAL_N, RADIAL_N, MOMENT_N_M, AZIMUTH_DEG = 163.0, 500.0, 1.0, 90.0

PROGRAM = f"""
name: radial_side_load
description: a side load and a moment at 900 rpm
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {{name: side, speed_rpm: 900, ramp_s: 1.0, axial_load_n: {AXIAL_N:g}, radial_load_n: {RADIAL_N:g}, moment_n_m: {MOMENT_N_M:g}, radial_azimuth_deg: {AZIMUTH_DEG:g}, dwell_s: 600.0}}
"""
"""Held far longer than the test needs. Its spindle command is not sent: the simulator starts at
900 rpm (initial_speed_rad_s)."""


class Memory:
    """A message writer keeping what the session records, by topic."""

    def __init__(self) -> None:
        self.raw: dict[str, list[bytes]] = {}

    def add_topic(self, name: str, msgtype: str, qos: str) -> None:
        self.raw.setdefault(name, [])

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None:
        self.raw[topic].append(data)

    def messages(self, topic: Any) -> list[Any]:
        return [deserialize_message(raw, MESSAGE_TYPES[topic.msgtype]) for raw in self.raw[topic.name]]

    def diagnostic(self, prefix: str, key: str) -> str:
        """The latest value of ``key`` in a status whose name starts with ``prefix`` ('' before any)."""
        for array in reversed(self.messages(DIAGNOSTICS)):
            for status in array.status:
                if status.name.startswith(prefix):
                    for kv in status.values:
                        if kv.key == key:
                            return str(kv.value)
        return ""


def test_shipped_rig_file_refuses_the_radial_program_naming_segment_and_limit(tmp_path: Path) -> None:
    program = tmp_path / "program.yaml"
    program.write_text(PROGRAM, encoding="utf-8")
    with pytest.raises(ConfigError, match=r"segment 'side': 500 N is above the rig's limit of 0 N \(combined_loading\.max_radial_setpoint_n in rig\.yaml\)"):
        load_program(program)


def test_programs_radial_load_and_moment_reach_the_simulator_through_the_load_controller(ros_graph: Any, tmp_path: Path) -> None:
    rig_file = radial_rig_file(tmp_path)
    program_file = tmp_path / "program.yaml"
    program_file.write_text(PROGRAM, encoding="utf-8")
    program = load_program(program_file, RigLimits.from_rig_file(rig_file))
    ros_graph.spawn_python(
        "-m",
        "bearing_rig_sim.nodes.simulator",
        "--autostart",
        "--no-realtime",
        "--ros-args",
        "-p",
        f"initial_speed_rad_s:={900 * math.pi / 30!r}",
        "-p",
        f"rig_file:={rig_file}",
    )
    controller = ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.load_controller", "--autostart", "--ros-args", "-p", f"rig_file:={rig_file}")
    memory = Memory()
    runner = ProgramRunner(program)
    assert runner.loads_radially
    session = SessionNode(SessionRecorder(memory), runner, context=ros_graph.context(), name="radial_session")
    executor = ros_graph.executor([session])

    def wait(condition: Any, what: str) -> None:
        def drained() -> bool:
            session.drain()
            return bool(condition())

        assert ros_graph.spin_until(drained, WAIT, executor=executor), f"timed out waiting for {what}"

    wait(
        lambda: session.count_subscribers(LOAD_SETPOINT.name) > 0,
        "the load controller's set-point reader",
    )
    wait(lambda: session.sim_time > 0.05 and memory.raw[BEARING_AXIAL_FORCE.name], "the simulator's clock and the controller's forces")
    assert all(m.wrench.force.y == 0.0 and m.wrench.torque.y == 0.0 for m in memory.messages(BEARING_AXIAL_FORCE))  # none asked for yet

    session.send_setpoint(runner.start(session.sim_time))
    sent = memory.messages
    wait(lambda: any(m.wrench.force.y == RADIAL_N for m in sent(BEARING_AXIAL_FORCE)), "the radial load in the force on the bearing")
    loaded = [m for m in sent(BEARING_AXIAL_FORCE) if m.wrench.force.y != 0.0]
    assert all(
        (m.wrench.force.x, m.wrench.force.y, m.wrench.torque.x, m.wrench.torque.y) == pytest.approx((0.0, RADIAL_N, 0.0, MOMENT_N_M), abs=1e-9) for m in loaded
    )
    [setpoint] = sent(LOAD_SETPOINT)  # one segment, one set-point, recorded
    assert (setpoint.wrench.force.z, setpoint.wrench.force.y, setpoint.wrench.torque.y) == (AXIAL_N, RADIAL_N, MOMENT_N_M)
    assert setpoint.wrench.force.x == pytest.approx(0.0, abs=1e-9)

    wait(lambda: memory.diagnostic("simulator", "radial_load_n") == f"{RADIAL_N:g}", "the simulator reporting the radial load")
    assert float(memory.diagnostic("simulator", "radial_load_azimuth_deg")) == pytest.approx(AZIMUTH_DEG, abs=1e-9)  # force.y: along y
    assert memory.diagnostic("simulator", "moment_n_m") == f"0 {MOMENT_N_M:g}"
    wait(lambda: memory.diagnostic("load_controller", "radial_setpoint_n") == f"{RADIAL_N:g}", "the load controller reporting the radial set-point")
    assert memory.diagnostic("load_controller", "moment_setpoint_n_m") == f"{MOMENT_N_M:g}"

    def truth() -> Any:
        return sent(TRUTH)[-1]

    wait(lambda: truth().cage_whirl_radius_um > 1.0, "the cage off the axis under the radial load")
    # a load zone: at F_a = 1.216 F_r tan a (half the ring loaded) the mean ball load is J_a(0.5) =
    # 0.3413 of the largest (Sjovall's integral, Harris and Kotzalas vol. 1, ch. 7), max/mean 2.9
    assert truth().inner_contact_load_max > 2.0 * truth().inner_contact_load_mean
    # the tilts free: the balls' moment on the ring balances the applied 1 N m about y
    wait(
        lambda: (
            tuple(float(v) for v in memory.diagnostic("simulator", "ring_moment_n_m").split() or ("nan", "nan")) == pytest.approx((0.0, MOMENT_N_M), abs=1e-3)
        ),
        "the ring balancing the moment",
    )
    assert controller.poll() is None

    # 900 N on the set-point topic is above the rig file's 800 N: refused on the load controller's
    # status naming the limit, the node up, the force on the bearing keeping 500 N and 1 N m
    bench = session.create_publisher(WrenchStamped, LOAD_SETPOINT.name, qos_profile(LOAD_SETPOINT))
    too_much = WrenchStamped()
    too_much.wrench.force.z = AXIAL_N
    too_much.wrench.force.x = 900.0
    bench.publish(too_much)
    refusal = (
        f"radial set-point by topic refused: radial force 900 N is above the rig's limit of 800 N (combined_loading.max_radial_setpoint_n in {rig_file.name})"
    )
    wait(lambda: any(s.level == DiagnosticStatus.WARN and refusal in s.message for a in sent(DIAGNOSTICS) for s in a.status), "WARN for 900 N")
    refused_at = session.sim_time
    wait(lambda: session.sim_time > refused_at + 0.05, "the rig going on after the refusal")
    after = [m for m in sent(BEARING_AXIAL_FORCE) if from_stamp(m.header.stamp) > refused_at]
    assert after and all((m.wrench.force.y, m.wrench.torque.y) == (RADIAL_N, MOMENT_N_M) for m in after)
    assert memory.diagnostic("load_controller", "radial_setpoint_n") == f"{RADIAL_N:g}"
    assert controller.poll() is None
