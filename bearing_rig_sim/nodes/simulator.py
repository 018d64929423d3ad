"""The simulator node: the rig's digital twin on the bench's topics (a thin shell around
:class:`~bearing_rig_sim.simulation.twin.RigTwin`).

Publishes (interface table, docs/interfaces.md; "reliable stream": reliable, history 5000):

* ``/clock`` (rosgraph_msgs/Clock, reliable stream): the simulated time, once per chunk
  (1 kHz simulated with 1 ms chunks), so the other nodes can run on ``use_sim_time``; the first
  one, at the first activation, is the time the simulation starts at (0), so that what the other
  nodes stamp before the first chunk (0) lies on the clock's timeline;
* every instrument of the rig file's ``sensors`` section on its contract topic
  (:mod:`bearing_rig_sim.instruments`; the twin samples them, this node only publishes their
  readings): as shipped, ``/rig/spindle/pulses``, ``/rig/cage/pulses``
  (bearing_rig_msgs/FibreOpticPulse, reliable stream): one per strip passage, stamped with the
  pulse time on the simulated clock; ``/rig/outer_ring/temperature`` (sensor_msgs/Temperature,
  reliable, 10 Hz simulated, degC; once the bearing file's ``thermal:`` section gives the
  network, docs/thermal.md) and ``/rig/housing/torque`` (geometry_msgs/WrenchStamped, torque.z
  in N m, reliable, 100 Hz simulated): the outer-ring thermocouple and the housing torque meter;
* ``/rig/speeds`` (sensor_msgs/JointState, reliable stream, ``speeds_rate_hz`` simulated): names
  ``inner_ring`` and ``cage``, velocity from the pulse counters (rad/s), position the
  pulse-counted angle (rad), effort empty;
* ``/rig/truth`` (bearing_rig_msgs/SimulatorTruth, reliable stream, ``truth_rate_hz`` simulated):
  the engine's ground truth with the achieved real-time factor and the overrun count;
* ``/diagnostics`` (diagnostic_msgs/DiagnosticArray, reliable): ``diagnostics_rate_hz`` wall and
  on every change of level (see :mod:`bearing_rig_sim.health`).

Subscribes ``/rig/spindle/command`` (bearing_rig_msgs/SpindleCommand, reliable, transient local)
and ``/rig/bearing/axial_force`` (geometry_msgs/WrenchStamped in the bearing's frame: force.z the
axial load, N; the magnitude of force.x and force.y the radial load, N, at the azimuth
atan2(force.y, force.x), where the engine centres its load zone, and refused (ERROR, the last
accepted loads kept) above the rig file's ``combined_loading.max_radial_setpoint_n`` (0 for the
paper's axially loaded bench); torque.x and torque.y a moment across the axis, N m, which
frees the inner ring's tilts (both 0: the tilts held, the reaction reported), refused above
``combined_loading.max_moment_setpoint_n_m``; read reliably (``force_reader``): the loop paces on
its stamps, and a lost last sample would hold it; 1 kHz, so its queue is taken by the loop, not dispatched message by message: the latest force
queued is the one applied). Bad input is refused with a
logged reason and an ERROR on /diagnostics; the node goes on.

One timer on the steady clock drives the loop (no threads), and sends the periodic diagnostics
when due: in real time it runs the chunks the wall clock asks for (:class:`~bearing_rig_sim.simulation.pacing.RealTimePacer`), otherwise a
batch of ``max_batch_chunks`` per call, as fast as its reliable readers take the streams: every
:data:`ACK_WINDOW_CHUNKS` chunks the loop waits until each reliable reader (the session's
recorder) has acknowledged all it was sent, so no sample leaves the writers' history unread and a
recording holds every message, no further than :data:`FORCE_LEAD_S` past the latest force on
the bearing while the load controller's force stream follows the clock (so a starved load
controller's force is never applied late; a deactivated or exited one holds nothing up), and no
further than :data:`MONITOR_LEAD_S` past the monitor's latest ``/rig/slip_status`` (read reliably,
transient local) while its statuses follow the clock (so the monitor's verdicts keep up with the
program under any load), and no further than :data:`SESSION_LEAD_S` past the session's latest
``/rig/session/progress`` (read reliably: the latest ``/clock`` the session has taken and
recorded) while a session publishes it (so the session's runner and recorder keep up, and the
commands it sends ahead arrive ahead). The four bounds, without real time: the recorder's
middleware has acknowledged every sample but the last :data:`ACK_WINDOW_CHUNKS` chunks' (2 s of
simulated time), the session has taken and recorded every message of the clock but the last 2 s
(its reader queues, 50000 deep, hold the rest), the force on the bearing lags the clock by at
most 0.1 s and the monitor by at most 0.5 s; the force, the monitor's statuses and the session's
progress are reliable streams, so none of the four waits on a message that can be lost.
``simulator --no-realtime`` sets the parameter ``realtime`` to false.

Lifecycle (:class:`~bearing_rig_sim.nodes.shell.ManagedNode`): the settings, the twin (engine,
drive, sensors), publishers, subscriptions and timers are made at configure; the simulated time
runs only while active (it stands still while inactive and goes on from there at the next
activation, anchored to the wall clock anew). A halted engine, refused inputs and overruns are
reported on /diagnostics (ERROR, WARN) with the node staying active; ``simulator --autostart``
configures and activates at once.
"""

