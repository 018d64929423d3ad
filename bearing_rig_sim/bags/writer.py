"""The recorder: a rosbag2 (format version 9) bag directory with MCAP storage (what it holds:
``docs/bags.md``).

::

    with BagWriter("bags/run-0001", metadata={"configuration": config_text}) as bag:
        bag.add_topic("/rig/speeds", "sensor_msgs/msg/JointState", "sensor_data")
        bag.write("/rig/speeds", sim_time_ns, raw_cdr_bytes)

Time: ``log_time`` is the simulation time in ns, strictly increasing over the whole bag (as
Foxglove's timeline and a faithful replay need): a message whose time is not greater than the
previous one is **nudged** to the previous time + 1 ns (:attr:`BagWriter.nudged_count`); its
``publish_time`` keeps the time it was given.

Robustness: chunks reach the operating system as soon as they are complete and ``metadata.yaml``
is rewritten whenever topics or files change, so a killed recording leaves every complete chunk
readable (:func:`~bearing_rig_sim.bags.repair.repair_bag` restores the index). Leaving the
``with`` block for any reason, Ctrl-C included, finalises the bag.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import IO, Any, Literal, Protocol, cast
from collections.abc import Callable

from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer
from rosbags.typesys.store import Typestore

import bearing_rig_sim
from bearing_rig_sim.bags.cdr import CdrBytes, make_normaliser
from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.layout import (
    RUN_METADATA_RECORD,
    BagLayout,
    FileEntry,
    TopicEntry,
    qos_yaml,
    storage_file_name,
    write_layout,
)
from bearing_rig_sim.bags.qos import QosSpec, qos_spec
from bearing_rig_sim.bags.typestore import msg_definition_text, rig_typestore, type_hash

PROJECT_VERSION_KEY = "project_version"
"""Run-context key the writer always fills with ``bearing_rig_sim.__version__``."""

DEFAULT_CHUNK_SIZE = 1 << 20
"""Uncompressed bytes per chunk (1 MiB: about 2 s of the rig's traffic, the most a kill loses)."""

Compression = Literal["zstd", "none"]
COMPRESSION = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4, "none": CompressionType.NONE, "": CompressionType.NONE}
"""The mcap writer's chunk compression by name (``""`` as a chunk index names none)."""


class McapWriter(Protocol):
    """The methods of mcap's ``Writer`` the project calls (the package carries no annotations)."""

    def register_schema(self, name: str, encoding: str, data: bytes) -> int: ...
    def register_channel(self, topic: str, message_encoding: str, schema_id: int, metadata: dict[str, str]) -> int: ...
    def add_metadata(self, name: str, data: dict[str, str]) -> None: ...
    def add_message(self, channel_id: int, log_time: int, data: bytes, publish_time: int) -> None: ...
    def flush(self) -> None: ...
    def finish(self) -> None: ...


def start_mcap(sink: CountingSink, chunk_size: int, compression: str, profile: str = "ros2", library: str = "") -> McapWriter:
    """An mcap ``Writer`` started on ``sink``, naming this project as the library by default."""
    writer = Writer(cast(IO[Any], sink), chunk_size=chunk_size, compression=COMPRESSION.get(compression, CompressionType.ZSTD))
    writer.start(profile=profile, library=library or f"bearing_rig_sim {bearing_rig_sim.__version__}; {LIBRARY_IDENTIFIER}")
    return cast(McapWriter, writer)


def register_topic(mcap: McapWriter, schema_ids: dict[str, int], topic: TopicEntry, typestore: Typestore) -> int:
    """Register a topic's channel as rosbag2 does (a ``ros2msg`` schema per type, registered once
    in ``schema_ids``; offered QoS and type hash in the channel metadata); returns its id."""
    schema_id = schema_ids.get(topic.msgtype)
    if schema_id is None:
        text = msg_definition_text(topic.msgtype, typestore)
        schema_id = schema_ids[topic.msgtype] = mcap.register_schema(topic.msgtype, "ros2msg", text.encode())
    metadata = {"offered_qos_profiles": qos_yaml(topic.qos), "topic_type_hash": topic.type_hash or type_hash(topic.msgtype, typestore)}
    return mcap.register_channel(topic.name, topic.serialization_format, schema_id, metadata)


class CountingSink:
    """Unbuffered output file that counts the bytes written: every chunk the MCAP writer finishes
    survives a kill of the recording process, and files are split by size without a system call."""

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
    name: str
    msgtype: str
    qos: QosSpec
    type_hash: str
    normalise: Callable[[CdrBytes], CdrBytes]
    channel_id: int = 0
    count: int = 0

    def entry(self) -> TopicEntry:
        """The topic as ``metadata.yaml`` states it."""
        return TopicEntry(self.name, self.msgtype, [self.qos.to_rosbags()], self.type_hash, self.count)


