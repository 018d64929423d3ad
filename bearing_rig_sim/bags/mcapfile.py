"""One MCAP storage file, read robustly: its index, its chunks, its messages in time order.

A finished file ends with a summary (schemas, channels, chunk indexes, statistics) and a footer;
the index comes from there. A file whose recording was killed has no summary: it is then scanned
record by record from the start, chunk headers and contents checked, up to the first damaged or
incomplete record; everything before it is readable, and the scan says how many bytes are lost.
The same index serves both cases, so reading and repairing share one code path.

Record layouts follow the MCAP specification (https://mcap.dev/spec); the ``mcap`` package parses
schema, channel and metadata records and the summary section.
"""

from __future__ import annotations

import heapq
import io
import itertools
import struct
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO, Callable, Iterable, Iterator

import lz4.frame
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Metadata, Schema

from bearing_rig_sim.bags.errors import BagError

MAGIC = b"\x89MCAP0\r\n"
"""Magic bytes at both ends of an MCAP file."""

OP_HEADER, OP_FOOTER, OP_SCHEMA, OP_CHANNEL, OP_MESSAGE, OP_CHUNK = 0x01, 0x02, 0x03, 0x04, 0x05, 0x06
OP_METADATA, OP_DATA_END = 0x0C, 0x0F
_FOOTER_LENGTH = 20
_RECORD_HEAD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")
_CHUNK_HEAD = struct.Struct("<QQQI")
_RECORD_LIMIT = 4 * 2**30
_OPCODE_NAMES = {
    0x01: "header", 0x02: "footer", 0x03: "schema", 0x04: "channel", 0x05: "message", 0x06: "chunk",
    0x07: "message index", 0x08: "chunk index", 0x09: "attachment", 0x0A: "attachment index",
    0x0B: "statistics", 0x0C: "metadata", 0x0D: "metadata index", 0x0E: "summary offset", 0x0F: "data end",
}

ProblemSink = Callable[[str], None]
"""Receives a one-line description of each problem met while reading."""


class DamagedRecord(Exception):
    """A chunk or record cannot be used (truncated, bad checksum, undecompressable)."""


@dataclass(frozen=True)
class ChunkRef:
    """Where a group of messages lies in a file.

    Attributes:
        offset: file offset of the chunk record (or of the first loose message record).
        start_ns: earliest log time in the group (ns).
        end_ns: latest log time in the group (ns).
        channel_ids: channels with messages in the group; None when not indexed.
        loose_end: for messages written outside chunks, the offset after the last record of the
            run; None for a chunk.
    """

    offset: int
    start_ns: int
    end_ns: int
    channel_ids: frozenset[int] | None = None
    loose_end: int | None = None


@dataclass
class FileIndex:
    """What one MCAP file holds, from its summary or from a scan.

    Attributes:
        path: the file.
        indexed: True when the file had a valid summary (it was finished properly).
        has_header: False when the file ends before its header record (nothing readable); True
            also for a damaged header when the summary at the end locates the data.
        profile / library: from the header record.
        schemas / channels: by id.
        chunks: message groups, in file order.
        metadata: metadata records by name.
        message_count / channel_counts / start_ns / end_ns: statistics (times in ns).
        readable_bytes: offset after the last record that could be read (file size if intact).
        file_size: size of the file in bytes.
        compression: compression of the first chunk (``zstd``, ``lz4`` or ``""``).
        problems: what was wrong, one line each.
    """

    path: Path
    indexed: bool = False
    has_header: bool = False
    profile: str = ""
    library: str = ""
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    chunks: list[ChunkRef] = field(default_factory=list)
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    message_count: int = 0
    channel_counts: dict[int, int] = field(default_factory=dict)
    start_ns: int = 0
    end_ns: int = 0
    readable_bytes: int = 0
    file_size: int = 0
    compression: str = ""
    problems: list[str] = field(default_factory=list)
    damaged_bytes: int = 0
    """Bytes of the chunks :func:`check_chunks` found damaged."""

    @property
    def bytes_lost(self) -> int:
        """Bytes at the end of the file that belong to no complete record."""
        return max(0, self.file_size - self.readable_bytes)


def _parse(record_type: Any, body: bytes) -> Any:  # mcap's record classes carry no type information
    return record_type.read(ReadDataStream(io.BytesIO(body)))


