"""One readiness rule for the session and the rig benchmark: each node is named with the first
thing it lacks, and all are ready only when each publishes and listens."""

from __future__ import annotations

from bearing_rig_sim.interfaces import AXIAL_LOAD_STATE, CAGE_PULSES, CLOCK, LOAD_SETPOINT, SLIP_STATUS, SPINDLE_COMMAND
from bearing_rig_sim.session.readiness import not_ready

ALL_SUBSCRIBED = frozenset({SPINDLE_COMMAND.name, LOAD_SETPOINT.name, CAGE_PULSES.name})


def missing(seen: bool, subscribed: frozenset[str], published: frozenset[str]) -> dict[str, str]:
    return not_ready(
        clock_seen=seen,
        load_state_seen=seen,
        subscribers=lambda topic: int(topic in subscribed),
        publishers=lambda topic: int(topic in published),
    )


def test_ready_when_every_node_publishes_and_listens() -> None:
    assert missing(True, ALL_SUBSCRIBED, frozenset({SLIP_STATUS.name})) == {}


def test_nothing_up_names_what_each_node_has_not_sent() -> None:
    assert missing(False, frozenset(), frozenset()) == {
        "simulator": f"no {CLOCK.name} received",
        "load_controller": f"no {AXIAL_LOAD_STATE.name} received",
        "monitor": f"nobody publishes {SLIP_STATUS.name}",
    }


def test_a_node_that_publishes_but_does_not_listen_is_not_ready() -> None:
    for topic, node in ((SPINDLE_COMMAND.name, "simulator"), (LOAD_SETPOINT.name, "load_controller"), (CAGE_PULSES.name, "monitor")):
        assert missing(True, ALL_SUBSCRIBED - {topic}, frozenset({SLIP_STATUS.name})) == {node: f"nobody subscribes {topic}"}
