"""Without real time the simulator keeps within ``MONITOR_LEAD_S`` (0.5 s of sim time) of the
monitor's latest ``/rig/slip_status`` while pulses flow: a monitor that falls silent holds the
simulation there, and its next status lets it go on. With the rig at rest (no pulse) the monitor
has nothing to take, and its statuses do not hold the simulation.

The simulator (``--no-realtime``) runs as a process on the test's isolated domain; the test's
node plays the monitor, publishing statuses stamped with the latest ``/clock`` it took, as the
monitor stamps with its rig time. Every wait is for a message (a ``/clock`` stamp, a periodic
diagnostics report of the simulator), bounded by a guard against a hang. The bound is the
contract's (the lead), not a figure measured from a run."""

from __future__ import annotations

import math
from typing import Any

import pytest

pytestmark = pytest.mark.ros
rclpy = pytest.importorskip("rclpy")

from bearing_rig_msgs.msg import SlipStatus  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402

from bearing_rig_sim.interfaces import CLOCK, DIAGNOSTICS, SLIP_STATUS  # noqa: E402
from bearing_rig_sim.nodes.common import RELIABLE_QOS, STATUS_QOS, from_stamp, qos_profile, to_stamp  # noqa: E402
from bearing_rig_sim.nodes.simulator import AT_REST, MONITOR_LEAD_S  # noqa: E402

RPM = math.pi / 30.0

WAIT = 120.0
"""Guard on any one wait, wall s."""

CHUNK_S = 0.001
"""The simulator's chunk (config/simulator.yaml), s."""

HELD_REPORTS = 3
"""Periodic diagnostics reports (1 Hz of wall time) the simulation must stay held for: well
beyond the time a loop not held would take to run 0.5 s of sim time (a few hundred ms)."""


def play_the_monitor(ros_graph: Any) -> tuple[Any, Any, dict[str, Any], Any]:
    """A node playing the monitor: its executor, what it has seen (the latest ``/clock``, and
    from the simulator's periodic reports the monitor pacing's state, their count and sim time)
    and its status publisher."""
    node = ros_graph.node("monitor")
    executor = ros_graph.executor([node])
    seen: dict[str, Any] = {"clock": -math.inf, "pacing": "", "reports": 0, "sim_time": -math.inf}

    def on_clock(msg: Clock) -> None:
        seen["clock"] = max(seen["clock"], from_stamp(msg.clock))

    def on_diagnostics(msg: DiagnosticArray) -> None:
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            if "monitor_pacing" in values:
                seen["pacing"] = values["monitor_pacing"]
                seen["reports"] += 1
                seen["sim_time"] = float(values["sim_time_s"])

    node.create_subscription(Clock, CLOCK.name, on_clock, qos_profile("clock_reader"))
    node.create_subscription(DiagnosticArray, DIAGNOSTICS.name, on_diagnostics, RELIABLE_QOS)
    return node, executor, seen, node.create_publisher(SlipStatus, SLIP_STATUS.name, STATUS_QOS)


def test_the_simulator_runs_no_further_than_its_lead_past_the_monitors_last_status(ros_graph: Any) -> None:
    """The spindle turns at 900 rpm from the start, so pulses flow throughout."""
    ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime", "--ros-args", "-p", f"initial_speed_rad_s:={900 * RPM!r}")
    node, executor, seen, statuses = play_the_monitor(ros_graph)

    def publish(stamp: float) -> None:
        msg = SlipStatus()
        msg.header.stamp = to_stamp(stamp)
        statuses.publish(msg)

    # follow the clock, as the monitor does, up to 2 s of sim time
    def following() -> bool:
        if seen["clock"] > 0.0:
            publish(seen["clock"])
        return seen["clock"] >= 2.0 and seen["pacing"] == "on"

    assert ros_graph.spin_until(following, WAIT, executor=executor), f"the simulator never paced on the statuses: {seen}"
    last = seen["clock"]
    publish(last)
    bound = last + MONITOR_LEAD_S + CHUNK_S  # a status stamped from a clock the test had not yet taken in full
    # silent monitor: the simulation reaches its lead and stays there while the simulator paces on
    # the statuses (it lets go by design after FORCE_SILENT_S of wall silence, which its report
    # then states: on a loaded host the held reports may take that long, so each report is
    # judged by what it says)
    assert ros_graph.spin_until(lambda: seen["clock"] >= last + MONITOR_LEAD_S - 0.1, WAIT, executor=executor), seen
    reports = seen["reports"]
    held: list[float] = []

    def judged() -> bool:
        if seen["reports"] > reports + len(held) and seen["pacing"] == "on":
            held.append(seen["sim_time"])
        return len(held) >= HELD_REPORTS or seen["pacing"] != "on"

    assert ros_graph.spin_until(judged, WAIT, executor=executor), seen
    assert held, f"no report while held: the simulator stopped pacing at once ({seen})"
    assert max(held) <= bound, f"held, the simulation ran to {max(held):.3f} s, the last status was {last:.3f} s"
    # the monitor's next status lets it go on (and sets the pacing on again if it had let go)
    publish(last + 1.0)
    assert ros_graph.spin_until(lambda: seen["clock"] > bound + 0.5, WAIT, executor=executor), seen


def test_at_rest_the_monitors_silence_does_not_hold_the_simulation(ros_graph: Any) -> None:
    """The spindle at rest from the start: no pulse is published, so a monitor whose statuses
    stand still (as they do between a stop's last pulse and the monitor's finding that the rig
    stopped, which needs more silence than the lead) does not hold the clock: it runs past the
    last status by more than the lead, and the simulator says why the statuses do not pace it."""
    ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime")
    _node, executor, seen, statuses = play_the_monitor(ros_graph)
    assert ros_graph.spin_until(lambda: seen["clock"] > 0.0, WAIT, executor=executor), seen
    last = seen["clock"]
    msg = SlipStatus()
    msg.header.stamp = to_stamp(last)
    statuses.publish(msg)  # then silent
    assert ros_graph.spin_until(lambda: seen["clock"] > last + 4.0 * MONITOR_LEAD_S, WAIT, executor=executor), seen
    assert ros_graph.spin_until(lambda: seen["pacing"] == f"off: {AT_REST}", WAIT, executor=executor), seen
