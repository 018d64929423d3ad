"""The bag reader: agreement with rosbags' AnyReader, bags from other writers, damaged bags."""

from __future__ import annotations

import gc
import os
import shutil
import struct
import time
import tracemalloc
import warnings
from pathlib import Path

import pytest
import yaml
from mcap.data_stream import ReadDataStream
from mcap.reader import breakup_chunk, make_reader
from mcap.records import Chunk, Message
from mcap.writer import Writer as McapWriter
from mcap_ros2.writer import Writer as McapRos2Writer
from rosbags.highlevel import AnyReader

from bearing_rig_sim.bags import BagError, BagWarning, BagWriter, open_bag, repair_bag, rig_typestore
from bearing_rig_sim.synthetic.traffic import (
    RIG_TRAFFIC_TOPICS,
    SPEEDS_TOPIC,
    TRUTH_TOPIC,
    message_fields,
    rig_traffic,
)
from bearing_rig_sim.bags.typestore import msg_folder
from conftest import write_foreign_metadata

HEADER_DEPENDENCIES = (
    "=" * 80
    + "\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
    + "=" * 80
    + "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
)
TEMPERATURE_SCHEMA = "float64 temperature   # K\nstring sensor\n"
JOINT_STATE_SCHEMA = "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n" + HEADER_DEPENDENCIES


def record_traffic(path: Path, seconds: float, **options: object) -> int:
    with BagWriter(path, **options) as bag:
        for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
            bag.add_topic(topic, msgtype, qos)
        for topic, time_ns, data in rig_traffic(seconds):
            bag.write(topic, time_ns, data)
        return bag.message_count


def anyreader_messages(path: Path, topics: set[str] | None = None) -> list[tuple[str, int, dict]]:
    store = rig_typestore()
    with AnyReader([path]) as reader:
        connections = [c for c in reader.connections if topics is None or c.topic in topics]
        return [(c.topic, t, message_fields(reader.deserialize(raw, c.msgtype), c.msgtype, store)) for c, t, raw in reader.messages(connections=connections)]


def chunk_message_counts(mcap_path: Path) -> list[tuple[int, int, int]]:
    """(start offset, end offset, messages) of every chunk, read with the mcap library."""
    out = []
    with open(mcap_path, "rb") as stream:
        summary = make_reader(stream).get_summary()
        for index in summary.chunk_indexes:
            stream.seek(index.chunk_start_offset + 9)
            chunk = Chunk.read(ReadDataStream(stream))
            count = sum(isinstance(r, Message) for r in breakup_chunk(chunk))
            out.append((index.chunk_start_offset, index.chunk_start_offset + index.chunk_length, count))
    return out


