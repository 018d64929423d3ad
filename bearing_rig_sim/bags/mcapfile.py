"""One MCAP storage file read with the ``mcap`` library, for reading and repairing: its index
(from its summary, else a scan record by record) and its messages in time order (docs/bags.md)."""

from __future__ import annotations

import contextlib
import io
import itertools
import struct
from dataclasses import dataclass, field
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import BinaryIO, NamedTuple, TypeVar

import numpy as np
import numpy.typing as npt
from mcap.data_stream import ReadDataStream
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.reader import NonSeekingReader, SeekingReader
from mcap.records import Channel, Chunk, DataEnd, Footer, Header, McapRecord, Message, Metadata, Schema
from mcap.stream_reader import StreamReader, breakup_chunk, get_chunk_data_stream, read_magic
from mcap.writer import MCAP0_MAGIC

from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.storage import ChannelInfo, FileIndex, MessageTuple, ProblemSink, merge_in_time

_UNREADABLE = (McapError, struct.error, ValueError, UnicodeDecodeError, OSError)
"""What the mcap library raises on bytes that are not records (a CRC mismatch is a ValueError)."""


class DamagedRecord(Exception):
    """A chunk or record cannot be used (truncated, bad checksum, undecompressable)."""


@dataclass(frozen=True)
class ChunkRef:
    """A chunk record from ``offset`` to ``stop`` in the file: its log-time range and channels
    (None when not indexed)."""

    offset: int
    stop: int
    start_ns: int
    end_ns: int
    channel_ids: frozenset[int] | None = None
    message_indexes: tuple[tuple[int, int], ...] = ()
    """(channel id, file offset) of the chunk's message index records (from the summary; empty
    when not known: the chunk is then read record by record)."""
    index_stop: int = 0
    """File offset after the chunk's message index records."""


@dataclass
class McapIndex(FileIndex):
    """:class:`.storage.FileIndex` of an MCAP file, plus its header's profile and library, chunks in
    file order, the offset after the last readable record, the first chunk's compression, and
    whether messages lie outside chunks (``unchunked``: read by the mcap library's own reader)."""

    profile: str = ""
    library: str = ""
    chunks: list[ChunkRef] = field(default_factory=list)
    readable_bytes: int = 0
    file_size: int = 0
    compression: str = ""
    unchunked: bool = False

    def add_channel(self, channel: Channel, schemas: dict[int, Schema]) -> None:
        """Record a channel; its type is its schema's name."""
        schema = schemas.get(channel.schema_id)
        self.channels[channel.id] = ChannelInfo(channel.topic, schema.name if schema else "", channel.message_encoding, dict(channel.metadata))

    def add_schema(self, schema: Schema) -> None:
        """Record a schema's definition (ros2msg or ros2idl text)."""
        if schema.name:
            self.definitions.setdefault(schema.name, (schema.encoding, schema.data.decode("utf-8", errors="replace")))


Indexed = TypeVar("Indexed", Chunk, Metadata)


def _one_record(stream: BinaryIO, offset: int, kind: type[Indexed]) -> Indexed:
    """The record of type ``kind`` at ``offset`` (a chunk not opened); McapError for another record."""
    stream.seek(offset)
    record = next(iter(StreamReader(stream, skip_magic=True, emit_chunks=True).records))
    if not isinstance(record, kind):
        raise McapError(f"no {kind.__name__.lower()} record at offset {offset} ({type(record).__name__} found)")
    return record


@contextlib.contextmanager
def _opening_chunk() -> Iterator[None]:
    """Turn whatever decompressing or checksumming a chunk raises into :class:`DamagedRecord`."""
    try:
        yield
    except Exception as exc:  # zstandard, lz4 and mcap raise their own classes
        raise DamagedRecord(f"chunk does not decompress or fails its checksum ({exc})") from None


_RECORD_HEAD = struct.Struct("<BQ")  # opcode, length (MCAP spec, "Records")
_MESSAGE_HEAD = struct.Struct("<HIQQ")  # channel id, sequence, log time, publish time ("Message")


