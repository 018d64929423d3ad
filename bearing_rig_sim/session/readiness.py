"""When the rig's nodes are ready to run a program (no ROS): one rule, used by the session
(:meth:`bearing_rig_sim.session.node.SessionNode.missing`) and by the rig benchmark
(``bearing-rig bench rig``), so both wait for the same thing.

A node is ready when it publishes and listens: the simulator has sent a ``/clock`` and
subscribes the spindle commands, the load controller has sent a state and subscribes the
set-point the session sends (``/rig/load/setpoint``), the monitor publishes its status and
subscribes the cage pulses.
"""

from __future__ import annotations

from collections.abc import Callable

from bearing_rig_sim.interfaces import AXIAL_LOAD_STATE, CAGE_PULSES, CLOCK, LOAD_SETPOINT, SLIP_STATUS, SPINDLE_COMMAND

__all__ = ["not_ready"]


def not_ready(
    *,
    clock_seen: bool,
    load_state_seen: bool,
    subscribers: Callable[[str], int],
    publishers: Callable[[str], int],
) -> dict[str, str]:
    """Which node is not ready yet, and what is missing (empty when all are ready).

    Args:
        clock_seen: a ``/clock`` message was received.
        load_state_seen: a load-controller state message was received.
        subscribers: the number of subscriptions to a topic, the caller's own left out.
        publishers: the number of publishers of a topic, the caller's own left out.
    """
    missing = {}
    if not clock_seen:
        missing["simulator"] = f"no {CLOCK.name} received"
    elif subscribers(SPINDLE_COMMAND.name) == 0:
        missing["simulator"] = f"nobody subscribes {SPINDLE_COMMAND.name}"
    if not load_state_seen:
        missing["load_controller"] = f"no {AXIAL_LOAD_STATE.name} received"
    elif subscribers(LOAD_SETPOINT.name) == 0:
        missing["load_controller"] = f"nobody subscribes {LOAD_SETPOINT.name}"
    if publishers(SLIP_STATUS.name) == 0:
        missing["monitor"] = f"nobody publishes {SLIP_STATUS.name}"
    elif subscribers(CAGE_PULSES.name) == 0:
        missing["monitor"] = f"nobody subscribes {CAGE_PULSES.name}"
    return missing
