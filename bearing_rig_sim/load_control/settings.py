"""The load controller's parameters, validated (``config/load_controller.yaml``,
``load_controller: ros__parameters:``), the one place their defaults live.

The node declares its ROS parameters with the shipped file's values as defaults and hands the
values in force to :meth:`LoadControllerSettings.from_values` at configure, so the same checks,
with messages naming the key and the allowed range, apply to the file, to a user's parameter
file and to ``-p name:=value`` overrides. The loading chain's own data (brake, rope, lever,
clutch, PI gains, interlock levels) are in the rig file, section ``loading_chain``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

from pydantic import field_validator

from bearing_rig_sim.interfaces import AXIAL_LOAD_STATE, CLOCK, DIAGNOSTICS
from bearing_rig_sim.settings_model import Flag, NodeSettings, Number, field_error, param, resolve_rig_file

__all__ = ["NODE_NAME", "SHIPPED_FILE", "LoadControllerSettings", "shipped_parameters"]

NODE_NAME = "load_controller"
"""The load controller node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "load_controller.yaml"
"""The shipped parameter file, under ``config/``."""


class LoadControllerSettings(NodeSettings):
    """The load controller's validated parameters (SI units; the unit is in each name), declared
    once (:mod:`bearing_rig_sim.settings_model`): the YAML checks, the errors and the node's ROS
    descriptors come from these fields.

    ``use_sim_time`` may be in the file and must be true: the chain is stepped on the
    simulation clock. ``rig_file`` is resolved to an existing file ('' = the shipped
    ``config/rig.yaml``; a relative name is under ``config/``). The set-point's upper bound is
    that file's ``loading_chain.max_setpoint_n``, in the checks and in the ROS descriptor.
    """

    NODE_NAME: ClassVar[str] = NODE_NAME
    SHIPPED_FILE: ClassVar[str] = SHIPPED_FILE

    rig_file: Path = param("rig data file with the loading chain ('' = the shipped config/rig.yaml)")
    axial_load_setpoint_n: Number = param(
        "axial-load set-point; also settable by topic and service; mirrors the one in force",
        unit="N",
        ge=0.0,
        le=10_000.0,
        live=True,
        rig_limit="loading_chain.max_setpoint_n",
    )
    engage_clutch_on_start: Flag = param("close the magnet clutch when the node is configured")
    state_rate_hz: Number = param(f"rate of {AXIAL_LOAD_STATE.name} in simulated time", unit="Hz", gt=0.0, le=1000.0)
    diagnostics_period_s: Number = param(f"simulated time between two periodic {DIAGNOSTICS.name}", unit="s", gt=0.0, le=600.0)
    max_clock_gap_s: Number = param("longest clock advance stepped at once (a larger jump is stepped as this much)", unit="s", gt=0.0, le=600.0)
    force_rate_hz: Number = param("rate of the force messages (one chain step each) in simulated time", unit="Hz", gt=0.0, le=10_000.0)
    step_period_s: Number = param(f"wall time between two wake-ups stepping the chain to the {CLOCK.name} time", unit="s", ge=0.001, le=0.1)

    @classmethod
    def check_other_keys(cls, values: Mapping[str, Any]) -> None:
        if values.get("use_sim_time") is False:
            raise field_error("use_sim_time", "steps the loading chain on the simulation clock: use_sim_time must be true")

    @field_validator("rig_file", mode="before")
    @classmethod
    def _existing_rig_file(cls, raw: object) -> Path:
        return resolve_rig_file(raw)


def shipped_parameters() -> dict[str, Any]:
    """The raw values of the shipped ``config/load_controller.yaml`` (the node's declared defaults).

    Raises:
        ConfigError: the shipped file is missing or malformed.
    """
    return LoadControllerSettings.shipped_parameters()
