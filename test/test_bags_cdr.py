"""The CDR module: the length walk agrees with rosbags' serializer on every type of the store,
padding after a message is ignored, a cut message is refused, and the hand-tuned decoders give
what rosbags' general decoder gives (and hand over to it whatever they should not read)."""

from __future__ import annotations

import contextlib
import struct
from typing import Any

import numpy as np
import pytest

from bearing_rig_sim.bags import BagError, rig_typestore
from bearing_rig_sim.bags.cdr import (
    PULSE_TYPE,
    JointVelocities,
    TruthSpeeds,
    decode_joint_velocities,
    decode_pulse,
    decode_pulses,
    decode_status_fields,
    decode_truth_speeds,
    has_sequences,
    header_stamp_ns,
    length_function,
    make_decoder,
    make_field_decoder,
    make_normaliser,
)
from bearing_rig_sim.synthetic.traffic import message_fields, sample_message

STORE = rig_typestore()
WALKABLE = sorted(name for name in STORE.fielddefs if "wstring" not in str(STORE.fielddefs[name]))


@pytest.mark.parametrize("little_endian", [True, False], ids=["le", "be"])
def test_length_walk_agrees_with_rosbags_serializer_on_every_type(little_endian: bool) -> None:
    """The serializer writes exactly the message: its length is the walk's independent check."""
    for msgtype in WALKABLE:
        for seed in range(3):
            message = sample_message(msgtype, seed, STORE)
            data = bytes(STORE.serialize_cdr(message, msgtype, little_endian=little_endian))
            length = length_function(STORE, msgtype)
            assert length is not None and length(data + bytes(12)) == len(data), msgtype
            decoded = make_decoder(STORE, msgtype)(data + b"\xaa" * 12)
            assert message_fields(decoded, msgtype, STORE) == message_fields(message, msgtype, STORE), msgtype


def test_normaliser_trims_padding_of_types_with_sequences_only() -> None:
    empty = np.array([], dtype=np.float64)
    joint = STORE.types["sensor_msgs/msg/JointState"](
        header=sample_message("std_msgs/msg/Header", 0, STORE), name=["inner_ring"], position=empty, velocity=empty, effort=empty
    )
    exact = bytes(STORE.serialize_cdr(joint, "sensor_msgs/msg/JointState"))
    normalise = make_normaliser(STORE, "sensor_msgs/msg/JointState")
    assert normalise is not None and bytes(normalise(exact + bytes(8))) == exact
    assert has_sequences(STORE, "sensor_msgs/msg/JointState") and not has_sequences(STORE, "std_msgs/msg/Float64")
    float64 = b"\x00\x01\x00\x00" + bytes(8)
    assert make_normaliser(STORE, "std_msgs/msg/Float64")(float64) is float64
    with pytest.raises(BagError, match="not a CDR message"):
        make_normaliser(STORE, "std_msgs/msg/Float64")(b"\x00\x07" + float64[2:])
    with pytest.raises(BagError, match="do not hold a complete message"):
        normalise(exact[:-4])
    with pytest.raises(BagError, match="not a CDR message"):
        normalise(b"\x00\x03\x00\x00" + exact[4:])


def test_a_cut_message_is_refused_not_decoded_short() -> None:
    """rosbags alone would decode a message cut inside its last string with a shorter string."""
    message = sample_message(PULSE_TYPE, 1, STORE)
    data = bytes(STORE.serialize_cdr(message, PULSE_TYPE))
    decode = make_decoder(STORE, PULSE_TYPE)
    for cut in (1, 5, 17):
        with pytest.raises(BagError):
            decode(data[:-cut])


def test_pulse_decoder_agrees_with_rosbags() -> None:
    for seed in range(20):
        message = sample_message(PULSE_TYPE, seed, STORE)
        fields = decode_pulse(bytes(STORE.serialize_cdr(message, PULSE_TYPE)))
        stamp = message.header.stamp
        assert fields == (stamp.sec + stamp.nanosec * 1e-9, message.strip_id, message.strip_count, message.revolution, message.pulse_index, message.sensor_id)