from __future__ import annotations

import importlib
import math
import sys
import time
from array import array
from dataclasses import fields
from typing import Any
from collections.abc import Sequence

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import WrenchStamped
from lifecycle_msgs.msg import State as LifecycleState
from lifecycle_msgs.msg import TransitionEvent
from rclpy.clock import Clock, ClockType
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from rclpy.subscription import Subscription
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import JointState
from std_msgs.msg import Header

from bearing_rig_msgs.msg import SimulatorTruth, SlipStatus, SpindleCommand as SpindleCommandMsg
from bearing_rig_sim.bags.cdr import header_stamp_ns
from bearing_rig_sim.interfaces import BEARING_AXIAL_FORCE, CLOCK, DIAGNOSTICS, SESSION_PROGRESS, SLIP_STATUS, SPEEDS, SPINDLE_COMMAND, TRUTH
from bearing_rig_sim.interfaces import topic as contract_topic
from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.dynamics import MIN_AXIAL_LOAD
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.nodes.common import (
    RELIABLE_QOS,
    STATUS_QOS,
    UNKNOWN_NODE_NAME,
    diagnostic_array,
    diagnostic_status,
    drain,
    from_stamp,
    node_main,
    qos_profile,
    to_stamp,
    unspun_reader,
)
from bearing_rig_sim.nodes.shell import ManagedNode, declare_described, parameter_values, survives_shutdown
from bearing_rig_sim.instruments.base import Reading
from bearing_rig_sim.simulation.drive import SpindleCommand, profile_from_code
from bearing_rig_sim.health import Health, HealthLevel
from bearing_rig_sim.simulation.health import STOPPED_KEY, SimulatorHealth
from bearing_rig_sim.simulation.pacing import RealTimePacer, StreamLead
from bearing_rig_sim.simulation.settings import NODE_NAME, SimulatorSettings, shipped_parameters
from bearing_rig_sim.simulation.twin import AxialLoadError, MomentError, RigTwin, TickOutput

NO_REALTIME_FLAG = "--no-realtime"
"""Command-line flag: run as fast as possible (parameter ``realtime`` false)."""

MAX_UINT32 = 2**32 - 1

FORCE_QOS = qos_profile("force_reader")
"""The force reader: best effort, deep enough for 1 s at 1 kHz. Each loop applies the latest force
queued, so a sample lost in transport is superseded by the next one a millisecond later; a
reliable reader here cost the load controller some 3 % of a core in acknowledgements. (The
recorder reads the force reliably: the publisher is reliable.)"""


ACK_WINDOW_CHUNKS = 2000
"""Without real time, chunks published between two waits for every reliable reader (the
session's recorder above all) to acknowledge all it was sent. The reliable streams keep 5000
samples for a reader that has not acknowledged them (the contract's history); a 1 kHz stream
publishes one per chunk, so a window of 2000 keeps every sample a slow reader still needs in the
writer's history, and the run goes as fast as its slowest reliable reader, never faster. Readers
acknowledge when a writer's heartbeat asks: every 50 ms with the rig's Fast DDS profile
(:mod:`bearing_rig_sim.dds_profile`), so a wait costs a few tens of milliseconds per window;
under Fast DDS's default of 3 s, a window would wait up to 3 s. (In real time the pace is the
wall clock's: a reader that falls 5 s behind loses samples, as on a bench.)"""

