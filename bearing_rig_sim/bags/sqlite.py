"""rosbag2 bags with SQLite 3 storage (``.db3``, docs/bags.md), read through rosbags as one
:class:`~.storage.FileIndex` per bag."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from pathlib import Path

from rosbags.interfaces import ConnectionExtRosbag2, MessageDefinitionFormat
from rosbags.rosbag2 import Reader, ReaderError

from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.layout import qos_yaml
from bearing_rig_sim.bags.storage import ChannelInfo, FileIndex, MessageTuple, ProblemSink

_ENCODINGS = {MessageDefinitionFormat.MSG: "ros2msg", MessageDefinitionFormat.IDL: "ros2idl"}


class Sqlite3Format:
    """SQLite 3 storage, one index per bag."""

    identifier = "sqlite3"

    def indexes(self, bag: Path, files: list[Path]) -> list[FileIndex]:
        """The bag's topics, definitions and statistics; BagError when rosbags cannot open the bag."""
        index = FileIndex(path=bag, indexed=True, has_header=True)
        try:
            with Reader(bag) as reader:
                for conn in reader.connections:
                    ext = conn.ext
                    assert isinstance(ext, ConnectionExtRosbag2)  # a rosbag2 bag's connections
                    metadata = {"offered_qos_profiles": qos_yaml(ext.offered_qos_profiles), "topic_type_hash": conn.digest}
                    index.channels[conn.id] = ChannelInfo(conn.topic, conn.msgtype, ext.serialization_format, metadata)
                    index.channel_counts[conn.id] = conn.msgcount
                    if conn.msgdef.format in _ENCODINGS:
                        index.definitions.setdefault(conn.msgtype, (_ENCODINGS[conn.msgdef.format], conn.msgdef.data))
                index.message_count = reader.message_count
                if reader.message_count:
                    index.start_ns, index.end_ns = reader.start_time, reader.end_time - 1
        except ReaderError as exc:
            raise BagError(f"{bag}: cannot read the SQLite 3 bag ({exc})") from None
        return [index]

    def messages(
        self, index: FileIndex, report: ProblemSink, channel_ids: Iterable[int] | None = None, start_ns: int | None = None, stop_ns: int | None = None
    ) -> Iterator[MessageTuple]:
        """Messages with ``start_ns <= log_time < stop_ns`` in time order, as rosbags reads them."""
        wanted = None if channel_ids is None else set(channel_ids)
        try:
            with Reader(index.path) as reader:
                connections = [c for c in reader.connections if wanted is None or c.id in wanted]
                if connections:
                    for conn, log_time, data in reader.messages(connections, start=start_ns, stop=stop_ns):
                        yield log_time, conn.id, log_time, data
        except ReaderError as exc:
            report(f"{index.path}: reading stopped ({exc})")
