"""The rig's Fast DDS profile (bearing_rig_sim.dds_profile): written where asked, a user's own
profile kept, and a reliable writer's acknowledgements coming within its heartbeat period, not
Fast DDS's default 3 s (the heartbeat the simulator paces itself on without real time)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from bearing_rig_sim.dds_profile import RIG_PROFILE_XML, apply_rig_profile
from conftest import time_left


def test_the_profile_is_written_and_a_users_own_is_kept(tmp_path: Path) -> None:
    import xml.etree.ElementTree as ET

    env: dict[str, str] = {}
    written = apply_rig_profile(env, tmp_path / "logs")
    assert written == tmp_path / "logs" / "fastdds_profile.xml" and env["FASTRTPS_DEFAULT_PROFILES_FILE"] == str(written)
    assert written.read_text(encoding="utf-8") == RIG_PROFILE_XML
    ns = {"p": "http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles"}
    period = ET.fromstring(RIG_PROFILE_XML).find("p:data_writer/p:times/p:heartbeatPeriod", ns)
    assert period is not None and int(period.findtext("p:sec", namespaces=ns) or "") == 0
    assert int(period.findtext("p:nanosec", namespaces=ns) or "") == 50_000_000  # 50 ms
    mine = {"FASTDDS_DEFAULT_PROFILES_FILE": "/etc/my_profile.xml"}
    assert apply_rig_profile(mine, tmp_path / "other") is None and mine == {"FASTDDS_DEFAULT_PROFILES_FILE": "/etc/my_profile.xml"}


READER = """
import rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64
rclpy.init()
node = rclpy.create_node("ack_reader")
node.create_subscription(Float64, "/ack_probe", lambda m: None, QoSProfile(depth=5000, reliability=ReliabilityPolicy.RELIABLE))
rclpy.spin(node)
"""

WRITER = """
import sys, time, rclpy
from rclpy.duration import Duration
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64
from bearing_rig_sim.dds_profile import use_rig_profile
if sys.argv[1] == "rig":
    use_rig_profile()
rclpy.init()
node = rclpy.create_node("ack_writer")
pub = node.create_publisher(Float64, "/ack_probe", QoSProfile(depth=5000, reliability=ReliabilityPolicy.RELIABLE))
deadline = time.monotonic() + 60.0
while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
    time.sleep(0.01)
pub.publish(Float64(data=0.0))
pub.wait_for_all_acked(Duration(seconds=10.0))  # the match settled on both sides
worst = 0.0
for _ in range(5):
    for i in range(200):
        pub.publish(Float64(data=float(i)))
    start = time.monotonic()
    acked = pub.wait_for_all_acked(Duration(seconds=10.0))
    worst = max(worst, time.monotonic() - start if acked else float("inf"))
print(worst)
"""


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.parametrize("profile, low, high", [("rig", 0.0, 1.5), ("fastdds", 1.5, 10.0)])
def test_a_reliable_reader_acknowledges_within_the_heartbeat(ros_graph: Any, profile: str, low: float, high: float) -> None:
    """Across two processes, the worst wait for a reader's acknowledgement of 200 samples: with
    the rig's profile well under a second (a heartbeat every HEARTBEAT_PERIOD_S = 50 ms, with
    room for a loaded host); without it, Fast DDS's default heartbeat period of 3 s (its
    WriterTimes documentation) shows."""
    assert "FASTRTPS_DEFAULT_PROFILES_FILE" not in ros_graph.env  # the fixture leaves Fast DDS's defaults
    reader = ros_graph.spawn_python("-c", READER)
    writer = ros_graph.spawn_python("-c", WRITER, profile)
    out, err = writer.communicate(timeout=time_left())
    assert writer.returncode == 0, err[-2000:]
    worst = float(out.strip().splitlines()[-1])
    assert low <= worst < high, f"worst wait for acknowledgement {worst:.3f} s with the {profile} profile"
    assert reader.poll() is None  # the reader was there all along
