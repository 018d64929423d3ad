"""The storage seam: MCAP and SQLite 3 bags read through the same reader; unknown formats refused
by name. A SQLite 3 bag is written with rosbags' own rosbag2 writer (the format older benches
record) and must give what the same messages give in an MCAP bag: topics, counts, run context,
decoded messages, ``bag info`` and the offline analysis."""

from __future__ import annotations

import io
from pathlib import Path

import pytest
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Rosbag2Writer

import bearing_rig_sim
from bearing_rig_sim.bags import QOS_PROFILES, BagError, BagWriter, open_bag, rig_typestore
from bearing_rig_sim.bags.mcapfile import McapFormat
from bearing_rig_sim.bags.reader import storage_format
from bearing_rig_sim.benchmarks.bags import STATUS_TOPIC, program_traffic
from bearing_rig_sim.commands.bag import print_info
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.synthetic.traffic import CAGE_PULSES_TOPIC, SPINDLE_PULSES_TOPIC, message_fields

PULSE = "bearing_rig_msgs/msg/FibreOpticPulse"
TYPES = {SPINDLE_PULSES_TOPIC: PULSE, CAGE_PULSES_TOPIC: PULSE, STATUS_TOPIC: "bearing_rig_msgs/msg/SlipStatus"}
CONTEXT = {"test_program": "validation speeds (storage test)", "project_version": bearing_rig_sim.__version__}


@pytest.fixture(scope="module")
def twin_bags(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, list[tuple[str, int, bytes]]]:
    """The same 40 s of pulses and slip status in an MCAP bag (the project's writer) and in a
    SQLite 3 bag (rosbags' writer)."""
    folder = tmp_path_factory.mktemp("storage")
    messages = list(program_traffic(40.0))
    store = rig_typestore()
    with BagWriter(folder / "mcap", metadata=CONTEXT) as writer:
        for topic, msgtype in TYPES.items():
            writer.add_topic(topic, msgtype)
        for topic, time_ns, data in messages:
            writer.write(topic, time_ns, data)
    with Rosbag2Writer(folder / "sqlite", version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        for key, value in CONTEXT.items():
            writer.set_custom_data(key, value)
        qos = [QOS_PROFILES["reliable"].to_rosbags()]
        connections = {topic: writer.add_connection(topic, msgtype, typestore=store, offered_qos_profiles=qos) for topic, msgtype in TYPES.items()}
        for topic, time_ns, data in messages:
            writer.write(connections[topic], time_ns, data)
    return folder / "mcap", folder / "sqlite", messages


def test_a_sqlite3_bag_reads_as_what_was_written(twin_bags: tuple[Path, Path, list[tuple[str, int, bytes]]]) -> None:
    _mcap, sqlite, messages = twin_bags
    store = rig_typestore()
    assert any(sqlite.glob("*.db3"))
    with open_bag(sqlite) as bag:
        assert bag.complete and not bag.problems
        assert bag.run_metadata == CONTEXT
        assert bag.message_count == len(messages)
        assert {name: (t.msgtype, t.message_count) for name, t in bag.topics.items()} == {
            topic: (msgtype, sum(1 for m in messages if m[0] == topic)) for topic, msgtype in TYPES.items()
        }
        assert (bag.start_ns, bag.end_ns) == (min(m[1] for m in messages), max(m[1] for m in messages))
        got = [(m.topic, m.log_time_ns, message_fields(m.message, m.msgtype, store)) for m in bag.messages()]
        assert bag.verify() == []
    # rosbags' writer keeps equal stamps in writing order only within a topic: compare sorted
    sent = [(topic, t, message_fields(store.deserialize_cdr(data, TYPES[topic]), TYPES[topic], store)) for topic, t, data in messages]
    assert sorted(got, key=repr) == sorted(sent, key=repr)
    assert [t for _topic, t, _f in got] == sorted(t for _topic, t, _d in messages)


def test_bag_info_and_analysis_agree_across_storages(twin_bags: tuple[Path, Path, list[tuple[str, int, bytes]]], tmp_path: Path) -> None:
    mcap, sqlite, _messages = twin_bags
    infos = []
    for bag in (mcap, sqlite):
        out = io.StringIO()
        print_info(bag, out)
        infos.append([line for line in out.getvalue().splitlines() if not line.startswith(("bag:", "files:"))])
    assert infos[0] == infos[1] and "state:      complete" in infos[0]
    results = [analyse_bag(bag, csv_dir=tmp_path / bag.name) for bag in (mcap, sqlite)]
    assert results[0].pulses == results[1].pulses and sum(results[0].pulses.values()) > 1000
    assert results[0].windows == results[1].windows > 50
    csv = sorted(p.name for p in (tmp_path / "mcap").glob("*.csv"))
    assert csv and csv == sorted(p.name for p in (tmp_path / "sqlite").glob("*.csv"))
    for name in csv:
        assert (tmp_path / "mcap" / name).read_bytes() == (tmp_path / "sqlite" / name).read_bytes(), name


def test_unknown_storage_is_refused_naming_it_and_the_known_ones(tmp_path: Path) -> None:
    assert storage_format("mcap").identifier == "mcap" and storage_format("sqlite3").identifier == "sqlite3"
    with pytest.raises(BagError, match=r"'rosbag_v1' is not supported .*mcap, sqlite3"):
        storage_format("rosbag_v1")
    bag = tmp_path / "run"
    with BagWriter(bag) as writer:
        writer.add_topic("/x", "std_msgs/msg/Float64", "reliable")
        writer.write("/x", 1, b"\x00\x01\x00\x00" + bytes(8))
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text().replace("storage_identifier: mcap", "storage_identifier: rosbag_v1"))
    with pytest.raises(BagError, match="metadata.yaml: storage 'rosbag_v1' is not supported"):
        open_bag(bag)


def test_messages_through_the_mcap_format_round_trip(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    payloads = [b"\x00\x01\x00\x00" + bytes([i]) * 8 for i in range(5)]
    with BagWriter(bag) as writer:
        writer.add_topic("/x", "std_msgs/msg/Float64", "reliable")
        for i, data in enumerate(payloads):
            writer.write("/x", 1000 + i, data)
    fmt = McapFormat()
    (index,) = fmt.indexes(bag, list(bag.glob("*.mcap")))
    assert index.indexed and not index.problems
    problems: list[str] = []
    assert [(t, d) for t, _c, _p, d in fmt.messages(index, problems.append)] == [(1000 + i, d) for i, d in enumerate(payloads)]
    assert problems == []
    assert [(c.topic, c.msgtype, c.encoding) for c in index.channels.values()] == [("/x", "std_msgs/msg/Float64", "cdr")]
