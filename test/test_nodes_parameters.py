"""Every parameter of every node describes itself (what, unit, range, read-only), and the ranges
agree with the settings classes that validate the values at configure.

The nodes are made in this process (unconfigured: declaring parameters is all their constructor
does) and asked through rclpy's own parameter API, which the ``describe_parameters`` and
``set_parameters`` services answer with.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any
from collections.abc import Callable

import pytest
import yaml

rclpy = pytest.importorskip("rclpy")

from rcl_interfaces.msg import ParameterType  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402

from bearing_rig_sim.config import ConfigError, config_path  # noqa: E402
from bearing_rig_sim.errors import RigError  # noqa: E402
from bearing_rig_sim.load_control.settings import LoadControllerSettings  # noqa: E402
from bearing_rig_sim.load_control.settings import shipped_parameters as load_controller_parameters  # noqa: E402
from bearing_rig_sim.monitoring import MonitorSettings  # noqa: E402
from bearing_rig_sim.monitoring import shipped_parameters as monitor_parameters  # noqa: E402
from bearing_rig_sim.nodes.load_controller import LoadControllerNode  # noqa: E402
from bearing_rig_sim.nodes.monitor import MonitorNode  # noqa: E402
from bearing_rig_sim.nodes.parameters import NODE_PARAMETERS  # noqa: E402
from bearing_rig_sim.nodes.shadow import ShadowNode  # noqa: E402
from bearing_rig_sim.nodes.simulator import SimulatorNode  # noqa: E402
from bearing_rig_sim.shadow import ShadowSettings  # noqa: E402
from bearing_rig_sim.shadow import shipped_parameters as shadow_parameters  # noqa: E402
from bearing_rig_sim.simulation.settings import SimulatorSettings  # noqa: E402
from bearing_rig_sim.simulation.settings import shipped_parameters as simulator_parameters  # noqa: E402

pytestmark = pytest.mark.ros

NODES: dict[str, tuple[Any, Callable[[], dict[str, Any]], Any]] = {
    "simulator": (SimulatorNode, simulator_parameters, SimulatorSettings),
    "load_controller": (LoadControllerNode, load_controller_parameters, LoadControllerSettings),
    "monitor": (MonitorNode, monitor_parameters, MonitorSettings),
    "shadow": (ShadowNode, shadow_parameters, ShadowSettings),
}

LIVE = {("load_controller", "axial_load_setpoint_n")}
"""The parameters that may change while the node runs; every other one is read-only."""


@pytest.mark.parametrize("name", sorted(NODES))
def test_every_parameter_has_a_descriptor_with_unit_and_range(ros_graph: Any, name: str) -> None:
    node_class, shipped, _settings = NODES[name]
    node = node_class(context=ros_graph.context())
    try:
        declared = set(node.list_parameters([], 0).names) - {"use_sim_time", "start_type_description_service"}  # rclpy's own
        assert declared == set(shipped()) - {"use_sim_time"}, "every key of the shipped file is a declared parameter"
        assert declared == set(NODE_PARAMETERS[name]), "every declared parameter has a spec, every spec a parameter"
        numeric = 0
        for parameter in sorted(declared):
            (descriptor,) = node.describe_parameters([parameter])
            value = node.get_parameter(parameter).value
            assert descriptor.description, parameter
            assert descriptor.read_only == ((name, parameter) not in LIVE), parameter
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                numeric += 1
                assert "unit: " in descriptor.additional_constraints, (parameter, descriptor.additional_constraints)
                ranges = descriptor.integer_range if isinstance(value, int) else descriptor.floating_point_range
                assert len(ranges) == 1, (parameter, descriptor)
                assert ranges[0].from_value <= value <= ranges[0].to_value, (parameter, value, ranges[0])
            else:
                assert not descriptor.floating_point_range and not descriptor.integer_range, parameter
        assert numeric >= 5
    finally:
        node.destroy_node()


def chain_limit(rig: Path) -> float:
    """The loading chain's set-point limit as the rig file writes it (read here with PyYAML)."""
    return float(yaml.safe_load(rig.read_text(encoding="utf-8"))["loading_chain"]["max_setpoint_n"])