def test_pulse_arrays_agree_with_rosbags_and_refuse_what_the_single_decoder_refuses() -> None:
    """:func:`decode_pulses` over one buffer of messages of varied string lengths (so varied
    alignments), each checked against rosbags' decoder; the messages the one-by-one decoder
    refuses (cut, big-endian, bad UTF-8) are marked invalid, and their neighbours still decode."""
    good = [bytes(STORE.serialize_cdr(sample_message(PULSE_TYPE, seed, STORE), PULSE_TYPE)) for seed in range(20)]
    big = bytes(STORE.serialize_cdr(sample_message(PULSE_TYPE, 3, STORE), PULSE_TYPE, little_endian=False))
    bad_text = bytearray(good[4])
    bad_text[4 + ((12 + struct.unpack_from("<I", good[4], 12)[0] + 3) & ~3) + 4] = 0xFF  # first byte of sensor_id
    messages = [*good[:10], good[10][:-3], big, bytes(bad_text), b"\x00\x01", *good[10:]]
    refused = set()
    for k, data in enumerate(messages):
        with contextlib.suppress(BagError):
            decode_pulse(data)
            continue
        refused.add(k)
    assert refused == {10, 11, 12, 13}
    ends = np.cumsum([len(m) for m in messages])
    arrays = decode_pulses(b"".join(messages), ends - [len(m) for m in messages], ends)
    assert set(np.flatnonzero(~arrays.valid).tolist()) == refused
    columns = (arrays.time, arrays.strip_id, arrays.strip_count, arrays.revolution, arrays.pulse_index)
    for k, data in enumerate(messages):
        if k in refused:
            continue
        message = STORE.deserialize_cdr(data, PULSE_TYPE)
        stamp = message.header.stamp
        expected = (stamp.sec + stamp.nanosec * 1e-9, message.strip_id, message.strip_count, message.revolution, message.pulse_index, message.sensor_id)
        got = (*(c.tolist()[k] for c in columns), arrays.sensor_id[k])
        assert got == expected, k


def test_header_stamp_is_read_in_both_byte_orders() -> None:
    assert header_stamp_ns(b"\x00\x01\x00\x00" + struct.pack("<iI", 12, 345)) == 12_000_000_345
    assert header_stamp_ns(b"\x00\x00\x00\x00" + struct.pack(">iI", 7, 9)) == 7_000_000_009
    assert header_stamp_ns(b"\x00\x01\x00\x00\x01") is None


JOINT_STATE, TRUTH, STATUS = "sensor_msgs/msg/JointState", "bearing_rig_msgs/msg/SimulatorTruth", "bearing_rig_msgs/msg/SlipStatus"


def _joint_state(seed: int, names: list[str], velocity: list[float], position: list[float]) -> object:
    header = sample_message("std_msgs/msg/Header", seed, STORE)
    return STORE.types[JOINT_STATE](header=header, name=names, position=np.array(position), velocity=np.array(velocity), effort=np.array([], dtype=np.float64))


