"""A full check of a bag: every chunk decompressed and checksummed, the timeline looked at.

Opening a bag reads its index only, where a chunk damaged after the recording still looks fine.
:func:`verify_indexes` reads every message once: a chunk that fails is named, messages the index
counts but no chunk delivers are unreadable, and log times are grouped into stretches with no gap
over :data:`TIMELINE_GAP_NS`; every stretch but the largest is a log-time outlier (a stamp from
another clock). Memory stays bounded: messages come in time order, only stretches are kept.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

from bearing_rig_sim.bags.storage import FileIndex, MessageTuple, merge_in_time
from bearing_rig_sim.clock_guard import DEFAULT_MAX_STEP_NS

TIMELINE_GAP_NS = DEFAULT_MAX_STEP_NS
"""A gap over this (10 s, the largest step the clock guard accepts) splits the timeline."""


@dataclass
class Stretch:
    """Log times with no gap over :data:`TIMELINE_GAP_NS` between neighbours (ns)."""

    start_ns: int
    end_ns: int
    count: int


@dataclass
class BagCheck:
    """What :func:`verify_indexes` found: a line per damaged chunk, messages read and counted by
    the indexes, the timeline's stretches in time order."""

    damaged: list[str] = field(default_factory=list)
    messages_read: int = 0
    messages_indexed: int = 0
    stretches: list[Stretch] = field(default_factory=list)

    @property
    def messages_unreadable(self) -> int:
        """Messages counted by the index that no chunk delivered."""
        return max(0, self.messages_indexed - self.messages_read)

    @property
    def main(self) -> Stretch | None:
        """The stretch with the most messages."""
        return max(self.stretches, key=lambda s: s.count, default=None)

    @property
    def outliers(self) -> list[Stretch]:
        """Every stretch but the main one."""
        return [s for s in self.stretches if s is not self.main]

    def problems(self) -> list[str]:
        """One line per finding (empty for a sound bag)."""
        lines = list(self.damaged)
        if self.messages_unreadable:
            share = 100.0 * self.messages_unreadable / self.messages_indexed
            lines.append(f"{self.messages_unreadable} of {self.messages_indexed} messages ({share:.1f} %) are in chunks that cannot be read")
        main = self.main
        for s in self.outliers:
            assert main is not None  # there are outliers only beside a main stretch
            after = s.start_ns > main.end_ns
            distance = (s.start_ns - main.end_ns) if after else (main.start_ns - s.end_ns)
            lines.append(
                f"log-time outliers: {s.count} message(s) at {s.start_ns * 1e-9:.3f}-{s.end_ns * 1e-9:.3f} s, "
                f"{distance * 1e-9:.3f} s {'after' if after else 'before'} the main timeline ({main.start_ns * 1e-9:.3f}-"
                f"{main.end_ns * 1e-9:.3f} s, {main.count} messages)"
            )
        return lines


def verify_indexes(indexes: list[FileIndex], messages: Callable[..., Iterator[MessageTuple]]) -> BagCheck:
    """Read every message of the files with their format's ``messages`` (see the module documentation)."""
    check = BagCheck(messages_indexed=sum(i.message_count for i in indexes))
    streams = [(i.start_ns, i.end_ns, messages(i, report=check.damaged.append)) for i in indexes]
    for log_time, _channel, _publish, _data in merge_in_time(streams):
        check.messages_read += 1
        last = check.stretches[-1] if check.stretches else None
        if last is not None and log_time - last.end_ns <= TIMELINE_GAP_NS:
            last.end_ns = max(last.end_ns, log_time)
            last.count += 1
        else:
            check.stretches.append(Stretch(log_time, log_time, 1))
    return check