def chunk_time_ranges(mcap_path: Path) -> list[tuple[int, int, int]]:
    """(start offset, first and last log time) of every chunk, from the mcap library's summary."""
    with open(mcap_path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    return [(c.chunk_start_offset, c.message_start_time, c.message_end_time) for c in summary.chunk_indexes]


@pytest.fixture(scope="module")
def traffic_bag(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, int]:
    path = tmp_path_factory.mktemp("bags") / "traffic"
    count = record_traffic(path, 2.0, chunk_size=4096, metadata={"test_program": "steady 9000 rpm"})
    return path, count


def test_reader_agrees_with_anyreader(traffic_bag: tuple[Path, int]) -> None:
    path, count = traffic_bag
    expected = anyreader_messages(path)
    store = rig_typestore()
    with open_bag(path) as bag:
        assert bag.complete and not bag.problems
        assert bag.message_count == count == len(expected)
        assert bag.start_ns == expected[0][1] and bag.end_ns == expected[-1][1]
        assert {name: (info.msgtype, info.message_count) for name, info in bag.topics.items()} == {
            topic: (msgtype, sum(1 for t, _time, _f in expected if t == topic)) for topic, (msgtype, _qos) in RIG_TRAFFIC_TOPICS.items()
        }
        # the contract's reliable_stream profile, as offered by the twin (docs/interfaces.md)
        speeds_qos = bag.topics[SPEEDS_TOPIC].qos
        assert speeds_qos is not None and (speeds_qos.reliability, speeds_qos.depth) == ("reliable", 5000)
        assert bag.run_metadata["test_program"] == "steady 9000 rpm"
        got = [(m.topic, m.log_time_ns, message_fields(m.message, m.msgtype, store)) for m in bag.messages()]
    assert got == expected


def test_topic_and_time_selection_and_raw_bytes(traffic_bag: tuple[Path, int]) -> None:
    path, _count = traffic_bag
    truth = anyreader_messages(path, {TRUTH_TOPIC})
    start, stop = truth[5][1], truth[15][1]
    with open_bag(path) as bag:
        window = list(bag.messages([TRUTH_TOPIC], start_ns=start, stop_ns=stop))
        assert [m.log_time_ns for m in window] == [t for _topic, t, _f in truth[5:15]]
        raw = next(bag.messages(TRUTH_TOPIC, raw=True)).message
        assert rig_typestore().deserialize_cdr(raw, "bearing_rig_msgs/msg/SimulatorTruth").inner_ring_speed > 0
        with pytest.raises(BagError, match="no topic /rig/nothing"):
            bag.messages(["/rig/nothing"])


def test_batches_hold_each_topics_messages_as_the_mcap_library_reads_them(traffic_bag: tuple[Path, int]) -> None:
    """:meth:`BagReader.batches` (chunks located through their message indexes, arrays) against the
    mcap library's own reader with a topic filter: the same log times and bytes per topic, in
    log-time order, batches in time order; an unknown topic refused."""
    path, _count = traffic_bag
    topics = [SPEEDS_TOPIC, TRUTH_TOPIC]
    expected: dict[str, list[tuple[int, bytes]]] = {t: [] for t in topics}
    with open(next(path.glob("*.mcap")), "rb") as stream:
        for _schema, channel, message in make_reader(stream).iter_messages(topics=topics, log_time_order=True):
            expected[channel.topic].append((message.log_time, bytes(message.data)))
    got: dict[str, list[tuple[int, bytes]]] = {t: [] for t in topics}
    batches = 0
    with open_bag(path) as bag:
        for batch in bag.batches(topics):
            batches += 1
            for topic, part in batch.items():
                got[topic] += [(t, part.data[a:b]) for t, a, b in zip(part.log_times.tolist(), part.starts.tolist(), part.ends.tolist())]
        with pytest.raises(BagError, match="no topic /rig/nothing"):
            next(bag.batches(["/rig/nothing"]))
    assert batches > 1  # 4 kB chunks
    for topic in topics:
        assert got[topic] == expected[topic] and len(got[topic]) > 10


def test_ordered_batches_give_the_messages_in_the_order_messages_gives_them(traffic_bag: tuple[Path, int], tmp_path: Path) -> None:
    """:meth:`BagReader.ordered_batches` (chunks through their message indexes) against
    :meth:`BagReader.messages` (checked against AnyReader above): the same topics, log times and
    bytes in the same order, each message's topic as its position in the list asked for; chunks
    that overlap in time (a file whose chunks are out of order) are merged the same way."""
    path, _count = traffic_bag
    topics = [TRUTH_TOPIC, SPEEDS_TOPIC]
    overlapping = tmp_path / "overlapping.mcap"  # written topic by topic with the mcap library: the chunks overlap
    with open(overlapping, "wb") as stream:
        writer = McapWriter(stream, chunk_size=2048)
        writer.start("ros2", "test")
        channels = {
            topic: writer.register_channel(topic, "cdr", writer.register_schema(msgtype, "ros2msg", b""))
            for topic, (msgtype, _qos) in RIG_TRAFFIC_TOPICS.items()
        }
        for topic, time_ns, data in sorted(rig_traffic(0.2), key=lambda m: m[0]):
            writer.add_message(channels[topic], time_ns, data, time_ns)
        writer.finish()
    starts_ends = sorted((start, end) for _offset, start, end in chunk_time_ranges(overlapping))
    assert any(b[0] < a[1] for a, b in zip(starts_ends, starts_ends[1:]))
    for where in (path, overlapping):
        with open_bag(where) as bag:
            expected = [(m.topic, m.log_time_ns, m.message) for m in bag.messages(topics, raw=True)]
            got = []
            for batch in bag.ordered_batches(topics):
                got += [
                    (topics[c], t, batch.data[a:b]) for c, t, a, b in zip(*(x.tolist() for x in (batch.channel_ids, batch.log_times, batch.starts, batch.ends)))
                ]
            with pytest.raises(BagError, match="no topic /rig/nothing"):
                next(bag.ordered_batches(["/rig/nothing"]))
        assert got == expected and len(got) > 100, where


def test_a_single_mcap_file_opens_as_a_bag(traffic_bag: tuple[Path, int]) -> None:
    path, count = traffic_bag
    with open_bag(path / "traffic_0.mcap") as bag:
        assert bag.message_count == count
        assert sum(1 for _ in bag.messages()) == count


def test_bag_from_an_independent_writer(tmp_path: Path) -> None:
    """Written with mcap_ros2's writer from plain dicts, with a hand-written metadata.yaml: the
    layout a bench tool produces. One type is unknown to the project; its definition is in the bag."""
    bag = tmp_path / "bench"
    bag.mkdir()
    pulse_text = (msg_folder() / "FibreOpticPulse.msg").read_text() + HEADER_DEPENDENCIES
    sent = []
    with open(bag / "bench.mcap", "wb") as stream:
        writer = McapRos2Writer(stream)
        pulse = writer.register_msgdef("bearing_rig_msgs/msg/FibreOpticPulse", pulse_text)
        temperature = writer.register_msgdef("bench_msgs/msg/Temperature", TEMPERATURE_SCHEMA)
        for index in range(300):
            stamp = {"sec": index // 100, "nanosec": (index % 100) * 10_000_000}
            message = {
                "header": {"stamp": stamp, "frame_id": "bench"},
                "sensor_id": "cage",
                "strip_id": 0,
                "strip_count": 1,
                "revolution": index,
                "pulse_index": index,
            }
            writer.write_message("/rig/cage/pulses", pulse, message, log_time=index * 10_000_000 + 7)
            sent.append(("/rig/cage/pulses", message))
            if index % 10 == 0:
                reading = {"temperature": 300.0 + index / 100, "sensor": "outer ring"}
                writer.write_message("/bench/temperature", temperature, reading, log_time=index * 10_000_000 + 9)
                sent.append(("/bench/temperature", reading))
        writer.finish()
    write_foreign_metadata(
        bag, [("/rig/cage/pulses", "bearing_rig_msgs/msg/FibreOpticPulse", 300), ("/bench/temperature", "bench_msgs/msg/Temperature", 30)], ["bench.mcap"]
    )

    with warnings.catch_warnings():
        warnings.simplefilter("error", BagWarning)
        reader = open_bag(bag)
        got = [(m.topic, message_fields(m.message, m.msgtype, reader.typestore)) for m in reader.messages()]
    assert got == sent
    assert reader.topics["/bench/temperature"].decodable
    assert reader.complete


def test_a_channel_contradicting_its_topics_type_is_neither_counted_nor_read(tmp_path: Path) -> None:
    """A split bag from another writer whose second file carries /x as Int32 where the first and
    metadata.yaml say Float64: the second file's /x is left out of the count and of the messages
    alike (10 Float64 values 0.5, 1.5, ... 9.5 from the first file, by construction)."""
    bag = tmp_path / "split"
    bag.mkdir()
    for number, (msgtype, text, fmt) in enumerate([("std_msgs/msg/Float64", "float64 data\n", "<d"), ("std_msgs/msg/Int32", "int32 data\n", "<i")]):
        with open(bag / f"split_{number}.mcap", "wb") as stream:
            writer = McapWriter(stream)
            writer.start(profile="ros2", library="test")
            schema = writer.register_schema(msgtype, "ros2msg", text.encode())
            channel = writer.register_channel("/x", "cdr", schema)
            for index in range(10):
                data = b"\x00\x01\x00\x00" + struct.pack(fmt, index + 0.5 if fmt == "<d" else index)
                writer.add_message(channel, number * 1000 + index, data, number * 1000 + index)
            writer.finish()
    write_foreign_metadata(bag, [("/x", "std_msgs/msg/Float64", 20)], ["split_0.mcap", "split_1.mcap"])
    with pytest.warns(BagWarning, match="carries std_msgs/msg/Int32 here but std_msgs/msg/Float64 before; left out"):
        reader = open_bag(bag)
    assert reader.topics["/x"].message_count == 10
    assert [m.message.data for m in reader.messages()] == [index + 0.5 for index in range(10)]


def test_padded_bytes_from_ros2_bag_record_decode(tmp_path: Path) -> None:
    """rosbag2 stores what the middleware hands over, Fast-CDR padding included."""
    from rclpy.serialization import serialize_message
    from sensor_msgs.msg import JointState

    message = JointState(name=["inner_ring", "cage"], position=[0.1, 0.2], velocity=[942.0, 367.0])
    raw = serialize_message(message)
    bag = tmp_path / "recorded"
    bag.mkdir()
    with open(bag / "recorded_0.mcap", "wb") as stream:
        writer = McapWriter(stream)
        writer.start(profile="ros2", library="rosbag2")
        schema = writer.register_schema("sensor_msgs/msg/JointState", "ros2msg", JOINT_STATE_SCHEMA.encode())
        channel = writer.register_channel("/rig/speeds", "cdr", schema)
        for index in range(50):
            writer.add_message(channel, index * 1_000_000, raw, index * 1_000_000)
        writer.finish()
    write_foreign_metadata(bag, [("/rig/speeds", "sensor_msgs/msg/JointState", 50)], ["recorded_0.mcap"])
    with AnyReader([bag]) as strict:  # the premise: the strict decoder refuses these bytes
        conn, _t, data = next(strict.messages())
        with pytest.raises(Exception, match="size mismatch"):
            strict.deserialize(data, conn.msgtype)
    with open_bag(bag) as reader:
        velocities = [list(m.message.velocity) for m in reader.messages()]
    assert velocities == [[942.0, 367.0]] * 50


def test_unknown_type_is_skipped_with_a_warning(tmp_path: Path) -> None:
    bag = tmp_path / "bench"
    bag.mkdir()
    with open(bag / "bench_0.mcap", "wb") as stream:
        writer = McapWriter(stream)
        writer.start(profile="ros2", library="bench")
        schema = writer.register_schema("std_msgs/msg/Float64", "ros2msg", b"float64 data\n")
        known = writer.register_channel("/rig/axial_load/setpoint", "cdr", schema)
        secret = writer.register_channel("/bench/secret", "cdr", 0)  # no schema at all
        for index in range(20):
            writer.add_message(known, index * 2, b"\x00\x01\x00\x00" + struct.pack("<d", index), index * 2)
            writer.add_message(secret, index * 2 + 1, b"\x00\x01\x00\x00\x01\x02\x03\x04", index * 2 + 1)
        writer.finish()
    write_foreign_metadata(bag, [("/rig/axial_load/setpoint", "std_msgs/msg/Float64", 20), ("/bench/secret", "bench_msgs/msg/Secret", 20)], ["bench_0.mcap"])
    with pytest.warns(BagWarning, match=r"topic /bench/secret: type bench_msgs/msg/Secret is unknown"):
        reader = open_bag(bag)
    assert not reader.topics["/bench/secret"].decodable
    assert [m.message.data for m in reader.messages()] == [float(i) for i in range(20)]
    assert sum(1 for m in reader.messages(raw=True) if m.topic == "/bench/secret") == 20
    with pytest.raises(BagError, match="unknown"):
        open_bag(bag, strict=True)


def test_truncated_file_is_read_up_to_its_last_complete_chunk(tmp_path: Path, traffic_bag: tuple[Path, int]) -> None:
    source, count = traffic_bag
    chunks = chunk_message_counts(source / "traffic_0.mcap")
    bag = tmp_path / "traffic"
    shutil.copytree(source, bag)
    cut = (chunks[len(chunks) // 2][0] + chunks[len(chunks) // 2][1]) // 2  # inside a chunk
    os.truncate(bag / "traffic_0.mcap", cut)
    expected = sum(n for _start, end, n in chunks if end <= cut)
    with pytest.warns(BagWarning) as caught:
        reader = open_bag(bag)
    text = " | ".join(str(w.message) for w in caught)
    assert "chunk record at offset" in text and "cut by the end of the file" in text
    assert f"states {count} messages" in text  # metadata.yaml no longer matches
    assert reader.message_count == expected and not reader.complete
    full = anyreader_messages(source)
    store = rig_typestore()
    got = [(m.topic, m.log_time_ns, message_fields(m.message, m.msgtype, store)) for m in reader.messages()]
    assert got == full[:expected]
    with pytest.raises(BagError, match="cut by the end of the file"):
        open_bag(bag, strict=True)


def test_corrupt_chunk_is_skipped(tmp_path: Path, traffic_bag: tuple[Path, int]) -> None:
    source, count = traffic_bag
    chunks = chunk_message_counts(source / "traffic_0.mcap")
    bag = tmp_path / "traffic"
    shutil.copytree(source, bag)
    start, end, lost = chunks[3]
    with open(bag / "traffic_0.mcap", "r+b") as stream:
        stream.seek(end - 64)
        stream.write(bytes(64))  # zero the tail of the compressed data
    with open_bag(bag) as reader:
        assert reader.complete  # the index is intact: the damage shows only on reading
        with pytest.warns(BagWarning, match=f"chunk at offset {start}"):
            got = sum(1 for _ in reader.messages())
    assert got == count - lost
    with pytest.raises(BagError, match=f"chunk at offset {start}"):
        sum(1 for _ in open_bag(bag, strict=True).messages())


def test_not_a_bag(tmp_path: Path, traffic_bag: tuple[Path, int]) -> None:
    with pytest.raises(BagError, match="does not exist"):
        open_bag(tmp_path / "missing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(BagError, match="no metadata.yaml"):
        open_bag(tmp_path / "empty")
    garbage = tmp_path / "garbage"
    shutil.copytree(traffic_bag[0], garbage)
    (garbage / "traffic_0.mcap").write_bytes(os.urandom(5000))
    with pytest.raises(BagError, match="traffic_0.mcap: not an MCAP file"):
        open_bag(garbage)
    (tmp_path / "notes.txt").write_text("not a bag")
    with pytest.raises(BagError, match="not an MCAP file"):
        open_bag(tmp_path / "notes.txt")
    stub = tmp_path / "stub.mcap"
    stub.write_bytes(b"\x89MC")
    with pytest.raises(BagError, match="nothing readable: stub.mcap: file ends after 3 bytes, before its header"):
        open_bag(stub)


def test_empty_file_of_a_split_bag_is_reported(tmp_path: Path, traffic_bag: tuple[Path, int]) -> None:
    """A recorder killed just as it opened its next file leaves that file empty."""
    bag = tmp_path / "traffic"
    shutil.copytree(traffic_bag[0], bag)
    (bag / "traffic_1.mcap").write_bytes(b"")
    layout = yaml.safe_load((bag / "metadata.yaml").read_text())
    layout["rosbag2_bagfile_information"]["relative_file_paths"].append("traffic_1.mcap")
    (bag / "metadata.yaml").write_text(yaml.safe_dump(layout))
    with pytest.warns(BagWarning, match="traffic_1.mcap: file ends after 0 bytes, before its header"):
        reader = open_bag(bag)
    assert sum(1 for _ in reader.messages()) == traffic_bag[1]


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("rosbag2_bagfile_information: [unclosed", "not valid YAML"),
        ("something_else: {}", "rosbag2_bagfile_information is missing"),
        (
            "rosbag2_bagfile_information: {version: 9, storage_identifier: rosbag_v1, relative_file_paths: [], topics_with_message_count: []}",
            "storage .rosbag_v1. is not supported",
        ),
        ("rosbag2_bagfile_information: {version: 9, storage_identifier: mcap}", "relative_file_paths is missing"),
        # hostile metadata: an alias bomb (a few hundred bytes, gigabytes once expanded) and nesting
        # that used to end in a RecursionError
        (
            "a: &a [x, x, x, x, x, x, x, x, x]\n"
            + "".join(f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join(['*' + chr(97 + i)] * 9)}]\n" for i in range(8))
            + "rosbag2_bagfile_information: *i\n",
            "aliases",
        ),
        ("rosbag2_bagfile_information: " + "[" * 100000 + "]" * 100000, "nested deeper than 32 levels"),
        (b"rosbag2_bagfile_information: caf\xe9", "not UTF-8"),
    ],
)
def test_corrupt_metadata_yaml(tmp_path: Path, traffic_bag: tuple[Path, int], text: str | bytes, problem: str) -> None:
    bag = tmp_path / "traffic"
    shutil.copytree(traffic_bag[0], bag)
    path = bag / "metadata.yaml"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    started = time.process_time()
    with pytest.raises(BagError, match=problem) as info:
        open_bag(bag)
    assert time.process_time() - started < 1.0  # CPU s: refused at once, not after expanding
    assert "\n" not in str(info.value)


def test_reading_streams(tmp_path: Path) -> None:
    """Peak memory while reading does not grow with the bag's length (4x longer bag)."""
    peaks = []
    for seconds in (3.0, 12.0):
        path = tmp_path / f"traffic-{seconds:g}"
        record_traffic(path, seconds, chunk_size=32768)
        with open_bag(path) as bag:
            for _ in bag.messages():  # decoders generated and warmed before measuring
                pass
            gc.collect()
            tracemalloc.start()
            count = sum(1 for _ in bag.messages())
            peaks.append(tracemalloc.get_traced_memory()[1])
            tracemalloc.stop()
            assert count == bag.message_count
    short, long = peaks
    assert long < 1.3 * short + 200_000, f"peak {long} B for the long bag vs {short} B for the short one"


def test_unchunked_file_finished_and_cut(tmp_path: Path, traffic_bag: tuple[Path, int]) -> None:
    """Messages outside chunks (an MCAP writer without chunking), written in an order that is not
    the log-time order: read in log-time order, finished or cut inside a message (then every
    message whose record the cut leaves complete, by the writer's own offsets)."""
    source, _count = traffic_bag
    with open(source / "traffic_0.mcap", "rb") as stream:
        reader = make_reader(stream)
        sent = [(channel.topic, schema.name, schema.data, message.log_time, message.data) for schema, channel, message in reader.iter_messages()]
    sent = sent[1::2] + sent[::2]  # later messages first
    path = tmp_path / "unchunked.mcap"
    ends = []
    with open(path, "wb") as stream:
        writer = McapWriter(stream, use_chunking=False)
        writer.start(profile="ros2", library="test")
        channels: dict[str, int] = {}
        for topic, msgtype, text, log_time, data in sent:
            if topic not in channels:
                schema = writer.register_schema(msgtype, "ros2msg", text)
                channels[topic] = writer.register_channel(topic, "cdr", schema)
            writer.add_message(channels[topic], log_time, data, log_time)
            ends.append(stream.tell())
        writer.finish()
    expected = sorted(((t, topic, data) for topic, _type, _text, t, data in sent), key=lambda m: m[0])
    with open_bag(path) as bag:
        assert bag.complete and bag.message_count == len(sent)
        assert [(m.log_time_ns, m.topic, m.message) for m in bag.messages(raw=True)] == expected
    cut = (ends[len(ends) // 2 - 1] + ends[len(ends) // 2]) // 2  # inside a message record
    os.truncate(path, cut)
    kept = sorted(((t, topic, data) for (topic, _type, _text, t, data), end in zip(sent, ends) if end <= cut), key=lambda m: m[0])
    with pytest.warns(BagWarning, match="cut by the end of the file"):
        bag = open_bag(path)
    assert bag.message_count == len(kept) == len(sent) // 2 and not bag.complete
    assert [(m.log_time_ns, m.topic, m.message) for m in bag.messages(raw=True)] == kept
    bag_dir = tmp_path / "cut"
    bag_dir.mkdir()
    shutil.copy(path, bag_dir / "cut_0.mcap")
    assert repair_bag(bag_dir).messages_recovered == len(kept)
    with open_bag(bag_dir) as repaired:
        assert repaired.complete and [(m.log_time_ns, m.topic, m.message) for m in repaired.messages(raw=True)] == kept
