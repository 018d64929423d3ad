"""Replaying a bag into a ROS 2 graph: its messages with their original timing, and ``/clock``.

::

    with open_bag("bags/run") as bag, RosReplaySink(bag.topics) as sink:
        stats = replay_bag(bag, sink, ReplayOptions(rate=2.0))

**Timing.** A message recorded at log time ``L`` is published at wall time
``w0 + (L - L0) / rate``, ``L0`` the first log time of the replayed range and ``w0`` the moment
the replay (or the loop) started. Deadlines are absolute: a slow publish makes the next message
late by at most its own delay, never the rest of the bag (no drift). No message is published
before it is due, and ``w0`` is taken after the range's first ``/clock`` was published, so every
message leaves at least ``(L - L0) / rate`` after that first ``/clock``. A message that is late is
published at once, never dropped. :class:`ReplaySchedule` is that rule with an injectable clock
(no ROS), so it is tested with a fake one.

**/clock.** Nodes on ``use_sim_time`` follow the bag's time: a bag holding ``/clock`` has it
replayed as recorded; otherwise ``/clock`` is made from the log time every ``1 / clock_hz`` of
bag time (and at the range's start). Each loop (``loop=True``) starts by publishing the range's
first time, a jump backwards the monitor treats as a reset.

**Messages** are republished as the raw CDR bytes recorded (no decoding), by rclpy publishers of
the recorded types, imported from the installed interface packages by name
(``bearing_rig_msgs/msg/SlipStatus`` -> ``bearing_rig_msgs.msg.SlipStatus``); a type that is not
installed is warned about and its topic skipped. Each topic is offered with the QoS recorded in
the bag, else the interface contract's (:func:`~bearing_rig_sim.interfaces.contract_qos`), else reliable.

The schedule and the player (:func:`replay_bag`) import no ROS; :class:`RosReplaySink` imports
rclpy when it is made.
"""

from __future__ import annotations

import heapq
import importlib
import importlib.util
import itertools
import re
import struct
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any, Literal, Protocol, cast
from collections.abc import Iterable, Iterator

from bearing_rig_sim.config import ConfigError, check_number
from bearing_rig_sim.bags.errors import BagError, BagWarning
from bearing_rig_sim.bags.qos import QOS_PROFILES, QosSpec
from bearing_rig_sim.bags.reader import BagReader, TopicInfo
from bearing_rig_sim.interfaces import CLOCK, contract_qos

CLOCK_TOPIC = CLOCK.name
CLOCK_TYPE = CLOCK.msgtype


def clock_message(time_ns: int) -> bytes:
    """A serialized ``rosgraph_msgs/Clock`` (little-endian CDR) for a time in ns (>= 0)."""
    sec, nanosec = divmod(time_ns, 1_000_000_000)
    return b"\x00\x01\x00\x00" + struct.pack("<iI", sec, nanosec)


def _check_rate(rate: float) -> float:
    return check_number(rate, "replay", "rate", gt=0.0)


class ReplayClock(Protocol):
    """Where the schedule reads the time and waits (monotonic seconds)."""

    def now(self) -> float: ...

    def sleep(self, seconds: float) -> None: ...


class MonotonicClock:
    """The wall clock: ``time.monotonic`` and ``time.sleep``."""

    def now(self) -> float:
        """Monotonic time, s."""
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        """Sleep ``seconds`` (s, > 0)."""
        time.sleep(seconds)


class ReplaySchedule:
    """When each message is due (see the module documentation).

    Args:
        rate: bag seconds per wall second (> 0; 2 replays twice as fast).
        clock: the clock to read and wait on.

    Raises:
        ConfigError: a rate that is not a finite number > 0.
    """

    def __init__(self, rate: float, clock: ReplayClock) -> None:
        self.rate = _check_rate(rate)
        self.clock = clock
        self._wall0 = 0.0
        self._log0 = 0

    def start(self, log_time_ns: int) -> None:
        """Start (or restart, for a loop) now, at bag time ``log_time_ns``."""
        self._wall0 = self.clock.now()
        self._log0 = log_time_ns

    def due(self, log_time_ns: int) -> float:
        """Wall time (the clock's) at which a message of log time ``log_time_ns`` is due, s."""
        return self._wall0 + (log_time_ns - self._log0) * 1e-9 / self.rate

    def wait(self, log_time_ns: int) -> float:
        """Wait until the message is due; returns how late it is then, s (>= 0)."""
        deadline = self.due(log_time_ns)
        now = self.clock.now()
        while now < deadline:  # never early, whatever the sleep's rounding
            self.clock.sleep(deadline - now)
            now = self.clock.now()
        return now - deadline


