"""The simulator's outer-ring thermocouple and housing torque meter, on the test's isolated ROS
domain: the temperature rises from ambient at 2700 rpm, the torque meter reads the engine's
friction torque (the truth's), both stamped on the simulated clock at their contract rates."""

from __future__ import annotations

import math
import statistics
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.ros
rclpy = pytest.importorskip("rclpy")

from bearing_rig_msgs.msg import SimulatorTruth  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from sensor_msgs.msg import Temperature  # noqa: E402

from bearing_rig_sim.interfaces import HOUSING_TORQUE, OUTER_RING_TEMPERATURE, TRUTH  # noqa: E402
from bearing_rig_sim.nodes.common import RELIABLE_QOS, SENSOR_QOS, from_stamp  # noqa: E402
from bearing_rig_sim.instruments.first_order import ThermocoupleSettings  # noqa: E402
from bearing_rig_sim.instruments.registry import InstrumentSet  # noqa: E402

CONFIG = Path(__file__).resolve().parents[1] / "config"
AMBIENT_C = 22.0
"""Ambient temperature, degC (config/bearings/h7006c.yaml, thermal section)."""
WAIT = 120.0
"""Longest wait, wall s."""
THERMOCOUPLE_NOISE_K = InstrumentSet.from_rig_file().on_topic(OUTER_RING_TEMPERATURE.name, ThermocoupleSettings).noise_std_k
"""The thermocouple's RMS noise, K (config/rig.yaml, sensors.outer_ring_thermocouple)."""


def test_thermocouple_warms_and_torque_meter_reads_the_friction_torque(ros_graph: Any) -> None:
    node = ros_graph.node("probe")
    temps: list[Temperature] = []
    torques: list[WrenchStamped] = []
    truth: list[SimulatorTruth] = []
    node.create_subscription(Temperature, OUTER_RING_TEMPERATURE.name, temps.append, RELIABLE_QOS)
    node.create_subscription(WrenchStamped, HOUSING_TORQUE.name, torques.append, RELIABLE_QOS)
    node.create_subscription(SimulatorTruth, TRUTH.name, truth.append, SENSOR_QOS)
    executor = ros_graph.executor([node])
    ros_graph.spawn_python(
        "-m",
        "bearing_rig_sim.nodes.simulator",
        "--autostart",
        "--no-realtime",
        "--ros-args",
        "-p",
        f"bearing_file:={CONFIG / 'bearings' / 'h7006c.yaml'}",
        "-p",
        f"calibration_file:={CONFIG / 'calibration' / 'h7006c_table3.yaml'}",
        "-p",
        f"initial_speed_rad_s:={2700 * math.pi / 30}",
    )
    assert ros_graph.spin_until(lambda: len(temps) >= 80 and len(truth) >= 10, WAIT, executor=executor), (len(temps), len(torques))
    stamps = [from_stamp(m.header.stamp) for m in temps]
    gaps = [b - a for a, b in zip(stamps, stamps[1:])]
    assert statistics.median(gaps) == pytest.approx(0.1, abs=1e-6)  # 10 Hz simulated
    assert all(m.header.frame_id == "outer_ring" and m.variance == pytest.approx(THERMOCOUPLE_NOISE_K**2) for m in temps)
    first = statistics.mean(m.temperature for m in temps[:10])
    last = statistics.mean(m.temperature for m in temps[-10:])
    # The probe may match the simulator's publisher a few simulated seconds late on a busy host
    # (the run without real time waits only for readers it has discovered), so the warming is
    # judged against the ambient the bearing file states, not against the first reading seen.
    assert first > AMBIENT_C - 1.0  # never below ambient beyond the noise
    assert last > AMBIENT_C + 10 * THERMOCOUPLE_NOISE_K  # warmed, well beyond the noise
    assert last > first + 3 * THERMOCOUPLE_NOISE_K / math.sqrt(10)  # and still warming
    tq = [m.wrench.torque.z for m in torques[-50:]]
    friction = statistics.mean(m.friction_torque for m in truth[-5:])
    assert statistics.mean(tq) == pytest.approx(friction, rel=0.02)