def _messages_in(data: bytes, keep: Callable[[int, int], bool]) -> list[MessageTuple]:
    """The message records ``keep`` accepts in a decompressed chunk, sliced out by hand: four times
    faster than ``breakup_chunk`` (docs/bags.md)."""
    out = []
    position, end = 0, len(data)
    head, message = _RECORD_HEAD.unpack_from, _MESSAGE_HEAD.unpack_from
    while position < end:
        opcode, length = head(data, position)
        if opcode == Opcode.MESSAGE:
            channel_id, _sequence, log_time, publish_time = message(data, position + 9)
            if keep(channel_id, log_time):
                out.append((log_time, channel_id, publish_time, data[position + 31 : position + 9 + length]))
        position += 9 + length
    if position != end:
        raise DamagedRecord(f"a record runs {position - end} bytes past the end of its chunk")
    return out


class ChunkBatch(NamedTuple):
    """The wanted messages of one chunk as arrays, in log-time order (file order at equal times):
    ``log_times`` and ``publish_times`` (ns), ``channel_ids``, and each payload's ``starts`` and
    ``ends`` in ``data`` (the decompressed chunk)."""

    log_times: npt.NDArray[np.int64]
    channel_ids: npt.NDArray[np.int64]
    publish_times: npt.NDArray[np.int64]
    starts: npt.NDArray[np.int64]
    ends: npt.NDArray[np.int64]
    data: bytes

    @classmethod
    def of(cls, messages: list[MessageTuple]) -> ChunkBatch:
        """The batch of messages already read one by one (in log-time order)."""
        lengths = np.array([len(m[3]) for m in messages], dtype=np.int64)
        ends = np.cumsum(lengths, dtype=np.int64)
        log_times, channel_ids, publish_times = (np.array([m[k] for m in messages], dtype=np.int64) for k in (0, 1, 2))
        return cls(log_times, channel_ids, publish_times, ends - lengths, ends, b"".join(m[3] for m in messages))

    def of_channels(self, channel_ids: list[int]) -> ChunkBatch:
        """The messages of these channels (the same ``data``)."""
        keep = np.isin(self.channel_ids, channel_ids)
        if keep.all():
            return self
        return ChunkBatch(self.log_times[keep], self.channel_ids[keep], self.publish_times[keep], self.starts[keep], self.ends[keep], self.data)

    def tuples(self) -> list[MessageTuple]:
        """The messages as :data:`.storage.MessageTuple`."""
        data = self.data
        return [
            (t, c, p, data[a:b])
            for t, c, p, a, b in zip(self.log_times.tolist(), self.channel_ids.tolist(), self.publish_times.tolist(), self.starts.tolist(), self.ends.tolist())
        ]


_INDEX_HEAD = struct.Struct("<BQHI")  # opcode, length, channel id, byte length of the (time, offset) pairs ("Message Index")
_U64 = np.dtype("<u8")


