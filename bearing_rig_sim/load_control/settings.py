"""The load controller's parameters, validated (``config/load_controller.yaml``,
``load_controller: ros__parameters:``), the one place their defaults live.

The node declares its ROS parameters with the shipped file's values as defaults and hands the
values in force to :meth:`LoadControllerSettings.from_values` at configure, so the same checks,
with messages naming the key and the allowed range, apply to the file, to a user's parameter
file and to ``-p name:=value`` overrides. The loading chain's own data (brake, rope, lever,
clutch, PI gains, interlock levels) are in the rig file, section ``loading_chain``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, ClassVar

from bearing_rig_sim.config import NodeSettingsFile, Section, config_path

__all__ = ["NODE_NAME", "SHIPPED_FILE", "LoadControllerSettings", "shipped_parameters"]

NODE_NAME = "load_controller"
"""The load controller node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "load_controller.yaml"
"""The shipped parameter file, under ``config/``."""


@dataclass(frozen=True)
class LoadControllerSettings(NodeSettingsFile):
    """The load controller's validated parameters (SI units; the unit is in each name).

    Attributes:
        rig_file: rig data file with the loading chain.
        axial_load_setpoint_n: set-point at configure, N (the chain refuses one above its
            ``max_setpoint_n``).
        engage_clutch_on_start: close the magnet clutch at configure.
        state_rate_hz: rate of ``/rig/axial_load/state``, simulated Hz.
        force_rate_hz: rate of the force messages (``/rig/bearing/axial_force``,
            ``/rig/axial_load/force``): one chain step per sample, simulated Hz.
        diagnostics_period_s: simulated time between two periodic ``/diagnostics``, s.
        max_clock_gap_s: longest clock advance stepped at once, s.
        step_period_s: wall time between two wake-ups that step the chain to the ``/clock``
            time in force samples, s.
    """

    NODE_NAME: ClassVar[str] = NODE_NAME
    SHIPPED_FILE: ClassVar[str] = SHIPPED_FILE

    rig_file: Path
    axial_load_setpoint_n: float
    engage_clutch_on_start: bool
    state_rate_hz: float
    force_rate_hz: float
    diagnostics_period_s: float
    max_clock_gap_s: float
    step_period_s: float

    @classmethod
    def from_section(cls, s: Section) -> LoadControllerSettings:
        """Validate the parameters in ``s`` (every key required, none unknown besides
        ``use_sim_time``, which must be true: the chain is stepped on the simulation clock).

        Raises:
            ConfigError: naming the source, the key and the allowed range.
        """
        s.reject_unknown([*(f.name for f in fields(cls)), "use_sim_time"])
        if s.data.get("use_sim_time") is False:
            raise s.error("use_sim_time", "steps the loading chain on the simulation clock: use_sim_time must be true")
        raw = s.data.get("rig_file")
        if not isinstance(raw, str):
            raise s.error("rig_file", f"must be a file name ('' = the shipped rig.yaml), got {raw!r}")
        rig = Path(raw) if raw and Path(raw).is_absolute() else config_path(*(Path(raw).parts if raw else ("rig.yaml",)))
        if not rig.is_file():
            raise s.error("rig_file", f"file not found: {raw!r} (looked for {rig})")
        return cls(
            rig_file=rig,
            axial_load_setpoint_n=s.number("axial_load_setpoint_n", ge=0.0),
            engage_clutch_on_start=s.boolean("engage_clutch_on_start"),
            state_rate_hz=s.number("state_rate_hz", gt=0.0, le=1000.0),
            force_rate_hz=s.number("force_rate_hz", gt=0.0, le=10_000.0),
            diagnostics_period_s=s.number("diagnostics_period_s", gt=0.0),
            max_clock_gap_s=s.number("max_clock_gap_s", gt=0.0),
            step_period_s=s.number("step_period_s", ge=0.001, le=0.1),
        )


def shipped_parameters() -> dict[str, Any]:
    """The raw values of the shipped ``config/load_controller.yaml`` (the node's declared defaults).

    Raises:
        ConfigError: the shipped file is missing or malformed.
    """
    return LoadControllerSettings.shipped_parameters()
