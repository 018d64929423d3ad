"""The session recorder's log-time rule with a fake writer (no ROS, no disk): stamps from headers
and /clock, the fallbacks (no stamp, zero, a wall-clock stamp), strictly increasing log times,
ordering within a batch; then the same through the project's BagWriter and back.
"""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from bearing_rig_sim.bags import BagWriter, open_bag
from bearing_rig_sim.session.recorder import RECORDED_TOPICS, SessionRecorder, header_stamp_ns

S = 1_000_000_000  # ns per s


def stamped(ns: int, tail: bytes = b"", big_endian: bool = False) -> bytes:
    """CDR bytes beginning with a builtin_interfaces/Time (a Clock message when tail is empty)."""
    sec, nanosec = divmod(ns, S)
    if big_endian:
        return b"\x00\x00\x00\x00" + struct.pack(">iI", sec, nanosec) + tail
    return b"\x00\x01\x00\x00" + struct.pack("<iI", sec, nanosec) + tail


def float64(value: float) -> bytes:
    return b"\x00\x01\x00\x00" + struct.pack("<d", value)


class FakeWriter:
    def __init__(self) -> None:
        self.topics: dict[str, tuple[str, str]] = {}
        self.written: list[tuple[str, int, bytes]] = []

    def add_topic(self, name: str, msgtype: str, qos: str) -> None:
        self.topics[name] = (msgtype, qos)

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None:
        assert topic in self.topics
        self.written.append((topic, log_time_ns, data))


@pytest.fixture
def fake() -> tuple[FakeWriter, SessionRecorder]:
    writer = FakeWriter()
    return writer, SessionRecorder(writer)


def test_every_topic_of_the_interface_table_is_declared_with_its_qos(fake: tuple[FakeWriter, SessionRecorder]) -> None:
    writer, _ = fake
    assert set(writer.topics) == {t.name for t in RECORDED_TOPICS}
    assert writer.topics["/rig/speeds"] == ("sensor_msgs/msg/JointState", "reliable_stream")
    assert writer.topics["/rig/axial_load/force"][1] == "reliable_stream"
    assert writer.topics["/rig/load/setpoint"][1] == "transient_stream"
    assert writer.topics["/rig/slip_status"][1] == "transient_stream"
    assert writer.topics["/rig/housing/torque"][1] == "reliable_stream"
    assert writer.topics["/clock"][1] == "reliable_stream"


def test_header_stamp_is_read_in_either_byte_order() -> None:
    assert header_stamp_ns(stamped(12 * S + 345)) == 12 * S + 345
    assert header_stamp_ns(stamped(7 * S + 9, big_endian=True)) == 7 * S + 9
    assert header_stamp_ns(b"\x00\x01\x00\x00\x01") is None
    assert header_stamp_ns(b"\x00\x03\x00\x00" + bytes(8)) is None  # not plain CDR


def test_stamps_come_from_headers_and_clock(fake: tuple[FakeWriter, SessionRecorder]) -> None:
    writer, rec = fake
    assert rec.record("/clock", stamped(5 * S)) == 5 * S
    assert rec.sim_time == 5.0
    assert rec.record("/rig/speeds", stamped(5 * S + 300_000, b"speeds")) == 5 * S + 300_000
    # no header: the last /clock (moved 1 ns past the speeds written before it)
    assert rec.record("/rig/axial_load/setpoint", float64(100.0)) == 5 * S + 300_001
    rec.record("/clock", stamped(6 * S))
    assert rec.record("/rig/axial_load/setpoint", float64(100.0)) == 6 * S + 1
    assert rec.record("/diagnostics", stamped(0, b"diag")) == 6 * S + 2  # zero stamp: the clock
    wall = 1_750_000_000 * S  # a wall-clock stamp: not sim time
    assert rec.record("/diagnostics", stamped(wall, b"diag")) == 6 * S + 3
    assert rec.record("/rig/truth", stamped(6 * S + 5_000_000, b"truth")) == 6 * S + 5_000_000
    times = [t for _, t, _ in writer.written]
    assert all(b > a for a, b in zip(times, times[1:]))


