"""The shadow node live, across processes: ``bearing-rig replay`` of a bench bag feeds a shadow
node in another process; its residuals are recorded into a bag that both readers (rosbags'
AnyReader and mcap_ros2) decode, and agree with the offline run over the same bag."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from bearing_rig_sim.bags import BagWriter
from bearing_rig_sim.interfaces import DIAGNOSTICS, TWIN_RESIDUAL, TWIN_TEMPERATURE_RESIDUAL, TWIN_TORQUE_RESIDUAL
from bearing_rig_sim.session.recorder import SessionRecorder
from bearing_rig_sim.shadow.offline import shadow_bag
from bearing_rig_sim.synthetic.twin_bench import Hold, twin_bench_run, write_bench_bag
from conftest import time_left


@pytest.mark.ros
def test_replay_feeds_a_shadow_node_in_another_process(ros_graph, tmp_path: Path) -> None:
    from bearing_rig_msgs.msg import ShadowResidual
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import Vector3Stamped
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosbags.highlevel import AnyReader

    run = twin_bench_run([Hold(1800.0, 3.0)], clock_offset_s=1.7e9)
    bench = write_bench_bag(run, tmp_path / "bench")
    offline = shadow_bag(bench, None)
    assert offline.counts["compared"] > 20 and offline.counts["anomalous"] == 0

    node = ros_graph.node("observer")
    received: list[tuple[str, bytes]] = []
    levels: list[str] = []
    counts: dict[str, str] = {}  # the shadow node's latest diagnostic values
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    node.create_subscription(ShadowResidual, TWIN_RESIDUAL.name, lambda data: received.append((TWIN_RESIDUAL.name, data)), qos, raw=True)
    sensors: dict[str, list[Vector3Stamped]] = {TWIN_TEMPERATURE_RESIDUAL.name: [], TWIN_TORQUE_RESIDUAL.name: []}
    for name, into in sensors.items():
        node.create_subscription(Vector3Stamped, name, into.append, qos)

    def on_diagnostics(msg: DiagnosticArray) -> None:
        for status in msg.status:
            if status.name.startswith("shadow"):
                levels.append(status.message)
                counts.update((v.key, v.value) for v in status.values)

    node.create_subscription(DiagnosticArray, DIAGNOSTICS.name, on_diagnostics, qos)
    executor = ros_graph.executor([node])
    shadow = ros_graph.spawn_python("-c", "import sys; from bearing_rig_sim.nodes.shadow import main; sys.exit(main())", "--autostart")
    assert ros_graph.spin_until(lambda: bool(levels), timeout=time_left(), executor=executor), "the shadow node did not come up"
    replay = ros_graph.spawn_python("-m", "bearing_rig_sim.cli", "replay", str(bench), "--wait-for-subscribers", "--delay", "20")
    assert ros_graph.spin_until(lambda: replay.poll() is not None, timeout=time_left(), executor=executor), "the replay did not end"
    assert replay.returncode == 0, replay.communicate()[1]
    # Done when the node's diagnostics say it has taken every pulse of the bag (the windows come
    # from the pulses alone) and every residual it had published by then has arrived here: the
    # count is then the one the whole bag makes. The timeout only guards against a hang.
    pulses = {"spindle_pulses_received": str(len(run.spindle)), "cage_pulses_received": str(len(run.cage))}

    def every_window_in() -> bool:
        return all(counts.get(k) == v for k, v in pulses.items()) and len(received) >= int(counts["windows"])

    done = ros_graph.spin_until(every_window_in, timeout=time_left(), executor=executor)
    assert done, f"the shadow node did not report every pulse and window: {counts} for {pulses}, {len(received)} residuals received"
    assert shadow.poll() is None, "the shadow node died"
    expected = offline.counts["windows"]

    bag = tmp_path / "recorded"
    with BagWriter(bag) as writer:
        recorder = SessionRecorder(writer, topics=(TWIN_RESIDUAL,))
        for name, data in received:
            recorder.record(name, bytes(data))
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == TWIN_RESIDUAL.name]
        by_rosbags = [reader.deserialize(raw, c.msgtype) for c, _t, raw in reader.messages(connections=connections)]
    with next(bag.glob("*.mcap")).open("rb") as stream:
        mcap = make_reader(stream, decoder_factories=[DecoderFactory()])
        by_mcap = [decoded for _s, _c, _m, decoded in mcap.iter_decoded_messages(topics=[TWIN_RESIDUAL.name])]
    assert len(by_rosbags) == len(by_mcap) == len(received)
    assert abs(len(received) - expected) <= 1
    for a, b in zip(by_rosbags, by_mcap):
        assert a.measured_slip == b.measured_slip and a.compared == b.compared and a.detail == b.detail
    live_compared = [m for m in by_rosbags if m.compared]
    assert len(live_compared) >= offline.counts["compared"] - 2
    assert not any(m.anomaly for m in by_rosbags)
    assert all(abs(m.residual) <= m.band for m in live_compared)
    # the same pulses make the same windows: the measured slip agrees with the offline run's
    matched = 0
    for m in by_rosbags:
        t = m.header.stamp.sec + m.header.stamp.nanosec * 1e-9
        same = [r for r in offline.rows if abs(r.time - t) < 2e-6]
        if same:
            matched += 1
            assert m.measured_slip == pytest.approx(same[0].measured_slip, abs=1e-9)
    assert matched >= len(by_rosbags) - 2
    assert math.isfinite(by_rosbags[-1].predicted_slip)
    # the thermocouple's and the torque meter's residuals on their own topics, each with its
    # threshold, one per window that compared them (the window's stamp): the same bench, inside
    with_sensor = {
        name: [m for m in by_rosbags if math.isfinite(getattr(m, field))]
        for name, field in ((TWIN_TEMPERATURE_RESIDUAL.name, "temperature_residual"), (TWIN_TORQUE_RESIDUAL.name, "torque_residual"))
    }
    done = ros_graph.spin_until(lambda: all(len(sensors[n]) >= len(with_sensor[n]) for n in sensors), timeout=time_left(), executor=executor)
    assert done, {n: (len(sensors[n]), len(with_sensor[n])) for n in sensors}
    for name, field in ((TWIN_TEMPERATURE_RESIDUAL.name, "temperature"), (TWIN_TORQUE_RESIDUAL.name, "torque")):
        assert len(with_sensor[name]) >= 0.9 * len(live_compared) > 0
        by_stamp = {(m.header.stamp.sec, m.header.stamp.nanosec): m for m in with_sensor[name]}
        for v in sensors[name]:
            row = by_stamp[(v.header.stamp.sec, v.header.stamp.nanosec)]
            assert (v.vector.x, v.vector.y, v.vector.z) == (
                getattr(row, f"{field}_residual"),
                getattr(row, f"{field}_band"),
                getattr(row, f"predicted_{field}"),
            )
            assert 0.0 < v.vector.y and abs(v.vector.x) <= v.vector.y


def test_the_session_records_the_shadow_topics_too() -> None:
    """A session records every topic of the contract; its recorder needs each one's rclpy class."""
    from bearing_rig_sim.interfaces import TOPICS, TWIN_ESTIMATE
    from bearing_rig_sim.session.node import MESSAGE_TYPES

    assert {TWIN_RESIDUAL, TWIN_ESTIMATE, TWIN_TEMPERATURE_RESIDUAL, TWIN_TORQUE_RESIDUAL} <= set(TOPICS)
    assert {t.msgtype for t in TOPICS} <= MESSAGE_TYPES.keys()
