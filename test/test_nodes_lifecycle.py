"""The nodes as managed (lifecycle) nodes, driven from a separate process through the standard
``lifecycle_msgs`` services, as ``ros2 lifecycle set`` or a launch file would.

Every wait is for an event (a service answer, a message, a discovered endpoint). "Publishes
nothing while not active" is checked through what the simulator's stamps say: it publishes one
``/clock`` per simulated chunk, so a simulation that ran while unconfigured or inactive would
show as a first stamp later than one chunk or as a gap in the stamps.
"""

from __future__ import annotations

from typing import Any

import pytest

rclpy = pytest.importorskip("rclpy")

from lifecycle_msgs.msg import State, Transition, TransitionEvent  # noqa: E402
from lifecycle_msgs.srv import ChangeState, GetState  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402

from bearing_rig_sim.nodes.common import from_stamp  # noqa: E402
from conftest import time_left  # noqa: E402

pytestmark = pytest.mark.ros

CHUNK = 0.001
"""The simulator's chunk in config/simulator.yaml (chunk_s), s."""


class LifecycleClient:
    """A separate node calling a managed node's lifecycle services."""

    def __init__(self, ros_graph: Any, target: str) -> None:
        self.graph = ros_graph
        self.node = ros_graph.node(f"{target}_lifecycle_client")
        self.executor = ros_graph.executor([self.node])
        self.get_state_client = self.node.create_client(GetState, f"/{target}/get_state")
        self.change_client = self.node.create_client(ChangeState, f"/{target}/change_state")
        self.events: list[TransitionEvent] = []
        self.node.create_subscription(TransitionEvent, f"/{target}/transition_event", self.events.append, 10)
        ready = self.spin_until(lambda: self.get_state_client.service_is_ready() and self.change_client.service_is_ready())
        assert ready, f"no lifecycle services of /{target}"

    def spin_until(self, condition: Any, timeout: float | None = None) -> bool:
        """Spin until ``condition()``, at most ``timeout`` s (default: the test's time left)."""
        return self.graph.spin_until(condition, timeout=time_left() if timeout is None else timeout, executor=self.executor)

    def call(self, client: Any, request: Any, resend_after: float | None = None) -> Any:
        answer = self.graph.call(client, request, self.executor, time_left(), resend_after)
        assert answer is not None, "no answer"
        return answer

    def state(self) -> str:
        # get_state changes nothing: sent again when DDS drops the answer to the first request
        return self.call(self.get_state_client, GetState.Request(), resend_after=5.0).current_state.label

    def change(self, transition_id: int) -> bool:
        return self.call(self.change_client, ChangeState.Request(transition=Transition(id=transition_id))).success


def test_simulator_streams_only_while_active(ros_graph: Any) -> None:
    process = ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--no-realtime")
    client = LifecycleClient(ros_graph, "simulator")
    node = client.node
    stamps: list[float] = []
    clock_sub = node.create_subscription(
        Clock, "/clock", lambda m: stamps.append(from_stamp(m.clock)), QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE)
    )

    # started alone: unconfigured, with no publisher of the rig's topics at all
    assert client.state() == "unconfigured"
    assert node.count_publishers("/clock") == 0 and node.count_publishers("/rig/speeds") == 0

    assert client.change(Transition.TRANSITION_CONFIGURE)
    assert client.state() == "inactive"
    assert client.spin_until(lambda: clock_sub.get_publisher_count() > 0), "the /clock publisher made at configure"
    assert client.state() == "inactive"  # a round trip through the node after the match
    assert stamps == []

    assert client.change(Transition.TRANSITION_ACTIVATE)
    assert client.spin_until(lambda: len(stamps) >= 200)
    # the twin did not run before activation: the clock's origin (0), then the first chunk
    assert stamps[0] == 0.0 and stamps[1] == pytest.approx(CHUNK, abs=1e-9)

    assert client.change(Transition.TRANSITION_DEACTIVATE)
    assert client.state() == "inactive"
    received = len(stamps)
    assert client.change(Transition.TRANSITION_ACTIVATE)
    assert client.spin_until(lambda: len(stamps) >= received + 200)
    # consecutive chunks throughout: nothing was simulated (so nothing published) while inactive
    steps = [round((b - a) / CHUNK, 6) for a, b in zip(stamps, stamps[1:])]
    assert set(steps) == {1.0}, sorted(set(steps))

    assert client.change(Transition.TRANSITION_DEACTIVATE)
    assert client.change(Transition.TRANSITION_CLEANUP)
    assert client.state() == "unconfigured"
    assert client.spin_until(lambda: clock_sub.get_publisher_count() == 0), "publishers destroyed at cleanup"
    # the standard transition events, ending in the primary states reached
    inactive, active, unconfigured = State.PRIMARY_STATE_INACTIVE, State.PRIMARY_STATE_ACTIVE, State.PRIMARY_STATE_UNCONFIGURED
    expected = [inactive, active, inactive, active, inactive, unconfigured]

    def primary_goals() -> list[int]:
        return [e.goal_state.id for e in client.events if e.goal_state.id in (inactive, active, unconfigured)]

    assert client.spin_until(lambda: primary_goals() == expected), primary_goals()
    assert process.poll() is None


def test_a_failed_configure_is_reported_and_the_node_stays_up(ros_graph: Any) -> None:
    process = ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.monitor", "--ros-args", "-p", "bearing_file:=bearings/missing.yaml")
    client = LifecycleClient(ros_graph, "monitor")
    assert client.state() == "unconfigured"
    assert not client.change(Transition.TRANSITION_CONFIGURE)
    assert client.state() == "unconfigured"
    assert client.node.count_publishers("/rig/slip_status") == 0
    assert process.poll() is None
    process.terminate()
    _, err = process.communicate(timeout=time_left())
    failed = [line for line in err.splitlines() if "configure failed:" in line]
    assert len(failed) == 1 and "bearing_file" in failed[0] and "missing.yaml" in failed[0], err[-2000:]


def test_autostart_configure_failure_is_one_line_and_exit_2(ros_graph: Any) -> None:
    process = ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--ros-args", "-p", "model:=no_such_model")
    _, err = process.communicate(timeout=time_left())
    assert process.returncode == 2, err[-2000:]
    assert "simulator: error:" in err and "model" in err and "no_such_model" in err and "Traceback" not in err
