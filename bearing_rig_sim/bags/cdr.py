"""CDR bytes as stored in bags, the project's one CDR module: Fast-CDR pads a message with an empty
sequence of 8-byte elements by 4 to 12 bytes and rosbags' ``deserialize_cdr`` refuses more than 3,
so :func:`length_function` walks a message's fields to its real length, for the recorder
(:func:`make_normaliser`) and the reader (:func:`make_decoder`); :func:`decode_pulse` and
:func:`header_stamp_ns` read fields by hand, building no object."""

from __future__ import annotations

import struct
from collections.abc import Callable
from typing import Any, NamedTuple, cast

import numpy as np
import numpy.typing as npt

from rosbags.interfaces import Nodetype
from rosbags.serde import SerdeError
from rosbags.typesys.store import Typestore

from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.typestore import dependencies, rig_typestore
from bearing_rig_sim.interfaces import CAGE_PULSES

PULSE_TYPE = CAGE_PULSES.msgtype

CdrBytes = bytes | memoryview
"""Serialized message: 4-byte encapsulation header, then the CDR body."""

LITTLE_ENDIAN = b"\x00\x01"
BIG_ENDIAN = b"\x00\x00"

_MALFORMED = (SerdeError, struct.error, IndexError, ValueError, UnicodeDecodeError)

_SIZES = {"bool": 1, "byte": 1, "char": 1, "int8": 1, "uint8": 1, "int16": 2, "uint16": 2, "int32": 4,
          "uint32": 4, "int64": 8, "uint64": 8, "float32": 4, "float64": 8}  # fmt: skip

_U32 = {True: struct.Struct("<I").unpack_from, False: struct.Struct(">I").unpack_from}
Walk = Callable[[memoryview, int, Callable[..., tuple[int, ...]]], int]
"""``walk(body, position, read_u32) -> position after the item``."""


def has_sequences(typestore: Typestore, msgtype: str) -> bool:
    """True when the type, or a type nested in it, has a variable-length sequence field."""
    return any(desc[0] == Nodetype.SEQUENCE for name in dependencies(typestore, [msgtype]) for _field, desc in typestore.fielddefs[name][1])


def _string(body: memoryview, position: int, u32: Callable[..., tuple[int, ...]]) -> int:
    position = (position + 3) & ~3
    return position + 4 + u32(body, position)[0]


def _repeat(item: Walk | int, count: int | None) -> Walk:
    """``count`` items, or a sequence (uint32 count first) when None; an int item is a primitive of that size."""

    def walk(body: memoryview, position: int, u32: Callable[..., tuple[int, ...]]) -> int:
        n = count
        if n is None:
            position = ((position + 3) & ~3) + 4
            n = u32(body, position - 4)[0]
        if isinstance(item, int):
            return ((position + item - 1) & -item) + item * n if n else position
        for _ in range(n):
            position = item(body, position, u32)
        return position

    return walk


def _primitives(sizes: list[int]) -> Walk:
    """Consecutive primitive fields of these sizes, each aligned to its size (one step, not one
    per field: a message of many numbers is walked at a fraction of the cost)."""
    run = tuple(sizes)

    def walk(_body: memoryview, position: int, _u32: Callable[..., tuple[int, ...]]) -> int:
        for size in run:
            position = ((position + size - 1) & -size) + size
        return position

    return walk


def _walker(typestore: Typestore, kind: Nodetype, arg: Any) -> Walk:
    """The walk over one field (raises KeyError for a type it cannot walk: ``wstring``)."""
    if kind == Nodetype.BASE:
        return _string if arg[0] == "string" else _repeat(_SIZES[arg[0]], 1)
    if kind == Nodetype.NAME:
        steps: list[Walk] = []
        sizes: list[int] = []  # a run of single primitive fields, walked in one step
        for _name, desc in typestore.fielddefs[arg][1]:
            field_kind, field_arg = cast("tuple[Nodetype, Any]", desc)
            if field_kind == Nodetype.BASE and field_arg[0] != "string":
                sizes.append(_SIZES[field_arg[0]])
                continue
            if sizes:
                steps.append(_primitives(sizes))
                sizes = []
            steps.append(_walker(typestore, field_kind, field_arg))
        if sizes:
            steps.append(_primitives(sizes))

        def walk(body: memoryview, position: int, u32: Callable[..., tuple[int, ...]]) -> int:
            for step in steps:
                position = step(body, position, u32)
            return position

        return walk
    (subkind, subarg), length = arg
    count = length if kind == Nodetype.ARRAY else None
    item = _SIZES[subarg[0]] if subkind == Nodetype.BASE and subarg[0] != "string" else _walker(typestore, subkind, subarg)
    return _repeat(item, count)


