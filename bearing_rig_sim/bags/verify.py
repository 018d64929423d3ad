"""A full check of a bag's contents: every chunk decompressed and checksummed, the timeline looked at.

Opening a bag reads its index only (fast, and enough to list topics and counts); a chunk whose
bytes were damaged after the recording (a bad disk, a truncated copy) still looks fine there.
:func:`verify_bag` reads every chunk once:

* **Chunks**: each is read through the bag's storage format (:mod:`.storage`; for MCAP
  decompressed and its CRC-32 compared); a chunk that fails is named, and the messages the index
  promised but no chunk delivered are counted as unreadable.
* **Timeline**: the log times of all readable messages are grouped into stretches with no gap
  longer than :data:`TIMELINE_GAP_NS`; a healthy recording is one stretch. Every stretch but the
  largest is reported as log-time outliers (a stamp from another clock, a ``/clock`` far in the
  future that became the recording's time).

Memory stays bounded: messages come in log-time order and only the stretches are kept.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from collections.abc import Callable, Iterator

from bearing_rig_sim.bags.storage import FileIndex, MessageTuple

__all__ = ["TIMELINE_GAP_NS", "BagCheck", "Stretch", "verify_indexes"]

TIMELINE_GAP_NS = 10_000_000_000
"""A gap of more than 10 s between two consecutive log times splits the timeline. The rig's
recordings carry /clock at 1 kHz; the session's recorder treats a stamp 10 s from the clock as
not sim time, with the same bound."""


@dataclass
class Stretch:
    """Log times with no gap over :data:`TIMELINE_GAP_NS` between neighbours (ns)."""

    start_ns: int
    end_ns: int
    count: int


@dataclass
class BagCheck:
    """What :func:`verify_indexes` found."""

    damaged: list[str] = field(default_factory=list)
    """One line per chunk that failed to decompress or whose checksum did not match."""
    messages_read: int = 0
    """Messages delivered by the chunks."""
    messages_indexed: int = 0
    """Messages the files' indexes (statistics) count."""
    stretches: list[Stretch] = field(default_factory=list)
    """The timeline's stretches, in time order."""

    @property
    def messages_unreadable(self) -> int:
        """Messages counted by the index that no chunk delivered."""
        return max(0, self.messages_indexed - self.messages_read)

    @property
    def outliers(self) -> list[Stretch]:
        """Every stretch but the one with the most messages."""
        if len(self.stretches) < 2:
            return []
        main = max(self.stretches, key=lambda s: s.count)
        return [s for s in self.stretches if s is not main]

    def problems(self) -> list[str]:
        """One line per finding (empty for a sound bag)."""
        lines = list(self.damaged)
        if self.messages_unreadable:
            share = 100.0 * self.messages_unreadable / self.messages_indexed
            lines.append(
                f"{self.messages_unreadable} of {self.messages_indexed} messages ({share:.1f} %) are in chunks that "
                "cannot be read"
            )
        if self.outliers:
            main = max(self.stretches, key=lambda s: s.count)
            for s in self.outliers:
                side = "after" if s.start_ns > main.end_ns else "before"
                distance = (s.start_ns - main.end_ns) if side == "after" else (main.start_ns - s.end_ns)
                lines.append(
                    f"log-time outliers: {s.count} message(s) at {s.start_ns * 1e-9:.3f}-{s.end_ns * 1e-9:.3f} s, "
                    f"{distance * 1e-9:.3f} s {side} the main timeline ({main.start_ns * 1e-9:.3f}-"
                    f"{main.end_ns * 1e-9:.3f} s, {main.count} messages)"
                )
        return lines


def _merge(stretches: list[Stretch]) -> list[Stretch]:
    """Stretches that overlap or lie within the gap of each other, joined; in time order."""
    merged: list[Stretch] = []
    for s in sorted(stretches, key=lambda s: s.start_ns):
        if merged and s.start_ns - merged[-1].end_ns <= TIMELINE_GAP_NS:
            last = merged[-1]
            last.end_ns = max(last.end_ns, s.end_ns)
            last.count += s.count
        else:
            merged.append(Stretch(s.start_ns, s.end_ns, s.count))
    return merged


def verify_indexes(indexes: list[FileIndex], messages: Callable[..., Iterator[MessageTuple]]) -> BagCheck:
    """Read every message of the indexed files with their storage format's ``messages`` (see
    the module documentation)."""
    check = BagCheck()
    pieces: list[Stretch] = []
    for index in indexes:
        check.messages_indexed += index.message_count
        current: Stretch | None = None
        for log_time, _channel, _publish, _data in messages(index, report=check.damaged.append):
            check.messages_read += 1
            if current is not None and log_time - current.end_ns <= TIMELINE_GAP_NS:
                current.end_ns = max(current.end_ns, log_time)
                current.count += 1
            else:
                current = Stretch(log_time, log_time, 1)
                pieces.append(current)
    check.stretches = _merge(pieces)
    return check