def _indexed_batch(stream: BinaryIO, ref: ChunkRef, wanted: frozenset[int] | None, low: int, high: int) -> ChunkBatch | None:
    """The chunk's wanted messages located through its message index records, without walking
    its other records; None when the chunk has no usable index (DamagedRecord when the chunk
    itself is damaged)."""
    entries = [(c, offset) for c, offset in ref.message_indexes if wanted is None or c in wanted]
    if not ref.message_indexes:
        return None
    try:
        chunk = _one_record(stream, ref.offset, Chunk)
        with _opening_chunk():
            stream_of_data, size = get_chunk_data_stream(chunk, validate_crc=True)
            data = stream_of_data.read(size)
        first = min((offset for _c, offset in entries), default=ref.index_stop)
        stream.seek(first)
        block = stream.read(ref.index_stop - first)
    except _UNREADABLE as exc:
        raise DamagedRecord(f"unreadable at offset {ref.offset} ({exc or type(exc).__name__})") from None
    times, channels, offsets = [], [], []
    for channel, offset in entries:
        if offset - first + _INDEX_HEAD.size > len(block):
            return None
        opcode, _length, found, size = _INDEX_HEAD.unpack_from(block, offset - first)
        if opcode != Opcode.MESSAGE_INDEX or found != channel or offset - first + _INDEX_HEAD.size + size > len(block) or size % 16:
            return None
        pairs = np.frombuffer(block, dtype=_U64, count=size // 8, offset=offset - first + _INDEX_HEAD.size).reshape(-1, 2).astype(np.int64)
        times.append(pairs[:, 0])
        offsets.append(pairs[:, 1])
        channels.append(np.full(len(pairs), channel, dtype=np.int64))
    log_times = np.concatenate(times) if times else np.zeros(0, np.int64)
    where = np.concatenate(offsets) if offsets else np.zeros(0, np.int64)
    channel_ids = np.concatenate(channels) if channels else np.zeros(0, np.int64)
    raw = np.frombuffer(data, dtype=np.uint8)
    if where.size and (where.min() < 0 or where.max() + 31 > raw.size):
        return None
    heads = raw[where[:, None] + np.arange(31)]  # opcode, length, channel, sequence, log time, publish time
    lengths = heads[:, 1:9].copy().view(_U64).ravel().astype(np.int64)
    ends = where + 9 + lengths
    if np.any(heads[:, 0] != Opcode.MESSAGE) or np.any(ends > raw.size) or np.any(lengths < 22):
        return None
    publish = heads[:, 23:31].copy().view(_U64).ravel().astype(np.int64)
    keep = (log_times >= low) & (log_times < high)
    order = np.lexsort((where[keep], log_times[keep]))  # time, then file order
    return ChunkBatch(log_times[keep][order], channel_ids[keep][order], publish[keep][order], where[keep][order] + 31, ends[keep][order], data)


def read_chunk_batch(stream: BinaryIO, ref: ChunkRef, wanted: frozenset[int] | None = None, low: int = -1, high: int = 2**64) -> ChunkBatch:
    """The messages of one chunk on ``wanted`` channels (None: all) with ``low <= log_time < high``
    as arrays (:class:`ChunkBatch`): through the chunk's message indexes when the summary lists
    them, else record by record; DamagedRecord for a chunk truncated, corrupt or not decompressing."""
    batch = _indexed_batch(stream, ref, wanted, low, high)
    if batch is not None:
        return batch
    return ChunkBatch.of(read_chunk_messages(stream, ref, lambda c, t: (wanted is None or c in wanted) and low <= t < high))


def read_chunk_messages(stream: BinaryIO, ref: ChunkRef, keep: Callable[[int, int], bool] = lambda _c, _t: True) -> list[MessageTuple]:
    """Messages of one chunk that ``keep(channel_id, log_time)`` accepts, stably sorted by log time;
    DamagedRecord for a chunk truncated, corrupt or not decompressing."""
    try:
        chunk = _one_record(stream, ref.offset, Chunk)
        with _opening_chunk():
            stream_of_data, size = get_chunk_data_stream(chunk, validate_crc=True)
            messages = _messages_in(stream_of_data.read(size), keep)
    except _UNREADABLE as exc:
        raise DamagedRecord(f"unreadable at offset {ref.offset} ({exc or type(exc).__name__})") from None
    messages.sort(key=lambda m: m[0])
    return messages


def _index_from_summary(stream: BinaryIO, index: McapIndex) -> bool:
    """Fill ``index`` from the summary section; False when there is none usable."""
    try:
        stream.seek(-len(MCAP0_MAGIC), io.SEEK_END)
        read_magic(ReadDataStream(stream))
        stream.seek(0)
        summary = SeekingReader(stream).get_summary()
    except _UNREADABLE:
        return False
    if summary is None or summary.statistics is None:
        return False
    stats = summary.statistics
    if stats.message_count and not summary.channels:
        return False  # channels not repeated in the summary: only a scan finds them
    if any(c.chunk_start_offset + c.chunk_length > index.file_size for c in summary.chunk_indexes):
        return False
    for schema in summary.schemas.values():
        index.add_schema(schema)
    for channel in summary.channels.values():
        index.add_channel(channel, summary.schemas)
    for c in sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset):
        channels = frozenset(c.message_index_offsets) if c.message_index_offsets else None
        stop = c.chunk_start_offset + c.chunk_length
        offsets = tuple(sorted(c.message_index_offsets.items()))
        if any(not stop <= offset < stop + c.message_index_length for _channel, offset in offsets):
            offsets = ()  # an index pointing elsewhere: read the chunk record by record
        index.chunks.append(ChunkRef(c.chunk_start_offset, stop, c.message_start_time, c.message_end_time, channels, offsets, stop + c.message_index_length))
    index.compression = summary.chunk_indexes[0].compression if summary.chunk_indexes else ""
    index.unchunked = bool(stats.message_count and not summary.chunk_indexes)
    index.message_count, index.channel_counts = stats.message_count, dict(stats.channel_message_counts)
    index.start_ns, index.end_ns = stats.message_start_time, stats.message_end_time
    for entry in summary.metadata_indexes:
        try:
            record = _one_record(stream, entry.offset, Metadata)
        except (*_UNREADABLE, StopIteration):
            index.problems.append(f"{index.path.name}: metadata record {entry.name!r} is unreadable")
            continue
        index.metadata.setdefault(record.name, {}).update(record.metadata)
    index.readable_bytes = index.file_size
    index.indexed = True
    return True