def little_endian(msgtype: str, data: CdrBytes | bytearray) -> bool:
    """True for little-endian CDR, False for big-endian; BagError for another encapsulation."""
    header = bytes(data[:2])
    if len(data) < 4 or header not in (LITTLE_ENDIAN, BIG_ENDIAN):
        raise BagError(f"{msgtype}: {len(data)} bytes are not a CDR message (bad encapsulation header {bytes(data[:4]).hex()})")
    return header == LITTLE_ENDIAN


def length_function(typestore: Typestore, msgtype: str) -> Callable[[CdrBytes], int] | None:
    """A function giving the bytes a message of ``msgtype`` occupies, header included (BagError
    for bytes that end before the message does); None for a type with ``wstring`` fields."""
    try:
        walk = _walker(typestore, Nodetype.NAME, msgtype)
    except KeyError:
        return None

    def length(data: CdrBytes) -> int:
        try:
            end = 4 + walk(memoryview(data)[4:], 0, _U32[little_endian(msgtype, data)])
        except _MALFORMED as exc:
            raise BagError(f"{msgtype}: {len(data)} bytes do not hold a complete message ({exc})") from None
        if end > len(data):
            raise BagError(f"{msgtype}: {len(data)} bytes do not hold a complete message ({end} needed)")
        return end

    return length


def make_normaliser(typestore: Typestore, msgtype: str) -> Callable[[CdrBytes], CdrBytes]:
    """A function returning messages of ``msgtype`` as the recorder stores them: padding trimmed
    for a type with sequences, else as received (the Fast-CDR size is exact) once the header is
    checked; BagError for bytes that are not a complete message."""
    length = length_function(typestore, msgtype) if has_sequences(typestore, msgtype) else None

    def normalise(data: CdrBytes) -> CdrBytes:
        if length is None:
            little_endian(msgtype, data)
            return data
        end = length(data)
        return data[:end] if end < len(data) else data

    return normalise


def make_decoder(typestore: Typestore, msgtype: str) -> Callable[[CdrBytes], object]:
    """A function decoding messages of ``msgtype`` with rosbags' ``deserialize_cdr``, ignoring
    bytes after the message (padding: the bytes are trimmed to the message's length when they do
    not decode as they are); BagError for a malformed or cut message."""
    length = length_function(typestore, msgtype)
    deserialize = typestore.deserialize_cdr

    def decode(data: CdrBytes) -> object:
        try:  # as the recorder stores them: the exact bytes (a walk to the end costs as much again)
            return deserialize(data, msgtype)
        except _MALFORMED:
            pass  # padded by Fast-CDR, or malformed: trimmed to the message's own length, or refused
        end = length(data) if length is not None else len(data)
        try:
            return deserialize(data[:end] if end < len(data) else data, msgtype)
        except _MALFORMED as exc:
            raise BagError(f"{msgtype}: malformed message of {len(data)} bytes ({exc})") from None

    return decode


PulseFields = tuple[float, int, int, int, int, str]
"""``header.stamp`` (s), ``strip_id``, ``strip_count``, ``revolution``, ``pulse_index``, ``sensor_id``."""

_PULSE_HEAD = struct.Struct("<iII")  # stamp.sec, stamp.nanosec, frame_id length
_STRIPS = struct.Struct("<HH")
_COUNTS = struct.Struct("<QQ")