def _decompress(compression: str, data: bytes, size: int) -> bytes:
    if compression == "zstd":
        return zstandard.decompress(data, max_output_size=size)
    if compression == "lz4":
        return lz4.frame.decompress(data)
    if compression == "":
        return data
    raise DamagedRecord(f"unsupported chunk compression {compression!r}")


def _open_chunk(body: bytes | memoryview) -> tuple[int, int, str, bytes]:
    """Start time, end time, compression and decompressed records of a chunk record body."""
    try:
        start, end, size, crc = _CHUNK_HEAD.unpack_from(body, 0)
        (name_length,) = struct.unpack_from("<I", body, 28)
        compression = bytes(body[32 : 32 + name_length]).decode()
        (data_length,) = struct.unpack_from("<Q", body, 32 + name_length)
    except (struct.error, UnicodeDecodeError) as exc:
        raise DamagedRecord(f"unreadable chunk header ({exc})") from None
    data_start = 40 + name_length
    if data_start + data_length > len(body):
        raise DamagedRecord("chunk data runs past the chunk record")
    try:
        records = _decompress(compression, bytes(body[data_start : data_start + data_length]), size)
    except DamagedRecord:
        raise
    except Exception as exc:  # noqa: BLE001 - zstandard and lz4 raise their own error classes
        raise DamagedRecord(f"chunk does not decompress ({exc})") from None
    if len(records) != size:
        raise DamagedRecord(f"chunk decompresses to {len(records)} bytes, {size} expected")
    if crc and zlib.crc32(records) != crc:
        raise DamagedRecord("chunk checksum mismatch")
    return start, end, compression, records


def _walk_records(buffer: bytes, start: int = 0, end: int | None = None) -> Iterator[tuple[int, int, int]]:
    """(opcode, body offset, body length) of each record in ``buffer[start:end]``."""
    limit = len(buffer) if end is None else end
    position = start
    while position < limit:
        if position + 9 > limit:
            raise DamagedRecord(f"record header cut at offset {position}")
        opcode, length = _RECORD_HEAD.unpack_from(buffer, position)
        body = position + 9
        if body + length > limit:
            raise DamagedRecord(f"{_OPCODE_NAMES.get(opcode, 'unknown')} record cut at offset {position}")
        yield opcode, body, length
        position = body + length


def _messages_in(buffer: bytes, start: int = 0, end: int | None = None) -> list[tuple[int, int, int, bytes]]:
    """(log_time, channel_id, publish_time, data) of every message record in a record run."""
    out = []
    unpack = _MESSAGE_HEAD.unpack_from
    for opcode, body, length in _walk_records(buffer, start, end):
        if opcode == OP_MESSAGE:
            if length < _MESSAGE_HEAD.size:
                raise DamagedRecord(f"message record of {length} bytes")
            channel_id, _sequence, log_time, publish_time = unpack(buffer, body)
            out.append((log_time, channel_id, publish_time, buffer[body + _MESSAGE_HEAD.size : body + length]))
    return out


def read_chunk_messages(stream: BinaryIO, ref: ChunkRef) -> list[tuple[int, int, int, bytes]]:
    """Messages of one chunk (or loose run) as (log_time, channel_id, publish_time, data),
    sorted by log time (stable).

    Raises:
        DamagedRecord: the chunk is truncated, corrupt or does not decompress.
    """
    stream.seek(ref.offset)
    if ref.loose_end is not None:
        buffer = stream.read(ref.loose_end - ref.offset)
        if len(buffer) != ref.loose_end - ref.offset:
            raise DamagedRecord(f"messages at offset {ref.offset} are cut by the end of the file")
        messages = _messages_in(buffer)
    else:
        head = stream.read(9)
        if len(head) != 9:
            raise DamagedRecord(f"chunk at offset {ref.offset} lies past the end of the file")
        opcode, length = _RECORD_HEAD.unpack(head)
        if opcode != OP_CHUNK or length > _RECORD_LIMIT:
            raise DamagedRecord(f"no chunk record at offset {ref.offset}")
        body = stream.read(length)
        if len(body) != length:
            raise DamagedRecord(f"chunk at offset {ref.offset} is cut by the end of the file")
        messages = _messages_in(_open_chunk(body)[3])
    messages.sort(key=lambda m: m[0])
    return messages