def _scan(stream: BinaryIO, records: Iterator[McapRecord], index: McapIndex) -> None:
    """Fill ``index`` from the records after the header (see the module documentation)."""
    name = index.path.name
    start = stream.tell()
    schemas: dict[int, Schema] = {}

    def note(record: McapRecord) -> None:
        if isinstance(record, Message):
            index.count(record.channel_id, record.log_time)
        elif isinstance(record, Schema):
            schemas[record.id] = record
            index.add_schema(record)
        elif isinstance(record, Channel):
            index.add_channel(record, schemas)
        elif isinstance(record, Metadata):
            index.metadata.setdefault(record.name, {}).update(record.metadata)

    try:
        for record in records:
            end = stream.tell()
            index.unchunked = index.unchunked or isinstance(record, Message)
            inner: list[McapRecord] = [record]
            if isinstance(record, Chunk):
                index.compression = index.compression or record.compression
                try:
                    with _opening_chunk():
                        inner = breakup_chunk(record, validate_crc=True)
                except DamagedRecord as exc:
                    index.problems.append(f"{name}: chunk record at offset {start} is damaged ({exc}); skipped")
                    inner = []
                if messages := [(m.channel_id, m.log_time) for m in inner if isinstance(m, Message)]:
                    times = [t for _c, t in messages]
                    index.chunks.append(ChunkRef(start, end, min(times), max(times), frozenset(c for c, _t in messages)))
            for item in inner:
                note(item)
            start = end
            if isinstance(record, (DataEnd, Footer)):
                break
    except _UNREADABLE as exc:
        if start >= index.file_size:
            index.problems.append(f"{name}: file ends after {start} bytes without a summary (recording interrupted?)")
        else:
            stream.seek(start)
            head = stream.read(9)
            kind = next((o.name.lower().replace("_", " ") for o in Opcode if o == head[0]), "unknown")
            size = f" of {9 + _RECORD_HEAD.unpack(head)[1]}" if len(head) == 9 else ""  # none when the length itself is cut
            state = "cut by the end of the file" if isinstance(exc, (EndOfFile, struct.error)) else f"damaged ({exc})"
            index.problems.append(f"{name}: {kind} record at offset {start} is {state} ({index.file_size - start}{size} bytes present)")
    index.readable_bytes = start