def decode_pulse(data: CdrBytes) -> PulseFields:
    """The fields of a little-endian CDR ``FibreOpticPulse`` the slip monitor uses (offline analysis
    reads hundreds of thousands); BagError for other bytes."""
    if not little_endian(PULSE_TYPE, data):
        raise BagError(f"{PULSE_TYPE}: not little-endian CDR (encapsulation {bytes(data[:4]).hex()})")
    try:
        sec, nanosec, length = _PULSE_HEAD.unpack_from(data, 4)
        pos = (12 + length + 3) & ~3  # body offsets; the body starts at byte 4
        (length,) = _U32[True](data, 4 + pos)
        sensor = bytes(data[8 + pos : 8 + pos + max(length - 1, 0)]).decode("utf-8")
        pos = (pos + 4 + length + 1) & ~1
        strip_id, strip_count = _STRIPS.unpack_from(data, 4 + pos)
        pos = (pos + 4 + 7) & ~7
        revolution, pulse_index = _COUNTS.unpack_from(data, 4 + pos)
    except (struct.error, UnicodeDecodeError) as exc:
        raise BagError(f"{PULSE_TYPE}: malformed message of {len(data)} bytes ({exc})") from None
    return sec + nanosec * 1e-9, strip_id, strip_count, revolution, pulse_index, sensor


def header_stamp_ns(data: CdrBytes | bytearray) -> int | None:
    """The leading ``builtin_interfaces/Time`` of a CDR message (ns); None when too short or not CDR."""
    if len(data) < 12:
        return None
    try:
        little = little_endian("header", data)
    except BagError:
        return None
    sec, nanosec = struct.unpack_from("<iI" if little else ">iI", data, 4)
    return int(sec) * 1_000_000_000 + int(nanosec)


class PulseArrays(NamedTuple):
    """The fields of many ``FibreOpticPulse`` messages (:func:`decode_pulses`), one entry per
    message: ``valid`` False where the bytes are not a complete little-endian message (its other
    entries then meaningless: decode it alone, :func:`decode_pulse`, for the reason)."""

    valid: npt.NDArray[np.bool_]
    time: npt.NDArray[np.float64]
    strip_id: npt.NDArray[np.int64]
    strip_count: npt.NDArray[np.int64]
    revolution: npt.NDArray[np.uint64]
    pulse_index: npt.NDArray[np.uint64]
    sensor_id: list[str]


def _read(raw: npt.NDArray[np.uint8], at: npt.NDArray[np.int64], dtype: str) -> npt.NDArray[Any]:
    """The value of ``dtype`` at each byte offset ``at`` of ``raw`` (offsets within ``raw``)."""
    size = np.dtype(dtype).itemsize
    values: npt.NDArray[Any] = raw[at[:, None] + np.arange(size)].view(dtype).ravel()
    return values


def decode_pulses(data: bytes, starts: npt.NDArray[np.int64], ends: npt.NDArray[np.int64]) -> PulseArrays:
    """:func:`decode_pulse` of the messages ``data[starts[k]:ends[k]]`` at once, as arrays (numpy
    over the byte offsets; the variable-length strings located per message from their lengths),
    with the same values bit for bit; an hour of the rig's traffic has 600,000 pulses."""
    raw = np.frombuffer(data, dtype=np.uint8)
    n = len(starts)
    size = ends - starts
    last = max(len(raw) - 1, 0)

    def read(at: npt.NDArray[np.int64], dtype: str, valid: npt.NDArray[np.bool_]) -> npt.NDArray[Any]:
        return _read(raw, np.where(valid, np.minimum(starts + at, last - np.dtype(dtype).itemsize + 1), 0), dtype)

    valid = size >= 16  # encapsulation, stamp, frame_id length
    valid &= read(np.zeros(n, np.int64), "<u2", valid) == 0x0100  # bytes 00 01: little-endian CDR
    sec = read(np.full(n, 4, np.int64), "<i4", valid)
    nanosec = read(np.full(n, 8, np.int64), "<u4", valid)
    pos = (12 + read(np.full(n, 12, np.int64), "<u4", valid).astype(np.int64) + 3) & ~3  # body offsets, as decode_pulse
    valid &= 4 + pos + 4 <= size
    length = read(4 + pos, "<u4", valid).astype(np.int64)
    sensor_start = starts + 8 + pos
    sensor_stop = sensor_start + np.maximum(length - 1, 0)
    pos = (pos + 4 + length + 1) & ~1
    strips = 4 + pos
    pos = (pos + 4 + 7) & ~7
    valid &= 4 + pos + 16 <= size
    strip_id = read(strips, "<u2", valid).astype(np.int64)
    strip_count = read(strips + 2, "<u2", valid).astype(np.int64)
    revolution = read(4 + pos, "<u8", valid)
    pulse_index = read(12 + pos, "<u8", valid)
    names: dict[bytes, str] = {}
    sensors = []
    for k, (a, b) in enumerate(zip(sensor_start.tolist(), sensor_stop.tolist())):
        text = data[a:b] if valid[k] else b""
        name = names.get(text)
        if name is None:
            try:
                name = names[text] = text.decode("utf-8")
            except UnicodeDecodeError:
                valid[k], name = False, ""
        sensors.append(name)
    return PulseArrays(valid, sec + nanosec * 1e-9, strip_id, strip_count, revolution, pulse_index, sensors)