def test_sets_are_refused_with_the_reason(ros_graph: Any) -> None:
    node = LoadControllerNode(context=ros_graph.context())
    try:
        (result,) = node.set_parameters([Parameter("axial_load_setpoint_n", value=chain_limit(config_path("rig.yaml")) + 1.0)])
        assert not result.successful and "out of range" in result.reason and f"{chain_limit(config_path('rig.yaml'))}" in result.reason, result.reason
        (result,) = node.set_parameters([Parameter("axial_load_setpoint_n", value=math.nan)])
        assert not result.successful and result.reason
        (result,) = node.set_parameters([Parameter("state_rate_hz", value=50.0)])
        assert not result.successful and "read-only" in result.reason
        (result,) = node.set_parameters([Parameter("axial_load_setpoint_n", value=250.0)])
        assert result.successful
        assert node.get_parameter("axial_load_setpoint_n").value == 250.0
    finally:
        node.destroy_node()


def test_the_set_points_upper_bound_is_the_rig_files_chain_limit(ros_graph: Any, tmp_path: Path) -> None:
    """``ros2 param describe`` shows the loading chain's limit (config/rig.yaml: 1000 N), not a
    bound of its own; a node given another rig file shows that file's limit and refuses a set
    above it."""
    shipped = chain_limit(config_path("rig.yaml"))
    doc = yaml.safe_load(config_path("rig.yaml").read_text(encoding="utf-8"))
    doc["loading_chain"]["max_setpoint_n"] = 600.0
    small = tmp_path / "small_rig.yaml"
    small.write_text(yaml.safe_dump(doc), encoding="utf-8")
    for overrides, limit in (([], shipped), ([Parameter("rig_file", value=str(small))], 600.0)):
        node = LoadControllerNode(context=ros_graph.context(), parameter_overrides=overrides)
        try:
            (descriptor,) = node.describe_parameters(["axial_load_setpoint_n"])
            (bound,) = descriptor.floating_point_range
            assert (bound.from_value, bound.to_value) == (0.0, limit)
            assert f"<= {limit:g} (loading_chain.max_setpoint_n in " in descriptor.additional_constraints, descriptor.additional_constraints
            (result,) = node.set_parameters([Parameter("axial_load_setpoint_n", value=limit + 1.0)])
            assert not result.successful
            (result,) = node.set_parameters([Parameter("axial_load_setpoint_n", value=limit)])
            assert result.successful
        finally:
            node.destroy_node()


def test_a_start_value_out_of_range_is_one_line_naming_the_parameter(ros_graph: Any) -> None:
    context = ros_graph.context()
    with pytest.raises(RigError, match=r"simulator: parameter rate refused: unit: 1; range: > 0 and <= 100"):
        SimulatorNode(context=context, parameter_overrides=[Parameter("rate", value=500.0)])


DEPENDENT = {
    ("simulator", "initial_speed_rad_s"): "at most the rig file's spindle speed limit",
    ("load_controller", "axial_load_setpoint_n"): "at most the rig file's max_setpoint_n (checked by the chain at configure)",
    ("shadow", "warn_after_s"): "below error_after_s",
    ("shadow", "error_after_s"): "above warn_after_s",
}
"""Bounds that depend on another value: their settings check is relative to it."""


@pytest.mark.parametrize("name", sorted(NODES))
def test_descriptor_ranges_lie_inside_what_the_settings_accept(name: str) -> None:
    _node, shipped, settings = NODES[name]
    defaults = shipped()
    for spec in NODE_PARAMETERS[name].values():
        if not spec.numeric or (name, spec.name) in DEPENDENT:
            continue
        assert spec.low is not None and spec.high is not None
        cast: Callable[[float], Any] = int if spec.integer else float
        settings.from_values({**defaults, spec.name: cast(spec.high)})  # the top of the range is accepted
        if spec.low_exclusive:
            with pytest.raises(ConfigError, match=spec.name):
                settings.from_values({**defaults, spec.name: cast(spec.low)})
            settings.from_values({**defaults, spec.name: cast(spec.low) + (1 if spec.integer else 1e-6)})
        else:
            settings.from_values({**defaults, spec.name: cast(spec.low)})


def test_parameter_types_are_the_shipped_files() -> None:
    for name, (_node, shipped, _settings) in NODES.items():
        for key, value in shipped().items():
            if key == "use_sim_time":
                continue
            spec = NODE_PARAMETERS[name][key]
            expected = ParameterType.PARAMETER_INTEGER if spec.integer else ParameterType.PARAMETER_DOUBLE
            if spec.numeric:
                kind = ParameterType.PARAMETER_INTEGER if isinstance(value, int) else ParameterType.PARAMETER_DOUBLE
                assert kind == expected, (name, key, value)
