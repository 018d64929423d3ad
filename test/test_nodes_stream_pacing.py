"""Without real time the simulator keeps within a lead of two streams that follow its clock:
``MONITOR_LEAD_S`` (0.5 s of sim time) of the monitor's latest ``/rig/slip_status`` while pulses
flow, and ``SESSION_LEAD_S`` (2 s) of the session's latest ``/rig/session/progress`` (the latest
``/clock`` the session has taken and recorded). A silent publisher holds the simulation there,
its next message lets it go on. With the rig at rest (no pulse) the monitor has nothing to take,
and its statuses do not hold the simulation; a session whose publisher is gone (it ended) does
not hold it either.

The simulator (``--no-realtime``) runs as a process on the test's isolated domain; the test's
node plays the monitor or the session, publishing messages stamped with the latest ``/clock`` it
took, as they stamp with their rig time. Every wait is for a message (a ``/clock`` stamp, a
periodic diagnostics report of the simulator), bounded by a guard against a hang. The bounds are
the contract's (the leads), not figures measured from a run."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import pytest

pytestmark = pytest.mark.ros
rclpy = pytest.importorskip("rclpy")

from bearing_rig_msgs.msg import SlipStatus  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from std_msgs.msg import Header  # noqa: E402

from bearing_rig_sim.interfaces import CLOCK, DIAGNOSTICS, SESSION_PROGRESS, SLIP_STATUS  # noqa: E402
from bearing_rig_sim.nodes.common import RELIABLE_QOS, STATUS_QOS, from_stamp, qos_profile, to_stamp  # noqa: E402
from bearing_rig_sim.nodes.simulator import AT_REST, MONITOR_LEAD_S, SESSION_LEAD_S  # noqa: E402

RPM = math.pi / 30.0

WAIT = 120.0
"""Guard on any one wait, wall s."""

CHUNK_S = 0.001
"""The simulator's chunk (config/simulator.yaml), s."""

HELD_REPORTS = 3
"""Periodic diagnostics reports (1 Hz of wall time) the simulation must stay held for: well
beyond the time a loop not held would take to run its lead of sim time (under a second)."""


def play(ros_graph: Any, role: str) -> tuple[Any, Any, dict[str, Any]]:
    """A node playing ``role`` ("monitor" or "session"): its executor and what it has seen (the
    latest ``/clock``, and from the simulator's periodic reports the role's pacing state, their
    count and sim time)."""
    node = ros_graph.node(role)
    executor = ros_graph.executor([node])
    seen: dict[str, Any] = {"clock": -math.inf, "pacing": "", "reports": 0, "sim_time": -math.inf}

    def on_clock(msg: Clock) -> None:
        seen["clock"] = max(seen["clock"], from_stamp(msg.clock))

    def on_diagnostics(msg: DiagnosticArray) -> None:
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            if f"{role}_pacing" in values:
                seen["pacing"] = values[f"{role}_pacing"]
                seen["reports"] += 1
                seen["sim_time"] = float(values["sim_time_s"])

    node.create_subscription(Clock, CLOCK.name, on_clock, qos_profile("clock_reader"))
    node.create_subscription(DiagnosticArray, DIAGNOSTICS.name, on_diagnostics, RELIABLE_QOS)
    return node, executor, seen


