"""No lifecycle request ends a node: every ``change_state`` request, in every state, is answered.

rclpy in Jazzy raises "Transition is not registered" out of the ``change_state`` service callback
for a transition the node's state does not offer (``ros2 service call /simulator/change_state
lifecycle_msgs/srv/ChangeState '{transition: {id: 3}}'`` while unconfigured), and the node's
process died of it. The nodes now refuse such a request (``success: false``). The expectation
of each answer comes from the standard lifecycle state machine (design.ros2.org, "Managed
nodes"; the ids of ``lifecycle_msgs/msg/Transition``), written out below, not from the node.

The fuzz: random transition ids (the valid ones, their neighbours, 0, and ids past the last)
sent to each managed node in whatever state the previous requests left it; after each request
the node must have answered, its state must be what the state machine says, and its process
must be alive.
"""

from __future__ import annotations

import random
from typing import Any

import pytest

rclpy = pytest.importorskip("rclpy")

from lifecycle_msgs.msg import Transition  # noqa: E402
from lifecycle_msgs.srv import ChangeState, GetState  # noqa: E402
from conftest import time_left  # noqa: E402

pytestmark = [pytest.mark.ros, pytest.mark.slow]

T = Transition
MACHINE: dict[str, dict[int, str]] = {
    "unconfigured": {T.TRANSITION_CONFIGURE: "inactive", T.TRANSITION_UNCONFIGURED_SHUTDOWN: "finalized"},
    "inactive": {
        T.TRANSITION_CLEANUP: "unconfigured",
        T.TRANSITION_ACTIVATE: "active",
        T.TRANSITION_INACTIVE_SHUTDOWN: "finalized",
    },
    "active": {T.TRANSITION_DEACTIVATE: "inactive", T.TRANSITION_ACTIVE_SHUTDOWN: "finalized"},
    "finalized": {},
}
"""The primary states and, for each, the transition ids it offers and the state each reaches
(design.ros2.org/articles/node_lifecycle.html; every one of the rig's transitions succeeds with
the shipped parameters)."""

NODES = ("simulator", "load_controller", "monitor", "shadow")
"""Every managed node of the rig (the shadow node is managed too)."""


class Lifecycle:
    """Clients of one node's ``get_state`` and ``change_state`` services."""

    def __init__(self, ros_graph: Any, target: str) -> None:
        self.graph = ros_graph
        self.node = ros_graph.node(f"fuzz_{target}")
        self.executor = ros_graph.executor([self.node])
        self.get_state = self.node.create_client(GetState, f"/{target}/get_state")
        self.change_state = self.node.create_client(ChangeState, f"/{target}/change_state")
        ready = ros_graph.spin_until(
            lambda: self.get_state.service_is_ready() and self.change_state.service_is_ready(), timeout=time_left(), executor=self.executor
        )
        assert ready, f"no lifecycle services of /{target}"

    def _call(self, client: Any, request: Any, resend_after: float | None = None) -> Any:
        answer = self.graph.call(client, request, self.executor, time_left(), resend_after)  # a first configure compiles the kernels
        assert answer is not None, f"no answer to {request} within the test's time"
        return answer

    def state(self) -> str:
        return str(self._call(self.get_state, GetState.Request(), resend_after=5.0).current_state.label)

    def change(self, transition_id: int = 0, label: str = "") -> bool:
        return bool(self._call(self.change_state, ChangeState.Request(transition=Transition(id=transition_id, label=label))).success)


def _ids(rng: random.Random) -> int:
    """A transition id: a real one, one of the error-path ids, 0, or an id no machine has."""
    return rng.choice([*range(0, 9), *range(10, 16), 60, 61, 62, 99, 255])


@pytest.mark.parametrize("name", NODES)
def test_a_transition_the_state_does_not_offer_is_refused_and_the_node_answers_on(ros_graph: Any, name: str) -> None:
    process = ros_graph.spawn_python("-m", f"bearing_rig_sim.nodes.{name}")
    node = Lifecycle(ros_graph, name)
    assert node.state() == "unconfigured"
    # the request of issue 26: activate while unconfigured
    assert node.change(Transition.TRANSITION_ACTIVATE) is False
    assert node.change(label="deactivate") is False
    assert node.change(label="no_such_transition") is False
    assert node.state() == "unconfigured" and process.poll() is None
    assert node.change(Transition.TRANSITION_CONFIGURE) is True
    assert node.change(Transition.TRANSITION_CONFIGURE) is False  # configured already
    assert node.change(Transition.TRANSITION_DEACTIVATE) is False
    assert node.change(label="activate") is True
    assert node.state() == "active" and process.poll() is None
    process.terminate()
    _, err = process.communicate(timeout=time_left())
    refused = [line for line in err.splitlines() if "change_state refused" in line]
    assert len(refused) == 5, err[-3000:]
    assert "id 3" in refused[0] and "unconfigured" in refused[0] and "configure (1)" in refused[0], refused[0]
    assert "Traceback" not in err and "Transition is not registered" not in err, err[-3000:]


@pytest.mark.parametrize("name", NODES)
def test_random_lifecycle_requests_leave_the_node_alive_and_answering(ros_graph: Any, name: str) -> None:
    rng = random.Random(f"lifecycle fuzz {name}")
    process = ros_graph.spawn_python("-m", f"bearing_rig_sim.nodes.{name}")
    node = Lifecycle(ros_graph, name)
    state = node.state()
    assert state == "unconfigured"
    shutdowns = {T.TRANSITION_UNCONFIGURED_SHUTDOWN, T.TRANSITION_INACTIVE_SHUTDOWN, T.TRANSITION_ACTIVE_SHUTDOWN}
    requests = 0
    while requests < 40:
        wanted = _ids(rng)
        if wanted in shutdowns and requests < 36:  # finalized ends the walk: only near its end
            continue
        requests += 1
        expected = MACHINE[state].get(wanted)
        assert node.change(wanted) is (expected is not None), (state, wanted)
        state = expected or state
        assert node.state() == state, (wanted, state)
        assert process.poll() is None, f"{name} died after transition id {wanted}"
    process.terminate()
    _, err = process.communicate(timeout=time_left())
    assert "Traceback" not in err and "Transition is not registered" not in err, err[-3000:]
