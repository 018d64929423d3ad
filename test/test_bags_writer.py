"""The recorder: round trips through rosbags' AnyReader and mcap + mcap_ros2, both required.

Round trips cover every custom message type and the standard types of the interface contract,
parametrised over chunk compression, split files and run metadata. Bytes serialized by rclpy
(Fast-CDR, with trailing padding after an empty sequence) must decode with both readers.
"""

from __future__ import annotations

import importlib
import json
import os
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader
from rosbags.interfaces import Nodetype
from rosbags.serde import SerdeError

import bearing_rig_sim
from bearing_rig_sim.bags import BagError, BagWriter, QosSpec, open_bag, rig_typestore
from bearing_rig_sim.bags.qos import QOS_PROFILES
from bearing_rig_sim.synthetic.traffic import message_fields, sample_message
from bearing_rig_sim.bags.typestore import rig_message_texts, type_hash

STANDARD_TYPES = [
    "sensor_msgs/msg/JointState",
    "rosgraph_msgs/msg/Clock",
    "diagnostic_msgs/msg/DiagnosticArray",
    "geometry_msgs/msg/WrenchStamped",
    "std_msgs/msg/Float64",
]
ROUND_TRIP_TYPES = sorted(rig_message_texts()) + STANDARD_TYPES
MESSAGES_PER_TOPIC = 40
RUN_CONTEXT = {
    "configuration": "bearing: h7006c\nrig:\n  axial_load_limit_n: 900\n",
    "calibration": "spin_friction: 0.12\n",
    "test_program": "- {at_s: 0, speed_rpm: 9000}\n",
}


def topic_of(msgtype: str) -> str:
    return "/t/" + msgtype.split("/")[-1].lower()


def storage_files(bag: Path) -> list[Path]:
    """Storage files in the order metadata.yaml lists them."""
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    return [bag / name for name in info["relative_file_paths"]]


def read_with_anyreader(bag: Path) -> list[tuple[str, int, dict]]:
    store = rig_typestore()
    with AnyReader([bag]) as reader:
        return [(conn.topic, stamp, message_fields(reader.deserialize(raw, conn.msgtype), conn.msgtype, store)) for conn, stamp, raw in reader.messages()]


def read_with_mcap(bag: Path) -> list[tuple[str, int, dict]]:
    out = []
    for path in storage_files(bag):
        with open(path, "rb") as stream:
            reader = make_reader(stream, decoder_factories=[DecoderFactory()])
            for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
                out.append((channel.topic, message.log_time, message_fields(decoded, schema.name)))
    return out


