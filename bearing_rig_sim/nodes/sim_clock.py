"""A :class:`~bearing_rig_sim.clock_guard.ClockGuard` between ``/clock`` and a node's sim-time clock.

rclpy's ``TimeSource`` sets the node's clock from every ``/clock`` message it receives: one
stamped far ahead moves the node's time there, one stamped before 1970 raises ``ValueError`` in
the middle of the spin and ends the node. :func:`guard_sim_clock` hands each message to a guard
first; a refused stamp is logged (at most once a second, with the running count) and dropped.
"""

from __future__ import annotations

from typing import Any
from collections.abc import Callable

from rclpy.node import Node

from bearing_rig_sim.clock_guard import ClockGuard
from bearing_rig_sim.interfaces import CLOCK

__all__ = ["guard_sim_clock"]

REPORT_PERIOD_S = 1.0
"""Shortest wall time between two log lines about refused stamps, s."""


def guard_sim_clock(node: Node, guard: ClockGuard | None = None) -> ClockGuard:
    """Validate every ``/clock`` message before it reaches ``node``'s sim-time clock.

    Works whether the node's ``/clock`` subscription exists yet or not (``use_sim_time`` may be
    set later). Returns the guard, whose ``refused`` and ``jumps`` count what it did.
    """
    guard = guard if guard is not None else ClockGuard(name=f"{node.get_name()}: {CLOCK.name}")
    source: Any = node._time_source
    logger = node.get_logger()
    forward: Callable[[Any], None] = source.clock_callback

    def guarded(msg: Any) -> None:
        verdict = guard.check(msg.clock.sec * 1_000_000_000 + msg.clock.nanosec)
        if verdict.note:
            logger.warning(f"{verdict.note} ({guard.refused} refused so far)", throttle_duration_sec=REPORT_PERIOD_S)
        if verdict.accepted:
            forward(msg)

    source.clock_callback = guarded  # for a subscription made later
    if source._clock_sub is not None:
        source._clock_sub.callback = guarded
    return guard
