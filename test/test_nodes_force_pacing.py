"""Without real time the simulator follows the load controller's force on the bearing: a stopped
load controller holds the simulation, a set-point stamped ahead lands at its stamp, a deactivated
load controller holds nothing.

The simulator (``--no-realtime``) and the load controller run as processes on the test's isolated
domain; the test's node reads ``/clock``, the force on the bearing, the load controller's state,
the simulator's truth and diagnostics. Every wait is for a message, bounded.

Expected values, from the contract rather than the code: while the load controller is stopped
(SIGSTOP) no force sample is published, so the simulation may run no further than the latest
force stamp plus ``FORCE_LEAD_S`` (0.1 s) however long it stays stopped; a set-point that
reached it just before the stop (sent ahead, as a session sends it), stamped T on the 10 ms grid
of the state messages, shows first in the state stamped T (the one 10 ms before shows the previous set-point); from T + 0.5 s (``LOAD_SETTLE_S``;
the chain's stated settle bound for 100 -> 300 N is under 0.1 s) the force on the bearing and the
axial load the simulator applied lie within the settle band of 300 N (2 %: 6 N). Deactivated,
the load controller publishes nothing, and the simulation goes on without it (its diagnostics
say why), to resume pacing when it is activated again.
"""

from __future__ import annotations

import math
import os
import signal
import time
from typing import Any

import pytest

pytestmark = pytest.mark.ros
rclpy = pytest.importorskip("rclpy")

from bearing_rig_msgs.msg import AxialLoadState, SimulatorTruth  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from lifecycle_msgs.msg import Transition  # noqa: E402
from lifecycle_msgs.srv import ChangeState  # noqa: E402
from rclpy.duration import Duration  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402

from bearing_rig_sim.interfaces import AXIAL_LOAD_STATE, BEARING_AXIAL_FORCE, CLOCK, DIAGNOSTICS, LOAD_SETPOINT, TRUTH  # noqa: E402
from bearing_rig_sim.load_control import settle_band  # noqa: E402
from bearing_rig_sim.nodes.common import RELIABLE_QOS, drain, from_stamp, qos_profile, to_stamp  # noqa: E402
from bearing_rig_sim.nodes.simulator import FORCE_LEAD_S  # noqa: E402
from bearing_rig_sim.session.runner import LOAD_SETTLE_S  # noqa: E402

WAIT = 120.0
"""Longest wait for any one condition, wall s (two nodes start on a busy host)."""

CHUNK_S = 0.001
"""The simulator's chunk (config/simulator.yaml), s."""

BEFORE_N, AFTER_N = 100.0, 300.0

AHEAD_S = 3.0
"""How far ahead of the clock the set-point is stamped, s of sim time: the simulation, held by
the stopped load controller, stays far short of it. The set-point is published just before the
stop, once the load controller's reader has acknowledged a sample of this writer (the set-point
in force, sent again): the writer can match the reader before the reader matches the writer,
and a sample sent in between is dropped by the reader and repaired only after a heartbeat (3 s
in the test's process), which a resumed, fast simulation outruns; CI saw the chain pass the
stamp on the old set-point. Waiting for the acknowledgement of the stamped set-point itself
would let the simulation pass its stamp before the stop."""


