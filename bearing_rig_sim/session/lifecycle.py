"""The session as the nodes' lifecycle manager: which transition to ask of which node, and in
what order (no ROS; :mod:`.manager` sends them through ``lifecycle_msgs`` services).

Like nav2's lifecycle manager:

* **bring-up**: configure every node in order, then activate every node in order (simulator,
  load controller, monitor: the source of ``/clock`` first). The first transition that fails
  stops the bring-up; the node is named.
* **shut-down** (end of the program, Ctrl-C, a node's failure or death): deactivate the active
  nodes in reverse order, then clean up the configured ones in reverse order, skipping nodes
  that are gone (their process ended).

Every transition, done or failed, becomes a :class:`TransitionRecord`: a line in the session's
output and log, and a ``/diagnostics`` status.
"""

from __future__ import annotations

from dataclasses import dataclass
from collections.abc import Mapping, Sequence

__all__ = [
    "GOAL",
    "Step",
    "TransitionRecord",
    "bring_up",
    "shut_down",
]

GOAL = {"configure": "inactive", "cleanup": "unconfigured", "activate": "active", "deactivate": "inactive"}
"""The primary state each transition reaches when it succeeds."""

START = {"configure": "unconfigured", "cleanup": "inactive", "activate": "inactive", "deactivate": "active"}
"""The primary state each transition starts from."""


@dataclass(frozen=True)
class Step:
    """One transition to ask of one node."""

    node: str
    transition: str
    """``configure``, ``activate``, ``deactivate`` or ``cleanup``."""


@dataclass(frozen=True)
class TransitionRecord:
    """What one transition did."""

    step: Step
    success: bool
    detail: str = ""
    """Why it failed (the node's own reason when known; a timeout; no answer)."""

    @property
    def state(self) -> str:
        """The node's primary state after the transition."""
        return GOAL[self.step.transition] if self.success else START[self.step.transition]

    def line(self) -> str:
        """One line for the session's output and log."""
        step = self.step
        if self.success:
            return f"lifecycle: {step.node} {step.transition}: {START[step.transition]} -> {GOAL[step.transition]}"
        why = f": {self.detail}" if self.detail else ""
        return f"lifecycle: {step.node} {step.transition} FAILED, stays {START[step.transition]}{why}"


def bring_up(nodes: Sequence[str]) -> list[Step]:
    """Configure all of ``nodes`` in order, then activate all in reverse order (the simulator
    last: the load controller and the monitor take the clock from its first message, so the
    force and the statuses start with it, not some 0.3 s of sim time later)."""
    return [Step(n, "configure") for n in nodes] + [Step(n, "activate") for n in reversed(nodes)]


def shut_down(nodes: Sequence[str], states: Mapping[str, str], gone: Sequence[str] = ()) -> list[Step]:
    """Deactivate the active nodes in the order of ``nodes`` (the simulator first: the clock
    stops, and the nodes after it take its last messages while still active), then clean up the
    configured ones in reverse order; nodes in ``gone`` (their process ended) and unknown states
    are skipped."""
    alive = [n for n in nodes if n not in gone]
    steps = [Step(n, "deactivate") for n in alive if states.get(n) == "active"]
    steps += [Step(n, "cleanup") for n in reversed(alive) if states.get(n) in ("active", "inactive")]
    return steps
