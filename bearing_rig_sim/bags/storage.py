"""What reading a bag needs from its storage, MCAP (:mod:`.mcapfile`) or SQLite 3 (:mod:`.sqlite`):
a format gives :class:`FileIndex` objects and streams messages in log-time order, nothing else."""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

ProblemSink = Callable[[str], None]
"""Receives a one-line description of each problem met while reading."""


MessageTuple = tuple[int, int, int, bytes]
"""A message as (log_time_ns, channel_id, publish_time_ns, serialized data)."""


@dataclass(frozen=True)
class ChannelInfo:
    """A topic as a storage file holds it; ``msgtype`` is empty when the storage does not say,
    ``metadata`` holds rosbag2's ``offered_qos_profiles`` (YAML) and ``topic_type_hash``."""

    topic: str
    msgtype: str
    encoding: str
    metadata: Mapping[str, str]


@dataclass
class FileIndex:
    """What a storage file (for SQLite 3, a whole bag) holds: ``indexed`` when it was finished
    properly, ``has_header`` False when nothing is readable, message ``definitions`` by type as
    (``ros2msg`` or ``ros2idl``, text), named string maps in ``metadata`` (the run context under
    ``bearing_rig_sim``), one line per problem in ``problems``."""

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
        first = self.message_count == 0
        self.start_ns = log_time if first else min(self.start_ns, log_time)
        self.end_ns = log_time if first else max(self.end_ns, log_time)
        self.message_count += 1
        self.channel_counts[channel_id] = self.channel_counts.get(channel_id, 0) + 1


Item = TypeVar("Item", bound=tuple[Any, ...])


def merge_in_time(streams: Sequence[tuple[int, int, Iterable[Item]]]) -> Iterator[Item]:
    """Merge streams given as (earliest, latest log time, items with the log time first) into
    log-time order; equal times keep the order of the streams by earliest time. Streams that
    follow each other are chained (each read when the one before is done), others merged on a heap."""
    ordered = sorted(streams, key=lambda s: s[0])
    items = [s[2] for s in ordered]
    if all(b[0] >= a[1] for a, b in zip(ordered, ordered[1:])):
        return itertools.chain.from_iterable(items)
    return heapq.merge(*items, key=lambda item: item[0])