def write_round_trip_bag(path: Path, compression: str, split: bool, metadata: dict | None) -> list[tuple[str, dict]]:
    """Every round-trip type on its own topic, interleaved, three messages per time stamp (so
    log times collide and get nudged); returns (topic, fields) in writing order."""
    store = rig_typestore()
    sent = []
    with BagWriter(
        path,
        compression=compression,
        chunk_size=4096,
        max_file_bytes=16384 if split else None,
        metadata=metadata,
    ) as bag:
        for index, msgtype in enumerate(ROUND_TRIP_TYPES):
            bag.add_topic(topic_of(msgtype), msgtype, list(QOS_PROFILES)[index % len(QOS_PROFILES)])
        step = 0
        for seed in range(MESSAGES_PER_TOPIC):
            for msgtype in ROUND_TRIP_TYPES:
                message = sample_message(msgtype, seed)
                if seed % 2:
                    bag.write(topic_of(msgtype), (step // 3) * 1000, store.serialize_cdr(message, msgtype))
                else:
                    bag.write_message(topic_of(msgtype), (step // 3) * 1000, message)
                sent.append((topic_of(msgtype), message_fields(message, msgtype, store)))
                step += 1
        assert bag.nudged_count == len(sent) - len(sent) // 3 - (1 if len(sent) % 3 else 0)
    return sent


@pytest.mark.parametrize("metadata", [None, RUN_CONTEXT], ids=["no-metadata", "metadata"])
@pytest.mark.parametrize("split", [False, True], ids=["one-file", "split"])
@pytest.mark.parametrize("compression", ["zstd", "none"])
def test_round_trip_through_both_readers(tmp_path: Path, compression: str, split: bool, metadata: dict | None) -> None:
    bag = tmp_path / "run"
    sent = write_round_trip_bag(bag, compression, split, metadata)

    files = storage_files(bag)
    assert (len(files) > 1) == split
    for reader in (read_with_anyreader, read_with_mcap):
        got = reader(bag)
        assert [(topic, fields) for topic, _time, fields in got] == sent, reader.__name__
        times = [time for _topic, time, _fields in got]
        assert all(later > earlier for earlier, later in zip(times, times[1:])), "log times not strictly increasing"

    expected_context = {**(metadata or {}), "project_version": bearing_rig_sim.__version__}
    for path in files:
        with open(path, "rb") as stream:
            reader = make_reader(stream)
            records = {record.name: record.metadata for record in reader.iter_metadata()}
            assert records["bearing_rig_sim"] == expected_context
            summary = reader.get_summary()
            assert summary is not None and summary.chunk_indexes
            assert {c.compression for c in summary.chunk_indexes} == {"zstd" if compression == "zstd" else ""}
            assert {s.encoding for s in summary.schemas.values()} == {"ros2msg"}
            assert {c.message_encoding for c in summary.channels.values()} == {"cdr"}
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["version"] == 9 and info["storage_identifier"] == "mcap"
    assert info["custom_data"] == expected_context
    assert info["message_count"] == len(sent)


def test_offered_qos_and_type_hashes_reach_rosbags(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    profiles = {
        "/rig/speeds": ("sensor_msgs/msg/JointState", "sensor_data"),
        "/rig/slip_status": ("bearing_rig_msgs/msg/SlipStatus", "transient_local"),
        "/clock": ("rosgraph_msgs/msg/Clock", "reliable"),
        "/custom": ("std_msgs/msg/Float64", QosSpec("best_effort", "volatile", 7)),
    }
    with BagWriter(bag) as writer:
        for topic, (msgtype, qos) in profiles.items():
            writer.add_topic(topic, msgtype, qos)
            writer.write_message(topic, 5, sample_message(msgtype))
    store = rig_typestore()
    with AnyReader([bag]) as reader:  # checks every stored hash against the stored definitions
        for conn in reader.connections:
            msgtype, qos = profiles[conn.topic]
            spec = QOS_PROFILES[qos] if isinstance(qos, str) else qos
            assert conn.ext.offered_qos_profiles == [spec.to_rosbags()]
            assert conn.digest == store.hash_rihs01(msgtype)


@pytest.mark.parametrize(
    ("names", "position", "velocity"),
    [
        (["inner_ring", "cage"], [0.5, 1.5], [942.477, 367.566]),
        (["a"], [0.25], []),
        (["abcd"], [], []),
    ],
)
def test_rclpy_bytes_with_empty_trailing_sequence_decode_with_both_readers(
    tmp_path: Path, names: list[str], position: list[float], velocity: list[float]
) -> None:
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import JointState

    message = JointState()
    message.header.stamp.sec = 12
    message.header.stamp.nanosec = 345
    message.header.frame_id = "rig"
    message.name = names
    message.position = position
    message.velocity = velocity
    message.effort = []
    raw = serialize_message(message)
    store = rig_typestore()
    with pytest.raises(SerdeError):  # the trap: rosbags refuses Fast-CDR's padded bytes as they are
        store.deserialize_cdr(raw, "sensor_msgs/msg/JointState")

    bag = tmp_path / "run"
    with BagWriter(bag) as writer:
        writer.add_topic("/rig/speeds", "sensor_msgs/msg/JointState", "sensor_data")
        writer.write("/rig/speeds", 1_000, raw)
        writer.write("/rig/speeds", 2_000, memoryview(raw))
    expected = {
        "header": {"stamp": {"sec": 12, "nanosec": 345}, "frame_id": "rig"},
        "name": names,
        "position": position,
        "velocity": velocity,
        "effort": [],
    }
    for reader in (read_with_anyreader, read_with_mcap):
        got = reader(bag)
        assert [fields for _topic, _time, fields in got] == [expected, expected], reader.__name__
    with open_bag(bag) as reader:
        stored = [m.message for m in reader.messages(raw=True)]
    assert all(len(data) < len(raw) for data in stored), "padding was not trimmed"


def to_rclpy(msgtype: str, fields: dict[str, Any]) -> object:
    """The rclpy (rosidl-generated) message with the given field values."""
    package, _msg, name = msgtype.split("/")
    message = getattr(importlib.import_module(f"{package}.msg"), name)()
    for field, (kind, arg) in rig_typestore().fielddefs[msgtype][1]:
        value = fields[field]
        if kind == Nodetype.NAME:
            value = to_rclpy(arg, value)
        elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE) and arg[0][0] == Nodetype.NAME:
            value = [to_rclpy(arg[0][1], item) for item in value]
        elif kind == Nodetype.BASE and arg[0] == "byte":
            value = bytes([value])
        setattr(message, field, value)
    return message


def test_rclpy_serialized_messages_of_every_type_round_trip(tmp_path: Path) -> None:
    """Bytes as the middleware hands them to a raw subscription, for every round-trip type."""
    from rclpy.serialization import serialize_message

    bag = tmp_path / "run"
    sent = []
    with BagWriter(bag) as writer:
        for msgtype in ROUND_TRIP_TYPES:
            writer.add_topic(topic_of(msgtype), msgtype)
        for seed in range(12):
            for msgtype in ROUND_TRIP_TYPES:
                fields = message_fields(sample_message(msgtype, seed), msgtype)
                writer.write(topic_of(msgtype), len(sent), serialize_message(to_rclpy(msgtype, fields)))
                sent.append((topic_of(msgtype), fields))
    for reader in (read_with_anyreader, read_with_mcap):
        assert [(topic, fields) for topic, _time, fields in reader(bag)] == sent, reader.__name__


def test_type_hashes_are_the_ones_rosidl_generates() -> None:
    """rosidl writes each type's description and hash to share/<package>/msg/<Name>.json."""
    prefixes = [*filter(None, os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)), sys.prefix]
    for msgtype in ROUND_TRIP_TYPES:
        package, _msg, name = msgtype.split("/")
        found = [Path(p, "share", package, "msg", f"{name}.json") for p in prefixes]
        path = next((f for f in found if f.is_file()), None)
        assert path is not None, f"{msgtype}: no rosidl type description under {prefixes} (is msg_defs built?)"
        description = json.loads(path.read_text())
        generated = {h["type_name"]: h["hash_string"] for h in description["type_hashes"]}
        assert type_hash(msgtype) == generated[msgtype], msgtype


def test_nudged_messages_keep_their_time_as_publish_time(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    with BagWriter(bag) as writer:
        writer.add_topic("/a", "std_msgs/msg/Float64")
        for time_ns in (100, 100, 100, 50, 200):
            writer.write_message("/a", time_ns, sample_message("std_msgs/msg/Float64"))
        assert writer.nudged_count == 3
    with open(storage_files(bag)[0], "rb") as stream:
        times = [(m.log_time, m.publish_time) for _s, _c, m in make_reader(stream).iter_messages()]
    assert times == [(100, 100), (101, 100), (102, 100), (103, 50), (200, 200)]


def test_leaving_the_block_by_an_interrupt_finalises_the_bag(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    with pytest.raises(KeyboardInterrupt), BagWriter(bag, chunk_size=1024) as writer:
        writer.add_topic("/a", "std_msgs/msg/Float64")
        for index in range(500):
            writer.write_message("/a", index, sample_message("std_msgs/msg/Float64", index))
        raise KeyboardInterrupt
    assert writer.closed
    with open_bag(bag) as reader:
        assert reader.complete
        assert reader.message_count == 500
    assert len(read_with_anyreader(bag)) == 500


def test_bag_directory_is_not_overwritten(tmp_path: Path) -> None:
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "notes.txt").write_text("keep me")
    with pytest.raises(BagError, match="exists already"):
        BagWriter(tmp_path / "run")
    assert (tmp_path / "run" / "notes.txt").read_text() == "keep me"


def test_bad_writer_options_are_refused(tmp_path: Path) -> None:
    with pytest.raises(BagError, match="compression"):
        BagWriter(tmp_path / "a", compression="lzma")  # type: ignore[arg-type]
    with pytest.raises(BagError, match="chunk_size"):
        BagWriter(tmp_path / "b", chunk_size=10)
    with pytest.raises(BagError, match="max_file_bytes"):
        BagWriter(tmp_path / "c", max_file_bytes=0)
    with pytest.raises(BagError, match="strings"):
        BagWriter(tmp_path / "d", metadata={"configuration": 3})  # type: ignore[dict-item]
    assert not any((tmp_path / name).exists() for name in "abcd")


def test_bad_topics_and_messages_are_refused(tmp_path: Path) -> None:
    float64 = sample_message("std_msgs/msg/Float64")
    with BagWriter(tmp_path / "run") as writer:
        with pytest.raises(BagError, match="unknown message type 'bench_msgs/msg/Nothing'"):
            writer.add_topic("/x", "bench_msgs/msg/Nothing")
        with pytest.raises(BagError, match="fully qualified"):
            writer.add_topic("rig/speeds", "sensor_msgs/msg/JointState")
        with pytest.raises(BagError, match="unknown QoS profile 'fast'"):
            writer.add_topic("/x", "std_msgs/msg/Float64", "fast")
        writer.add_topic("/x", "std_msgs/Float64")
        writer.add_topic("/x", "std_msgs/msg/Float64")  # same again: accepted
        with pytest.raises(BagError, match="cannot add it as"):
            writer.add_topic("/x", "sensor_msgs/msg/JointState")
        with pytest.raises(BagError, match="was not added"):
            writer.write("/y", 0, b"\x00\x01\x00\x00" + bytes(8))
        with pytest.raises(BagError, match="outside"):
            writer.write_message("/x", -1, float64)
        with pytest.raises(BagError, match="integer"):
            writer.write_message("/x", 1.5, float64)  # type: ignore[arg-type]
        with pytest.raises(BagError, match="not a CDR message"):
            writer.write("/x", 0, b"garbage!")
        with pytest.raises(BagError, match="carries std_msgs/msg/Float64"):
            writer.write_message("/x", 0, sample_message("rosgraph_msgs/msg/Clock"))
        writer.add_topic("/s", "sensor_msgs/msg/JointState")
        with pytest.raises(BagError, match="do not hold a complete message"):
            writer.write("/s", 0, bytes(rig_typestore().serialize_cdr(sample_message("sensor_msgs/msg/JointState"), "sensor_msgs/msg/JointState"))[:30])
        writer.write_message("/x", 0, float64)
    with pytest.raises(BagError, match="closed"):
        writer.write_message("/x", 1, float64)
    with open_bag(tmp_path / "run") as reader:
        assert reader.message_count == 1
