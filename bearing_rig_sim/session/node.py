"""The session's ROS side: recorder subscriptions, the program runner's commands, what the
progress line and the summary read. A thin shell around :mod:`.runner`, :mod:`.recorder` and
:mod:`.progress`.

**Recording without losing messages.** About 4-5 kHz of messages reach the session (``/clock``,
speeds and both forces at 1 kHz each, the rest slower), and several times that without real
time. Dispatching each through the executor costs some 100 us in rclpy, most of a core; so the
recorder's subscriptions live on a second node, ``<name>_recorder``, that is *not* added to the
executor, with deep reader queues (:data:`RECORDER_DEPTH`), and a timer of the session node
takes every queued message every :data:`DRAIN_PERIOD_S` (about 10 us each) and hands them, in
order of arrival, to the recorder. One ``SingleThreadedExecutor`` thus runs the whole session.

**Progress.** After each take that found a new clock, the session publishes the latest
``/clock`` it has taken and recorded on ``/rig/session/progress`` (:meth:`SessionNode.send_progress`);
without real time the simulator runs no further than its ``SESSION_LEAD_S`` (2 s of sim time)
past it, so a session starved of CPU holds the rig back instead of falling behind it.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
from collections import Counter
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from bearing_rig_msgs.msg import SpindleCommand
from builtin_interfaces.msg import Time
from rclpy.context import Context
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from geometry_msgs.msg import WrenchStamped
from std_msgs.msg import Header
from sensor_msgs.msg import JointState

from bearing_rig_sim.clock_guard import ClockGuard
from bearing_rig_sim.interfaces import (
    QOS_TABLE,
    AXIAL_LOAD_FORCE,
    AXIAL_LOAD_SETPOINT,
    AXIAL_LOAD_STATE,
    BEARING_AXIAL_FORCE,
    CAGE_PULSES,
    CLOCK,
    DIAGNOSTICS,
    LOAD_SETPOINT,
    SLIP_STATUS,
    SPEEDS,
    SPINDLE_COMMAND,
    SESSION_PROGRESS,
    SPINDLE_PULSES,
    TOPICS,
    TRUTH,
)
from bearing_rig_sim.nodes.common import UNKNOWN_NODE_NAME, drain, from_stamp, qos_profile, to_stamp
from bearing_rig_sim.monitoring.settings import DIAGNOSTIC_NAME as MONITOR_DIAGNOSTIC_NAME
from bearing_rig_sim.nodes.shell import PUBLISHED_SUFFIX
from bearing_rig_sim.session.manager import DIAGNOSTIC_PREFIX
from bearing_rig_sim.session.readiness import not_ready
from bearing_rig_sim.session.recorder import RecordedTopic, SessionRecorder, header_stamp_ns
from bearing_rig_sim.session.runner import ProgramRunner, SegmentPlan, SlipObservation, StatusState
from bearing_rig_sim.rig.program import Segment
from bearing_rig_sim.simulation.health import stopped_reason

__all__ = ["DRAIN_PERIOD_S", "ONE_PUBLISHER_TOPICS", "RECORDER_DEPTH", "MESSAGE_TYPES", "UNNAMED_PUBLISHER", "SessionNode", "message_class"]

ONE_PUBLISHER_TOPICS = (TRUTH.name, AXIAL_LOAD_STATE.name, SLIP_STATUS.name)
"""Topics a session's graph must have one publisher of, each a node's own output: one simulator
(its ground truth, not ``/clock``, which anyone may publish: a stray stamp is the clock guard's
business), one load controller, one monitor."""

DRAIN_PERIOD_S = 0.02
"""Wall time between two takes of the recorder's queues, s."""

MAX_CLOCK_EVENTS = 10
"""Most event lines about refused ``/clock`` stamps (the summary gives the count)."""

UNNAMED_PUBLISHER = "a node the graph has not named yet"
"""How an event line names a publisher whose node the graph has not named (yet): its endpoint
was matched before its node's participant data came (:data:`UNKNOWN_NODE_NAME`), which may come
later, or never (a plain DDS writer, not a ROS node)."""


RECORDER_DEPTH = 50000
"""Reader queue depth of each recorded topic: 50 s of a 1 kHz topic in real time, some 15 s at
the 3x of a session without real time. The reader's history drops its oldest sample once this many
wait (reliable or not): at 5000 a session held up for two seconds on a busy host lost stretches of
/clock."""