FORCE_LEAD_S = 0.1
"""Without real time, how far the simulation may run ahead of the force on the bearing, s of
simulated time. The load controller steps its chain to the latest /clock and stamps each force
sample with it; a simulator that ran on regardless would apply a starved load controller's force
seconds late (two busy loops on two cores: a load sweep's 50 N segment at 618 N). So while the
force stream follows the clock, the loop runs no further than the latest force stamp plus this
lead: a set-point reaches the bearing within it whatever the host's load (the session judges a
segment's load from 0.5 s after its start, the chain settling within 0.37 s).

Only a stream whose stamps advance and lie within :data:`FORCE_FOLLOW_S` of the simulated time
sets the pace (a probe's unstamped messages do not). Pacing stops at once when its publisher
leaves the active lifecycle state (its ``transition_event``: a deactivated load controller
publishes nothing, and holds nothing up) or when no publisher is left (one that exited), and
resumes when the stream advances again (after an activation); a stream silent for
:data:`FORCE_SILENT_S` of wall time otherwise (a process killed before the middleware noticed)
stops it too."""

MONITOR_LEAD_S = 0.5
"""Without real time, how far the simulation may run ahead of the monitor, s of simulated time:
past the stamp of its latest status (one per ``status_rate_hz`` of pulse time, 10 Hz, and per
closed slip window; while no pulse comes, one per 0.1 s of wall time stamped with the load cell's
latest sample, the clock's). So the monitor's pulse queue never holds more than some 0.6 s of
pulses (its depth, 10000, is 20 s at 9000 rpm), its verdicts keep up with the program on any
host, and its last status at the end of a session lies within this of the clock's end. Paced as
the force stream (:data:`FORCE_LEAD_S`): only while the statuses follow the clock, not while the
monitor is inactive, gone, or silent for :data:`FORCE_SILENT_S` of wall time; and only while
pulses flow: once none has been published for this long of simulated time (the rig at rest),
the monitor has taken or will take every pulse there is, and the lead would hold the clock
where the monitor cannot yet tell a stop from a silent sensor (its statuses keep their last
window's stamp until the silence exceeds ``loss_min_timeout_s``, 0.5 s, and four pulse periods),
so the simulation goes on, paced by the force stream, until a pulse comes again."""

SESSION_LEAD_S = 2.0
"""Without real time, how far the simulation may run ahead of the session, s of simulated time:
past the stamp of its latest ``/rig/session/progress``, the latest ``/clock`` the session has
taken from its recorder's queues and written to the bag. The recorder's middleware acknowledges
samples as they arrive in its reader queues, whatever the session's Python has taken, so the
acknowledgement windows bound only what is in those queues; a session starved on a loaded host
fell more than 9 s behind the simulator (six busy loops on two cores), and a stop command sent
:data:`~bearing_rig_sim.session.runner.COMMAND_LEAD_S` (9 s) ahead of its stamp by the session's
clock reached the simulator 1.1 s after it. Held to this lead, the session's view of the rig is
never more than 2 s old, so such a command arrives at least 7 s ahead, and its recorder's queues
(50000 deep) never hold more than some 2 s of each stream. Two seconds is some 40 of the
session's takes (every 20 ms of wall time) at the 3x of an unloaded host, so the lead holds the
simulation back only when the session cannot keep up. Paced as the force stream
(:data:`FORCE_LEAD_S`), with :data:`SESSION_FOLLOW_S` for a stream that follows the clock: not
before the session's first message, not once its publisher has gone (the session ended), not
after :data:`FORCE_SILENT_S` of wall time without a new stamp."""

SESSION_FOLLOW_S = 30.0
"""A session progress stamp this close (s of simulated time) to the simulation when it arrives
is taken as a session that follows the clock: wide, since a session taking its first ``/clock``
late (bring-up on a loaded host) is behind by more than the lead, and pacing on it from then on
is what brings it back within the lead. A stamp off the simulated time by more (a stray
publisher on another clock) does not pace."""

AT_REST = f"the rig at rest (no pulse for {MONITOR_LEAD_S:g} s of simulated time)"
"""Why the monitor's statuses do not pace the loop while no pulse comes (:data:`MONITOR_LEAD_S`)."""

MONITOR_FOLLOW_S = 2.0
"""A status stamp this close (s of simulated time) to the simulation when it arrives is taken as
a monitor that follows the clock."""

FORCE_FOLLOW_S = 1.0
"""A force stamp this close (s of simulated time) to the simulation when it arrives is taken as
a stream that follows the clock."""

FORCE_SILENT_S = 10.0
"""Wall time without a new force sample after which the loop stops waiting for one, s: the last
resort for a publisher gone without a word (as :data:`ACK_GIVE_UP_S` for a reliable reader; two
busy loops on two cores starved the load controller for over 2 s). A stopped process (SIGSTOP)
holds the simulation until then."""

GRAPH_RECHECK_S = 0.2
"""Wall time between two look-ups of the force stream's publishers while they change, s."""

ACK_POLL_S = 0.005
"""Longest block on one acknowledgement check, s of wall time; the loop then yields to the
executor (commands, lifecycle services) and checks again."""

