"""What the session records, and the log-time rule (no ROS).

Every topic of the interface table (README) is recorded as the serialized CDR the publisher sent
(:data:`RECORDED_TOPICS`), into anything with ``add_topic`` and ``write`` (the project's
:class:`~bearing_rig_sim.bags.BagWriter`, or a fake in tests).

**Log time** (the bag's timeline; the MCAP ``log_time``), simulation time in ns:

1. the message's own stamp when it has one (``header.stamp``; ``clock`` for ``/clock``): the first
   ``builtin_interfaces/Time`` after the 4-byte CDR encapsulation header, read without decoding;
   a ``/clock`` stamp the :class:`~bearing_rig_sim.clock_guard.ClockGuard` refuses (negative, or a
   jump back or far ahead that the next stamps do not confirm) is recorded at the time of the
   last accepted ``/clock`` and does not move the rule's clock: a stray publisher cannot put the
   bag's timeline in 2038;
2. else (``std_msgs/Float64`` set-points), or when the stamp is zero (not set) or more than
   :data:`PLAUSIBLE_SPAN_NS` away from the last ``/clock`` (a wall-clock stamp from some other
   publisher), the time of the last ``/clock`` received before it; so too a spindle command or a
   load set-point stamped ahead of that ``/clock`` (:data:`STAMPED_AHEAD`): its stamp is when it
   is to take effect (the session sends the next segment's ahead), and logged there it would drag
   the timeline of every message received meanwhile up to it (rule 3); it is logged when
   received, its header keeps the stamp (``analyze`` starts the segment there);
3. strictly increasing over the bag: messages taken together (one drain of the subscriptions) are
   ordered by that time (ties keep their arrival order), and a time not after the previous one
   becomes previous + 1 ns. A stamp earlier than the last message written (a pulse interpolated
   inside a step that arrives after the next ``/clock``) is so moved forward, by at most the time
   between two drains; its header keeps the exact stamp.
"""

from __future__ import annotations

from typing import Protocol
from collections.abc import Iterable, Sequence

from bearing_rig_sim.bags.cdr import header_stamp_ns
from bearing_rig_sim.clock_guard import DEFAULT_MAX_STEP_NS, ClockGuard
from bearing_rig_sim.interfaces import CLOCK, LOAD_SETPOINT, SPINDLE_COMMAND, TOPICS, Topic

__all__ = [
    "PLAUSIBLE_SPAN_NS",
    "RECORDED_TOPICS",
    "LogTimeRule",
    "MessageWriter",
    "RecordedTopic",
    "SessionRecorder",
    "header_stamp_ns",
]

PLAUSIBLE_SPAN_NS = DEFAULT_MAX_STEP_NS
"""A stamp further than this (10 s) from the last ``/clock`` is not sim time: the clock's time is
used (the largest step the clock guard accepts as the same clock)."""


RecordedTopic = Topic
"""A topic the session records: a topic of the interface contract."""

RECORDED_TOPICS: tuple[Topic, ...] = TOPICS
"""Every topic of the interface contract (services are not recorded)."""

CLOCK_TOPIC = CLOCK.name

STAMPED_AHEAD = frozenset({SPINDLE_COMMAND.name, LOAD_SETPOINT.name})
"""Topics whose stamp is when the message takes effect, which the session sends ahead of it."""

MAX_CLOCK_NOTES = 20
"""Most notes about refused ``/clock`` stamps kept (the count is kept whole)."""


class MessageWriter(Protocol):
    """What the recorder writes into (:class:`~bearing_rig_sim.bags.BagWriter`'s methods)."""

    def add_topic(self, name: str, msgtype: str, qos: str) -> None: ...

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None: ...


class LogTimeRule:
    """Rules 1 and 2 of the module documentation: the sim time a message belongs to."""

    def __init__(self, plausible_span_ns: int = PLAUSIBLE_SPAN_NS) -> None:
        self.plausible_span_ns = plausible_span_ns
        self.last_clock_ns = 0
        """Time of the last ``/clock`` seen, ns (0 before the first)."""
        self.clock_count = 0
        """``/clock`` messages seen."""
        self.clock_guard = ClockGuard()
        """Validates each ``/clock`` stamp; its ``refused`` counts the stamps kept off the timeline."""
        self.clock_notes: list[str] = []
        """The guard's notes (refusals, confirmed jumps), the first :data:`MAX_CLOCK_NOTES`."""

    def sim_time_ns(self, topic: RecordedTopic, data: bytes | bytearray | memoryview) -> int:
        """The message's sim time, ns; a ``/clock`` message also advances the rule's clock."""
        stamp = header_stamp_ns(data) if topic.stamped else None
        if topic.name == CLOCK_TOPIC:
            if stamp is not None:
                verdict = self.clock_guard.check(stamp)
                if verdict.note and len(self.clock_notes) < MAX_CLOCK_NOTES:
                    self.clock_notes.append(verdict.note)
                if verdict.accepted:
                    self.last_clock_ns = stamp
                    self.clock_count += 1
            return self.last_clock_ns
        if stamp is None or stamp <= 0 or abs(stamp - self.last_clock_ns) > self.plausible_span_ns:
            return self.last_clock_ns
        if topic.name in STAMPED_AHEAD and stamp > self.last_clock_ns:
            return self.last_clock_ns
        return stamp


class SessionRecorder:
    """Declares the recorded topics on a writer and writes messages with their log time.

    Args:
        writer: where messages go (``add_topic`` is called for every topic here).
        topics: the topics to record.
    """

    def __init__(self, writer: MessageWriter, topics: Sequence[RecordedTopic] = RECORDED_TOPICS) -> None:
        self.writer = writer
        self.topics = {t.name: t for t in topics}
        self.rule = LogTimeRule()
        self.last_log_ns = -1
        """Log time of the last message written, ns."""
        self.counts: dict[str, int] = {t.name: 0 for t in topics}
        """Messages written per topic."""
        self.moved = 0
        """Messages whose log time was moved forward to keep the timeline strictly increasing."""
        for topic in topics:
            writer.add_topic(topic.name, topic.msgtype, topic.qos)

    @property
    def sim_time(self) -> float:
        """Time of the last ``/clock`` recorded, s."""
        return self.rule.last_clock_ns * 1e-9

    def record_batch(self, messages: Iterable[tuple[str, bytes]]) -> list[int]:
        """Write ``(topic, serialized message)`` pairs given in arrival order (rule 3).

        Returns:
            The log times written, ns, in the order written.

        Raises:
            KeyError: a topic that is not recorded.
        """
        timed = []
        for order, (name, data) in enumerate(messages):
            topic = self.topics[name]
            timed.append((self.rule.sim_time_ns(topic, data), order, name, data))
        timed.sort(key=lambda item: (item[0], item[1]))
        written = []
        for candidate, _order, name, data in timed:
            log_time = candidate
            if log_time <= self.last_log_ns:
                log_time = self.last_log_ns + 1
                self.moved += 1
            self.writer.write(name, log_time, data)
            self.last_log_ns = log_time
            self.counts[name] += 1
            written.append(log_time)
        return written

    def record(self, name: str, data: bytes) -> int:
        """Write one message; returns its log time, ns."""
        return self.record_batch([(name, data)])[0]