def message_class(msgtype: str) -> type:
    """The rclpy class of a ``pkg/msg/Name`` message type (from its generated ``pkg.msg`` module).

    Raises:
        ImportError: the package's Python module is not installed.
        AttributeError: the package has no such message.
    """
    package, _, name = msgtype.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), name)


MESSAGE_TYPES: dict[str, type] = {topic.msgtype: message_class(topic.msgtype) for topic in TOPICS}
"""The rclpy class of each message type of the interface table (:data:`interfaces.TOPICS`)."""

_LEVEL_NAMES = {0: "OK", 1: "WARN", 2: "ERROR", 3: "STALE"}

EVENT_WIDTH = 100
"""Longest diagnostic message shown in an event line (the bag keeps it whole)."""


BRING_UP_STREAMS = (CLOCK, SPINDLE_PULSES, CAGE_PULSES, SPEEDS, TRUTH, BEARING_AXIAL_FORCE, AXIAL_LOAD_FORCE, AXIAL_LOAD_STATE, SLIP_STATUS)
"""The topics the managed nodes publish from their activation on, which the recorder must have
matched before the session activates them (see :meth:`SessionNode.unmatched_streams`)."""


def reader_qos(topic: RecordedTopic) -> QoSProfile:
    """The recorder's subscription QoS: compatible with the publisher's offered profile, deep;
    reliable for every topic but plain sensor data, so that none of the samples of the
    contract's reliable streams is lost on a busy host."""
    offered = QOS_TABLE[topic.qos]
    return qos_profile(dataclasses.replace(offered, depth=RECORDER_DEPTH, reliability="best_effort" if topic.qos == "sensor_data" else "reliable"))


@dataclass
class LiveValues:
    """The latest values the progress line shows (SI)."""

    inner_ring_speed: float | None = None
    cage_speed: float | None = None
    speeds_raw: bytes | None = field(default=None, repr=False)
    state_count: int = 0
    """AxialLoadState messages seen (the load controller is stepping)."""

    def decode_speeds(self) -> None:
        """Decode the last ``/rig/speeds`` message (names ``inner_ring``, ``cage``)."""
        if self.speeds_raw is None:
            return
        msg = deserialize_message(self.speeds_raw, JointState)
        velocities = list(msg.velocity)
        for name, value in zip(msg.name, velocities):
            if name == "inner_ring":
                self.inner_ring_speed = value
            elif name == "cage":
                self.cage_speed = value


