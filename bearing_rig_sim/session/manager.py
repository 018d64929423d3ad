"""The lifecycle manager's ROS side: ``lifecycle_msgs`` service calls to the nodes, one at a time,
and a ``/diagnostics`` status per transition (a thin shell around :mod:`.lifecycle`).

Nothing here blocks: :meth:`LifecycleManager.poll` is called from the session's timer, sends the
next transition when the previous one has answered, and reports each answer. A transition not
answered is asked again every second (:class:`~bearing_rig_sim.nodes.service_call.RetriedCall`:
an answer lost right after discovery), and fails when none came within its time limit (the node
is named, with "no answer within N s"). A repeat refused (the first request was made, its answer
lost) is settled by the node's ``get_state``: done when the node is in the transition's goal state.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from diagnostic_msgs.msg import DiagnosticArray
from lifecycle_msgs.msg import Transition
from lifecycle_msgs.srv import ChangeState, GetState
from rclpy.node import Node

from bearing_rig_sim.interfaces import DIAGNOSTICS
from bearing_rig_sim.nodes.common import OK, ERROR, RELIABLE_QOS, diagnostic_array, diagnostic_status, to_stamp
from bearing_rig_sim.nodes.service_call import RetriedCall
from bearing_rig_sim.session.lifecycle import GOAL, Step, TransitionRecord

__all__ = ["DIAGNOSTIC_PREFIX", "LifecycleManager"]

TRANSITION_IDS = {
    "configure": Transition.TRANSITION_CONFIGURE,
    "cleanup": Transition.TRANSITION_CLEANUP,
    "activate": Transition.TRANSITION_ACTIVATE,
    "deactivate": Transition.TRANSITION_DEACTIVATE,
}
"""The ``lifecycle_msgs/msg/Transition`` id of each transition the manager asks for."""

DIAGNOSTIC_PREFIX = "lifecycle_manager: "
"""``/diagnostics`` status name of a node's lifecycle: the prefix and the node's name."""


class LifecycleManager:
    """Asks the nodes for transitions through their ``<name>/change_state`` services.

    Args:
        node: the session's node (clients and the diagnostics publisher are made on it).
        names: the managed nodes, in bring-up order.
        on_record: called with each transition's record (done or failed).
        sim_time: the session's simulation time now, s (stamps of the diagnostics).
    """

    def __init__(
        self,
        node: Node,
        names: Sequence[str],
        on_record: Callable[[TransitionRecord], None],
        sim_time: Callable[[], float],
    ) -> None:
        self.names = list(names)
        self.states = {name: "unconfigured" for name in names}
        """Each node's primary state as the manager knows it."""
        self.records: list[TransitionRecord] = []
        self.failed: TransitionRecord | None = None
        """The transition that failed (the queue is dropped then), else None."""
        self._clients = {name: node.create_client(ChangeState, f"/{name}/change_state") for name in names}
        self._state_clients = {name: node.create_client(GetState, f"/{name}/get_state") for name in names}
        self.published = 0
        """Lifecycle statuses published on ``/diagnostics``."""
        self._diagnostics = node.create_publisher(DiagnosticArray, DIAGNOSTICS.name, RELIABLE_QOS)
        self._on_record = on_record
        self._sim_time = sim_time
        self._queue: list[Step] = []
        self._pending: tuple[Step, RetriedCall, RetriedCall | None] | None = None
        self._limit = 10.0

    def services_missing(self) -> list[str]:
        """Nodes whose ``change_state`` service is not available yet."""
        return [name for name, client in self._clients.items() if not client.service_is_ready()]

    def run(self, steps: Sequence[Step], limit_s: float) -> None:
        """Queue ``steps`` (after any queued), each given ``limit_s`` wall s to answer."""
        self._queue.extend(steps)
        self._limit = limit_s
        self.failed = None

    @property
    def busy(self) -> bool:
        """Transitions queued or waiting for an answer."""
        return bool(self._queue) or self._pending is not None

    def poll(self) -> None:
        """Take the pending answer (if any) and send the next transition."""
        if self._pending is not None:
            step, call, state_call = self._pending
            if state_call is not None:
                if state_call.poll():
                    self._pending = None
                    state = state_call.response.current_state.label if state_call.answered else ""
                    done = state == GOAL[step.transition]
                    self._record(TransitionRecord(step, done, "" if done else f"the node refused the transition (it is {state or 'not answering'})"))
            elif call.poll():
                success = bool(call.answered and call.response.success)
                if call.answered and not success and call.attempts > 1:  # perhaps the first request's answer was lost
                    self._pending = (step, call, RetriedCall(self._state_clients[step.node], GetState.Request(), self._limit))
                else:
                    self._pending = None
                    detail = "" if success else "the node refused the transition" if call.answered else f"no answer within {self._limit:g} s"
                    self._record(TransitionRecord(step, success, detail))
        if self._pending is None and self._queue:
            step = self._queue.pop(0)
            request = ChangeState.Request(transition=Transition(id=TRANSITION_IDS[step.transition], label=""))
            self._pending = (step, RetriedCall(self._clients[step.node], request, self._limit), None)

    def drop(self, name: str) -> None:
        """Forget a node whose process ended: no more transitions for it."""
        self.states[name] = "gone"
        self._queue = [s for s in self._queue if s.node != name]
        if self._pending is not None and self._pending[0].node == name:
            self._pending = None

    def _record(self, record: TransitionRecord) -> None:
        self.records.append(record)
        self.states[record.step.node] = record.state
        if not record.success:
            self.failed = record
            self._queue.clear()
        step = record.step
        level = OK if record.success else ERROR
        message = f"{step.transition}: {GOAL[step.transition]}" if record.success else f"{step.transition} failed: {record.detail or 'refused'}"
        status = diagnostic_status(
            DIAGNOSTIC_PREFIX + step.node, level, message, {"state": record.state, "transition": step.transition}, hardware_id="bearing_rig_session"
        )
        self._diagnostics.publish(diagnostic_array(to_stamp(max(self._sim_time(), 0.0)), [status]))
        self.published += 1
        self._on_record(record)
