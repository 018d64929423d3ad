"""Benchmarks: each module exposes add_arguments(parser) and run(args) -> Iterator[dict].

Shared here: :func:`percentile`, and :func:`rig_graph`, the ROS graph in which a benchmark runs
the rig's processes and its own probe as a session runs its nodes.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

_Probe = TypeVar("_Probe")


def percentile(values: list[float], q: float) -> float:
    """The ``q`` (0-1) quantile of ``values`` by nearest rank from below (the value at index
    ``int(q n)`` of the sorted values, the last for q = 1); NaN for no values."""
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


@dataclass
class RigGraph:
    """A benchmark's graph (:func:`rig_graph`): the environment its processes start with, and the
    rclpy context of its probe (initialised by :meth:`join`)."""

    env: dict[str, str]
    context: Any

    def join(self, make_probe: Callable[[Any], _Probe]) -> _Probe:
        """Initialise the probe's context on the graph's domain and make the probe (``make_probe``
        gets the context), both with this process's ROS variables taken from :attr:`env`: the
        middleware reads them when the first node of a context is made."""
        import rclpy
        from rclpy.signals import SignalHandlerOptions

        from bearing_rig_sim.session.processes import own_ros_environment

        with own_ros_environment(self.env):
            rclpy.init(args=[], context=self.context, domain_id=int(self.env["ROS_DOMAIN_ID"]), signal_handler_options=SignalHandlerOptions.NO)
            return make_probe(self.context)


@contextmanager
def rig_graph(work: Path) -> Iterator[RigGraph]:
    """The session's environment for a benchmark (its domain isolation, a private domain leased
    unless the user set one, and the rig's transport profile written into ``work``:
    :func:`~bearing_rig_sim.session.processes.session_environment`) with a context for the
    probe. On exit the context is shut down and the domain released; the benchmark stops its
    processes before (inside the block)."""
    import rclpy

    from bearing_rig_sim.dds_profile import apply_rig_profile
    from bearing_rig_sim.session.processes import session_environment

    env, lease = session_environment(os.environ)
    apply_rig_profile(env, work)
    graph = RigGraph(env, rclpy.Context())
    try:
        yield graph
    finally:
        graph.context.try_shutdown()
        lease.release()