class Probe:
    """The test's node: what the rig publishes, by topic."""

    def __init__(self, ros_graph: Any) -> None:
        self.graph = ros_graph
        self.node = ros_graph.node("pacing_probe")
        self.executor = ros_graph.executor([self.node])
        self.clock = -math.inf
        self.forces: dict[int, float] = {}
        """Bearing force (N) by stamp in ns."""
        self.published: dict[int, int] = {}
        """Wall time (ns, the publisher's source timestamp) each force sample was sent, by stamp in ns."""
        self.states: list[tuple[int, float]] = []
        """(stamp ns, set-point N) of the load controller's states."""
        self.truth: list[tuple[float, float]] = []
        """(stamp s, applied axial load N) of the simulator's truth."""
        self.pacing = ""
        node = self.node
        node.create_subscription(Clock, CLOCK.name, self._on_clock, qos_profile("clock_reader"))
        # the forces are taken with their source timestamps (when they were sent), by hand
        self.tap = ros_graph.node("pacing_tap")
        self.force_reader = self.tap.create_subscription(WrenchStamped, BEARING_AXIAL_FORCE.name, lambda _m: None, qos_profile(BEARING_AXIAL_FORCE))
        node.create_subscription(AxialLoadState, AXIAL_LOAD_STATE.name, self._on_state, qos_profile("reliable_stream"))
        node.create_subscription(SimulatorTruth, TRUTH.name, self._on_truth, qos_profile(TRUTH))
        node.create_subscription(DiagnosticArray, DIAGNOSTICS.name, self._on_diagnostics, RELIABLE_QOS)
        self.setpoint = node.create_publisher(WrenchStamped, LOAD_SETPOINT.name, qos_profile(LOAD_SETPOINT))
        self.change_state = node.create_client(ChangeState, "/load_controller/change_state")

    def _on_clock(self, msg: Clock) -> None:
        self.clock = max(self.clock, from_stamp(msg.clock))

    def take_forces(self) -> None:
        for msg, info in drain(self.force_reader, WrenchStamped, serialized=False):
            stamp = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
            self.forces[stamp] = msg.wrench.force.z
            self.published[stamp] = info["source_timestamp"]

    def _on_state(self, msg: AxialLoadState) -> None:
        self.states.append((msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec, msg.setpoint))

    def _on_truth(self, msg: SimulatorTruth) -> None:
        self.truth.append((from_stamp(msg.header.stamp), msg.axial_load))

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        for status in msg.status:
            for kv in status.values:
                if kv.key == "force_pacing":
                    self.pacing = kv.value

    @property
    def last_force(self) -> float:
        return max(self.forces) * 1e-9 if self.forces else -math.inf

    def last_force_sent_before(self, wall_ns: int) -> float:
        """Stamp (s) of the latest force sample sent before ``wall_ns`` (system clock)."""
        return max((t for t, sent in self.published.items() if sent < wall_ns), default=-1) * 1e-9

    def wait(self, condition: Any, what: str, timeout: float = WAIT) -> bool:
        def taken() -> bool:
            self.take_forces()
            return bool(condition())

        done = self.graph.spin_until(taken, timeout, executor=self.executor)
        assert done or timeout < WAIT, f"timed out waiting for {what} (pacing: {self.pacing!r})"
        return done

    def transition(self, transition_id: int) -> None:
        self.wait(self.change_state.service_is_ready, "the load controller's change_state service")
        future = self.change_state.call_async(ChangeState.Request(transition=Transition(id=transition_id)))
        self.wait(future.done, f"the answer to transition {transition_id}")
        assert future.result().success


def stopped(pid: int) -> bool:
    """The process is stopped (state T in /proc/PID/stat): a SIGSTOP has taken effect."""
    with open(f"/proc/{pid}/stat", encoding="ascii") as stat:
        return stat.read().rsplit(")", 1)[1].split()[0] == "T"


