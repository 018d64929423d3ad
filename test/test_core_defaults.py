"""A core has no default of its own for a parameter the shipped files hold: each such argument is
required (or its default is the file's value), and a core built from the shipped files runs with
the files' values. The files are read here with PyYAML, not through the settings classes, so a
copy of a value in code cannot agree with itself."""

from __future__ import annotations

import inspect
import math
from collections.abc import Callable
from typing import Any

import pytest
import yaml

from bearing_rig_sim.analysis.streaming import TrailingSlope
from bearing_rig_sim.config import config_path
from bearing_rig_sim.monitoring.windows import SlipWindows
from bearing_rig_sim.simulation.drive import SpindleDrive
from bearing_rig_sim.simulation.pacing import RealTimePacer
from bearing_rig_sim.simulation.settings import SimulatorSettings
from bearing_rig_sim.simulation.twin import RigTwin


def node_file(node: str) -> dict[str, Any]:
    """``<node>: ros__parameters:`` of the shipped ``config/<node>.yaml``."""
    return dict(yaml.safe_load(config_path(f"{node}.yaml").read_text(encoding="utf-8"))[node]["ros__parameters"])


def rig_file() -> dict[str, Any]:
    return dict(yaml.safe_load(config_path("rig.yaml").read_text(encoding="utf-8")))


CORES: list[tuple[Callable[..., Any], str, dict[str, str]]] = [
    (
        RealTimePacer,
        "simulator",
        {
            "chunk": "chunk_s",
            "loop_period": "loop_period_s",
            "realtime": "realtime",
            "rate": "rate",
            "overrun_margin": "overrun_margin_s",
            "rtf_window": "rtf_window_s",
            "max_batch": "max_batch_chunks",
            "resync_lag": "resync_lag_s",
        },
    ),
    (
        RigTwin,
        "simulator",
        {
            "chunk": "chunk_s",
            "initial_speed": "initial_speed_rad_s",
            "initial_axial_load": "initial_axial_load_n",
            "counter_timeout": "counter_timeout_s",
            "max_command_lead": "max_command_lead_s",
        },
    ),
    (SpindleDrive, "simulator", {"initial_speed": "initial_speed_rad_s", "max_lead": "max_command_lead_s"}),
    (
        TrailingSlope,
        "monitor",
        {
            "span": "slope_span_s",
            "min_points": "min_slope_points",
            "resolution": "slip_resolution_pct",
            "change_threshold": "change_threshold",
        },
    ),
    (SlipWindows, "monitor", {"window_revolutions": "window_revolutions", "min_window_s": "min_window_s"}),
]
"""Class (its constructor's signature: also where its module runs compiled, whose ``__init__``
has none), the node whose shipped file holds its parameters, argument -> key in that file."""

RIG_FACTS: list[tuple[Callable[..., Any], dict[str, str]]] = [
    (SpindleDrive, {"max_speed": "spindle.max_speed_rad_s", "max_acceleration": "spindle.max_acceleration_rad_s2"}),
    (
        RigTwin,
        {
            "max_speed": "spindle.max_speed_rad_s",
            "max_acceleration": "spindle.max_acceleration_rad_s2",
            "max_radial_load": "combined_loading.max_radial_setpoint_n",
            "max_moment": "combined_loading.max_moment_setpoint_n_m",
        },
    ),
]
"""Class (its constructor's signature), argument -> dotted key of config/rig.yaml."""


def _dotted(doc: dict[str, Any], key: str) -> Any:
    for part in key.split("."):
        doc = doc[part]
    return doc


def _default_agrees(function: Callable[..., Any], argument: str, shipped: Any) -> None:
    parameter = inspect.signature(function).parameters[argument]
    if parameter.default is inspect.Parameter.empty:
        return  # required: the caller brings the file's value
    assert parameter.default == shipped, f"{function.__qualname__}({argument}={parameter.default!r}) but the shipped file says {shipped!r}"


@pytest.mark.parametrize(("function", "node", "arguments"), CORES, ids=lambda c: getattr(c, "__qualname__", None))
def test_no_core_default_differs_from_the_shipped_node_file(function: Callable[..., Any], node: str, arguments: dict[str, str]) -> None:
    values = node_file(node)
    for argument, key in arguments.items():
        _default_agrees(function, argument, values[key])


@pytest.mark.parametrize(("function", "arguments"), RIG_FACTS, ids=lambda c: getattr(c, "__qualname__", None))
def test_no_core_default_differs_from_the_rig_file(function: Callable[..., Any], arguments: dict[str, str]) -> None:
    rig = rig_file()
    for argument, key in arguments.items():
        _default_agrees(function, argument, _dotted(rig, key))


def test_a_core_with_a_wrong_default_is_caught() -> None:
    """The check itself can fail: a constructor defaulting to the old 50-chunk batch."""

    def pacer(chunk: float, *, max_batch: int = 50) -> None:
        del chunk, max_batch

    with pytest.raises(AssertionError, match="max_batch=50"):
        _default_agrees(pacer, "max_batch", node_file("simulator")["max_batch_chunks"])


def test_the_simulators_pacer_and_twin_run_with_the_shipped_values() -> None:
    """Built as the simulator builds them, without naming a value: the files' values are in force."""
    values, rig = node_file("simulator"), rig_file()
    pacer = RealTimePacer.from_settings(SimulatorSettings.from_yaml())
    assert (pacer.chunk, pacer.loop_period, pacer.realtime, pacer.rate) == (values["chunk_s"], values["loop_period_s"], values["realtime"], values["rate"])
    assert (pacer.max_batch, pacer.overrun_margin, pacer.rtf_window, pacer.resync_lag) == (
        values["max_batch_chunks"],
        values["overrun_margin_s"],
        values["rtf_window_s"],
        values["resync_lag_s"],
    )
    twin = RigTwin.from_files()
    assert twin.chunk == values["chunk_s"] and twin.counter_timeout == values["counter_timeout_s"]
    assert twin.drive.max_lead == values["max_command_lead_s"] and math.isfinite(twin.drive.max_lead)
    assert twin.drive.max_speed == rig["spindle"]["max_speed_rad_s"]
    assert twin.drive.max_acceleration == rig["spindle"]["max_acceleration_rad_s2"]
    assert twin.axial_load == values["initial_axial_load_n"]