def held_at_the_lead(ros_graph: Any, executor: Any, seen: dict[str, Any], publish: Callable[[float], None], lead: float) -> float:
    """Follow the clock as the paced node does (up to 3 s of sim time), fall silent, and check
    that the simulation stays within ``lead`` of the last stamp for :data:`HELD_REPORTS` reports
    of the simulator; then publish once more and check that it goes on. Returns the bound."""

    def following() -> bool:
        if seen["clock"] > 0.0:
            publish(seen["clock"])
        return seen["clock"] >= 3.0 and seen["pacing"] == "on"

    assert ros_graph.spin_until(following, WAIT, executor=executor), f"the simulator never paced on the stream: {seen}"
    last = seen["clock"]
    publish(last)
    bound = last + lead + CHUNK_S  # a stamp from a clock the test had not yet taken in full
    # silent: the simulation reaches its lead and stays there while the simulator paces on the
    # stream (it lets go by design after FORCE_SILENT_S of wall silence, which its report then
    # states: on a loaded host the held reports may take that long, so each report is judged by
    # what it says)
    assert ros_graph.spin_until(lambda: seen["clock"] >= last + lead - 0.1, WAIT, executor=executor), seen
    reports = seen["reports"]
    held: list[float] = []

    def judged() -> bool:
        if seen["reports"] > reports + len(held) and seen["pacing"] == "on":
            held.append(seen["sim_time"])
        return len(held) >= HELD_REPORTS or seen["pacing"] != "on"

    assert ros_graph.spin_until(judged, WAIT, executor=executor), seen
    assert held, f"no report while held: the simulator stopped pacing at once ({seen})"
    assert max(held) <= bound, f"held, the simulation ran to {max(held):.3f} s, the last stamp was {last:.3f} s"
    # the next message lets it go on (and sets the pacing on again if it had let go)
    publish(last + 1.0)
    assert ros_graph.spin_until(lambda: seen["clock"] > bound + 0.5, WAIT, executor=executor), seen
    return bound


def test_the_simulator_runs_no_further_than_its_lead_past_the_monitors_last_status(ros_graph: Any) -> None:
    """The spindle turns at 900 rpm from the start, so pulses flow throughout."""
    ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime", "--ros-args", "-p", f"initial_speed_rad_s:={900 * RPM!r}")
    node, executor, seen = play(ros_graph, "monitor")
    statuses = node.create_publisher(SlipStatus, SLIP_STATUS.name, STATUS_QOS)

    def publish(stamp: float) -> None:
        msg = SlipStatus()
        msg.header.stamp = to_stamp(stamp)
        statuses.publish(msg)

    held_at_the_lead(ros_graph, executor, seen, publish, MONITOR_LEAD_S)


def test_the_simulator_runs_no_further_than_its_lead_past_the_sessions_progress(ros_graph: Any) -> None:
    """The rig at rest, no load controller: neither the monitor nor the force paces it. Once
    the session's publisher is gone (as when a session ends), the clock runs on far past its last
    progress, and the simulator says why."""
    ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime")
    node, executor, seen = play(ros_graph, "session")
    progress = node.create_publisher(Header, SESSION_PROGRESS.name, qos_profile(SESSION_PROGRESS))

    def publish(stamp: float) -> None:
        progress.publish(Header(stamp=to_stamp(stamp), frame_id="test"))

    held_at_the_lead(ros_graph, executor, seen, publish, SESSION_LEAD_S)
    final = seen["clock"]
    publish(final)
    node.destroy_publisher(progress)
    assert ros_graph.spin_until(lambda: seen["pacing"] == f"off: no publisher of {SESSION_PROGRESS.name}", WAIT, executor=executor), seen
    assert ros_graph.spin_until(lambda: seen["clock"] > final + 4.0 * SESSION_LEAD_S, WAIT, executor=executor), seen


def test_at_rest_the_monitors_silence_does_not_hold_the_simulation(ros_graph: Any) -> None:
    """The spindle at rest from the start: no pulse is published, so a monitor whose statuses
    stand still (as they do between a stop's last pulse and the monitor's finding that the rig
    stopped, which needs more silence than the lead) does not hold the clock: it runs past the
    last status by more than the lead, and the simulator says why the statuses do not pace it."""
    ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime")
    node, executor, seen = play(ros_graph, "monitor")
    statuses = node.create_publisher(SlipStatus, SLIP_STATUS.name, STATUS_QOS)
    assert ros_graph.spin_until(lambda: seen["clock"] > 0.0, WAIT, executor=executor), seen
    last = seen["clock"]
    msg = SlipStatus()
    msg.header.stamp = to_stamp(last)
    statuses.publish(msg)  # then silent
    assert ros_graph.spin_until(lambda: seen["clock"] > last + 4.0 * MONITOR_LEAD_S, WAIT, executor=executor), seen
    assert ros_graph.spin_until(lambda: seen["pacing"] == f"off: {AT_REST}", WAIT, executor=executor), seen