class JointVelocities(NamedTuple):
    """The fields of a ``sensor_msgs/JointState`` the offline status rows read (rad/s by joint)."""

    name: list[str]
    velocity: tuple[float, ...]


class TruthSpeeds(NamedTuple):
    """The fields of a ``SimulatorTruth`` the offline status rows read (rad/s, percent, N)."""

    inner_ring_speed: float
    cage_speed: float
    slip_rate: float
    axial_load: float


def _text(data: CdrBytes, at: int) -> tuple[str, int]:
    """The CDR string whose length is at byte ``at`` of ``data`` (body offsets from byte 4, aligned
    to 4 already), and the body offset after it."""
    (length,) = _U32[True](data, 4 + at)
    return bytes(data[8 + at : 8 + at + max(length - 1, 0)]).decode("utf-8"), at + 4 + length


def _doubles(data: CdrBytes, at: int) -> tuple[tuple[float, ...], int]:
    """The float64 sequence at body offset ``at`` and the body offset after it (an empty one is
    not aligned to 8, as :func:`length_function` walks it)."""
    at = (at + 3) & ~3
    (count,) = _U32[True](data, 4 + at)
    at += 4
    if not count:
        return (), at
    at = (at + 7) & ~7
    return struct.unpack_from(f"<{count}d", data, 4 + at), at + 8 * count


def _past_doubles(data: CdrBytes, at: int) -> int:
    """The body offset after the float64 sequence at body offset ``at`` (aligned as
    :func:`_doubles` reads it), not reading its values."""
    at = (at + 3) & ~3
    (count,) = _U32[True](data, 4 + at)
    at += 4
    return ((at + 7) & ~7) + 8 * count if count else at


def _whole(data: CdrBytes, end: int) -> None:
    """Raise struct.error unless the message, ending at body offset ``end``, lies within ``data``
    (a decoder by hand reads its fields at offsets that only grow: within the bytes if its end is)."""
    if 4 + end > len(data):
        raise struct.error(f"{len(data)} bytes end before the message does ({4 + end} needed)")


def decode_joint_velocities(data: CdrBytes) -> JointVelocities:
    """Names and velocities of a little-endian CDR ``sensor_msgs/JointState`` read by hand (the
    values rosbags' decoder gives, bit for bit, at a tenth of its cost); struct.error or
    UnicodeDecodeError for bytes that end before the message does or a name that is not UTF-8."""
    _frame, at = _text(data, 8)
    at = (at + 3) & ~3
    (count,) = _U32[True](data, 4 + at)
    at += 4
    names = []
    for _ in range(count):
        name, at = _text(data, (at + 3) & ~3)
        names.append(name)
    _position, at = _doubles(data, at)
    velocity, at = _doubles(data, at)
    _whole(data, _past_doubles(data, at))  # effort
    return JointVelocities(names, velocity)


_TRUTH_HEAD = struct.Struct("<6d")  # inner_ring_speed .. axial_load
_TRUTH_NUMBERS = 15 * 8 + 8 + 4 + 4 + 3 * 8
"""Bytes from ``inner_ring_speed`` (aligned to 8) to the end of ``cage_whirl_radius_um``: 15 float64,
a uint64, a uint32 (with 4 bytes of padding to the next float64), 3 float64."""
_TRUTH_SEQUENCES = 8  # ball_azimuth .. ball_pocket_load, float64[] each
_TRUTH_TAIL = 2 * 8  # cage_centre_x, cage_centre_y