def index_file(path: Path) -> McapIndex:
    """Index one MCAP file: from its summary when it has a valid one, else by scanning it; BagError
    when the file cannot be opened or is not MCAP (bad magic, no header)."""
    index = McapIndex(path=path)
    try:
        stream = open(path, "rb")  # closed below
    except OSError as exc:
        raise BagError(f"{path}: cannot open ({exc.strerror or exc})") from None
    with stream:
        index.file_size = stream.seek(0, io.SEEK_END)
        stream.seek(0)
        start = stream.read(len(MCAP0_MAGIC) + 1)
        if start[: len(MCAP0_MAGIC)] != MCAP0_MAGIC[: len(start)]:
            raise BagError(f"{path}: not an MCAP file (its first bytes are not the MCAP magic)")
        if len(start) > len(MCAP0_MAGIC) and start[-1] != Opcode.HEADER:
            raise BagError(f"{path}: not an MCAP file (no header record after the magic)")
        stream.seek(0)
        records = iter(StreamReader(stream, emit_chunks=True, validate_crcs=True).records)
        try:
            header = next(records)
        except (*_UNREADABLE, StopIteration):
            if len(start) > len(MCAP0_MAGIC) and _index_from_summary(stream, index):
                index.has_header = True  # its data are readable: the header holds only two names
                index.problems.append(f"{path.name}: the MCAP header record is damaged; read through the file's summary")
            else:
                cut = f"file ends after {index.file_size} bytes, before its header is complete (recording interrupted as it started?)"
                index.problems.append(f"{path.name}: {cut}: no data")
            return index
        assert isinstance(header, Header)  # checked by its opcode above
        index.has_header = True
        index.profile, index.library = header.profile, header.library
        index.readable_bytes = position = stream.tell()
        if _index_from_summary(stream, index):
            return index
        stream.seek(position)
        _scan(stream, records, index)
        if not index.problems:
            index.problems.append(
                f"{path.name}: no valid summary (index) at the end of the file; all "
                f"{index.message_count} messages are readable, `bearing-rig bag repair` on its bag restores the index"
            )
    return index


def damaged_chunk_bytes(index: McapIndex) -> int:
    """Decompress and checksum every chunk: the bytes within the file of those that fail (reading
    the file's messages names each of them)."""
    damaged = 0
    with open(index.path, "rb") as stream:
        for ref in index.chunks:
            try:
                read_chunk_messages(stream, ref)
            except DamagedRecord:
                damaged += max(0, min(ref.stop, index.file_size) - ref.offset)
    return damaged


def _chunks_of(index: McapIndex, wanted: frozenset[int] | None, low: int, high: int) -> list[ChunkRef]:
    """The chunks that may hold messages on ``wanted`` channels (None: any) with ``low <=
    log_time < high``, in the order :meth:`McapFormat.messages` merges them."""
    refs = [r for r in index.chunks if r.end_ns >= low and r.start_ns < high and (wanted is None or r.channel_ids is None or r.channel_ids & wanted)]
    return sorted(refs, key=lambda r: (r.start_ns, r.offset))


def _chunk_batches(index: McapIndex, report: ProblemSink, refs: list[ChunkRef], wanted: frozenset[int]) -> Iterator[ChunkBatch]:
    """The wanted messages of each chunk of ``refs`` in turn (none empty); damaged chunks reported
    through ``report`` and skipped."""
    stream = _open(index, report)
    if stream is None:
        return
    with stream:
        for ref in refs:
            try:
                batch = read_chunk_batch(stream, ref, wanted)
            except DamagedRecord as exc:
                report(f"{index.path.name}: chunk at offset {ref.offset}: {exc}; its messages are skipped")
                continue
            if batch.log_times.size:
                yield batch


def batched(messages: Iterable[MessageTuple], size: int) -> Iterator[ChunkBatch]:
    """Messages read one by one, in batches of ``size``."""
    messages = iter(messages)
    while block := list(itertools.islice(messages, size)):
        yield ChunkBatch.of(block)


def _lazy_chunk(stream: BinaryIO, ref: ChunkRef, wanted: frozenset[int] | None, low: int, high: int, report: ProblemSink, label: str) -> Iterator[MessageTuple]:
    """A chunk's wanted messages after a marker (channel -1) at its start time, so that a merge
    holds many chunks without reading them."""
    yield (ref.start_ns, -1, 0, b"")
    try:
        yield from read_chunk_batch(stream, ref, wanted, low, high).tuples()
    except DamagedRecord as exc:
        report(f"{label}: chunk at offset {ref.offset}: {exc}; its messages are skipped")


