"""Reading rig bags (rosbag2 directories with MCAP or SQLite 3 storage, or one ``.mcap`` file)::

    with open_bag("bags/run-0001") as bag:
        for topic, log_time_ns, msgtype, message in bag.messages(["/rig/cage/pulses"]): ...

Messages come in log-time order, streamed, decoded as docs/bags.md says. Damage is not fatal: each
problem is a :class:`BagWarning` and a line in :attr:`BagReader.problems` (:class:`BagError` with
``strict=True``).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from types import TracebackType
from typing import Literal, NamedTuple, cast

import numpy as np

from rosbags.interfaces.typing import Constdefs, Fielddefs, Typesdict
from rosbags.typesys import Stores, get_types_from_idl, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from bearing_rig_sim.bags.cdr import make_decoder
from bearing_rig_sim.bags.errors import BagError, BagWarning
from bearing_rig_sim.bags.layout import BagLayout, layout_from_indexes, read_layout
from bearing_rig_sim.bags.mcapfile import ChunkBatch, McapFormat, batched
from bearing_rig_sim.bags.sqlite import Sqlite3Format
from bearing_rig_sim.bags.storage import FileIndex, MessageTuple, merge_in_time
from bearing_rig_sim.bags.qos import QosSpec
from bearing_rig_sim.bags.typestore import SCHEMA_SEPARATOR, dependencies, rig_typestore
from bearing_rig_sim.clock_guard import DEFAULT_MAX_STEP_NS

StorageFormat = McapFormat | Sqlite3Format
STORAGE_FORMATS: dict[str, StorageFormat] = {"mcap": McapFormat(), "sqlite3": Sqlite3Format()}
"""The storage formats this project reads, by ``storage_identifier`` (see :mod:`.storage`)."""


def storage_format(identifier: str, source: str = "") -> StorageFormat:
    """The format of a ``storage_identifier`` (stated in ``source``); BagError naming those read for another."""
    try:
        return STORAGE_FORMATS[identifier]
    except KeyError:
        raise BagError(
            f"{source}{': ' if source else ''}storage {identifier!r} is not supported (this project reads: {', '.join(sorted(STORAGE_FORMATS))})"
        ) from None


class BagMessage(NamedTuple):
    """One message read from a bag."""

    topic: str
    log_time_ns: int
    msgtype: str
    message: object  # the rosbags message object, or the CDR bytes with raw=True


@dataclass(frozen=True)
class TopicInfo:
    """A topic of a bag: messages readable on it, first offered QoS (None when not stored or not
    modelled), RIHS01 hash (empty when not stored); not ``decodable`` when the type is unknown
    (:meth:`BagReader.messages` then skips it unless ``raw=True``)."""

    name: str
    msgtype: str
    message_count: int
    qos: QosSpec | None
    type_hash: str
    decodable: bool


def _same_fields(a: tuple[Constdefs, Fielddefs], b: tuple[Constdefs, Fielddefs]) -> bool:
    return [(n.lower(), d) for n, d in a[1]] == [(n.lower(), d) for n, d in b[1]]


def _parse_definition(msgtype: str, encoding: str, text: str) -> Typesdict:
    if encoding == "ros2msg":
        return get_types_from_msg(text, msgtype)
    separator = SCHEMA_SEPARATOR + "\n"  # rosbag2's ros2idl schema: sections headed "IDL: <type>"
    sections = [s.split("\n", 1)[1] for s in text.split(separator)[1:]] if text.startswith(separator + "IDL: ") else [text]
    types: Typesdict = {}
    for idl in sections:
        types.update(get_types_from_idl(idl))
    return types


class BagReader:
    """An open bag (see the module documentation): ``files`` read, ``topics`` by name,
    ``message_count`` readable and their log-time range ``start_ns``, ``end_ns``, ``duration_ns``
    (ns; 0 when empty), ``run_metadata`` (the run context, docs/bags.md), the ``typestore`` decoding
    them, ``layout`` (``metadata.yaml``; None for a bare ``.mcap`` file), ``problems`` met so far."""

    def __init__(self, path: str | Path, *, strict: bool = False) -> None:
        self.path = Path(path)
        self.strict = strict
        self.problems: list[str] = []
        self.layout: BagLayout | None = None
        self._closed = False
        if not self.path.exists():
            raise BagError(f"{self.path}: no such bag (the path does not exist)")
        self._format = STORAGE_FORMATS["mcap"]
        if self.path.is_dir():
            self.layout = read_layout(self.path)
            self._format = storage_format(self.layout.storage_identifier, str(self.path / "metadata.yaml"))
            files = [self.path / f.path for f in self.layout.files]
            missing = [f for f in files if not f.is_file()]
            if files and len(missing) == len(files):
                raise BagError(f"{self.path}: none of the storage files listed in metadata.yaml exists ({', '.join(f.name for f in missing)})")
            for f in missing:
                self._report(f"{f}: listed in metadata.yaml but missing; its messages are not read")
            files = [f for f in files if f not in missing]
        else:
            files = [self.path]
        self.files = files
        self._indexes: list[FileIndex] = self._format.indexes(self.path, files) if files else []
        if self._indexes and not any(i.has_header for i in self._indexes):
            raise BagError(f"{self.path}: nothing readable: " + "; ".join(p for i in self._indexes for p in i.problems))
        for index in self._indexes:
            for problem in index.problems:
                self._report(problem)
        self._channel_topics: list[dict[int, str]] = []  # per file, the topic of each channel read
        self._found = layout_from_indexes(self._indexes, self.layout, self._report, accepted=self._channel_topics)  # what the files hold
        self.typestore = self._build_typestore()
        self.message_count, self.start_ns, self.end_ns = self._found.message_count, self._found.start_ns, self._found.end_ns
        self.duration_ns = self._found.duration_ns
        self.run_metadata = self._found.custom_data
        self.topics = self._collect_topics()
        if self.layout is not None and self.layout.message_count != self.message_count:
            self._report(
                f"{self.path / 'metadata.yaml'}: states {self.layout.message_count} messages but the files hold "
                f"{self.message_count} readable ones (stale metadata after an interrupted recording? "
                f"`bearing-rig bag repair {self.path}` rewrites it)"
            )

    def verify(self) -> list[str]:
        """Read every chunk: a line per finding of :func:`verify_indexes` (none for a sound bag);
        slower than opening, which reads the index only."""
        return verify_indexes(self._indexes, self._format.messages)

    @property
    def complete(self) -> bool:
        """True when every file was finished properly and nothing was found damaged."""
        return all(i.indexed for i in self._indexes) and not self.problems

    def messages(
        self, topics: Iterable[str] | None = None, *, start_ns: int | None = None, stop_ns: int | None = None, raw: bool = False
    ) -> Iterator[BagMessage]:
        """Messages of ``topics`` (None: every decodable one) with ``start_ns <= log_time < stop_ns``
        in log-time order, streamed; ``raw`` yields the CDR bytes instead (undecodable topics too).
        BagError for a topic not in the bag, and (strict) for a damaged chunk or message."""
        if self._closed:
            raise BagError(f"{self.path}: the bag is closed")
        if topics is None:
            selected = {name for name, info in self.topics.items() if raw or info.decodable}
        else:
            selected = set([topics] if isinstance(topics, str) else topics)
            unknown = sorted(selected - self.topics.keys())
            if unknown:
                raise BagError(f"{self.path}: no topic {', '.join(unknown)} in the bag (it has {', '.join(sorted(self.topics)) or 'none'})")
            if not raw:
                selected = {name for name in selected if self.topics[name].decodable}
        return self._iterate(selected, start_ns, stop_ns, raw)

    def batches(self, topics: Iterable[str], *, size: int = 4096) -> Iterator[dict[str, ChunkBatch]]:
        """The raw messages of ``topics`` in batches of arrays (:class:`.mcapfile.ChunkBatch`), by
        topic, each in log-time order and the batches in the order of their first times: one per
        MCAP chunk, located through the chunk's message indexes, no message handled one by one
        (for topics sampled now and then rather than read whole); other storage in batches of
        ``size`` messages. Files of a split bag follow each other in time; overlapping chunks or
        files give batches whose time ranges overlap. BagError for a topic not in the bag."""
        if self._closed:
            raise BagError(f"{self.path}: the bag is closed")
        selected = set(topics)
        unknown = sorted(selected - self.topics.keys())
        if unknown:
            raise BagError(f"{self.path}: no topic {', '.join(unknown)} in the bag (it has {', '.join(sorted(self.topics)) or 'none'})")
        for k in sorted(range(len(self._indexes)), key=lambda k: self._indexes[k].start_ns):
            index = self._indexes[k]
            wanted = {cid: name for cid, name in self._channel_topics[k].items() if name in selected}
            if not wanted or not index.message_count:
                continue
            found = (
                self._format.batches(index, self._report, wanted)
                if isinstance(self._format, McapFormat)
                else batched(self._format.messages(index, self._report, wanted), size)
            )
            for batch in found:
                split = {name: batch.of_channels([c for c, n in wanted.items() if n == name]) for name in set(wanted.values())}
                yield {name: part for name, part in split.items() if part.log_times.size}

    def ordered_batches(self, topics: Sequence[str], *, size: int = 4096) -> Iterator[ChunkBatch]:
        """The raw messages of ``topics`` in the order of :meth:`messages` (log time), as batches
        of arrays (:class:`.mcapfile.ChunkBatch`) whose ``channel_ids`` are each message's topic
        as its position in ``topics``: an MCAP chunk at a time through its message indexes when
        the chunks and files follow each other in time, else the merged messages in batches of
        ``size`` (their ``publish_times`` then 0). For topics read whole but decoded as arrays
        (no message object built). BagError for a topic not in the bag."""
        if self._closed:
            raise BagError(f"{self.path}: the bag is closed")
        unknown = sorted(set(topics) - self.topics.keys())
        if unknown:
            raise BagError(f"{self.path}: no topic {', '.join(unknown)} in the bag (it has {', '.join(sorted(self.topics)) or 'none'})")
        position = {name: k for k, name in enumerate(topics)}
        files = [
            (index, {cid: position[name] for cid, name in topic_of.items() if name in position}) for index, topic_of in zip(self._indexes, self._channel_topics)
        ]
        files = sorted(((i, w) for i, w in files if w and i.message_count), key=lambda f: f[0].start_ns)
        if not isinstance(self._format, McapFormat) or any(b.start_ns < a.end_ns for (a, _), (b, _) in zip(files, files[1:])):
            names = self._iterate(set(topics), None, None, raw=True)
            yield from batched(((log_time, position[name], 0, cast(bytes, data)) for name, log_time, _type, data in names), size)
            return
        for index, wanted in files:
            lookup = np.full(max(wanted) + 1, -1, dtype=np.int64)
            lookup[list(wanted)] = list(wanted.values())
            for batch in self._format.ordered_batches(index, self._report, wanted, size):
                yield batch._replace(channel_ids=lookup[batch.channel_ids])

    def close(self) -> None:
        """Mark the reader closed (files are opened only while messages are read)."""
        self._closed = True

    def __enter__(self) -> BagReader:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None, traceback: TracebackType | None) -> Literal[False]:
        self.close()
        return False

    def _report(self, problem: str) -> None:
        if self.strict:
            raise BagError(problem)
        self.problems.append(problem)
        warnings.warn(problem, BagWarning, stacklevel=3)

    def _build_typestore(self) -> Typestore:
        """The shared rig store when the bag's definitions agree with it, else a store built
        from the bag's own definitions completed with the rig's."""
        rig = rig_typestore()
        bag_types: Typesdict = {}
        parsed: set[tuple[str, str]] = set()
        for index in self._indexes:
            for msgtype, (encoding, text) in index.definitions.items():
                if not text or (msgtype, text) in parsed or encoding not in ("ros2msg", "ros2idl", "omgidl"):
                    continue
                parsed.add((msgtype, text))
                try:
                    bag_types.update(_parse_definition(msgtype, encoding, text))
                except Exception as exc:  # rosbags parser errors have several classes
                    self._report(f"{index.path.name}: the bag's definition of {msgtype} does not parse ({exc}); using the built-in one if any")
        if all(name in rig.fielddefs and _same_fields(rig.fielddefs[name], d) for name, d in bag_types.items()):
            return rig
        store = get_typestore(Stores.EMPTY)
        try:
            store.register(bag_types)
        except Exception as exc:  # TypesysError and parser errors
            self._report(f"{self.path}: the bag's message definitions are inconsistent ({exc}); using the built-in ones")
            return rig
        missing = {name for name in dependencies(rig, (t.msgtype for t in self._found.topics)) if name not in store.fielddefs}
        if missing:
            try:
                store.register({name: rig.fielddefs[name] for name in missing})
            except Exception as exc:
                self._report(f"{self.path}: built-in definitions of {', '.join(sorted(missing))} clash with the bag's ({exc})")
        return store

    def _collect_topics(self) -> dict[str, TopicInfo]:
        topics = {}
        for entry in sorted(self._found.topics, key=lambda t: t.name):
            cdr = entry.serialization_format == "cdr"
            decodable = cdr and bool(entry.msgtype) and entry.msgtype in self.typestore.fielddefs
            if not decodable:
                why = f"type {entry.msgtype or '(none)'} is unknown: no definition in the bag and not a ROS 2 Jazzy or bearing_rig_msgs type"
                why = why if cdr else f"message encoding {entry.serialization_format!r} is not cdr"
                self._report(f"{self.path.name}: topic {entry.name}: {why}; its {entry.message_count} messages are skipped")
            qos = QosSpec.from_rosbags(entry.qos[0]) if entry.qos else None
            topics[entry.name] = TopicInfo(entry.name, entry.msgtype, entry.message_count, qos, entry.type_hash, decodable)
        return topics

    def _iterate(self, selected: set[str], start_ns: int | None, stop_ns: int | None, raw: bool) -> Iterator[BagMessage]:
        def named(messages: Iterator[MessageTuple], topic_of: dict[int, str]) -> Iterator[tuple[int, str, bytes]]:
            return ((t, topic_of[cid], data) for t, cid, _publish, data in messages)

        streams = []
        for index, topic_of in zip(self._indexes, self._channel_topics):
            wanted = {cid: name for cid, name in topic_of.items() if name in selected}
            if wanted and index.message_count:
                messages = self._format.messages(index, self._report, wanted, start_ns, stop_ns)
                streams.append((index.start_ns, index.end_ns, named(messages, wanted)))
        types = {name: self.topics[name].msgtype for name in selected}
        decoders = {} if raw else {name: make_decoder(self.typestore, msgtype) for name, msgtype in types.items()}
        failed: dict[str, int] = {}
        for log_time, name, data in merge_in_time(streams):
            if raw:
                yield BagMessage(name, log_time, types[name], data)
                continue
            try:
                message = decoders[name](data)
            except BagError as exc:
                failed[name] = failed.get(name, 0) + 1
                if failed[name] == 1:
                    self._report(f"{self.path.name}: topic {name}: {exc}; such messages are skipped")
                continue
            yield BagMessage(name, log_time, types[name], message)
        for name, count in failed.items():
            if count > 1:
                self._report(f"{self.path.name}: topic {name}: {count} messages could not be decoded in all")


TIMELINE_GAP_NS = DEFAULT_MAX_STEP_NS
"""A gap over this (10 s, the largest step the clock guard accepts) splits the timeline."""


@dataclass
class Stretch:
    """Log times with no gap over :data:`TIMELINE_GAP_NS` between neighbours (ns)."""

    start_ns: int
    end_ns: int
    count: int


def verify_indexes(indexes: list[FileIndex], messages: Callable[..., Iterator[MessageTuple]]) -> list[str]:
    """The full check of a bag (docs/bags.md), one line per finding (none for a sound bag): every
    message of the files read once, in time order, with their format's ``messages``; a chunk that
    fails is named, messages the indexes count but no chunk delivers are unreadable, and the log
    times are cut into stretches at gaps over :data:`TIMELINE_GAP_NS`: every stretch but the one
    with the most messages is an outlier."""
    lines: list[str] = []
    stretches: list[Stretch] = []
    for log_time, _channel, _publish, _data in merge_in_time([(i.start_ns, i.end_ns, messages(i, lines.append)) for i in indexes]):
        last = stretches[-1] if stretches else None
        if last is not None and log_time - last.end_ns <= TIMELINE_GAP_NS:
            last.end_ns = max(last.end_ns, log_time)
            last.count += 1
        else:
            stretches.append(Stretch(log_time, log_time, 1))
    indexed = sum(i.message_count for i in indexes)
    if (unreadable := indexed - sum(s.count for s in stretches)) > 0:
        lines.append(f"{unreadable} of {indexed} messages ({100.0 * unreadable / indexed:.1f} %) are in chunks that cannot be read")
    main = max(stretches, key=lambda s: s.count, default=None)
    for s in stretches:
        if main is None or s is main:
            continue
        after = s.start_ns > main.end_ns
        distance = (s.start_ns - main.end_ns) if after else (main.start_ns - s.end_ns)
        lines.append(
            f"log-time outliers: {s.count} message(s) at {s.start_ns * 1e-9:.3f}-{s.end_ns * 1e-9:.3f} s, "
            f"{distance * 1e-9:.3f} s {'after' if after else 'before'} the main timeline ({main.start_ns * 1e-9:.3f}-"
            f"{main.end_ns * 1e-9:.3f} s, {main.count} messages)"
        )
    return lines


def open_bag(path: str | Path, *, strict: bool = False) -> BagReader:
    """Open a bag directory (with ``metadata.yaml``) or a single ``.mcap`` file for reading; BagError
    for no bag, a missing or corrupt ``metadata.yaml``, a storage format not read or a file not of
    its format, and (``strict``) any damage."""
    return BagReader(path, strict=strict)
