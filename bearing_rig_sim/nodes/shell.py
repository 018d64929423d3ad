"""What the simulator and monitor node shells share beyond nodes/common.py.

* :func:`declare_and_read`: ROS parameters declared from the shipped parameter file. Each key of
  ``config/<node>.yaml`` is declared with the file's value as default (so a partial user file or a
  ``-p`` override changes only what it names) and with dynamic typing (so ``-p rate:=2`` is not
  refused for being an integer where the file has ``2.0``); the node's ROS-free settings class
  then validates the values as one mapping, with messages naming the key and the allowed range.
* :func:`survives_shutdown`: a callback that publishes can be running when Ctrl-C or SIGTERM
  shuts the context down; its "context is invalid" error is swallowed then (and only then), so
  the executor's spin ends normally.
* :func:`release_executor`: called from a node's ``close()``. When a callback raised out of
  ``spin``, the executor's wait-set iterator stays suspended holding every entity's handle, and
  ``Node.destroy_node`` then busy-waits for ever for those handles (rclpy in Jazzy). Shutting the
  executor down drops the iterator and releases them.
"""

from __future__ import annotations

import functools
from typing import Any, TypeVar
from collections.abc import Callable, Mapping

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node

IMPLICIT = ("use_sim_time",)
"""Parameters every rclpy node declares by itself."""

F = TypeVar("F", bound=Callable[..., Any])


def declare_and_read(node: Node, defaults: Mapping[str, Any]) -> dict[str, Any]:
    """Declare each parameter of ``defaults`` (except :data:`IMPLICIT` ones) and return the
    values in force (defaults overridden by parameter files and ``-p``)."""
    values: dict[str, Any] = {}
    for name, default in defaults.items():
        if name in IMPLICIT:
            continue
        descriptor = ParameterDescriptor(dynamic_typing=True)
        values[name] = node.declare_parameter(name, default, descriptor).value
    return values


def survives_shutdown(method: F) -> F:
    """Decorate a node's callback method: an exception raised while the node's context is shut
    down (publishing during Ctrl-C) is dropped; any other propagates."""

    @functools.wraps(method)
    def wrapper(self: Node, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except Exception:
            if self.context.ok():
                raise
            return None

    return wrapper  # type: ignore[return-value]


def release_executor(node: Node) -> None:
    """Shut down the executor that spun ``node`` (if any) so that it lets go of the node's
    handles before ``destroy_node``; see the module docstring."""
    executor = node.executor
    if executor is not None:
        executor.shutdown(timeout_sec=0.0)