def _open(index: FileIndex, report: ProblemSink) -> BinaryIO | None:
    """The file of ``index`` opened for reading; None (reported) when it cannot be."""
    try:
        return open(index.path, "rb")
    except OSError as exc:
        report(f"{index.path}: cannot open ({exc.strerror or exc})")
        return None


class McapFormat:
    """MCAP storage files (https://mcap.dev/spec), one index per file."""

    identifier = "mcap"

    def indexes(self, bag: Path, files: list[Path]) -> list[FileIndex]:
        """One index per file (:func:`index_file`)."""
        return [index_file(f) for f in files]

    def messages(
        self, index: FileIndex, report: ProblemSink, channel_ids: Iterable[int] | None = None, start_ns: int | None = None, stop_ns: int | None = None
    ) -> Iterator[MessageTuple]:
        """Messages of one file on ``channel_ids`` (None: all) with ``start_ns <= log_time < stop_ns``
        in log-time order, streamed: memory holds the chunks whose time ranges overlap (the whole
        file's wanted messages for an ``unchunked`` one, read by the mcap library up to its first
        unreadable record). Damaged chunks are reported through ``report`` and skipped."""
        assert isinstance(index, McapIndex)
        wanted = None if channel_ids is None else frozenset(channel_ids)
        low = -1 if start_ns is None else start_ns
        high = 2**64 if stop_ns is None else stop_ns

        def keep(channel_id: int, log_time: int) -> bool:
            return (wanted is None or channel_id in wanted) and low <= log_time < high

        refs = _chunks_of(index, wanted, low, high)
        stream = _open(index, report)
        if stream is None:
            return
        with stream:
            if index.unchunked:
                found = []
                with contextlib.suppress(Exception):  # what the library raises at a cut or damage (as _opening_chunk)
                    for _schema, _channel, m in NonSeekingReader(stream, validate_crcs=True).iter_messages(log_time_order=False):
                        if keep(m.channel_id, m.log_time):
                            found.append((m.log_time, m.channel_id, m.publish_time, m.data))
                yield from sorted(found, key=lambda m: m[0])
                return
            chunks = [(r.start_ns, r.end_ns, _lazy_chunk(stream, r, wanted, low, high, report, index.path.name)) for r in refs]
            yield from (m for m in merge_in_time(chunks) if m[1] >= 0)

    def ordered_batches(self, index: FileIndex, report: ProblemSink, channel_ids: Iterable[int], size: int = 4096) -> Iterator[ChunkBatch]:
        """The messages of one file on ``channel_ids`` in the order of :meth:`messages`, as
        batches of arrays (:class:`ChunkBatch`): a chunk's through its message indexes when the
        chunks follow each other in time (what a recorder writes), else (chunks overlapping in
        time) the merged messages in batches of ``size``. Damaged chunks are reported through
        ``report`` and skipped."""
        assert isinstance(index, McapIndex)
        wanted = frozenset(channel_ids)
        refs = _chunks_of(index, wanted, -1, 2**64)
        if index.unchunked or any(b.start_ns < a.end_ns for a, b in zip(refs, refs[1:])):  # merge_in_time's chaining rule
            yield from batched(self.messages(index, report, wanted), size)
            return
        yield from _chunk_batches(index, report, refs, wanted)

    def batches(self, index: FileIndex, report: ProblemSink, channel_ids: Iterable[int]) -> Iterator[ChunkBatch]:
        """The messages of one file on ``channel_ids`` chunk by chunk (:class:`ChunkBatch`), the
        chunks in the order of their start times: for a topic sampled rather than read message by
        message (a chunk's messages located through its message indexes, no record walked).
        Damaged chunks are reported through ``report`` and skipped; an unchunked file is one batch."""
        assert isinstance(index, McapIndex)
        wanted = frozenset(channel_ids)
        if index.unchunked:
            yield ChunkBatch.of(list(self.messages(index, report, wanted)))
            return
        yield from _chunk_batches(index, report, _chunks_of(index, wanted, -1, 2**64), wanted)