class ReplaySink(Protocol):
    """Where replayed messages go (:class:`RosReplaySink`, or a list in tests)."""

    def publish(self, topic: str, data: bytes) -> None: ...

    def can_publish(self, topic: str) -> bool: ...


@dataclass(frozen=True)
class ReplayOptions:
    """What :func:`replay_bag` replays (checked when made: :class:`ConfigError` names a bad one).

    Attributes:
        rate: bag seconds per wall second (> 0).
        loop: start again at the end, until interrupted (or ``max_loops``).
        topics: topics to replay; None for all (``/clock`` is always published).
        start: seconds after the bag's first message where the replay starts (>= 0).
        duration: bag seconds to replay from there; None to the end.
        clock_hz: rate of the ``/clock`` made from the log time when the bag has none, per bag
            second (> 0).
        max_loops: with ``loop``, stop after this many passes (None: never).
    """

    rate: float = 1.0
    loop: bool = False
    topics: tuple[str, ...] | None = None
    start: float = 0.0
    duration: float | None = None
    clock_hz: float = 100.0
    max_loops: int | None = None

    def __post_init__(self) -> None:
        _check_rate(self.rate)
        check_number(self.start, "replay", "start", ge=0.0)
        if self.duration is not None:
            check_number(self.duration, "replay", "duration", gt=0.0)
        check_number(self.clock_hz, "replay", "clock_hz", gt=0.0)
        if self.max_loops is not None and self.max_loops < 1:
            raise ConfigError("replay", "max_loops", f"must be >= 1, got {self.max_loops!r}")


@dataclass
class ReplayStats:
    """What a replay did: messages per topic, clock messages, passes, lateness (s)."""

    published: dict[str, int] = field(default_factory=dict)
    clock_messages: int = 0
    loops: int = 0
    max_late: float = 0.0
    total_late: float = 0.0
    skipped_topics: list[str] = field(default_factory=list)

    @property
    def message_count(self) -> int:
        """Messages published, ``/clock`` included."""
        return sum(self.published.values()) + self.clock_messages

    def summary(self) -> str:
        """One line for a person."""
        count = self.message_count
        mean = self.total_late / count if count else 0.0
        return (
            f"{count} messages published in {self.loops} pass(es) ({self.clock_messages} on {CLOCK.name}); "
            f"lateness mean {mean * 1e3:.3g} ms, max {self.max_late * 1e3:.3g} ms"
        )


def _clock_ticks(first_ns: int, last_ns: int, period_ns: int) -> Iterator[tuple[int, int, str, bytes]]:
    for time_ns in range(first_ns, last_ns + 1, period_ns):
        yield time_ns, 0, CLOCK_TOPIC, clock_message(time_ns)


def check_topics(bag: BagReader, topics: Iterable[str] | None) -> list[str]:
    """The topics to replay: ``topics`` (duplicates removed) or all of the bag's.

    Raises:
        BagError: a topic is not in the bag (the message names it and lists the bag's).
    """
    available = bag.topics
    wanted = list(available) if topics is None else list(dict.fromkeys(topics))
    unknown = sorted(set(wanted) - set(available))
    if unknown:
        raise BagError(f"{bag.path}: no topic {', '.join(unknown)} in the bag (it has {', '.join(sorted(available)) or 'none'})")
    return wanted