def _footer_ok(stream: BinaryIO, size: int) -> bool:
    if size < 2 * len(MAGIC) + 9 + _FOOTER_LENGTH:
        return False
    stream.seek(size - len(MAGIC) - 9 - _FOOTER_LENGTH)
    tail = stream.read(9 + _FOOTER_LENGTH + len(MAGIC))
    opcode, length = _RECORD_HEAD.unpack_from(tail, 0)
    return opcode == OP_FOOTER and length == _FOOTER_LENGTH and tail.endswith(MAGIC)


def _index_from_summary(stream: BinaryIO, index: FileIndex) -> bool:
    """Fill ``index`` from the summary section; False when there is none usable."""
    try:
        stream.seek(0)
        summary = SeekingReader(stream).get_summary()
    except (McapError, struct.error, ValueError, UnicodeDecodeError, EOFError):
        return False
    if summary is None or summary.statistics is None:
        return False
    stats = summary.statistics
    if stats.message_count and (not summary.chunk_indexes or not summary.channels):
        return False  # messages outside chunks, or definitions not repeated: only a scan finds them
    for chunk in summary.chunk_indexes:
        if chunk.chunk_start_offset + chunk.chunk_length > index.file_size:
            return False
    index.schemas = dict(summary.schemas)
    index.channels = dict(summary.channels)
    index.chunks = [
        ChunkRef(
            c.chunk_start_offset,
            c.message_start_time,
            c.message_end_time,
            frozenset(c.message_index_offsets) if c.message_index_offsets else None,
        )
        for c in sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    ]
    index.compression = summary.chunk_indexes[0].compression if summary.chunk_indexes else ""
    index.message_count = stats.message_count
    index.channel_counts = dict(stats.channel_message_counts)
    index.start_ns = stats.message_start_time
    index.end_ns = stats.message_end_time
    for entry in summary.metadata_indexes:
        stream.seek(entry.offset)
        head = stream.read(9)
        if len(head) != 9:
            continue
        opcode, length = _RECORD_HEAD.unpack(head)
        if opcode == OP_METADATA and length <= _RECORD_LIMIT:
            try:
                record = _parse(Metadata, stream.read(length))
            except (McapError, struct.error, UnicodeDecodeError):
                index.problems.append(f"{index.path.name}: metadata record {entry.name!r} is unreadable")
                continue
            index.metadata.setdefault(record.name, {}).update(record.metadata)
    index.readable_bytes = index.file_size
    index.indexed = True
    return True


class _ScanState:
    """Accumulates statistics while a file is scanned."""

    def __init__(self, index: FileIndex) -> None:
        self.index = index
        self.loose: list[tuple[int, int]] = []  # (record offset, log time) of messages outside chunks
        self.loose_channels: set[int] = set()
        self.loose_end = 0

    def add_definitions(self, opcode: int, body: bytes) -> None:
        try:
            if opcode == OP_SCHEMA:
                schema = _parse(Schema, body)
                self.index.schemas[schema.id] = schema
            elif opcode == OP_CHANNEL:
                channel = _parse(Channel, body)
                self.index.channels[channel.id] = channel
        except (McapError, struct.error, UnicodeDecodeError) as exc:
            raise DamagedRecord(f"unreadable {_OPCODE_NAMES[opcode]} record ({exc})") from None

    def count(self, channel_id: int, log_time: int) -> None:
        index = self.index
        if index.message_count == 0:
            index.start_ns = index.end_ns = log_time
        else:
            index.start_ns = min(index.start_ns, log_time)
            index.end_ns = max(index.end_ns, log_time)
        index.message_count += 1
        index.channel_counts[channel_id] = index.channel_counts.get(channel_id, 0) + 1

    def close_loose_run(self) -> None:
        if self.loose:
            times = [t for _, t in self.loose]
            self.index.chunks.append(
                ChunkRef(self.loose[0][0], min(times), max(times), frozenset(self.loose_channels), self.loose_end)
            )
            self.loose, self.loose_channels = [], set()