ACK_GIVE_UP_S = 10.0
"""Wall time a reader may acknowledge nothing (a stopped process) before the loop goes on
without it, with a WARN on /diagnostics, s; it is not waited for again until every reader has
caught up."""


def _doubles(values: Any) -> array[float]:
    """A float64[] message field's value from an array of floats."""
    return array("d", np.ascontiguousarray(values, dtype=np.float64).tobytes())


class SimulatorNode(ManagedNode):
    """The simulator node (see the module docstring).

    Raises:
        ConfigError: a parameter or a configuration file it names is malformed.
    """

    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        self._defaults = shipped_parameters()
        declare_described(self, NODE_NAME, self._defaults)

    def configure(self) -> None:
        """Validate the parameters; build the twin, the pacer, publishers, subscriptions, timers."""
        s = SimulatorSettings.from_values(parameter_values(self, self._defaults), f"{NODE_NAME} parameters")
        self.settings = s
        self.twin = RigTwin.from_files(s.bearing_file, s.calibration_file, s.rig_file, model=s.model, bearing_model=s.bearing_model, settings=s)
        self.pacer = RealTimePacer.from_settings(s)
        self.health = SimulatorHealth(s.fault_hold_s)
        self._speeds_every = max(1, round(1.0 / (s.speeds_rate_hz * s.chunk_s)))
        self._truth_every = max(1, round(1.0 / (s.truth_rate_hz * s.chunk_s)))
        self._chunks = 0
        self._acked_chunks = 0
        """Chunks published when every reliable reader had last acknowledged all it was sent."""
        self._held_since: float | None = None
        """Wall time (monotonic) the loop began waiting for acknowledgements, or None."""
        self._gave_up = False
        """A reader stayed unacknowledging past :data:`ACK_GIVE_UP_S`; not waited for again until
        every reader has acknowledged all."""
        self._leads = {
            BEARING_AXIAL_FORCE.name: StreamLead("force on the bearing", FORCE_LEAD_S, follow_s=FORCE_FOLLOW_S, silent_s=FORCE_SILENT_S),
            SLIP_STATUS.name: StreamLead("monitor status", MONITOR_LEAD_S, follow_s=MONITOR_FOLLOW_S, silent_s=FORCE_SILENT_S),
            SESSION_PROGRESS.name: StreamLead("session progress", SESSION_LEAD_S, follow_s=SESSION_FOLLOW_S, silent_s=FORCE_SILENT_S),
        }
        """Without real time, the streams the loop keeps within a lead of (see the module docstring)."""
        self._stream_publishers = {name: -1 for name in self._leads}
        """Publishers of each paced stream whose node is known (-1: not looked up yet)."""
        self._graph_checked = {name: -math.inf for name in self._leads}
        """Wall time (monotonic) of the last look-up of each paced stream's publishers."""
        self._lifecycle_events: dict[str, tuple[Subscription, set[str]]] = {}
        """The ``transition_event`` reader of each node publishing a paced stream, and those streams."""
        self._pulses = {"spindle": 0, "cage": 0}
        self._last_pulse_time = -math.inf
        """Simulated time of the latest chunk that published a pulse, s."""
        self._last_level: HealthLevel | None = None
        self._anchor = True
        self._clock_started = False
        """The clock's first message (the time the simulation starts at) was published."""

        self._clock_pub = self.publisher(ClockMsg, CLOCK.name, qos_profile(CLOCK))
        self._instrument_pubs: dict[str, tuple[Any, Any]] = {}
        """Contract topic -> its publisher and message class, one per instrument of the rig file."""
        for name in self.twin.instruments.set.topics():
            topic = contract_topic(name)
            kind = message_class(topic.msgtype)
            self._instrument_pubs[name] = (self.publisher(kind, topic.name, qos_profile(topic)), kind)
        self._speeds_pub = self.publisher(JointState, SPEEDS.name, qos_profile(SPEEDS))
        self._truth_pub = self.publisher(SimulatorTruth, TRUTH.name, qos_profile(TRUTH))
        self._diag_pub = self.publisher(DiagnosticArray, DIAGNOSTICS.name, qos_profile(DIAGNOSTICS))
        self._attach_thermal(s.bearing_file)
        self._stream_pubs = {
            topic.name: pub
            for topic, pub in (
                (CLOCK, self._clock_pub),
                *((contract_topic(name), pub) for name, (pub, _kind) in self._instrument_pubs.items()),
                (SPEEDS, self._speeds_pub),
                (TRUTH, self._truth_pub),
            )
            if topic.qos == "reliable_stream"
        }
        self.subscription(SpindleCommandMsg, SPINDLE_COMMAND.name, self._on_command, STATUS_QOS)
        # The force comes at 1 kHz: its queue is taken by the loop (one wake-up per loop call
        # instead of one per message), from a reader on a node no executor spins.
        self._force_tap: Node | None = Node(f"{NODE_NAME}_force", context=self.context)
        self._force_sub = unspun_reader(self._force_tap, WrenchStamped, BEARING_AXIAL_FORCE.name, FORCE_QOS)
        self._stamp_readers = {
            SLIP_STATUS.name: (unspun_reader(self._force_tap, SlipStatus, SLIP_STATUS.name, STATUS_QOS), SlipStatus),
            SESSION_PROGRESS.name: (unspun_reader(self._force_tap, Header, SESSION_PROGRESS.name, RELIABLE_QOS), Header),
        }
        """The readers of the paced streams whose stamp alone matters (the monitor's statuses, the
        session's progress), with their message types."""

        steady = Clock(clock_type=ClockType.STEADY_TIME)
        period = s.loop_period_s if s.realtime else 0.0
        self.timer(period, self._on_loop, clock=steady)
        # The periodic report is sent by the loop when due rather than by a timer of its own: a
        # loop timer of period 0 (no real time) is always ready, and the events executor then
        # never ran a second timer.
        self._diagnostics_period = 1.0 / s.diagnostics_rate_hz
        self._next_report = 0.0
        self._speeds_msg = JointState(name=["inner_ring", "cage"])
        self._clock_msg = ClockMsg()
        mode = f"real time x{s.rate:g}" if s.realtime else "as fast as possible"
        self.get_logger().info(
            f"simulating {s.bearing_file.name if s.bearing_model == 'bench' else s.bearing_model + ' model of the paper'} "
            f"({s.model} engine, {s.chunk_s * 1e3:g} ms chunks, {mode}); "
            f"spindle {s.initial_speed_rad_s:g} rad/s, axial load {self.twin.axial_load:g} N"
        )

    def activate(self) -> None:
        """The simulated time goes on from where it stands, anchored to the wall clock anew."""
        self._anchor = True
        self._last_level = None

    def deactivate(self) -> None:
        """Apply the forces that came while active; later ones are applied at the next activation
        (the latest is the load in force)."""
        self._take_forces()

    def delivery_stamp(self) -> Any:
        """The simulated time the simulation stands at."""
        return to_stamp(max(self.twin.time, 0.0))

    def cleanup(self) -> None:
        """Destroy the force reader's node (and the lifecycle readers on it)."""
        tap = getattr(self, "_force_tap", None)
        if tap is not None:
            tap.destroy_node()
            self._force_tap = None
        self._lifecycle_events = {}

    # -- the loop ------------------------------------------------------------------------------
    @survives_shutdown
    def _on_loop(self) -> None:
        now = time.monotonic()
        if now >= self._next_report:
            self._next_report = now + self._diagnostics_period
            self._report()
        if self.health.halted:
            return
        if not self.pacer.realtime and (self._held_since is not None or self._chunks - self._acked_chunks >= ACK_WINDOW_CHUNKS):
            if not self._readers_caught_up(now):
                return
        if self._anchor:
            self.pacer.start(self.twin.time)
            self._anchor = False
            if not self._clock_started:  # the clock's origin: what is stamped before the first chunk lies on it
                self._clock_started = True
                self._clock_msg.clock = to_stamp(max(self.twin.time, 0.0))
                self._clock_pub.publish(self._clock_msg)
        self._take_forces()
        for _ in range(self._force_paced(self.pacer.due_chunks(self.twin.time), now)):
            try:
                out = self.twin.tick(with_truth=(self._chunks + 1) % self._truth_every == 0)
            except RigError as exc:
                self.health.halt(str(exc))
                self.get_logger().error(f"simulation stopped: {exc}")
                break
            self._publish_chunk(out)
        self.pacer.record(self.twin.time)
        self._publish_diagnostics_on_change()

    def _force_paced(self, chunks: int, now: float) -> int:
        """Without real time, at most the chunks that keep the simulation within
        :data:`FORCE_LEAD_S` of the force stream, :data:`MONITOR_LEAD_S` of the monitor's
        statuses and :data:`SESSION_LEAD_S` of the session's progress, each while it follows the
        clock (see there)."""
        if self.pacer.realtime:
            return chunks
        self._take_stamps()
        for name in self._leads:
            self._follow_publishers(name)
        at_rest = self.twin.time - self._last_pulse_time > MONITOR_LEAD_S
        rooms = []
        for name, lead in self._leads.items():
            idle = AT_REST if name == SLIP_STATUS.name and at_rest else ""
            if (room := lead.room(self.twin.time, self.settings.chunk_s, now, idle=idle)) is not None:
                rooms.append(room)
        if not rooms:
            return chunks
        room = min(rooms)
        if room <= 0:
            time.sleep(ACK_POLL_S)  # yield the core to the load controller and the monitor rather than spin
        return max(0, min(chunks, room))

    def _take_stamps(self) -> None:
        """Follow the monitor's and the session's progress: the stamp of the latest message queued
        on each (read from its leading time stamp, no message decoded)."""
        for name, (reader, msgtype) in self._stamp_readers.items():
            queued = drain(reader, msgtype)
            ns = header_stamp_ns(queued[-1][0]) if queued else None
            if ns is not None:
                self._leads[name].observe(ns // 1_000_000_000 + (ns % 1_000_000_000) * 1e-9, self.twin.time, time.monotonic())

    def _follow_publishers(self, name: str) -> None:
        """Count a paced stream's publishers (none: pacing on it stops), read each one's
        lifecycle transitions (one leaving the active state pauses it until it is active again)."""
        tap = self._force_tap
        if tap is None:
            return
        lead = self._leads[name]
        count = tap.count_publishers(name)
        now = time.monotonic()
        if count != self._stream_publishers[name] and now >= self._graph_checked[name] + GRAPH_RECHECK_S:
            self._graph_checked[name] = now
            if count == 0:
                lead.stop(f"no publisher of {name}")
            # the graph may name a matched publisher's node later than the match (meanwhile
            # "_NODE_NAME_UNKNOWN_"): counted as known only once it does, so the lookup is
            # repeated until then
            infos = [i for i in tap.get_publishers_info_by_topic(name) if i.node_name != UNKNOWN_NODE_NAME]
            self._stream_publishers[name] = count if len(infos) >= count else len(infos)
            for info in infos:
                topic = f"{info.node_namespace.rstrip('/')}/{info.node_name}/transition_event"
                if topic not in self._lifecycle_events:
                    reader = unspun_reader(tap, TransitionEvent, topic, RELIABLE_QOS)
                    self._lifecycle_events[topic] = (reader, set())
                self._lifecycle_events[topic][1].add(name)
        for reader, streams in self._lifecycle_events.values():
            for event, _info in drain(reader, TransitionEvent, serialized=False):
                for stream in streams:
                    if event.goal_state.id != LifecycleState.PRIMARY_STATE_ACTIVE:
                        node = reader.topic_name.rsplit("/", 1)[0]
                        self._leads[stream].stop(f"{node} left the active state ({event.goal_state.label})", paused=True)
                    else:
                        self._leads[stream].paused = False

    def _readers_caught_up(self, now: float) -> bool:
        """Without real time: has every reliable reader acknowledged all the streams sent it?
        Blocks at most :data:`ACK_POLL_S`; after :data:`ACK_GIVE_UP_S` of waiting, goes on
        without the laggard (a WARN names the topics)."""
        behind = [name for name, pub in self._stream_pubs.items() if not pub.wait_for_all_acked(Duration(seconds=ACK_POLL_S if name == CLOCK.name else 0.0))]
        if not behind or self._gave_up:
            # a laggard given up on is not waited for again until every reader has caught up
            # (or its proxy is gone): a stopped process would otherwise hold each window anew
            self._gave_up = self._gave_up and bool(behind)
            self._acked_chunks, self._held_since = self._chunks, None
            return True
        if self._held_since is None:
            self._held_since = now
        elif now - self._held_since > ACK_GIVE_UP_S:
            self.health.reader_stalled(f"{', '.join(behind)} unacknowledged for {now - self._held_since:.0f} s")
            self.get_logger().warning(f"going on without a reliable reader: {', '.join(behind)} unacknowledged for {now - self._held_since:.0f} s")
            self._acked_chunks, self._held_since, self._gave_up = self._chunks, None, True
            return True
        return False

    def _publish_chunk(self, out: TickOutput) -> None:
        self._chunks += 1
        stamp = to_stamp(out.time)
        self._clock_msg.clock = stamp
        self._clock_pub.publish(self._clock_msg)
        for name, readings in out.readings.items():
            pub, kind = self._instrument_pubs[name]
            for reading in readings:
                pub.publish(instrument_message(kind, reading))
        self._pulses["spindle"] += len(out.spindle_pulses)
        self._pulses["cage"] += len(out.cage_pulses)
        if out.spindle_pulses or out.cage_pulses:
            self._last_pulse_time = out.time
        if self._chunks % self._speeds_every == 0:
            m = out.measured
            msg = self._speeds_msg
            msg.header.stamp = stamp
            msg.position = [m.inner_ring_angle, m.cage_angle]
            msg.velocity = [m.inner_ring_speed, m.cage_speed]
            self._speeds_pub.publish(msg)
        if out.truth is not None:
            self._truth_pub.publish(self._truth_message(out))

    # -- the bench's instruments -----------------------------------------------------------------
    def _attach_thermal(self, bearing_file: Any) -> None:
        """Couple the bearing's thermal network to the engine (its heat, term by term; with
        ``lubricant_feedback`` also back: the engine's lubricant follows the lubricant node every
        network step, 0.1 s; :class:`~bearing_rig_sim.thermal.coupling.ThermalCoupling`), whose
        temperatures the thermocouples read; a bearing file without a ``thermal:`` section has
        none, and its thermocouples publish nothing."""
        try:
            self.twin.attach_thermal(bearing_file, initial_rise_k=self.settings.initial_temperature_rise_k, feedback=self.settings.lubricant_feedback)
        except ConfigError as exc:
            self.get_logger().info(f"no thermal network, so no temperature readings: {exc}")

    def _truth_message(self, out: TickOutput) -> SimulatorTruth:
        t = out.truth
        assert t is not None
        msg = SimulatorTruth(
            inner_ring_speed=t.inner_ring_speed,
            inner_ring_acceleration=t.inner_ring_acceleration,
            cage_speed=t.cage_speed,
            theoretical_cage_speed=t.theoretical_cage_speed,
            slip_rate=t.slip_rate,
            axial_load=t.axial_load,
            inner_contact_load_mean=t.inner_contact_load_mean,
            inner_contact_load_max=t.inner_contact_load_max,
            outer_contact_load_mean=t.outer_contact_load_mean,
            outer_contact_load_max=t.outer_contact_load_max,
            pocket_load_max=t.pocket_load_max,
            inner_contact_angle=t.inner_contact_angle,
            outer_contact_angle=t.outer_contact_angle,
            inner_ring_axial_displacement=t.inner_ring_axial_displacement,
            real_time_factor=float(self.pacer.real_time_factor),
            step_count=t.step_count,
            overruns=min(self.pacer.overruns, MAX_UINT32),
            friction_torque=t.friction_torque,
            power_loss=t.power_loss,
            cage_whirl_radius_um=t.cage_whirl_radius * 1e6,
            cage_centre_x=t.cage_centre[0],
            cage_centre_y=t.cage_centre[1],
        )
        if t.balls is not None:  # each BallTruth field is the message's ball_<field>
            for item in fields(t.balls):
                setattr(msg, f"ball_{item.name}", _doubles(getattr(t.balls, item.name)))
        msg.header.stamp = to_stamp(t.time)
        msg.header.frame_id = "bearing"
        return msg

    # -- inputs --------------------------------------------------------------------------------
    @survives_shutdown
    def _on_command(self, msg: SpindleCommandMsg) -> None:
        try:
            stamp = from_stamp(msg.header.stamp)
            command = SpindleCommand(
                target_speed=msg.target_speed,
                profile=profile_from_code(msg.profile),
                ramp_time=msg.ramp_time,
                acceleration=msg.acceleration,
                time=stamp if stamp > 0.0 else None,
            )
            self.twin.command_spindle(command)
        except Exception as exc:
            self._refuse("spindle command", str(exc))
            return
        when = "now" if command.time is None or command.time <= self.twin.time else f"at t = {command.time:.6g} s"
        self.get_logger().info(
            f"spindle command accepted: {command.target_speed:g} rad/s by {command.profile.value} "
            f"(ramp {command.ramp_time:g} s, acceleration {command.acceleration:g} rad/s^2), {when} "
            f"(rig clock {self.twin.time:.6g} s)"
        )

    def _take_forces(self) -> None:
        """Apply the latest force queued since the last call: force.z the axial load, the
        magnitude of (force.x, force.y) the radial load at its azimuth (:meth:`RigTwin.set_loads`:
        refused above the rig file's radial limit); torque.x and torque.y the moment (refused
        above the rig file's moment limit).

        The queue is taken serialized and only its last sample is decoded and applied: the ones
        before it would be replaced before the next chunk anyway.
        """
        queued = drain(self._force_sub, WrenchStamped)
        if not queued:
            return
        message = deserialize_message(queued[-1][0], WrenchStamped)
        self._leads[BEARING_AXIAL_FORCE.name].observe(from_stamp(message.header.stamp), self.twin.time, time.monotonic())
        wrench = message.wrench
        force = wrench.force
        try:
            self.twin.set_loads(force.z, force.x, force.y, wrench.torque.x, wrench.torque.y)
        except AxialLoadError as exc:
            self._refuse("axial force", str(exc))
        except MomentError as exc:
            self._refuse("moment", str(exc))
        except Exception as exc:
            self._refuse("radial force", str(exc))

    def _refuse(self, kind: str, reason: str) -> None:
        self.get_logger().error(f"{kind} refused: {reason}", throttle_duration_sec=1.0)
        self.health.refuse(kind, reason, time.monotonic())
        self._publish_diagnostics_on_change()

    # -- diagnostics ---------------------------------------------------------------------------
    def _assess(self) -> Health:
        return self.health.assess(time.monotonic(), self.pacer.overruns, self.twin.load_clamped, MIN_AXIAL_LOAD)

    def _publish_diagnostics_on_change(self) -> None:
        health = self._assess()
        if health.level != self._last_level:
            self._publish_diagnostics(health)

    def _report(self) -> None:
        """The periodic report (``diagnostics_rate_hz``, wall clock)."""
        self._publish_diagnostics(self._assess())
        self.health.reported(self.pacer.overruns)

    def _publish_diagnostics(self, health: Health) -> None:
        self._last_level = health.level
        twin, pacer = self.twin, self.pacer
        measured = twin.measured()
        profile = twin.drive.profile
        values = {
            "sim_time_s": f"{twin.time:.6f}",
            "realtime": str(pacer.realtime).lower(),
            "real_time_factor": f"{pacer.real_time_factor:.4g}",
            "overruns": pacer.overruns,
            "resyncs": pacer.resyncs,
            "step_count": twin.step_count,
            "target_speed_rad_s": f"{profile.target_speed:.6g}",
            "inner_ring_speed_rad_s": f"{measured.inner_ring_speed:.6g}",
            "cage_speed_rad_s": f"{measured.cage_speed:.6g}",
            "axial_load_n": f"{twin.axial_load:.6g}",
            "requested_axial_load_n": f"{twin.requested_axial_load:.6g}",
            "radial_load_n": f"{twin.radial_load:.6g}",
            "radial_load_azimuth_deg": f"{math.degrees(twin.radial_angle):.6g}",
            "moment_n_m": " ".join(f"{m:.6g}" for m in twin.moment),
            "ring_moment_n_m": " ".join(f"{m:.6g}" for m in twin.ring_moment),
            "spindle_pulses": self._pulses["spindle"],
            "cage_pulses": self._pulses["cage"],
            "refused_inputs": self.health.refused,
            "reader_stalls": self.health.reader_stalls,
            **{
                f"{key}_pacing": "off" if pacer.realtime else (f"off: {lead.off}" if lead.off else "on")
                for key, lead in zip(("force", "monitor", "session"), self._leads.values())
            },
            STOPPED_KEY: self.health.halted,
        }
        status = diagnostic_status(f"{NODE_NAME}: rig twin", int(health.level), health.message, values)
        self._diag_pub.publish(diagnostic_array(to_stamp(max(twin.time, 0.0)), [status]))


def message_class(msgtype: str) -> Any:
    """The rclpy message class of a contract type ``pkg/msg/Name``."""
    package, _, name = msgtype.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), name)


def instrument_message(kind: Any, reading: Reading) -> Any:
    """A message of class ``kind`` holding an instrument's reading: stamped with its time (s),
    each of its fields set by dotted path."""
    msg = kind()
    msg.header.stamp = to_stamp(reading.time)
    for path, value in reading.message_fields().items():
        *parents, leaf = path.split(".")
        target = msg
        for part in parents:
            target = getattr(target, part)
        setattr(target, leaf, value)
    return msg


def node_arguments(argv: Sequence[str]) -> list[str]:
    """The command line for rclpy: ``--no-realtime`` becomes ``-p realtime:=false``."""
    args = [a for a in argv if a != NO_REALTIME_FLAG]
    if len(args) != len(argv):
        args += ["--ros-args", "-p", "realtime:=false"]
    return args


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``simulator`` / ``bearing-rig-simulator``: spin the node until Ctrl-C.

    ``--no-realtime`` runs as fast as possible; ROS arguments (``--ros-args -p name:=value``,
    ``--params-file``) set the parameters of ``config/simulator.yaml``.
    """
    return node_main(NODE_NAME, SimulatorNode, node_arguments(list(sys.argv if argv is None else argv)))


if __name__ == "__main__":
    sys.exit(main())
