"""Repair of bags whose recording was interrupted: a real SIGKILL, truncations, lost metadata."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader

from bearing_rig_sim.bags import BagError, BagWarning, BagWriter, open_bag, repair_bag
from bearing_rig_sim.cli import main as cli_main
from bearing_rig_sim.synthetic.traffic import RIG_TRAFFIC_TOPICS, rig_traffic
from conftest import time_left

REPO = Path(__file__).resolve().parents[1]
DURABLE_BEFORE_KILL = 3000

RECORDER = r"""
import sys
from bearing_rig_sim.bags import BagWriter, rig_typestore

types = rig_typestore().types
max_file_bytes = int(sys.argv[2]) or None
with BagWriter(sys.argv[1], chunk_size=2048, max_file_bytes=max_file_bytes, metadata={"test_program": "killed"}) as bag:
    bag.add_topic("/rig/axial_load/setpoint", "std_msgs/msg/Float64")
    bag.add_topic("/clock", "rosgraph_msgs/msg/Clock")
    index = 0
    while True:
        bag.write_message("/rig/axial_load/setpoint", index * 1000, types["std_msgs/msg/Float64"](data=float(index)))
        index += 1
        if index % 100 == 0:
            bag.flush()
            print(index, flush=True)  # everything up to here is on disk