def _scan(stream: BinaryIO, index: FileIndex) -> None:
    """Fill ``index`` by reading the file record by record, stopping at the first damaged one."""
    state = _ScanState(index)
    position = stream.seek(len(MAGIC))
    name = index.path.name
    while True:
        head = stream.read(9)
        if not head:
            index.problems.append(f"{name}: file ends after {position} bytes without a summary (recording interrupted?)")
            break
        if len(head) < 9:
            index.problems.append(f"{name}: file ends inside a record header at offset {position}")
            break
        opcode, length = _RECORD_HEAD.unpack(head)
        kind = _OPCODE_NAMES.get(opcode, f"unknown (opcode {opcode:#x})")
        if length > _RECORD_LIMIT or position + 9 + length > index.file_size:
            index.problems.append(
                f"{name}: {kind} record at offset {position} is cut by the end of the file "
                f"({index.file_size - position} of {9 + length} bytes present)"
            )
            break
        if opcode in (OP_DATA_END, OP_FOOTER):
            position += 9 + length
            break
        if opcode in (OP_CHUNK, OP_MESSAGE, OP_SCHEMA, OP_CHANNEL, OP_METADATA, OP_HEADER):
            body = stream.read(length)
        else:
            body = b""
            stream.seek(length, io.SEEK_CUR)
        try:
            if opcode == OP_CHUNK:
                state.close_loose_run()
                _start, _end, compression, records = _open_chunk(body)
                channels: set[int] = set()
                times: list[int] = []
                for inner, offset, inner_length in _walk_records(records):
                    if inner in (OP_SCHEMA, OP_CHANNEL):
                        state.add_definitions(inner, records[offset : offset + inner_length])
                    elif inner == OP_MESSAGE:
                        channel_id, _seq, log_time, _pub = _MESSAGE_HEAD.unpack_from(records, offset)
                        channels.add(channel_id)
                        times.append(log_time)
                        state.count(channel_id, log_time)
                if not index.chunks and not index.compression:
                    index.compression = compression
                if times:
                    index.chunks.append(ChunkRef(position, min(times), max(times), frozenset(channels)))
            elif opcode == OP_MESSAGE:
                channel_id, _seq, log_time, _pub = _MESSAGE_HEAD.unpack_from(body, 0)
                state.loose.append((position, log_time))
                state.loose_channels.add(channel_id)
                state.loose_end = position + 9 + length
                state.count(channel_id, log_time)
            elif opcode in (OP_SCHEMA, OP_CHANNEL):
                state.add_definitions(opcode, body)
            elif opcode == OP_METADATA:
                record = _parse(Metadata, body)
                index.metadata.setdefault(record.name, {}).update(record.metadata)
            elif opcode == OP_HEADER:
                pass
            else:
                state.close_loose_run()
        except (DamagedRecord, McapError, struct.error, UnicodeDecodeError) as exc:
            index.problems.append(f"{name}: {kind} record at offset {position} is damaged ({exc}); skipped")
        position += 9 + length
    state.close_loose_run()
    index.readable_bytes = position


def index_file(path: Path) -> FileIndex:
    """Index one MCAP file: from its summary when it has a valid one, else by scanning it.

    Raises:
        BagError: the file cannot be opened or is not MCAP (bad magic, no header).
    """
    index = FileIndex(path=path)
    try:
        stream = open(path, "rb")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise BagError(f"{path}: cannot open ({exc.strerror or exc})") from None
    with stream:
        index.file_size = stream.seek(0, io.SEEK_END)
        stream.seek(0)
        magic = stream.read(len(MAGIC))
        if magic != MAGIC[: len(magic)]:
            raise BagError(f"{path}: not an MCAP file (its first bytes are not the MCAP magic)")
        head = stream.read(9) if len(magic) == len(MAGIC) else b""
        if len(head) == 9 and head[0] != OP_HEADER:
            raise BagError(f"{path}: not an MCAP file (no header record after the magic)")
        length = struct.unpack_from("<Q", head, 1)[0] if len(head) == 9 else 0
        body = stream.read(min(length, 1 << 20)) if len(head) == 9 else b""
        if len(head) < 9 or len(body) < length:
            if len(head) == 9 and _footer_ok(stream, index.file_size) and _index_from_summary(stream, index):
                index.has_header = True  # its data are readable: the header holds only two names
                index.problems.append(  # a damaged length field; the summary still finds every chunk
                    f"{path.name}: the MCAP header record is damaged (it claims {length} bytes of a "
                    f"{index.file_size}-byte file); read through the file's summary"
                )
                return index
            index.problems.append(
                f"{path.name}: file ends after {index.file_size} bytes, before its header is complete "
                "(recording interrupted as it started?): no data"
            )
            return index
        try:
            header = ReadDataStream(io.BytesIO(body))
            index.profile = header.read_prefixed_string()
            index.library = header.read_prefixed_string()
        except (McapError, struct.error, UnicodeDecodeError):
            raise BagError(f"{path}: the MCAP header record is damaged") from None
        index.has_header = True
        index.readable_bytes = stream.tell()
        if _footer_ok(stream, index.file_size) and _index_from_summary(stream, index):
            return index
        _scan(stream, index)
        if not index.problems:
            index.problems.append(
                f"{path.name}: no valid summary (index) at the end of the file; all "
                f"{index.message_count} messages are readable, `bearing-rig bag repair` on its bag restores the index"
            )
    return index