def replay_bag(
    bag: BagReader,
    sink: ReplaySink,
    options: ReplayOptions,
    clock: ReplayClock | None = None,
) -> ReplayStats:
    """Publish the bag's messages into ``sink`` on the schedule of the module documentation.

    Raises:
        BagError: a topic of ``options.topics`` is not in the bag, or the range holds no message.
        KeyboardInterrupt: passed on (the caller cleans up); the stats so far are lost.
    """
    clock = clock if clock is not None else MonotonicClock()
    schedule = ReplaySchedule(options.rate, clock)
    wanted = check_topics(bag, options.topics)
    stats = ReplayStats()
    stats.skipped_topics = [t for t in wanted if not sink.can_publish(t)]
    publish_clock = sink.can_publish(CLOCK_TOPIC)
    bag_clock = publish_clock and CLOCK_TOPIC in bag.topics
    selected = [t for t in wanted if t not in stats.skipped_topics]
    if bag_clock and CLOCK_TOPIC not in selected:
        selected.append(CLOCK_TOPIC)
    first = bag.start_ns + int(round(options.start * 1e9))
    stop = None if options.duration is None else first + int(round(options.duration * 1e9))
    last = bag.end_ns if stop is None else min(bag.end_ns, stop - 1)
    if first > last:
        raise BagError(f"{bag.path}: nothing to replay: --start {options.start:g} s is past the bag's {bag.duration_ns * 1e-9:g} s")
    period_ns = max(1, int(round(1e9 / options.clock_hz)))
    for loop in itertools.count():
        if options.max_loops is not None and loop >= options.max_loops:
            break
        messages: Iterator[tuple[int, int, str, bytes]] = (
            (m.log_time_ns, 1, m.topic, cast(bytes, m.message)) for m in bag.messages(selected, start_ns=first, stop_ns=stop, raw=True)
        )
        if publish_clock and not bag_clock:
            messages = heapq.merge(_clock_ticks(first + period_ns, last, period_ns), messages)
        head = next(messages, None)  # the first chunk is read before the clock starts
        if publish_clock:
            sink.publish(CLOCK_TOPIC, clock_message(first))
            stats.clock_messages += 1
        schedule.start(first)  # after the first /clock left: no message is due before it was sent
        for log_time_ns, _order, topic, data in itertools.chain([head] if head is not None else [], messages):
            late = schedule.wait(log_time_ns)
            sink.publish(topic, data)
            stats.max_late = max(stats.max_late, late)
            stats.total_late += late
            if topic == CLOCK_TOPIC:
                stats.clock_messages += 1
            else:
                stats.published[topic] = stats.published.get(topic, 0) + 1
        stats.loops += 1
        if not options.loop:
            break
    return stats


# ---------------------------------------------------------------------------------------------
# The ROS side
# ---------------------------------------------------------------------------------------------
PACKAGE_NAME = re.compile(r"[a-z][a-z0-9_]*")
"""A ROS package name (REP 144): lower-case letters, digits and underscores, a letter first."""
MESSAGE_NAME = re.compile(r"[A-Z][A-Za-z0-9]*")
"""A message type name: CamelCase letters and digits."""


def is_interface_package(name: str) -> bool:
    """Whether ``name`` is an installed ROS interface package, found without running any of it.

    A bag names its types itself, so a crafted bag could name any module (``venv.__main__``):
    only a valid package name whose installed folder holds the ``msg`` subpackage and the C type
    support library rosidl generates (``<name>_s__rosidl_typesupport_c*``) counts.
    """
    if not PACKAGE_NAME.fullmatch(name):
        return False
    try:
        spec = importlib.util.find_spec(name)  # a top-level name: located, not executed
    except (ImportError, ValueError):
        return False
    if spec is None or not spec.submodule_search_locations:
        return False
    for location in spec.submodule_search_locations:
        folder = Path(location)
        if (folder / "msg" / "__init__.py").is_file() and any(folder.glob(f"{name}_s__rosidl_typesupport_c*")):
            return True
    return False


def message_class(msgtype: str) -> type | None:
    """The generated Python class of ``pkg/msg/Name`` from the installed interface packages;
    None when the name is malformed, or the package is not an installed interface package
    (:func:`is_interface_package`: nothing else is imported), or the type is not in it."""
    parts = msgtype.split("/")
    if len(parts) != 3 or parts[1] != "msg" or not MESSAGE_NAME.fullmatch(parts[2]) or not is_interface_package(parts[0]):
        return None
    try:
        module = importlib.import_module(f"{parts[0]}.msg")
    except ImportError:
        return None
    cls = getattr(module, parts[2], None)
    return cls if isinstance(cls, type) else None