class SessionNode(Node):
    """Publishes the runner's commands; records every rig topic; feeds the runner.

    Args:
        recorder: where recorded messages go.
        runner: the program runner to feed (statuses, truth, bearing force).
        context: the rclpy context.
        on_event: called with a line of text for notable events (diagnostics changes).
        name: node name (the recorder's node is ``<name>_recorder``).
    """

    def __init__(
        self,
        recorder: SessionRecorder,
        runner: ProgramRunner,
        *,
        context: Context,
        on_event: Callable[[str], None] = lambda _line: None,
        name: str = "bearing_rig_session",
    ) -> None:
        super().__init__(name, context=context)
        self.recorder = recorder
        self.runner = runner
        self.on_event = on_event
        self.live = LiveValues()
        self._spindle = self.create_publisher(SpindleCommand, SPINDLE_COMMAND.name, qos_profile(SPINDLE_COMMAND))
        self._setpoint = self.create_publisher(WrenchStamped, LOAD_SETPOINT.name, qos_profile(LOAD_SETPOINT))
        self._progress = self.create_publisher(Header, SESSION_PROGRESS.name, qos_profile(SESSION_PROGRESS))
        self._progress_msg = Header(frame_id=runner.program.name)
        self.progress_ns = -1
        """Stamp of the last ``/rig/session/progress`` published, ns (-1: none yet)."""
        self.tap = Node(f"{name}_recorder", context=context)
        self._recorded = [
            (topic, MESSAGE_TYPES[topic.msgtype], self.tap.create_subscription(MESSAGE_TYPES[topic.msgtype], topic.name, _unused, reader_qos(topic), raw=True))
            for topic in recorder.topics.values()
        ]
        self._unnamed: set[str] = set()
        """Topics read best effort whose best-effort publisher the graph had not named when the
        recorder adapted; :meth:`adapt_to_publishers` names them once it does."""
        self._diagnostic_levels: dict[str, int] = {}
        self._monitor_parameter_problem = ""
        self.last_lifecycle_status: tuple[str, str, str] | None = None
        """(name, transition, state) of the last lifecycle manager's status taken from
        ``/diagnostics`` (the session's own, :class:`~.manager.LifecycleManager`), or None."""
        self.simulator_stopped = ""
        """Why the simulator stopped for good (its diagnostics' ``simulation_stopped``), or ""."""
        self.axial_setpoint: tuple[float, float] | None = None
        """The load controller's latest state: (stamp s of sim time, axial set-point in force N)."""
        self._pending: list[tuple[str, bytes]] = []
        self.sim_time_ns = 0
        """Stamp of the last ``/clock`` taken, ns."""
        self.clock_count = 0
        """``/clock`` messages taken (and accepted by :attr:`clock_guard`)."""
        self.clock_guard = ClockGuard()
        """Validates each ``/clock`` stamp before the runner follows it (negative, far jumps)."""
        self.taken = 0
        """Messages taken from the recorder's queues so far."""
        self.sent: Counter[str] = Counter()
        """Messages this session published per topic (commands and set-points)."""
        self.reports: dict[str, dict[str, int]] = {}
        """Each node's delivery report (``<node>: published`` on ``/diagnostics``): messages
        published per topic, by node."""
        self._own: dict[str, Counter[str]] = {SPINDLE_COMMAND.name: Counter(), AXIAL_LOAD_SETPOINT.name: Counter(), LOAD_SETPOINT.name: Counter()}
        """Serialized commands and set-points this session published, not yet seen by its recorder:
        any other on those topics came from outside and marks the running segment."""

    def close(self) -> None:
        """Destroy the recorder's node (the session node is destroyed by its owner)."""
        self.tap.destroy_node()

    # -- commands ---------------------------------------------------------------------------------
    def send_command(self, plan: SegmentPlan) -> None:
        """The segment's spindle command, stamped with the segment's start: sent ahead of that
        time, it waits in the simulator's queue until then (:meth:`ProgramRunner.commands_due`)."""
        command = SpindleCommand()
        command.header.stamp = to_stamp(plan.start_time)
        command.header.frame_id = plan.segment.name
        command.target_speed = plan.segment.target_speed
        command.profile = plan.segment.profile.message_code
        command.ramp_time = plan.segment.ramp_time
        command.acceleration = plan.segment.acceleration
        self._own[SPINDLE_COMMAND.name][repr(command)] += 1
        self._spindle.publish(command)
        self.sent[SPINDLE_COMMAND.name] += 1

    def send_setpoint(self, plan: SegmentPlan) -> None:
        """The segment's load set-point on ``/rig/load/setpoint``, stamped with the segment's start
        and sent with its spindle command (:meth:`ProgramRunner.commands_due`: ahead of a fixed
        start), so the load controller puts it in force at the start however late the session
        runs: force.z the axial load (N), force.x/y the radial load at the segment's azimuth (N;
        both 0 for an axially loaded program), torque.y the moment (N m)."""
        self.send_load(plan.segment, plan.start_time)

    def send_load(self, segment: Segment, stamp: float) -> None:
        """``segment``'s load set-point stamped ``stamp`` (s of sim time; see :meth:`send_setpoint`)."""
        setpoint = WrenchStamped()
        setpoint.header.stamp = to_stamp(stamp)
        setpoint.header.frame_id = "bearing"
        setpoint.wrench.force.z = segment.axial_load
        setpoint.wrench.force.x, setpoint.wrench.force.y = segment.radial_components
        setpoint.wrench.torque.y = segment.moment
        self._own[LOAD_SETPOINT.name][repr(setpoint)] += 1
        self._setpoint.publish(setpoint)
        self.sent[LOAD_SETPOINT.name] += 1

    def send_progress(self) -> None:
        """Publish the sim time taken so far (:attr:`sim_time_ns`) on ``/rig/session/progress``
        when it has advanced since the last: without real time the simulator runs no further
        than its ``SESSION_LEAD_S`` past it (:mod:`bearing_rig_sim.nodes.simulator`), so the
        session (its recorder and its runner) never falls further behind the rig than that, and
        a command sent :data:`~bearing_rig_sim.session.runner.COMMAND_LEAD_S` ahead by the
        session's clock reaches the simulator before its stamp. A clock the clock guard accepted
        as restarted (earlier than the last progress) is published as it is: the simulator's
        pacing starts again from it."""
        if self.clock_count == 0 or self.sim_time_ns == self.progress_ns:
            return
        self.progress_ns = self.sim_time_ns
        self._progress_msg.stamp = Time(sec=self.sim_time_ns // 1_000_000_000, nanosec=self.sim_time_ns % 1_000_000_000)
        self._progress.publish(self._progress_msg)
        self.sent[SESSION_PROGRESS.name] += 1

    # -- readiness --------------------------------------------------------------------------------
    def unmatched_streams(self, *, published_only: bool = False) -> list[str]:
        """The managed nodes' streams (:data:`BRING_UP_STREAMS`) whose publisher the recorder's
        reader has not matched yet. Their publishers exist from configure on; the nodes publish
        only once active, so a session that activates them after this is empty records every
        sample from the first. ``published_only``: only the streams the graph has a publisher of
        (attached to nodes managed elsewhere, which may not publish them all: a bench has no
        ground truth); such a stream's publisher offering only best effort is matched once
        :meth:`adapt_to_publishers` has read it best effort."""
        counts = {topic.name: sub.get_publisher_count() for topic, _type, sub in self._recorded}
        return [t.name for t in BRING_UP_STREAMS if counts.get(t.name, 1) == 0 and (not published_only or self.count_publishers(t.name) > 0)]

    def subscribers_besides_recorder(self, topic: str) -> int:
        """Subscriptions to ``topic`` other than the recorder's."""
        return sum(1 for info in self.get_subscriptions_info_by_topic(topic) if info.node_name != self.tap.get_name())

    def publisher_names(self, topic: str, reliability: ReliabilityPolicy | None = None) -> list[str]:
        """The nodes publishing ``topic`` (``/namespace/name``, sorted), only those offering
        ``reliability`` when given (a publisher whose node the graph has not named yet under the
        graph's placeholder, :data:`UNKNOWN_NODE_NAME`)."""
        return sorted(
            f"{info.node_namespace.rstrip('/')}/{info.node_name}"
            for info in self.get_publishers_info_by_topic(topic)
            if reliability is None or info.qos_profile.reliability == reliability
        )

    def adapt_to_publishers(self) -> list[str]:
        """Read best effort every recorded topic that some publisher offers only best effort
        (a bench's own sensor driver, attached to): a reliable reader never matches such a
        writer and would record nothing of it (rosbag2 adapts its readers in the same way). The
        reliable reader is drained, then replaced, at the first look that shows such a writer,
        named or not. Returns a line per topic changed, naming its best-effort publishers; one
        the graph has not named yet (its endpoint matched before its node's participant data
        came) is :data:`UNNAMED_PUBLISHER`, and a later look that finds every best-effort
        publisher of that topic named returns the line again with their names."""
        changes = []
        for i, (topic, msgtype, subscription) in enumerate(self._recorded):
            weak = self.publisher_names(topic.name, ReliabilityPolicy.BEST_EFFORT)
            unnamed = any(map(_unnamed, weak))
            if subscription.qos_profile.reliability != ReliabilityPolicy.RELIABLE:
                if topic.name in self._unnamed and weak and not unnamed:  # named since the change
                    self._unnamed.discard(topic.name)
                    changes.append(f"recording {topic.name} best effort: {', '.join(weak)} publishes it best effort")
                continue
            if not weak:
                continue
            self.take()  # what the reliable reader holds goes to the bag first
            qos = reader_qos(topic)
            qos.reliability = ReliabilityPolicy.BEST_EFFORT
            self.tap.destroy_subscription(subscription)
            self._recorded[i] = (topic, msgtype, self.tap.create_subscription(msgtype, topic.name, _unused, qos, raw=True))
            if unnamed:
                self._unnamed.add(topic.name)
            changes.append(
                f"recording {topic.name} best effort: {_shown(weak)} publishes it best effort (a reliable reader receives nothing from such a writer)"
            )
        return changes

    def rival_publishers(self) -> str:
        """What makes the graph hold more than one rig: a description of every topic of
        :data:`ONE_PUBLISHER_TOPICS` that more than one node publishes (empty when none does;
        a node the graph has not named yet is :data:`UNNAMED_PUBLISHER`: a second writer is a
        second rig whether or not its name has come).
        Two simulators would interleave two sim times; two load controllers would fight over
        the load; two monitors would give two verdicts."""
        found = []
        for topic in ONE_PUBLISHER_TOPICS:
            names = self.publisher_names(topic)
            if len(names) > 1:
                found.append(f"{len(names)} nodes publish {topic} ({_shown(names)})")
        return "; ".join(found)

    def missing(self) -> dict[str, str]:
        """Which node is not ready yet, and what is missing (empty when all are ready;
        :func:`~bearing_rig_sim.session.readiness.not_ready`)."""
        missing = not_ready(
            clock_seen=self.clock_count > 0,
            load_state_seen=self.live.state_count > 0,
            subscribers=self.subscribers_besides_recorder,
            publishers=self.count_publishers,
        )
        # The graph lists a subscription before this publisher has matched it, and a set-point
        # published before the match is lost (volatile): ready once every subscription matched.
        if "load_controller" not in missing and self._setpoint.get_subscription_count() < self.count_subscribers(LOAD_SETPOINT.name):
            missing["load_controller"] = f"{LOAD_SETPOINT.name}: the session's publisher has not matched every subscription yet"
        return missing

    def published(self, own: Mapping[str, int]) -> dict[str, int]:
        """Messages published per topic by the nodes that sent their delivery report and by this
        session (:attr:`sent`, and ``own``: e.g. its lifecycle statuses)."""
        total: Counter[str] = Counter(self.sent)
        total.update(own)
        for counts in self.reports.values():
            total.update(counts)
        return dict(total)

    def undelivered(self, own: Mapping[str, int]) -> dict[str, tuple[int, int]]:
        """The topics the recorder holds fewer messages of than were published (:meth:`published`),
        with (published, recorded)."""
        counts = self.recorder.counts
        return {topic: (n, counts.get(topic, 0)) for topic, n in self.published(own).items() if counts.get(topic, 0) < n}

    # -- recording --------------------------------------------------------------------------------
    def take(self) -> int:
        """Take every queued message, in order of arrival: feed the runner and the live values,
        follow ``/clock``, and keep them for :meth:`record_pending`. Returns the number taken.

        Taking and recording are separate so that the runner decides on the freshest sim time
        before the bag's writing (a chunk being compressed) can hold the session up."""
        batch: list[tuple[int, int, str, bytes, type]] = []
        for topic, msgtype, subscription in self._recorded:
            for raw, info in drain(subscription, msgtype):
                batch.append((info.get("received_timestamp") or 0, len(batch), topic.name, raw, msgtype))
        if not batch:
            return 0
        batch.sort(key=lambda item: (item[0], item[1]))
        for _, _, name, raw, msgtype in batch:
            if name == CLOCK.name:
                stamp = header_stamp_ns(raw)
                verdict = self.clock_guard.check(stamp) if stamp is not None else None
                if verdict is not None and verdict.note and self.clock_guard.refused <= MAX_CLOCK_EVENTS:
                    self.on_event(verdict.note if self.clock_guard.refused < MAX_CLOCK_EVENTS else f"{verdict.note}; further ones only counted")
                if stamp is not None and verdict is not None and verdict.accepted:
                    self.sim_time_ns = stamp
                    self.clock_count += 1
            else:
                self._observe(name, raw, msgtype)
        self._pending.extend((name, raw) for _, _, name, raw, _ in batch)
        self.taken += len(batch)
        return len(batch)

    def record_pending(self) -> None:
        """Write what :meth:`take` took to the recorder."""
        if self._pending:
            pending, self._pending = self._pending, []
            self.recorder.record_batch(pending)

    def drain(self) -> int:
        """:meth:`take`, then :meth:`record_pending`; returns the number taken."""
        count = self.take()
        self.record_pending()
        return count

    @property
    def sim_time(self) -> float:
        """Sim time of the last ``/clock`` taken, s (0 before the first)."""
        return self.sim_time_ns * 1e-9

    def _observe(self, name: str, raw: bytes, msgtype: type) -> None:
        own = self._own.get(name)
        if own is not None:
            key = repr(deserialize_message(raw, msgtype))  # the fields, whatever the serializer's padding
            if own[key] > 0:
                own[key] -= 1
            else:
                self.runner.observe_disturbance(self.sim_time, f"a message on {name} not sent by this session")
        if name == SPEEDS.name:
            self.live.speeds_raw = raw
        elif name == SLIP_STATUS.name:
            msg = deserialize_message(raw, msgtype)
            self.runner.observe_status(
                SlipObservation(
                    time=from_stamp(msg.header.stamp),
                    state=StatusState(msg.state) if msg.state in StatusState._value2member_map_ else StatusState.UNKNOWN,
                    slip_rate=msg.slip_rate,
                    inner_ring_speed=msg.inner_ring_speed,
                    cage_speed=msg.cage_speed,
                    window_revolutions=msg.window_revolutions,
                    confidence=msg.confidence,
                    sweep_speed=getattr(msg, "sweep_speed", math.nan),
                    sweep_verdict=getattr(msg, "sweep_verdict", ""),
                )
            )
        elif name == TRUTH.name:
            msg = deserialize_message(raw, msgtype)
            self.runner.observe_truth(from_stamp(msg.header.stamp), msg.slip_rate, msg.axial_load)
        elif name == BEARING_AXIAL_FORCE.name and self.runner.loads_radially:  # 1 kHz: decoded only when judged
            msg = deserialize_message(raw, msgtype)
            self.runner.observe_radial(from_stamp(msg.header.stamp), msg.wrench.force.x, msg.wrench.force.y)
        elif name == AXIAL_LOAD_STATE.name:
            msg = deserialize_message(raw, msgtype)
            self.live.state_count += 1
            self.axial_setpoint = (from_stamp(msg.header.stamp), float(msg.setpoint))
            self.runner.observe_axial_setpoint(from_stamp(msg.header.stamp), msg.setpoint)
            self.runner.observe_load(from_stamp(msg.header.stamp), msg.bearing_force)
        elif name == DIAGNOSTICS.name:
            self._diagnostics_events(deserialize_message(raw, msgtype))

    def _diagnostics_events(self, msg: Any) -> None:
        """An event line when a component's diagnostic level changes to or from WARN/ERROR."""
        for status in msg.status:
            level = status.level[0] if isinstance(status.level, (bytes, bytearray)) else int(status.level)
            self.simulator_stopped = self.simulator_stopped or stopped_reason((kv.key, kv.value) for kv in status.values)
            if status.name.endswith(PUBLISHED_SUFFIX):
                self.reports[status.name[: -len(PUBLISHED_SUFFIX)]] = {kv.key: int(kv.value) for kv in status.values if kv.value.isdigit()}
                continue
            if status.name == MONITOR_DIAGNOSTIC_NAME:  # the running monitor's parameters: the time to stable's
                problem = self.runner.observe_monitor_parameters({kv.key: kv.value for kv in status.values})
                if problem and problem != self._monitor_parameter_problem:
                    self.on_event(f"{status.name}: parameters not taken: {problem}")
                self._monitor_parameter_problem = problem
            if status.name.startswith(DIAGNOSTIC_PREFIX):
                values = {kv.key: kv.value for kv in status.values}
                self.last_lifecycle_status = (status.name, values.get("transition", ""), values.get("state", ""))
            previous = self._diagnostic_levels.get(status.name, 0)
            self._diagnostic_levels[status.name] = level
            if level != previous and (level > 0 or previous > 0):
                message = status.message if len(status.message) <= EVENT_WIDTH else status.message[: EVENT_WIDTH - 3] + "..."
                self.on_event(f"{status.name}: {_LEVEL_NAMES.get(level, str(level))}: {message}")


def _unnamed(name: str) -> bool:
    """Whether a ``/namespace/name`` of :meth:`SessionNode.publisher_names` is the graph's
    placeholder for a node it has not named yet."""
    return name.endswith(UNKNOWN_NODE_NAME)


def _shown(names: list[str]) -> str:
    """``names`` as an event line gives them: the named ones, then :data:`UNNAMED_PUBLISHER`
    for each the graph has not named yet."""
    return ", ".join([name for name in names if not _unnamed(name)] + [UNNAMED_PUBLISHER] * sum(map(_unnamed, names)))


def _unused(_msg: object) -> None:  # pragma: no cover - the recorder's node is never spun
    """Callback of the recorder's subscriptions; their queues are taken by ``drain``."""