def test_the_simulator_waits_for_a_stopped_load_controller_and_not_for_a_deactivated_one(ros_graph: Any) -> None:
    ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime")
    controller = ros_graph.spawn_python(
        "-m", "bearing_rig_sim.nodes.load_controller", "--autostart", "--ros-args", "-p", f"axial_load_setpoint_n:={BEFORE_N!r}"
    )
    probe = Probe(ros_graph)
    probe.wait(lambda: probe.setpoint.get_subscription_count() > 0, "the load controller's set-point reader")
    probe.wait(lambda: probe.pacing == "on" and probe.last_force > 1.0, "the simulator pacing on the force stream, and its forces here")

    # the load controller's reader matched to this writer first: the set-point in force sent again
    # (unstamped: on arrival, no change) until the reader acknowledges it
    again = WrenchStamped()
    again.wrench.force.z = BEFORE_N
    probe.setpoint.publish(again)
    probe.wait(lambda: probe.setpoint.wait_for_all_acked(Duration(seconds=0)), "the load controller's reader to acknowledge the set-point in force")

    # a set-point stamped ahead, as a session sends it; then the load controller stopped
    stamp = math.ceil((probe.clock + AHEAD_S) / 0.01) * 0.01  # on the state messages' 10 ms grid
    message = WrenchStamped()
    message.header.stamp = to_stamp(stamp)
    message.wrench.force.z = AFTER_N
    probe.setpoint.publish(message)
    os.kill(controller.pid, signal.SIGSTOP)
    try:
        probe.wait(lambda: stopped(controller.pid), "the load controller to stop")
        stopped_at = time.time_ns()  # every force sent before this was sent before the stop
        # the simulation runs up to the last force sent plus the lead, and no further: what this
        # reader has of the forces sent before the stop is a lower bound of that (samples still
        # to be repaired come after the SIGCONT), so it reaches this at least
        probe.wait(lambda: probe.clock >= probe.last_force_sent_before(stopped_at) + FORCE_LEAD_S - 2 * CHUNK_S, "the simulation reaching the lead")
        held_clock = probe.clock
        probe.wait(
            lambda: probe.clock > held_clock + FORCE_LEAD_S, "", timeout=1.0
        )  # not a hang guard: a second of wall time, stopped, in which nothing is expected
        clock_while_stopped = probe.clock
    finally:
        resumed_at = time.time_ns()  # before the signal: a resumed process publishes at once
        os.kill(controller.pid, signal.SIGCONT)
    probe.wait(lambda: probe.last_force > clock_while_stopped, "the forces after the stop")
    assert not [t for t, sent in probe.published.items() if stopped_at < sent < resumed_at], "a stopped load controller sent a force"
    held = probe.last_force_sent_before(stopped_at)
    assert clock_while_stopped <= held + FORCE_LEAD_S + 1e-6, (
        f"the simulation ran to {clock_while_stopped:.4f} s past the last force {held:.4f} s + {FORCE_LEAD_S} s"
    )
    assert stamp > held  # the set-point's stamp still ahead of the load controller's chain when stopped

    stamp_ns = round(stamp * 1e9)
    settled = stamp + LOAD_SETTLE_S + 0.1
    probe.wait(
        lambda: any(t >= settled for t, _ in probe.truth) and probe.last_force >= settled and any(t * 1e-9 >= settled for t, _ in probe.states),
        "the rig going on past the set-point's settling",
    )
    before = [s for t, s in probe.states if t < stamp_ns]
    first_after = next(((t, s) for t, s in probe.states if s == AFTER_N), None)
    assert first_after is not None, f"no state with {AFTER_N} N: {sorted(set(s for _, s in probe.states))}"
    assert before and before[-1] == BEFORE_N
    assert first_after[0] == stamp_ns, f"the set-point took effect at {first_after[0] * 1e-9:.4f} s, stamped {stamp:.4f} s"
    band = settle_band(AFTER_N)
    judged = (stamp + LOAD_SETTLE_S, stamp + LOAD_SETTLE_S + 0.1)
    bearing = [f for t, f in probe.forces.items() if judged[0] <= t * 1e-9 <= judged[1]]
    applied = [f for t, f in probe.truth if judged[0] <= t <= judged[1]]
    assert bearing and all(abs(f - AFTER_N) <= band for f in bearing), bearing
    assert applied and all(abs(f - AFTER_N) <= band for f in applied), applied

    # deactivated: nothing published, nothing waited for; activated again: paced again
    probe.transition(Transition.TRANSITION_DEACTIVATE)
    probe.wait(lambda: probe.pacing.startswith("off: /load_controller left the active state"), "the simulator's word that it stopped pacing")
    quiet_from = probe.last_force
    probe.wait(lambda: probe.clock > quiet_from + 1.0, "the simulation going on without the load controller")
    assert probe.last_force == quiet_from
    probe.transition(Transition.TRANSITION_ACTIVATE)
    probe.wait(lambda: probe.pacing == "on" and probe.last_force > quiet_from, "pacing again after the activation")
    assert controller.poll() is None
