"""CDR bytes as stored in bags: normalising what rclpy hands over, and decoding leniently.

Fast-CDR (the middleware's serializer, behind ``rclpy.serialization.serialize_message`` and raw
subscriptions) sizes its buffer with the worst-case alignment of every empty sequence of 8-byte
elements (``float64[]``, ``int64[]``...), so such a message carries 4 to 12 bytes of padding after
its last field; the padding is uninitialised memory. rosbags' strict decoder refuses a message with
more than 3 bytes after its end ("CDR message size mismatch"); ``mcap_ros2`` accepts it.

The recorder stores every message of a type that contains a sequence trimmed to its encoded
length: the length is found by walking the bytes with rosbags' generated size function (no Python
objects built, a few microseconds), so both decoders accept what the project writes. Types without
sequences have an exact Fast-CDR size and are stored as received.

Bags written by other tools (``ros2 bag record`` on the physical bench) keep the padding: the
project's reader therefore decodes leniently, ignoring bytes after the message.
"""

from __future__ import annotations

import struct
from typing import Any, Callable, cast

from rosbags.interfaces import Nodetype
from rosbags.serde import SerdeError
from rosbags.typesys.store import Typestore

from bearing_rig_sim.bags.errors import BagError

CdrBytes = bytes | memoryview
"""Serialized message: 4-byte encapsulation header, then the CDR body."""

_MALFORMED = (SerdeError, struct.error, IndexError, ValueError, UnicodeDecodeError)
"""What rosbags' generated (de)serializers raise on bytes that are not a message of the type."""

_LITTLE_ENDIAN = b"\x00\x01"
_BIG_ENDIAN = b"\x00\x00"


def has_sequences(typestore: Typestore, msgtype: str, _seen: frozenset[str] = frozenset()) -> bool:
    """True when the type, or a type nested in it, has a variable-length sequence field."""
    if msgtype in _seen:
        return False
    seen = _seen | {msgtype}
    for _name, desc in typestore.fielddefs[msgtype][1]:
        kind, arg = cast("tuple[Nodetype, Any]", desc)
        if kind == Nodetype.SEQUENCE:
            return True
        if kind == Nodetype.NAME and has_sequences(typestore, arg, seen):
            return True
        if kind == Nodetype.ARRAY:
            (subkind, subarg), _count = arg
            if subkind == Nodetype.NAME and has_sequences(typestore, subarg, seen):
                return True
    return False


def _check_header(data: CdrBytes, msgtype: str) -> bool:
    """True for little-endian CDR; raises for anything that is not plain CDR."""
    header = bytes(data[:2])
    if len(data) < 4 or header not in (_LITTLE_ENDIAN, _BIG_ENDIAN):
        raise BagError(f"{msgtype}: {len(data)} bytes are not a CDR message (bad encapsulation header {bytes(data[:4]).hex()})")
    return header == _LITTLE_ENDIAN


def encoded_length(typestore: Typestore, msgtype: str, data: CdrBytes) -> int:
    """Bytes the message really occupies, header included (<= ``len(data)``).

    Raises:
        BagError: the bytes end before the message does, or are not CDR.
    """
    little = _check_header(data, msgtype)
    msgdef = typestore.get_msgdef(msgtype)
    body = memoryview(data)[4:]
    try:
        if little:
            end, _ = msgdef.getsize_cdr_to_ros1(body, 0, None, 0, typestore)
        else:
            _, end = msgdef.deserialize_cdr_be(body, 0, msgdef.cls, typestore)
    except _MALFORMED as exc:
        raise BagError(f"{msgtype}: {len(data)} bytes do not hold a complete message ({exc})") from None
    if 4 + end > len(data):
        raise BagError(f"{msgtype}: {len(data)} bytes do not hold a complete message ({4 + end} needed)")
    return 4 + end


def make_normaliser(typestore: Typestore, msgtype: str) -> Callable[[CdrBytes], CdrBytes] | None:
    """A function trimming trailing padding from serialized messages of ``msgtype``, or None
    when the type's Fast-CDR size is exact (no sequences) and bytes can be stored as received.

    The function raises :class:`BagError` for bytes that are not a complete message."""
    if not has_sequences(typestore, msgtype):
        return None
    walk = typestore.get_msgdef(msgtype).getsize_cdr_to_ros1

    def normalise(data: CdrBytes) -> CdrBytes:
        if data[:2] != _LITTLE_ENDIAN:
            length = encoded_length(typestore, msgtype, data)
        else:
            try:
                length = 4 + walk(memoryview(data)[4:], 0, None, 0, typestore)[0]
            except _MALFORMED as exc:
                raise BagError(f"{msgtype}: {len(data)} bytes do not hold a complete message ({exc})") from None
            if length > len(data):
                raise BagError(f"{msgtype}: {len(data)} bytes do not hold a complete message ({length} needed)")
        return data[:length] if length < len(data) else data

    return normalise


def make_decoder(typestore: Typestore, msgtype: str) -> Callable[[CdrBytes], object]:
    """A function decoding serialized messages of ``msgtype`` into rosbags message objects.

    Bytes after the end of the message (Fast-CDR padding) are ignored. A malformed message raises
    :class:`BagError`.
    """
    msgdef = typestore.get_msgdef(msgtype)
    cls = msgdef.cls
    little_func = msgdef.deserialize_cdr_le
    big_func = msgdef.deserialize_cdr_be

    def decode(data: CdrBytes) -> object:
        header = data[:2]
        if header == _LITTLE_ENDIAN:
            func = little_func
        elif header == _BIG_ENDIAN:
            func = big_func
        else:
            raise BagError(f"{msgtype}: not a CDR message (encapsulation header {bytes(data[:4]).hex()})")
        try:
            message, end = func(memoryview(data)[4:], 0, cls, typestore)
        except _MALFORMED as exc:
            raise BagError(f"{msgtype}: malformed message of {len(data)} bytes ({exc})") from None
        if 4 + end > len(data):
            raise BagError(f"{msgtype}: message of {len(data)} bytes is truncated ({4 + end} needed)")
        return message

    return decode


def header_stamp_ns(data: bytes | bytearray | memoryview) -> int | None:
    """The leading ``builtin_interfaces/Time`` of a CDR message, ns; None when ``data`` is too
    short or its encapsulation is not plain CDR (big or little endian)."""
    if len(data) < 12:
        return None
    kind = bytes(data[:2])
    if kind == b"\x00\x01":
        sec, nanosec = struct.unpack_from("<iI", data, 4)
    elif kind == b"\x00\x00":
        sec, nanosec = struct.unpack_from(">iI", data, 4)
    else:
        return None
    return sec * 1_000_000_000 + nanosec