def qos_profile(spec: QosSpec) -> Any:
    """An rclpy ``QoSProfile`` for a stored profile."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST if spec.history == "keep_last" else HistoryPolicy.KEEP_ALL,
        depth=spec.depth,
        reliability=ReliabilityPolicy.RELIABLE if spec.reliability == "reliable" else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if spec.durability == "transient_local" else DurabilityPolicy.VOLATILE,
    )


def offered_qos(topic: str, info: TopicInfo | None) -> QosSpec:
    """The QoS to offer on a replayed topic: the bag's, else the contract's, else reliable."""
    if info is not None and info.qos is not None:
        return info.qos
    return QOS_PROFILES[contract_qos(topic) or "reliable"]


class RosReplaySink:
    """A node ``bag_replay`` with one raw-bytes publisher per topic of the bag (and ``/clock``).

    Args:
        topics: the bag's topics (:attr:`BagReader.topics`).
        node_name: the node's name.
        args: rclpy arguments (``--ros-args ...``).

    A topic whose type is not installed gets no publisher: :meth:`can_publish` says False and a
    :class:`BagWarning` names it. Use as a context manager: leaving it destroys the node and
    shuts its context down (after Ctrl-C too).
    """

    def __init__(self, topics: dict[str, TopicInfo], node_name: str = "bag_replay", args: list[str] | None = None) -> None:
        import rclpy
        from rclpy.node import Node

        from bearing_rig_sim.dds_profile import use_rig_profile

        self._rclpy = rclpy
        self.context = rclpy.Context()
        use_rig_profile()  # a reliable reader of the replay gets a heartbeat every 50 ms, not 3 s
        rclpy.init(args=args or [], context=self.context)
        self.node = Node(node_name, context=self.context)
        self._publishers: dict[str, Any] = {}
        declared = dict(topics)
        declared.setdefault(CLOCK_TOPIC, None)  # type: ignore[arg-type]  # None: the clock topic has no recorded QoS
        for name, info in declared.items():
            msgtype = CLOCK_TYPE if info is None else info.msgtype
            cls = message_class(msgtype)
            if cls is None:
                warnings.warn(f"topic {name}: type {msgtype} is not installed (no Python class); not replayed", BagWarning, stacklevel=2)
                continue
            self._publishers[name] = self.node.create_publisher(cls, name, qos_profile(offered_qos(name, info)))

    def can_publish(self, topic: str) -> bool:
        """Whether the topic has a publisher."""
        return topic in self._publishers

    def publish(self, topic: str, data: bytes) -> None:
        """Publish serialized bytes on ``topic``."""
        self._publishers[topic].publish(bytes(data))

    def wait_for_subscribers(self, topics: Iterable[str], timeout: float, settle: float = 0.2) -> list[str]:
        """Wait until every one of ``topics`` that has a publisher has a matched subscriber, at
        most ``timeout`` s, then ``settle`` s more (the subscriber's side of the match); returns
        the topics still without one."""
        waiting = [t for t in dict.fromkeys(topics) if t in self._publishers]
        deadline = time.monotonic() + timeout
        while waiting:
            waiting = [t for t in waiting if self._publishers[t].get_subscription_count() == 0]
            if not waiting or time.monotonic() >= deadline:
                break
            time.sleep(0.02)
        if not waiting:
            time.sleep(settle)
        return waiting

    def close(self, linger: float = 0.2) -> None:
        """Let the last messages leave (reliable ones acknowledged, at most ``linger`` s in all),
        then destroy the node and shut its context down (idempotent)."""
        if self.node is not None:
            from rclpy.duration import Duration

            deadline = time.monotonic() + linger
            for publisher in self._publishers.values():
                publisher.wait_for_all_acked(Duration(nanoseconds=int(max(deadline - time.monotonic(), 0.0) * 1e9)))
            time.sleep(max(deadline - time.monotonic(), 0.0))
            self.node.destroy_node()
            self.node = None  # type: ignore[assignment]  # closed: the sink is not used again
        self.context.try_shutdown()

    def __enter__(self) -> RosReplaySink:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> Literal[False]:
        self.close()
        return False
