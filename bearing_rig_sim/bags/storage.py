"""The storage seam: what reading a bag needs from its storage, whatever the format.

rosbag2 keeps messages in storage files of the format ``metadata.yaml`` names
(``storage_identifier``): MCAP (:mod:`.mcapfile`; the rosbag2 default since Iron and what this
project records) or SQLite 3 (:mod:`.sqlite`; the default before, what older benches record).
A format turns a bag's storage into :class:`FileIndex` objects (channels, type definitions,
counts, time range, run context, problems) and streams messages in log-time order; the reader,
``bag info`` and the offline analysis see nothing else. The repair of a killed recording is
MCAP's alone (:mod:`.repair`).
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, TypeVar

ProblemSink = Callable[[str], None]
"""Receives a one-line description of each problem met while reading."""

MessageTuple = tuple[int, int, int, bytes]
"""A message as (log_time_ns, channel_id, publish_time_ns, serialized data)."""


@dataclass(frozen=True)
class ChannelInfo:
    """A topic as one storage file (or bag) holds it.

    Attributes:
        topic: topic name.
        msgtype: message type (``pkg/msg/Name``); empty when the storage does not say.
        encoding: message encoding (``cdr``).
        metadata: rosbag2's ``offered_qos_profiles`` (YAML text) and ``topic_type_hash``.
    """

    topic: str
    msgtype: str
    encoding: str
    metadata: Mapping[str, str]


@dataclass
class FileIndex:
    """What a storage file (or, for a format read a bag at a time, a bag) holds.

    Attributes:
        path: the file (or bag directory).
        indexed: True when it was finished properly (its own index is complete).
        has_header: False when nothing at all is readable.
        channels: by the storage's channel id.
        definitions: message definitions the storage carries, by type: (encoding, text) with
            encoding ``ros2msg`` or ``ros2idl``.
        metadata: named string maps (the run context under ``bearing_rig_sim``).
        message_count / channel_counts / start_ns / end_ns: statistics (times in ns).
        problems: what was wrong, one line each.
    """

    path: Path
    indexed: bool = False
    has_header: bool = False
    channels: dict[int, ChannelInfo] = field(default_factory=dict)
    definitions: dict[str, tuple[str, str]] = field(default_factory=dict)
    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    message_count: int = 0
    channel_counts: dict[int, int] = field(default_factory=dict)
    start_ns: int = 0
    end_ns: int = 0
    problems: list[str] = field(default_factory=list)

    def count(self, channel_id: int, log_time: int) -> None:
        """Add one message to the statistics."""
        if self.message_count == 0:
            self.start_ns = self.end_ns = log_time
        else:
            self.start_ns = min(self.start_ns, log_time)
            self.end_ns = max(self.end_ns, log_time)
        self.message_count += 1
        self.channel_counts[channel_id] = self.channel_counts.get(channel_id, 0) + 1


Item = TypeVar("Item", bound=tuple[Any, ...])


def merge_in_time(streams: Sequence[tuple[int, int, Iterable[Item]]]) -> Iterator[Item]:
    """The items of several streams, each given as (earliest, latest log time, items in log-time
    order) with the log time first in every item, in log-time order; equal times keep the order
    of the streams sorted by their earliest time. Streams that follow each other in time are
    chained (each is read when the one before is done), others merged on a heap."""
    ordered = sorted(streams, key=lambda s: s[0])
    items = [s[2] for s in ordered]
    if all(b[0] >= a[1] for a, b in zip(ordered, ordered[1:])):
        return itertools.chain.from_iterable(items)
    return heapq.merge(*items, key=lambda item: item[0])


class StorageFormat(Protocol):
    """One storage format of rosbag2 bags."""

    identifier: str
    """``storage_identifier`` in ``metadata.yaml`` (``"mcap"``, ``"sqlite3"``)."""

    def indexes(self, bag: Path, files: list[Path]) -> list[FileIndex]:
        """What the bag at ``bag`` (a directory, or a single storage file) holds in ``files``;
        damage goes into the indexes' ``problems``.

        Raises:
            BagError: a file is not of this format, or nothing can be read.
        """
        ...

    def messages(
        self,
        index: FileIndex,
        channel_ids: Iterable[int] | None = None,
        start_ns: int | None = None,
        stop_ns: int | None = None,
        report: ProblemSink = ...,
    ) -> Iterator[MessageTuple]:
        """Messages with ``start_ns <= log_time < stop_ns`` in log-time order, streamed;
        damaged parts are reported through ``report`` and skipped."""
        ...