"""


def anyreader_values(bag: Path) -> list[float]:
    with AnyReader([bag]) as reader:
        return [reader.deserialize(raw, conn.msgtype).data for conn, _t, raw in reader.messages()]


def mcap_values(bag: Path) -> list[float]:
    from mcap_ros2.decoder import DecoderFactory

    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    values = []
    for name in info["relative_file_paths"]:
        with open(bag / name, "rb") as stream:
            reader = make_reader(stream, decoder_factories=[DecoderFactory()])
            values += [decoded.data for _s, _c, _m, decoded in reader.iter_decoded_messages()]
    return values


def kill_recorder_midway(bag: Path, max_file_bytes: int) -> int:
    """Run a recorder in a child process, SIGKILL it once enough messages are on disk; returns
    the count it last reported durable."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    child = subprocess.Popen(
        [sys.executable, "-c", RECORDER, str(bag), str(max_file_bytes)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    durable = 0
    try:
        assert child.stdout is not None
        for line in child.stdout:
            durable = int(line)
            if durable >= DURABLE_BEFORE_KILL:
                break
        child.send_signal(signal.SIGKILL)
        _out, err = child.communicate(timeout=time_left())
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert durable >= DURABLE_BEFORE_KILL, f"recorder stopped early: {err}"
    assert child.returncode == -signal.SIGKILL
    return durable


@pytest.mark.parametrize("max_file_bytes", [0, 16384], ids=["one-file", "split"])
def test_killed_recording_is_recovered(tmp_path: Path, max_file_bytes: int) -> None:
    bag = tmp_path / "run"
    durable = kill_recorder_midway(bag, max_file_bytes)
    with pytest.raises(Exception):  # noqa: B017 - rosbags needs the index the kill prevented; its error type is rosbags' own
        anyreader_values(bag)
    with pytest.warns(BagWarning) as caught:  # no summary; maybe also a stale metadata.yaml
        before = open_bag(bag)
    assert any("without a summary" in str(w.message) for w in caught)
    readable = [m.message.data for m in before.messages()]

    report = repair_bag(bag)

    recovered = anyreader_values(bag)
    assert recovered == [float(i) for i in range(len(recovered))], "not a prefix of what was sent"
    assert len(recovered) >= durable
    assert recovered == readable == mcap_values(bag)
    assert report.messages_recovered == len(recovered)
    rebuilt = [f for f in report.files if f.action == "rebuilt"]
    assert len(rebuilt) == 1 and rebuilt[0].name == report.files[-1].name
    assert all(f.action == "intact" for f in report.files[:-1])
    assert (len(report.files) > 1) == bool(max_file_bytes)
    assert rebuilt[0].backup is not None and rebuilt[0].backup.exists()
    # metadata.yaml was refreshed at the last flush: rebuilt only if chunks completed after it
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["message_count"] == len(recovered)
    assert report.metadata_rewritten == (report.metadata_backup is not None)
    assert "messages recovered" in report.summary()
    with open_bag(bag) as after:
        assert after.complete
        assert after.run_metadata["test_program"] == "killed"
        assert set(after.topics) == {"/rig/axial_load/setpoint", "/clock"}
    again = repair_bag(bag)
    assert not again.changed and "nothing to repair" in again.summary()


def record_traffic(bag: Path) -> None:
    with BagWriter(bag, chunk_size=4096, metadata={"configuration": "rig: {}\n"}) as writer:
        for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
            writer.add_topic(topic, msgtype, qos)
        for topic, time_ns, data in rig_traffic(1.0):
            writer.write(topic, time_ns, data)


def chunk_bounds(path: Path) -> list[tuple[int, int, int]]:
    """(start, end, messages) of each chunk, from the mcap library's reading of the summary
    (log times strictly increase, so a chunk's messages are those of its time range)."""
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        indexes = sorted(reader.get_summary().chunk_indexes, key=lambda c: c.chunk_start_offset)
        return [
            (
                c.chunk_start_offset,
                c.chunk_start_offset + c.chunk_length,
                sum(1 for _ in reader.iter_messages(starting_at=c.message_start_time, ending_at=c.message_end_time)),
            )
            for c in indexes
        ]


def test_truncated_file_is_rebuilt_from_its_complete_chunks(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    record_traffic(bag)
    original = yaml.safe_load((bag / "metadata.yaml").read_text())
    file = bag / "run_0.mcap"
    chunks = chunk_bounds(file)
    cut_chunk = len(chunks) * 2 // 3
    cut = chunks[cut_chunk][0] + 100
    os.truncate(file, cut)

    report = repair_bag(bag)

    expected = sum(n for start, end, n in chunks if end <= cut)
    assert report.messages_recovered == expected
    assert report.bytes_lost == cut - chunks[cut_chunk][0]
    assert report.files[0].backup is not None and report.files[0].backup.stat().st_size == cut
    with AnyReader([bag]) as reader:
        assert reader.message_count == expected
        assert sum(1 for _ in reader.messages()) == expected
    rebuilt = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert rebuilt["message_count"] == expected
    assert rebuilt["custom_data"] == original["rosbag2_bagfile_information"]["custom_data"]


@pytest.mark.slow
def test_a_cut_anywhere_loses_only_the_chunk_it_falls_in(tmp_path: Path) -> None:
    """A kill may leave the file cut at any byte: reading and repair keep every chunk that ends
    before the cut (chunk bounds and counts from the mcap library's reading of the intact file)."""
    source = tmp_path / "run"
    record_traffic(source)
    chunks = chunk_bounds(source / "run_0.mcap")
    size = (source / "run_0.mcap").stat().st_size
    for k in range(1, 25):
        cut = size * k // 25
        bag = tmp_path / f"cut{k}"
        shutil.copytree(source, bag)
        os.truncate(bag / "run_0.mcap", cut)
        expected = sum(n for _start, end, n in chunks if end <= cut)
        with pytest.warns(BagWarning), open_bag(bag) as reader:
            assert sum(1 for _ in reader.messages()) == expected, cut
        assert repair_bag(bag).messages_recovered == expected, cut
        with open_bag(bag) as reader:
            assert reader.complete and reader.message_count == expected
        shutil.rmtree(bag)


def test_lost_metadata_yaml_is_rebuilt_identically(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    record_traffic(bag)
    original = yaml.safe_load((bag / "metadata.yaml").read_text())
    (bag / "metadata.yaml").unlink()
    with pytest.raises(BagError, match="no metadata.yaml"):
        open_bag(bag)

    report = repair_bag(bag)

    assert report.metadata_rewritten and report.metadata_backup is None
    assert [f.action for f in report.files] == ["intact"]
    assert yaml.safe_load((bag / "metadata.yaml").read_text()) == original
    with open_bag(bag) as reader:
        assert reader.complete


def test_corrupt_chunk_is_dropped_by_the_repair(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    record_traffic(bag)
    file = bag / "run_0.mcap"
    chunks = chunk_bounds(file)
    start, end, lost = chunks[2]
    with open(file, "r+b") as stream:
        stream.seek(end - 32)
        stream.write(bytes(32))
    total = sum(n for _s, _e, n in chunks)

    report = repair_bag(bag)

    assert report.files[0].action == "rebuilt"
    assert any(f"chunk at offset {start}" in p for p in report.files[0].problems)
    assert report.messages_recovered == total - lost
    # truthful loss figures: the chunk's messages and bytes (mcap's own chunk index), not "0 bytes"
    assert report.messages_lost == lost > 0
    assert report.bytes_lost == end - start
    assert f"{lost} messages and {end - start} bytes lost" in report.summary()
    with AnyReader([bag]) as reader:
        assert sum(1 for _ in reader.messages()) == total - lost


def test_a_damaged_header_length_loses_no_message(tmp_path: Path) -> None:
    """The header record's length field overwritten (2^62): the data and the summary at the
    end are intact, so every message is still read (counted by the mcap library on an intact
    copy), the damage is reported, and a repair writes a sound file with all of them."""
    import struct

    bag = tmp_path / "run"
    record_traffic(bag)
    file = bag / "run_0.mcap"
    total = sum(n for _s, _e, n in chunk_bounds(file))
    data = bytearray(file.read_bytes())
    assert data[8] == 0x01  # the header record's opcode follows the 8-byte magic (MCAP spec)
    data[9:17] = struct.pack("<Q", 1 << 62)
    file.write_bytes(bytes(data))

    with pytest.warns(BagWarning, match="the MCAP header record is damaged"), open_bag(bag) as reader:
        assert sum(1 for _ in reader.messages()) == total
    report = repair_bag(bag)
    assert report.messages_recovered == total and report.messages_lost == 0
    with open(file, "rb") as stream:
        assert sum(1 for _ in make_reader(stream).iter_messages()) == total


def test_every_chunk_damaged_is_every_message_lost(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    record_traffic(bag)
    file = bag / "run_0.mcap"
    chunks = chunk_bounds(file)
    with open(file, "r+b") as stream:
        for _start, end, _n in chunks:
            stream.seek(end - 32)
            stream.write(bytes(32))
    report = repair_bag(bag)
    total = sum(n for _s, _e, n in chunks)
    assert report.messages_recovered == 0 and report.messages_lost == total
    assert report.bytes_lost == sum(end - start for start, end, _n in chunks)


def test_empty_file_left_at_a_rollover_gets_the_topics(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    record_traffic(bag)
    (bag / "run_1.mcap").write_bytes(b"")  # killed as the recorder opened its next file

    report = repair_bag(bag)

    assert [(f.name, f.action, f.messages_recovered) for f in report.files] == [
        ("run_0.mcap", "intact", report.messages_recovered),
        ("run_1.mcap", "rebuilt", 0),
    ]
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["relative_file_paths"] == ["run_0.mcap", "run_1.mcap"]
    with open(bag / "run_1.mcap", "rb") as stream:
        channels = make_reader(stream).get_summary().channels.values()
    assert {c.topic for c in channels} == set(RIG_TRAFFIC_TOPICS)
    with AnyReader([bag]) as reader:
        assert sum(1 for _ in reader.messages()) == report.messages_recovered


def test_file_that_is_not_mcap_is_moved_aside(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    record_traffic(bag)
    (bag / "run_1.mcap").write_bytes(os.urandom(3000))
    report = repair_bag(bag)
    assert [f.action for f in report.files] == ["intact", "removed"]
    assert "not an MCAP file" in report.files[1].problems[0]
    assert not (bag / "run_1.mcap").exists() and (bag / "run_1.mcap.orig").exists()
    with open_bag(bag) as reader:
        assert reader.complete


def test_repair_refuses_what_is_not_a_bag(tmp_path: Path) -> None:
    with pytest.raises(BagError, match="not a bag directory"):
        repair_bag(tmp_path / "missing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(BagError, match="no .mcap file"):
        repair_bag(tmp_path / "empty")
    intact = tmp_path / "intact"
    record_traffic(intact)
    before = {p.name: p.read_bytes() for p in intact.iterdir()}
    assert not repair_bag(intact).changed
    assert {p.name: p.read_bytes() for p in intact.iterdir()} == before
    shutil.rmtree(intact)


def test_repair_from_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "run"
    record_traffic(bag)
    (bag / "metadata.yaml").unlink()
    assert cli_main(["bag", "repair", str(bag), str(tmp_path / "missing")]) == 2
    out, err = capsys.readouterr()
    assert "metadata.yaml: rebuilt from the files" in out
    assert err.startswith("bearing-rig: error: ") and "missing: not a bag directory" in err
    assert (bag / "metadata.yaml").exists()