def decode_truth_speeds(data: CdrBytes) -> TruthSpeeds:
    """Speeds, slip and load of a little-endian CDR ``SimulatorTruth`` read by hand (the fields
    right after its header); struct.error or UnicodeDecodeError for bytes that end before the
    message does or a frame id that is not UTF-8."""
    _frame, at = _text(data, 8)
    at = (at + 7) & ~7
    inner, _acceleration, cage, _theoretical, slip, axial = _TRUTH_HEAD.unpack_from(data, 4 + at)
    at += _TRUTH_NUMBERS
    for _ in range(_TRUTH_SEQUENCES):
        at = _past_doubles(data, at)
    _whole(data, ((at + 7) & ~7) + _TRUTH_TAIL)
    return TruthSpeeds(inner, cage, slip, axial)


class Stamp(NamedTuple):
    """A ``builtin_interfaces/Time``."""

    sec: int
    nanosec: int


class StampHeader(NamedTuple):
    """The stamp of a ``std_msgs/Header``."""

    stamp: Stamp


class StatusFields(NamedTuple):
    """The fields of a ``SlipStatus`` the offline analysis reads (rad/s, percent, 1)."""

    header: StampHeader
    inner_ring_speed: float
    cage_speed: float
    slip_rate: float
    state: int
    confidence: float
    sweep_speed: float
    sweep_verdict: str


_STATUS_SPEEDS = struct.Struct("<6dB")  # inner_ring_speed .. critical_slope, state
_STATUS_SWEEP = struct.Struct("<5d")  # axial_load .. sweep_stable_from


def decode_status_fields(data: CdrBytes) -> StatusFields:
    """Stamp, speeds, slip, state, confidence and load-sweep verdict of a little-endian CDR
    ``SlipStatus`` read by hand (the values rosbags' decoder gives); struct.error or
    UnicodeDecodeError for bytes that end before the message does or text that is not UTF-8."""
    sec, nanosec = _PULSE_HEAD.unpack_from(data, 4)[:2]
    _frame, at = _text(data, 8)
    at = (at + 7) & ~7
    inner, cage, _theoretical, slip, _fitted, _critical, state = _STATUS_SPEEDS.unpack_from(data, 4 + at)
    _criterion, at = _text(data, (at + 49 + 3) & ~3)
    at = (at + 7) & ~7
    confidence, _revolutions = struct.unpack_from("<dI", data, 4 + at)
    _detail, at = _text(data, (at + 12 + 3) & ~3)
    at = (at + 7) & ~7
    sweep_speed = _STATUS_SWEEP.unpack_from(data, 4 + at)[3]
    verdict, at = _text(data, (at + 40 + 3) & ~3)
    _whole(data, at)
    return StatusFields(StampHeader(Stamp(sec, nanosec)), inner, cage, slip, state, confidence, sweep_speed, verdict)


def make_field_decoder(typestore: Typestore, msgtype: str, fields: Callable[[CdrBytes], object]) -> Callable[[CdrBytes], object]:
    """A function giving ``fields(data)`` for a complete little-endian message of ``msgtype`` and
    :func:`make_decoder`'s message for any other bytes (BagError for a malformed or cut one).
    ``fields`` reads the rig's own layout of the type to the message's end and raises
    (struct.error, UnicodeDecodeError) for bytes that end before it, so what :func:`make_decoder`
    refuses is not read by hand (:func:`decode_joint_velocities`, :func:`decode_truth_speeds`,
    :func:`decode_status_fields`): a ``typestore`` (a bag's) that defines the type otherwise,
    such as an older recording's, is decoded by :func:`make_decoder` alone."""
    general = make_decoder(typestore, msgtype)
    rig = rig_typestore()
    same_layout = all(typestore.fielddefs.get(name) == rig.fielddefs.get(name) for name in dependencies(rig, [msgtype]))

    def decode(data: CdrBytes) -> object:
        if same_layout and bytes(data[:2]) == LITTLE_ENDIAN:
            try:
                return fields(data)
            except (BagError, *_MALFORMED):
                pass
        return general(data)

    return decode
