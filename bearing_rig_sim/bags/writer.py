"""The recorder: a rosbag2 (format version 9) bag directory with MCAP storage (``docs/bags.md``)::

    with BagWriter("bags/run-0001", metadata={"configuration": config_text}) as bag:
        bag.add_topic("/rig/speeds", "sensor_msgs/msg/JointState", "sensor_data")
        bag.write("/rig/speeds", sim_time_ns, raw_cdr_bytes)

``log_time`` is the simulation time (ns), strictly increasing: a time not after the previous one
is nudged to previous + 1 ns (:attr:`BagWriter.nudged_count`); ``publish_time`` keeps the time
given. A killed recording keeps every complete chunk (docs/bags.md); leaving the ``with`` block
for any reason, Ctrl-C included, finalises the bag.
"""

from __future__ import annotations

import operator
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import IO, Any, Literal, cast

from mcap.well_known import SchemaEncoding
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer
from rosbags.typesys.store import Typestore

import bearing_rig_sim
from bearing_rig_sim.bags.cdr import CdrBytes, make_normaliser
from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.layout import RUN_METADATA_RECORD, BagLayout, FileEntry, TopicEntry, qos_yaml, write_layout
from bearing_rig_sim.bags.qos import QosSpec, qos_spec
from bearing_rig_sim.bags.typestore import msg_definition_text, rig_typestore, type_hash

PROJECT_VERSION_KEY = "project_version"
"""Run-context key the writer always fills with ``bearing_rig_sim.__version__``."""

DEFAULT_CHUNK_SIZE = 1 << 20
"""Uncompressed bytes per chunk (1 MiB: about 2 s of the rig's traffic, the most a kill loses)."""

Compression = Literal["zstd", "none"]
COMPRESSION = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE, "": CompressionType.NONE}
"""The mcap writer's chunk compression by name (``""`` as a chunk index names none)."""


def start_mcap(sink: CountingSink, chunk_size: int, compression: str, profile: str = "ros2", library: str = "") -> Writer:
    """An mcap ``Writer`` started on ``sink``, naming this project as the library by default."""
    writer = Writer(cast(IO[Any], sink), chunk_size=chunk_size, compression=COMPRESSION.get(compression, CompressionType.ZSTD))
    writer.start(profile=profile, library=library or f"bearing_rig_sim {bearing_rig_sim.__version__}; {LIBRARY_IDENTIFIER}")
    return writer


def register_topic(mcap: Writer, schema_ids: dict[str, int], topic: TopicEntry, typestore: Typestore) -> int:
    """Register a topic's channel as rosbag2 does (one ``ros2msg`` schema per type, kept in
    ``schema_ids``; offered QoS and type hash in the channel metadata); returns its id."""
    schema_id = schema_ids.get(topic.msgtype)
    if schema_id is None:
        text = msg_definition_text(topic.msgtype, typestore)
        schema_id = schema_ids[topic.msgtype] = mcap.register_schema(topic.msgtype, SchemaEncoding.ROS2, text.encode())
    metadata = {"offered_qos_profiles": qos_yaml(topic.qos), "topic_type_hash": topic.type_hash or type_hash(topic.msgtype, typestore)}
    return mcap.register_channel(topic.name, topic.serialization_format, schema_id, metadata)


class CountingSink:
    """Unbuffered output file counting the bytes written: every chunk the MCAP writer finishes
    survives a kill, and files are split by size without a system call."""

    def __init__(self, path: Path) -> None:
        try:
            self._file = open(path, "xb", buffering=0)  # closed by close()
        except FileExistsError:
            raise BagError(f"{path}: exists already, not overwriting") from None
        except OSError as exc:
            raise BagError(f"{path}: cannot create ({exc.strerror or exc})") from None
        self.path = path
        self.position = 0

    def write(self, data: bytes | bytearray | memoryview) -> int:
        """Write everything (looping over partial writes); returns the byte count."""
        view = memoryview(data)
        while view:
            view = view[self._file.write(view) :]
        self.position += len(data)
        return len(data)

    def tell(self) -> int:
        """Bytes written so far."""
        return self.position

    def flush(self) -> None:
        """Nothing to do: writes are not buffered."""

    def close(self) -> None:
        """Close the file."""
        self._file.close()


@dataclass
class _Topic:
    entry: TopicEntry
    qos: QosSpec
    normalise: Callable[[CdrBytes], CdrBytes]
    channel_id: int = 0