class BagWriter:
    """Writes a rosbag2 v9 bag directory with MCAP storage (see the module documentation).

    The bag directory is created when the writer is constructed; :meth:`close` (or leaving the
    ``with`` block) finalises it.

    Args:
        path: bag directory to create (must not exist, or be empty).
        compression: chunk compression, ``"zstd"`` or ``"none"``.
        chunk_size: uncompressed bytes per chunk (>= 1024).
        max_file_bytes: start a new ``.mcap`` file once the current one reaches this size (the
            file is closed at the next chunk boundary, so it may exceed the limit by one chunk
            and its summary); None for a single file.
        metadata: run context as string key/value pairs (configuration, calibration, test
            program text...); ``project_version`` is added.
        typestore: types to accept; default :func:`~bearing_rig_sim.bags.typestore.rig_typestore`.

    Raises:
        BagError: bad option, or the path exists and is not an empty directory.
    """

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

        self._path = Path(path)
        if self._path.exists() and (not self._path.is_dir() or any(self._path.iterdir())):
            raise BagError(f"{self._path}: exists already and is not an empty directory, not overwriting")
        try:
            self._path.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise BagError(f"{self._path}: cannot create the bag directory ({exc.strerror or exc})") from None

        self._compression = compression
        self._chunk_size = chunk_size
        self._max_file_bytes = max_file_bytes
        self._run_context = run_context
        self._typestore = typestore if typestore is not None else rig_typestore()
        self._topics: dict[str, _Topic] = {}
        self._files: list[FileEntry] = []
        self._last_time = -1
        self._nudged = 0
        self._sink: CountingSink | None = None
        self._mcap: McapWriter | None = None
        self._schema_ids: dict[str, int] = {}
        self._start_file()

    # -- public API -------------------------------------------------------------------------

    @property
    def path(self) -> Path:
        """The bag directory."""
        return self._path

    @property
    def message_count(self) -> int:
        """Messages written so far."""
        return sum(f.message_count for f in self._files)

    @property
    def nudged_count(self) -> int:
        """Messages whose log time was moved forward to keep log times strictly increasing."""
        return self._nudged

    @property
    def files(self) -> list[Path]:
        """Storage files written so far (the last one is open until :meth:`close`)."""
        return [self._path / f.path for f in self._files]

    @property
    def closed(self) -> bool:
        """True once :meth:`close` has finalised the bag."""
        return self._mcap is None

    def add_topic(self, name: str, msgtype: str, qos: str | QosSpec = "reliable") -> None:
        """Declare a topic before writing to it.

        Args:
            name: fully qualified topic name, e.g. ``/rig/speeds``.
            msgtype: ``pkg/msg/Name`` (or ``pkg/Name``), a ROS 2 Jazzy or ``bearing_rig_msgs`` type.
            qos: the offered QoS: ``"reliable"``, ``"sensor_data"``, ``"transient_local"`` or a
                :class:`~bearing_rig_sim.bags.qos.QosSpec`.

        Raises:
            BagError: bag closed, bad name, unknown type, or the topic exists with another type
                or QoS.
        """
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
            if existing.msgtype == msgtype and existing.qos == spec:
                return
            raise BagError(f"topic {name} was added as {existing.msgtype} ({existing.qos}); cannot add it as {msgtype} ({spec})")
        topic = _Topic(
            name=name,
            msgtype=msgtype,
            qos=spec,
            type_hash=type_hash(msgtype, self._typestore),
            normalise=make_normaliser(self._typestore, msgtype),
        )
        self._topics[name] = topic
        self._register(topic)
        self._write_layout()

    def write(self, topic: str, log_time_ns: int, data: CdrBytes) -> None:
        """Record one serialized message (CDR with its 4-byte encapsulation header, as from
        ``rclpy.serialization.serialize_message`` or a raw subscription).

        Trailing Fast-CDR padding is trimmed (see :mod:`bearing_rig_sim.bags.cdr`).

        Args:
            topic: a topic declared with :meth:`add_topic`.
            log_time_ns: simulation time (ns, >= 0); nudged to keep log times strictly increasing.
            data: the serialized message.

        Raises:
            BagError: bag closed, unknown topic, bad time, or bytes that are not a message of
                the topic's type.
        """
        entry = self._topic(topic)
        if not isinstance(data, (bytes, bytearray, memoryview)):
            raise BagError(f"topic {topic}: data must be serialized bytes, got {type(data).__name__}")
        try:
            data = entry.normalise(data)
        except BagError as exc:
            raise BagError(f"topic {topic}: {exc}") from None
        self._append(entry, log_time_ns, data)

    def write_message(self, topic: str, log_time_ns: int, message: object) -> None:
        """Serialize a rosbags message object with the type store and record it.

        Raises:
            BagError: as :meth:`write`, or the message is not of the topic's type.
        """
        entry = self._topic(topic)
        msgtype = getattr(message, "__msgtype__", None)
        if msgtype != entry.msgtype:
            raise BagError(f"topic {topic} carries {entry.msgtype}, got a {msgtype or type(message).__name__}")
        try:
            data = bytes(self._typestore.serialize_cdr(message, msgtype))
        except Exception as exc:  # rosbags raises several classes for bad field values
            raise BagError(f"topic {topic}: cannot serialize the {msgtype} ({exc})") from None
        self._append(entry, log_time_ns, data)

    def flush(self) -> None:
        """Finish the chunk in progress and refresh ``metadata.yaml``: everything written so far
        then survives a kill. Each call costs a smaller chunk (less compression)."""
        self._check_open()
        assert self._mcap is not None
        self._mcap.flush()
        self._write_layout()

    def close(self) -> None:
        """Finalise: write the last chunk, the summary and the final ``metadata.yaml``.
        Calling it again does nothing.

        Raises:
            BagError: the file could not be completed (disk full...).
        """
        if self._mcap is None:
            return
        try:
            self._finish_file()
        finally:
            self._mcap = None
        self._write_layout()

    def __enter__(self) -> BagWriter:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> Literal[False]:
        """Finalise the bag whatever ended the block (an exception, Ctrl-C included)."""
        try:
            self.close()
        except Exception:
            if exc_type is None:
                raise
        return False

    # -- internals --------------------------------------------------------------------------

    def _check_open(self) -> None:
        if self._mcap is None:
            raise BagError(f"{self._path}: the bag is closed")

    def _topic(self, name: str) -> _Topic:
        entry = self._topics.get(name)
        if entry is None:
            self._check_open()
            raise BagError(f"topic {name!r} was not added to the bag (call add_topic first)")
        return entry

    def _append(self, entry: _Topic, log_time_ns: int, data: CdrBytes) -> None:
        mcap = self._mcap
        if mcap is None:
            self._check_open()
        if type(log_time_ns) is not int:
            try:
                log_time_ns = operator.index(log_time_ns)
            except TypeError:
                raise BagError(f"topic {entry.name}: log time must be an integer of nanoseconds, got {log_time_ns!r}") from None
        if log_time_ns < 0 or log_time_ns >= 2**63:
            raise BagError(f"topic {entry.name}: log time {log_time_ns} ns is outside 0 .. 2**63-1")
        # A full file is closed when the next message comes, not after the last one written, so
        # that no file is left without messages (and without a chunk) at the end of the bag.
        if self._max_file_bytes is not None and self._sink is not None and self._sink.position >= self._max_file_bytes and self._files[-1].message_count:
            self._finish_file()
            self._start_file()
            mcap = self._mcap
        log_time = log_time_ns
        if log_time <= self._last_time:
            log_time = self._last_time + 1
            self._nudged += 1
        assert mcap is not None
        mcap.add_message(entry.channel_id, log_time, cast(bytes, data), log_time_ns)  # mcap takes any buffer
        self._last_time = log_time
        entry.count += 1
        current = self._files[-1]
        if current.message_count == 0:
            current.start_ns = log_time
        current.duration_ns = log_time - current.start_ns
        current.message_count += 1

    def _start_file(self) -> None:
        name = storage_file_name(self._path, len(self._files))
        self._sink = CountingSink(self._path / name)
        self._mcap = start_mcap(self._sink, self._chunk_size, self._compression)
        self._mcap.add_metadata(RUN_METADATA_RECORD, dict(self._run_context))
        self._schema_ids = {}
        self._files.append(FileEntry(path=name))
        for topic in self._topics.values():
            self._register(topic)
        self._write_layout()

    def _register(self, topic: _Topic) -> None:
        assert self._mcap is not None
        topic.channel_id = register_topic(self._mcap, self._schema_ids, topic.entry(), self._typestore)

    def _finish_file(self) -> None:
        assert self._mcap is not None and self._sink is not None
        try:
            self._mcap.finish()
        except OSError as exc:
            raise BagError(f"{self._sink.path}: cannot finish the file ({exc.strerror or exc})") from None
        finally:
            self._sink.close()

    def _write_layout(self) -> None:
        layout = BagLayout([t.entry() for t in self._topics.values()], list(self._files), dict(self._run_context))
        try:
            write_layout(self._path, layout)
        except OSError as exc:
            raise BagError(f"{self._path}: cannot write metadata.yaml ({exc.strerror or exc})") from None