@pytest.mark.parametrize("seed", range(12))
def test_field_decoders_read_what_rosbags_reads(seed: int) -> None:
    """Names and velocities of JointState (frame ids, names and empty or full sequences that move
    the alignment), the speeds of SimulatorTruth and the fields of SlipStatus the analysis reads,
    against rosbags' decoder of the same bytes: the same values to the bit, so the rows built on
    them do not change."""
    names = ["inner_ring", "cage", "x" * seed][: 1 + seed % 3]
    joint = _joint_state(seed, names, [seed * 1.1 + k / 3.0 for k in range(len(names))], [1.0 / 7.0] * (seed % 2) * len(names))
    data = bytes(STORE.serialize_cdr(joint, JOINT_STATE))
    expected = STORE.deserialize_cdr(data, JOINT_STATE)
    assert decode_joint_velocities(data) == JointVelocities(list(expected.name), tuple(expected.velocity.tolist()))
    truth = sample_message(TRUTH, seed, STORE)
    raw = bytes(STORE.serialize_cdr(truth, TRUTH))
    read = STORE.deserialize_cdr(raw, TRUTH)
    assert decode_truth_speeds(raw) == TruthSpeeds(read.inner_ring_speed, read.cage_speed, read.slip_rate, read.axial_load)
    assert make_field_decoder(STORE, TRUTH, decode_truth_speeds)(raw + bytes(8)) == decode_truth_speeds(raw)  # Fast-CDR padding
    status = sample_message(STATUS, seed, STORE)  # strings of random lengths: every alignment
    raw = bytes(STORE.serialize_cdr(status, STATUS))
    read = STORE.deserialize_cdr(raw, STATUS)
    got = decode_status_fields(raw)
    assert (got.header.stamp.sec, got.header.stamp.nanosec) == (read.header.stamp.sec, read.header.stamp.nanosec)
    assert got[1:] == (read.inner_ring_speed, read.cage_speed, read.slip_rate, read.state, read.confidence, read.sweep_speed, read.sweep_verdict)


def test_field_decoder_hands_other_bytes_to_the_general_decoder() -> None:
    """Big-endian bytes decode through rosbags; a cut message is refused as :func:`make_decoder`
    refuses it, not read short by hand."""
    decode = make_field_decoder(STORE, JOINT_STATE, decode_joint_velocities)
    joint = _joint_state(1, ["inner_ring", "cage"], [10.0, 4.0], [])
    big = bytes(STORE.serialize_cdr(joint, JOINT_STATE, little_endian=False))
    general: Any = decode(big)  # rosbags' message
    assert list(general.velocity) == [10.0, 4.0]
    little = bytes(STORE.serialize_cdr(joint, JOINT_STATE))
    assert decode(little) == JointVelocities(["inner_ring", "cage"], (10.0, 4.0))
    for cut in (1, 8, 20):
        with pytest.raises(BagError):
            decode(little[:-cut])


@pytest.mark.parametrize("msgtype, fields", [(TRUTH, decode_truth_speeds), (STATUS, decode_status_fields), (JOINT_STATE, decode_joint_velocities)])
def test_field_decoders_refuse_every_cut_of_a_message(msgtype: str, fields: Any) -> None:
    """A decoder by hand reads a message to its end: cut anywhere (the last field included), the
    message is refused as rosbags refuses it, and padding after it is ignored."""
    message = _joint_state(3, ["inner_ring", "cage"], [10.0, 4.0], [0.5, 0.25]) if msgtype == JOINT_STATE else sample_message(msgtype, 5, STORE)
    raw = bytes(STORE.serialize_cdr(message, msgtype))
    decode = make_field_decoder(STORE, msgtype, fields)
    assert decode(raw + bytes(8)) == decode(raw) == fields(raw)
    for end in range(4, len(raw)):
        cut = raw[:end]
        with pytest.raises(BagError):
            decode(cut)
        with pytest.raises((struct.error, UnicodeDecodeError)):
            fields(cut)


def test_field_decoder_leaves_another_layout_of_the_type_to_rosbags() -> None:
    """A bag whose SlipStatus has other fields (an older recording) is not read by hand at the
    rig's offsets: its messages decode as that definition says."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    older = get_typestore(Stores.ROS2_JAZZY)
    older.register(get_types_from_msg("std_msgs/Header header\nuint8 state\nfloat64 slip_rate\n", STATUS))
    message = older.types[STATUS](header=sample_message("std_msgs/msg/Header", 2, STORE), state=2, slip_rate=1.5)
    decoded: Any = make_field_decoder(older, STATUS, decode_status_fields)(bytes(older.serialize_cdr(message, STATUS)))
    assert (decoded.state, decoded.slip_rate) == (2, 1.5) and not isinstance(decoded, tuple)