def test_batch_is_ordered_by_sim_time_and_kept_strictly_increasing(fake: tuple[FakeWriter, SessionRecorder]) -> None:
    writer, rec = fake
    rec.record("/clock", stamped(1 * S))
    batch = [
        ("/clock", stamped(1 * S + 1_000_000)),
        ("/rig/speeds", stamped(1 * S + 1_000_000, b"a")),
        ("/rig/cage/pulses", stamped(1 * S + 400_000, b"p")),  # interpolated inside the step, arrives late
        ("/clock", stamped(1 * S + 2_000_000)),
        ("/rig/speeds", stamped(1 * S + 2_000_000, b"b")),
        ("/rig/axial_load/setpoint", float64(50.0)),  # arrived after the second clock
    ]
    times = rec.record_batch(batch)
    topics = [name for name, _, _ in writer.written[1:]]
    assert topics == ["/rig/cage/pulses", "/clock", "/rig/speeds", "/clock", "/rig/speeds", "/rig/axial_load/setpoint"]
    assert times == [1 * S + 400_000, 1 * S + 1_000_000, 1 * S + 1_000_001, 1 * S + 2_000_000, 1 * S + 2_000_001, 1 * S + 2_000_002]
    # a pulse older than what was written is moved forward, not written back in time
    assert rec.record("/rig/spindle/pulses", stamped(1 * S + 1_500_000, b"late")) == 1 * S + 2_000_003
    assert rec.moved == 4  # three ties and the late pulse
    assert rec.counts["/clock"] == 3 and rec.counts["/rig/speeds"] == 2


def test_messages_before_the_first_clock_start_at_zero(fake: tuple[FakeWriter, SessionRecorder]) -> None:
    _, rec = fake
    assert rec.record("/rig/axial_load/setpoint", float64(1.0)) == 0
    assert rec.record("/rig/spindle/command", stamped(0, b"cmd")) == 1
    assert rec.record("/clock", stamped(0)) == 2


def test_unknown_topic_is_refused(fake: tuple[FakeWriter, SessionRecorder]) -> None:
    _, rec = fake
    with pytest.raises(KeyError):
        rec.record("/not/recorded", stamped(0))


def test_through_the_bag_writer_and_back(tmp_path: Path) -> None:
    bag = tmp_path / "bag"
    with BagWriter(bag) as writer:
        rec = SessionRecorder(writer)
        for k in range(50):
            rec.record_batch([("/clock", stamped(S + k * 1_000_000)), ("/rig/axial_load/setpoint", float64(float(k)))])
    with open_bag(bag) as reader:
        got = [(m.topic, m.log_time_ns) for m in reader.messages(["/clock", "/rig/axial_load/setpoint"])]
        assert reader.topics["/clock"].message_count == 50
    assert len(got) == 100
    times = [t for _, t in got]
    assert all(b > a for a, b in zip(times, times[1:]))
    assert got[0] == ("/clock", S) and got[1] == ("/rig/axial_load/setpoint", S + 1)


def test_hostile_clock_stamps_stay_off_the_timeline(fake: tuple[FakeWriter, SessionRecorder]) -> None:
    """A /clock stamped at 2^31 - 1 s (2038) and one before 1970, among a 1 kHz clock: both are recorded
    (the bag holds what was on the wire) at the last good clock's time; the timeline goes on."""
    writer, rec = fake
    ms = 1_000_000
    for k in range(5):
        rec.record("/clock", stamped(k * ms))
    assert rec.record("/clock", stamped((2**31 - 1) * S)) == 4 * ms + 1  # the largest int32 seconds
    assert rec.record("/rig/speeds", stamped(5 * ms, b"s")) == 5 * ms  # the header's own stamp
    assert rec.record("/clock", stamped(-3 * S)) == 5 * ms + 1
    assert rec.record("/clock", stamped(6 * ms)) == 6 * ms
    assert rec.sim_time == pytest.approx(0.006)
    assert rec.rule.clock_guard.refused == 2
    assert len(rec.rule.clock_notes) == 2 and "negative" in rec.rule.clock_notes[1]
    times = [t for _, t, _ in writer.written]
    assert max(times) == 6 * ms and all(b > a for a, b in zip(times, times[1:]))
    assert rec.counts["/clock"] == 8  # every message kept


@pytest.mark.parametrize("topic", ["/rig/spindle/command", "/rig/load/setpoint"])
def test_a_command_or_set_point_stamped_ahead_is_logged_when_received(fake: tuple[FakeWriter, SessionRecorder], topic: str) -> None:
    """The session sends a dwell segment's successor's command and load set-point ahead, stamped
    with its start: logged at that stamp, it would drag every message received before it up to it
    (strictly increasing); it is logged at the last /clock, its header keeps the stamp."""
    writer, rec = fake
    rec.record("/clock", stamped(10 * S))
    ahead = stamped(13 * S, b"command")
    assert rec.record(topic, ahead) == 10 * S + 1  # the /clock's time, 1 ns on
    assert writer.written[-1][2] == ahead and header_stamp_ns(ahead) == 13 * S
    assert rec.record("/rig/speeds", stamped(10 * S + 1_000_000, b"speeds")) == 10 * S + 1_000_000  # not moved