def check_chunks(index: FileIndex) -> list[str]:
    """Decompress and checksum every chunk of an indexed file: one line per damaged chunk. The
    bytes those chunks occupy (to the end of the file for one whose length cannot be read) are
    left in ``index.damaged_bytes``."""
    problems = []
    index.damaged_bytes = 0
    with open(index.path, "rb") as stream:
        for ref in index.chunks:
            try:
                read_chunk_messages(stream, ref)
            except DamagedRecord as exc:
                problems.append(f"{index.path.name}: chunk at offset {ref.offset}: {exc}")
                index.damaged_bytes += _record_size(stream, ref, index.file_size)
    return problems


def _record_size(stream: BinaryIO, ref: ChunkRef, file_size: int) -> int:
    """Bytes of the chunk record (or loose run) at ``ref``, bounded by the end of the file."""
    if ref.loose_end is not None:
        return max(0, min(ref.loose_end, file_size) - ref.offset)
    stream.seek(ref.offset)
    head = stream.read(9)
    if len(head) != 9:
        return max(0, file_size - ref.offset)
    _opcode, length = _RECORD_HEAD.unpack(head)
    return max(0, min(ref.offset + 9 + length, file_size) - ref.offset)


def _lazy_chunk(
    stream: BinaryIO, ref: ChunkRef, order: int, keep: Callable[[int, int], bool], report: ProblemSink, label: str
) -> Iterator[tuple[int, int, int, int, bytes]]:
    """A chunk's wanted messages as (log_time, order, channel, publish, data); the first item is a
    marker at the chunk's start time, so a merge can hold many chunks without reading them."""
    yield (ref.start_ns, order, -1, 0, b"")
    try:
        messages = read_chunk_messages(stream, ref)
    except DamagedRecord as exc:
        report(f"{label}: {exc}; its messages are skipped")
        return
    for log_time, channel_id, publish_time, data in messages:
        if keep(channel_id, log_time):
            yield (log_time, order, channel_id, publish_time, data)


def iter_file_messages(
    index: FileIndex,
    channel_ids: Iterable[int] | None = None,
    start_ns: int | None = None,
    stop_ns: int | None = None,
    report: ProblemSink = lambda _msg: None,
) -> Iterator[tuple[int, int, int, bytes]]:
    """Messages of one file as (log_time, channel_id, publish_time, data), in log-time order.

    Streams chunk by chunk: memory holds the chunks whose time ranges overlap, one for files
    written in time order. Damaged chunks are reported through ``report`` and skipped.

    Args:
        index: the file's index (:func:`index_file`).
        channel_ids: channels to read; None for all.
        start_ns / stop_ns: keep messages with ``start_ns <= log_time < stop_ns``.
        report: receives a line per damaged chunk.
    """
    wanted = None if channel_ids is None else frozenset(channel_ids)
    low = -1 if start_ns is None else start_ns
    high = 2**64 if stop_ns is None else stop_ns

    def keep(channel_id: int, log_time: int) -> bool:
        return (wanted is None or channel_id in wanted) and low <= log_time < high

    refs = [
        r
        for r in index.chunks
        if r.end_ns >= low and r.start_ns < high and (wanted is None or r.channel_ids is None or r.channel_ids & wanted)
    ]
    refs.sort(key=lambda r: (r.start_ns, r.offset))
    try:
        stream = open(index.path, "rb")  # noqa: SIM115 - closed in finally
    except OSError as exc:
        report(f"{index.path}: cannot open ({exc.strerror or exc})")
        return
    try:
        in_order = all(b.start_ns >= a.end_ns for a, b in zip(refs, refs[1:]))
        chunks = [_lazy_chunk(stream, r, i, keep, report, f"{index.path.name}: chunk at offset {r.offset}") for i, r in enumerate(refs)]
        source = itertools.chain.from_iterable(chunks) if in_order else heapq.merge(*chunks)
        for log_time, _order, channel_id, publish_time, data in source:
            if channel_id >= 0:
                yield log_time, channel_id, publish_time, data
    finally:
        stream.close()
