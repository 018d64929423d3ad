"""Service calls that survive discovery: :class:`~bearing_rig_sim.nodes.service_call.RetriedCall`
on fake futures and a fake wall clock (asks again every ``retry_s`` until an answer comes, any
answer counts, gives up at its guard), and the session's lifecycle manager against a real
``change_state`` server whose first answer is dropped, as Fast DDS drops an answer sent before
the server's response writer has matched the client's reader.

The ROS tests wait for the manager's record (an event), with a guard against a hang only."""

from __future__ import annotations

from typing import Any

import pytest

from bearing_rig_sim.nodes.service_call import RetriedCall
from conftest import time_left


class FakeFuture:
    def __init__(self) -> None:
        self.value: Any = None
        self.cancelled = False

    def done(self) -> bool:
        return self.value is not None

    def result(self) -> Any:
        return self.value

    def cancel(self) -> None:
        self.cancelled = True


class FakeClient:
    """A client whose requests' futures the test answers by hand."""

    def __init__(self) -> None:
        self.futures: list[FakeFuture] = []

    def call_async(self, _request: Any) -> FakeFuture:
        self.futures.append(FakeFuture())
        return self.futures[-1]


class FakeClock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def test_an_unanswered_request_is_asked_again_every_retry_period_until_answered() -> None:
    client, clock = FakeClient(), FakeClock()
    call = RetriedCall(client, "request", 10.0, retry_s=1.0, clock=clock)
    assert call.attempts == 1 and not call.poll()
    clock.now += 0.99
    assert not call.poll() and call.attempts == 1
    clock.now += 0.02
    assert not call.poll() and call.attempts == 2  # the first answer was lost: asked again
    client.futures[1].value = "answer"
    assert call.poll() and call.answered and call.response == "answer"
    assert client.futures[0].cancelled  # the first request is forgotten
    assert call.attempts == 2


def test_a_late_answer_to_the_first_request_counts_too() -> None:
    client, clock = FakeClient(), FakeClock()
    call = RetriedCall(client, "request", 10.0, retry_s=1.0, clock=clock)
    clock.now += 1.5
    call.poll()
    client.futures[0].value = "first"
    assert call.poll() and call.response == "first"


def test_a_request_never_answered_gives_up_at_its_guard() -> None:
    client, clock = FakeClient(), FakeClock()
    call = RetriedCall(client, "request", 3.0, retry_s=1.0, clock=clock)
    while not call.poll():
        clock.now += 0.25
    assert not call.answered and call.timed_out
    assert clock.now - 100.0 == pytest.approx(3.25)  # the first poll past the guard
    assert call.attempts == 4  # at 0, 1, 2, 3 s: never after the guard


def test_a_guard_that_is_not_positive_is_refused() -> None:
    with pytest.raises(ValueError, match="guard_s"):
        RetriedCall(FakeClient(), "request", 0.0)


# -- the session's lifecycle manager against a server whose first answer is dropped -----------


def drop_first_answer(service: Any) -> list[int]:
    """Make ``service`` lose its first response (counted in the list returned: answers sent)."""
    send = service.send_response
    sent = [0]

    def lossy(response: Any, header: Any) -> None:
        sent[0] += 1
        if sent[0] > 1:
            send(response, header)

    service.send_response = lossy
    return sent


@pytest.mark.ros
@pytest.mark.parametrize("repeat_refused", [False, True], ids=["repeat-answered", "repeat-refused"])
def test_the_lifecycle_manager_asks_again_when_the_first_answer_is_lost(ros_graph: Any, repeat_refused: bool) -> None:
    """A ``configure`` whose answer is lost is asked again and recorded done. ``repeat-refused``:
    the server made the transition on the first request and refuses the repeat (as a lifecycle
    node does); the manager reads its ``get_state`` and records the transition done."""
    from lifecycle_msgs.msg import State
    from lifecycle_msgs.srv import ChangeState, GetState

    from bearing_rig_sim.session.lifecycle import Step
    from bearing_rig_sim.session.manager import LifecycleManager

    server = ros_graph.node("fake")
    state = {"id": State.PRIMARY_STATE_UNCONFIGURED, "label": "unconfigured"}
    requests: list[int] = []

    def change_state(request: Any, response: Any) -> Any:
        requests.append(request.transition.id)
        if state["label"] == "unconfigured":
            state.update(id=State.PRIMARY_STATE_INACTIVE, label="inactive")
            response.success = True
        else:
            response.success = not repeat_refused
        return response

    def get_state(_request: Any, response: Any) -> Any:
        response.current_state = State(id=state["id"], label=state["label"])
        return response

    sent = drop_first_answer(server.create_service(ChangeState, "/fake/change_state", change_state))
    server.create_service(GetState, "/fake/get_state", get_state)
    session = ros_graph.node("session", context=server.context)
    records: list[Any] = []
    manager = LifecycleManager(session, ["fake"], records.append, lambda: 0.0)
    executor = ros_graph.executor([server, session])
    assert ros_graph.spin_until(lambda: not manager.services_missing(), timeout=time_left(), executor=executor)
    manager.run([Step("fake", "configure")], 60.0)

    def recorded() -> bool:
        manager.poll()
        return bool(records)

    assert ros_graph.spin_until(recorded, timeout=time_left(), executor=executor), "no record within the guard"
    (record,) = records
    assert record.success, record.detail
    assert record.state == "inactive" and state["label"] == "inactive"
    assert len(requests) >= 2 and sent[0] >= 2  # the first answer was lost, a repeat answered
