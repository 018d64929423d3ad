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

from bearing_rig_sim.load_control.settings import LoadControllerSettings
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.settings_model import NodeSettings, ParameterField
from bearing_rig_sim.shadow.settings import ShadowSettings
from bearing_rig_sim.simulation.settings import SimulatorSettings

__all__ = [
    "NODE_PARAMETERS",
    "NODE_SETTINGS",
    "STANDARD_PARAMETERS",
    "STANDARD_PREFIXES",
    "ParameterSpec",
    "is_standard",
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

NODE_SETTINGS: dict[str, type[NodeSettings]] = {
    settings.NODE_NAME: settings for settings in (SimulatorSettings, LoadControllerSettings, MonitorSettings, ShadowSettings)
}
"""The settings class of every node with parameters, by node name."""

NODE_PARAMETERS: dict[str, dict[str, ParameterSpec]] = {
    node: {f.name: f for f in settings.parameter_fields()} for node, settings in NODE_SETTINGS.items()
}
"""Every parameter of every node (besides rclpy's own ``use_sim_time``), by node name."""


def spec_for(node: str, name: str) -> ParameterSpec:
    """The spec of ``node``'s parameter ``name``.

    Raises:
        KeyError: naming the parameter that has no spec (every declared one must have one).
    """
    try:
        return NODE_PARAMETERS[node][name]
    except KeyError:
        raise KeyError(f"{node}: parameter {name!r} has no field in its settings class") from None
