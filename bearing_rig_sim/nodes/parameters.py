"""What every ROS parameter of the rig's nodes is: its meaning, unit, range and whether it may
change while the node runs, as each node's settings class declares it
(:mod:`bearing_rig_sim.settings_model`). No ROS here: :mod:`bearing_rig_sim.nodes.shell` turns
these into ``rcl_interfaces/ParameterDescriptor`` values, so ``ros2 param describe`` tells a
user what to set.

Nothing is written here by hand: the description, unit and range a node declares to ROS are the
ones its settings class checks its YAML file and its values in force against at configure, so a
value the ROS layer lets through is refused later only by an exclusive bound (ROS ranges are
inclusive; the descriptor's text says ``> low``) or a check across parameters. The values
themselves (defaults) live only in the shipped parameter files ``config/<node>.yaml``.

Read-only: everything a node reads in ``on_configure`` (files, models, rates, periods): a live
change would leave the running node inconsistent with its parameters, and ``ros2 param set``
refuses it with "read-only". They are set at start (parameter file, ``-p``). Only the load
controller's set-point is live.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator, Mapping

from bearing_rig_sim.settings_model import NodeSettings, ParameterField

__all__ = [
    "NODE_PARAMETERS",
    "NODE_SETTINGS",
    "STANDARD_PARAMETERS",
    "STANDARD_PREFIXES",
    "NODES",
    "in_force",
    "ParameterSpec",
    "is_standard",
    "settings_of",
    "spec_for",
]

STANDARD_PARAMETERS = ("use_sim_time", "start_type_description_service")
"""Parameters every ROS 2 Jazzy node declares by itself (rclpy and rclcpp alike): ``ros2 param
dump`` writes them for every node."""

STANDARD_PREFIXES = ("qos_overrides.",)
"""Prefixes of the parameters a node declares by itself for the QoS of its publishers and
subscriptions that allow overriding (``qos_overrides./parameter_events.publisher.depth``)."""


def is_standard(name: str) -> bool:
    """Whether ``name`` is one of the parameters every ROS 2 node has (not one of the rig's)."""
    return name in STANDARD_PARAMETERS or name.startswith(STANDARD_PREFIXES)


ParameterSpec = ParameterField
"""One parameter of a node as it is declared to ROS (the settings class's field)."""

NODES = ("simulator", "load_controller", "monitor", "shadow")
"""The nodes with parameters."""


def settings_of(node: str) -> type[NodeSettings]:
    """The settings class of ``node``, imported only when asked for: a node process loads its own
    settings module, not the others' (the simulator's and the shadow's bring in the engine).

    Raises:
        KeyError: no node of that name.
    """
    if node == "simulator":
        from bearing_rig_sim.simulation.settings import SimulatorSettings

        return SimulatorSettings
    if node == "load_controller":
        from bearing_rig_sim.load_control.settings import LoadControllerSettings

        return LoadControllerSettings
    if node == "monitor":
        from bearing_rig_sim.monitoring.settings import MonitorSettings

        return MonitorSettings
    if node == "shadow":
        from bearing_rig_sim.shadow.settings import ShadowSettings

        return ShadowSettings
    raise KeyError(node)


@functools.cache
def _parameters_of(node: str) -> dict[str, ParameterSpec]:
    return {f.name: f for f in settings_of(node).parameter_fields()}


class _ByNode(Mapping[str, dict[str, ParameterSpec]]):
    """Node name -> its parameters, each node's made when first asked for."""

    def __getitem__(self, node: str) -> dict[str, ParameterSpec]:
        return _parameters_of(node)

    def __iter__(self) -> Iterator[str]:
        return iter(NODES)

    def __len__(self) -> int:
        return len(NODES)


class _SettingsByNode(Mapping[str, type[NodeSettings]]):
    """Node name -> its settings class, imported when first asked for."""

    def __getitem__(self, node: str) -> type[NodeSettings]:
        return settings_of(node)

    def __iter__(self) -> Iterator[str]:
        return iter(NODES)

    def __len__(self) -> int:
        return len(NODES)


NODE_SETTINGS: Mapping[str, type[NodeSettings]] = _SettingsByNode()
"""The settings class of every node with parameters, by node name."""

NODE_PARAMETERS: Mapping[str, dict[str, ParameterSpec]] = _ByNode()
"""Every parameter of every node (besides rclpy's own ``use_sim_time``), by node name."""


def in_force(node: str, values: Mapping[str, object]) -> dict[str, ParameterSpec]:
    """``node``'s parameters with the bounds that the ``values`` in force give them (a limit of
    the rig file they name: :meth:`~bearing_rig_sim.settings_model.NodeSettings.parameter_fields`)."""
    return {f.name: f for f in settings_of(node).parameter_fields(values)}


def spec_for(node: str, name: str) -> ParameterSpec:
    """The spec of ``node``'s parameter ``name``.

    Raises:
        KeyError: naming the parameter that has no spec (every declared one must have one).
    """
    try:
        return NODE_PARAMETERS[node][name]
    except KeyError:
        raise KeyError(f"{node}: parameter {name!r} has no field in its settings class") from None