class BagWriter:
    """Writes a bag directory (see the module documentation), created at once (``path`` must not
    exist or be empty) and finalised by :meth:`close`. ``chunk_size`` is in uncompressed bytes
    (>= 1024); past ``max_file_bytes`` a new ``.mcap`` file starts at the next message (a file may
    exceed it by a chunk and its summary; None: one file); ``metadata`` is the run context, to which
    ``project_version`` is added; ``typestore`` defaults to :func:`.typestore.rig_typestore`.
    BagError for a bad option or an existing path."""

    def __init__(
        self,
        path: str | Path,
        *,
        compression: Compression = "zstd",
        chunk_size: int = DEFAULT_CHUNK_SIZE,
        max_file_bytes: int | None = None,
        metadata: dict[str, str] | None = None,
        typestore: Typestore | None = None,
    ) -> None:
        if compression not in ("zstd", "none"):
            raise BagError(f"compression must be 'zstd' or 'none', got {compression!r}")
        if not isinstance(chunk_size, int) or chunk_size < 1024:
            raise BagError(f"chunk_size must be an integer >= 1024 bytes, got {chunk_size!r}")
        if max_file_bytes is not None and (not isinstance(max_file_bytes, int) or max_file_bytes < 1024):
            raise BagError(f"max_file_bytes must be None or an integer >= 1024, got {max_file_bytes!r}")
        run_context = dict(metadata or {})
        for key, value in run_context.items():
            if not isinstance(key, str) or not isinstance(value, str):
                raise BagError(f"bag metadata must map strings to strings; {key!r} -> {type(value).__name__}")
        run_context.setdefault(PROJECT_VERSION_KEY, bearing_rig_sim.__version__)

        self.path = Path(path)
        if self.path.exists() and (not self.path.is_dir() or any(self.path.iterdir())):
            raise BagError(f"{self.path}: exists already and is not an empty directory, not overwriting")
        try:
            self.path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise BagError(f"{self.path}: cannot create the bag directory ({exc.strerror or exc})") from None

        self._compression, self._chunk_size, self._max_file_bytes, self._run_context = compression, chunk_size, max_file_bytes, run_context
        self._typestore = typestore if typestore is not None else rig_typestore()
        self._topics: dict[str, _Topic] = {}
        self._files: list[FileEntry] = []
        self._last_time = -1
        self.nudged_count = 0  # messages whose log time was moved forward (see the module documentation)
        self._sink: CountingSink | None = None
        self._mcap: Writer | None = None
        self._schema_ids: dict[str, int] = {}
        self._start_file()

    @property
    def message_count(self) -> int:
        """Messages written so far."""
        return sum(f.message_count for f in self._files)

    @property
    def closed(self) -> bool:
        """True once :meth:`close` has finalised the bag."""
        return self._mcap is None

    def add_topic(self, name: str, msgtype: str, qos: str | QosSpec = "reliable") -> None:
        """Declare a topic (``/name``, ``pkg/msg/Name`` or ``pkg/Name``, offered QoS: a name of
        :data:`.qos.QOS_PROFILES` or a ``QosSpec``) before writing to it; BagError when the bag is
        closed, for a bad name or unknown type, or when the topic exists with another type or QoS."""
        self._check_open()
        if not isinstance(name, str) or not name.startswith("/") or len(name) < 2:
            raise BagError(f"topic name must be fully qualified (start with '/'), got {name!r}")
        if msgtype.count("/") == 1:  # pkg/Name
            msgtype = msgtype.replace("/", "/msg/")
        spec = qos_spec(qos)
        if msgtype not in self._typestore.fielddefs:
            raise BagError(f"topic {name}: unknown message type {msgtype!r} (not a ROS 2 Jazzy or bearing_rig_msgs type)")
        existing = self._topics.get(name)
        if existing is not None:
            if existing.entry.msgtype == msgtype and existing.qos == spec:
                return
            raise BagError(f"topic {name} was added as {existing.entry.msgtype} ({existing.qos}); cannot add it as {msgtype} ({spec})")
        entry = TopicEntry(name, msgtype, [spec.to_rosbags()], type_hash(msgtype, self._typestore))
        topic = self._topics[name] = _Topic(entry, spec, make_normaliser(self._typestore, msgtype))
        self._register(topic)
        self._write_layout()

    def write(self, topic: str, log_time_ns: int, data: CdrBytes) -> None:
        """Record one serialized message (CDR with its 4-byte encapsulation header, as from
        ``rclpy.serialization.serialize_message``), Fast-CDR padding trimmed (:mod:`.cdr`); BagError
        when closed, for an unknown topic, a time outside 0 .. 2**63-1 ns, or bytes of another type."""
        entry = self._topic(topic)
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise BagError(f"topic {topic}: data must be serialized bytes, got {type(data).__name__}")
        try:
            data = entry.normalise(data)
        except BagError as exc:
            raise BagError(f"topic {topic}: {exc}") from None
        self._append(entry, log_time_ns, data)

    def write_message(self, topic: str, log_time_ns: int, message: object) -> None:
        """Serialize a rosbags message object and record it; BagError as :meth:`write`, or for a
        message not of the topic's type."""
        entry = self._topic(topic)
        msgtype = getattr(message, "__msgtype__", None)
        if msgtype != entry.entry.msgtype:
            raise BagError(f"topic {topic} carries {entry.entry.msgtype}, got a {msgtype or type(message).__name__}")
        try:
            data = bytes(self._typestore.serialize_cdr(message, msgtype))
        except Exception as exc:  # rosbags raises several classes for bad field values
            raise BagError(f"topic {topic}: cannot serialize the {msgtype} ({exc})") from None
        self._append(entry, log_time_ns, data)

    def flush(self) -> None:
        """Finish the chunk in progress and refresh ``metadata.yaml``: everything written so far
        survives a kill. Each call costs a smaller chunk (less compression)."""
        self._check_open().flush()  # type: ignore[no-untyped-call, unused-ignore]  # mcap leaves it unannotated (an error under --strict only)
        self._write_layout()

    def close(self) -> None:
        """Finalise: the last chunk, the summary, the final ``metadata.yaml`` (BagError if the file
        cannot be completed); again does nothing."""
        if self._mcap is None:
            return
        try:
            self._finish_file()
        finally:
            self._mcap = None
        self._write_layout()

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None, traceback: TracebackType | None) -> Literal[False]:
        """Finalise the bag whatever ended the block (an exception, Ctrl-C included)."""
        try:
            self.close()
        except Exception:
            if exc_type is None:
                raise
        return False

    def _check_open(self) -> Writer:
        if self._mcap is None:
            raise BagError(f"{self.path}: the bag is closed")
        return self._mcap

    def _topic(self, name: str) -> _Topic:
        entry = self._topics.get(name)
        if entry is None:
            self._check_open()
            raise BagError(f"topic {name!r} was not added to the bag (call add_topic first)")
        return entry

    def _append(self, topic: _Topic, log_time_ns: int, data: CdrBytes) -> None:
        self._check_open()
        if type(log_time_ns) is not int:
            try:
                log_time_ns = operator.index(log_time_ns)
            except TypeError:
                raise BagError(f"topic {topic.entry.name}: log time must be an integer of nanoseconds, got {log_time_ns!r}") from None
        if log_time_ns < 0 or log_time_ns >= 2**63:
            raise BagError(f"topic {topic.entry.name}: log time {log_time_ns} ns is outside 0 .. 2**63-1")
        current = self._files[-1]
        # A full file is closed when the next message comes, so that no file is left empty at the end.
        if self._max_file_bytes is not None and self._sink is not None and self._sink.position >= self._max_file_bytes and current.message_count:
            self._finish_file()
            self._start_file()
            current = self._files[-1]
        log_time = log_time_ns
        if log_time <= self._last_time:
            log_time = self._last_time + 1
            self.nudged_count += 1
        self._check_open().add_message(topic.channel_id, log_time, cast(bytes, data), log_time_ns)  # mcap takes any buffer
        self._last_time = log_time
        topic.entry.message_count += 1
        if current.message_count == 0:
            current.start_ns = log_time
        current.duration_ns = log_time - current.start_ns
        current.message_count += 1

    def _start_file(self) -> None:
        name = f"{self.path.name}_{len(self._files)}.mcap"
        self._sink = CountingSink(self.path / name)
        self._mcap = start_mcap(self._sink, self._chunk_size, self._compression)
        self._mcap.add_metadata(RUN_METADATA_RECORD, dict(self._run_context))
        self._schema_ids = {}
        self._files.append(FileEntry(path=name))
        for topic in self._topics.values():
            self._register(topic)
        self._write_layout()

    def _register(self, topic: _Topic) -> None:
        topic.channel_id = register_topic(self._check_open(), self._schema_ids, topic.entry, self._typestore)

    def _finish_file(self) -> None:
        assert self._mcap is not None and self._sink is not None
        try:
            self._mcap.finish()  # type: ignore[no-untyped-call, unused-ignore]  # mcap leaves it unannotated (an error under --strict only)
        except OSError as exc:
            raise BagError(f"{self._sink.path}: cannot finish the file ({exc.strerror or exc})") from None
        finally:
            self._sink.close()

    def _write_layout(self) -> None:
        layout = BagLayout([t.entry for t in self._topics.values()], list(self._files), dict(self._run_context))
        try:
            write_layout(self.path, layout)
        except OSError as exc:
            raise BagError(f"{self.path}: cannot write metadata.yaml ({exc.strerror or exc})") from None
