"""The simulator's parameters, validated (``config/simulator.yaml``, ``simulator: ros__parameters:``).

The node declares its ROS parameters with the shipped file's values as defaults and hands the
values it got to :meth:`SimulatorSettings.from_mapping`, so the same checks, with the same
messages naming the key and the allowed range, apply to the file, to a user's parameter file and
to ``-p name:=value`` overrides.

File parameters (bearing, calibration, rig) are relative to ``config/`` unless absolute.
"""

from __future__ import annotations

from typing import Annotated, Any, ClassVar

from pydantic import field_validator, PrivateAttr

from bearing_rig_sim.config import BEARING_MODELS
from bearing_rig_sim.dynamics.engine import MODELS
from bearing_rig_sim.interfaces import CLOCK, DIAGNOSTICS, SPEEDS, TRUTH
from bearing_rig_sim.rig.spindle import PLAUSIBLE_SPINDLE_SPEED_RAD_S, SpindleConfig
from bearing_rig_sim.settings_model import (
    ConfigFile,
    Flag,
    Integer,
    NodeSettings,
    Number,
    OptionalConfigFile,
    existing_config_file,
    one_of,
    param,
    resolve_config_file,
)

__all__ = [
    "NODE_NAME",
    "SHIPPED_FILE",
    "SimulatorSettings",
    "existing_config_file",
    "resolve_config_file",
    "shipped_parameters",
]

NODE_NAME = "simulator"
"""The simulator node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "simulator.yaml"
"""The shipped parameter file, under ``config/``."""


class SimulatorSettings(NodeSettings):
    """The simulator node's validated parameters (SI units; the unit is in each name), declared
    once (:mod:`bearing_rig_sim.settings_model`).

    ``initial_speed_rad_s`` is at most the rig file's spindle speed limit. The spindle's limits
    (:attr:`max_spindle_speed_rad_s`, :attr:`max_spindle_acceleration_rad_s2`) are the rig
    file's ``spindle`` section, not node parameters. The node's ROS descriptors are these fields
    (:mod:`bearing_rig_sim.nodes.parameters`).
    """

    NODE_NAME: ClassVar[str] = NODE_NAME
    SHIPPED_FILE: ClassVar[str] = SHIPPED_FILE

    bearing_file: ConfigFile = param("bearing data file (absolute, or relative to the package's config/)")
    calibration_file: OptionalConfigFile = param(
        "calibration laid over the bearing data: a name of the bench twin's (coupled, isothermal), a file relative to config/, or '' for none"
    )
    rig_file: ConfigFile = param("rig data file: sensors (strip counts, jitter, drop probability) and loading chain")
    model: Annotated[str, one_of(MODELS)] = param("engine model: 'reduced' (runs in real time) or 'stiff' (slow reference)")
    bearing_model: Annotated[str, one_of(BEARING_MODELS)] = param(
        "physics: 'bench' (the bench twin: bearing_file with calibration_file) or 'paper' (the paper's own model, config/models/paper.yaml, its own calibration; bearing_file and calibration_file unused)"
    )
    chunk_s: Number = param(f"simulated time per engine call and per {CLOCK.name} message (whole steps of the bearing file's model)", unit="s", gt=0.0, le=0.1)
    realtime: Flag = param("lock the simulated time to the wall clock (false: as fast as possible)")
    rate: Number = param("simulated seconds per wall second when in real time", unit="1", gt=0.0, le=100.0)
    loop_period_s: Number = param("period of the loop timer in real time (wall clock)", unit="s", ge=1e-4, le=0.1)
    max_batch_chunks: Integer = param("most chunks computed per loop call", unit="1", ge=1, le=10_000)
    overrun_margin_s: Number = param("lag behind the wall clock counted as an overrun", unit="s", gt=0.0, le=10.0)
    resync_lag_s: Number = param("lag behind the wall clock beyond which the debt is dropped", unit="s", gt=0.0, le=60.0)
    rtf_window_s: Number = param("sliding window of the reported real-time factor (wall clock)", unit="s", gt=0.0, le=600.0)
    initial_speed_rad_s: Number = param(
        "spindle speed at start (at most the rig file's spindle limit)",
        unit="rad/s",
        ge=0.0,
        le=PLAUSIBLE_SPINDLE_SPEED_RAD_S,
        rig_limit="spindle.max_speed_rad_s",
    )
    initial_axial_load_n: Number = param("axial load until the loading chain's first force message", unit="N", ge=0.0, le=10_000.0)
    initial_temperature_rise_k: Number = param(
        "start temperature of the bearing's thermal network above the bearing file's ambient (0: a cold start)", unit="K", ge=0.0, le=150.0
    )
    lubricant_feedback: Flag = param(
        "the engine's lubricant follows the thermal network's lubricant temperature (false: held at the bearing file's temperature, the calibration's)"
    )
    max_command_lead_s: Number = param("how far ahead of the rig clock a command's stamp may be", unit="s", ge=0.0, le=3600.0)
    counter_timeout_s: Number = param("the pulse counters show 0 after this long without a pulse", unit="s", gt=0.0, le=60.0)
    speeds_rate_hz: Number = param(f"rate of {SPEEDS.name} in simulated time (at most one per chunk)", unit="Hz", gt=0.0, le=100_000.0)
    truth_rate_hz: Number = param(f"rate of {TRUTH.name} in simulated time", unit="Hz", gt=0.0, le=100_000.0)
    diagnostics_rate_hz: Number = param(f"rate of {DIAGNOSTICS.name} besides every change (wall clock)", unit="Hz", gt=0.0, le=100.0)
    fault_hold_s: Number = param(f"a refused command or force keeps {DIAGNOSTICS.name} at ERROR this long (wall clock)", unit="s", ge=0.0, le=600.0)

    _spindle: SpindleConfig = PrivateAttr()

    @field_validator("calibration_file", mode="before")
    @classmethod
    def _named_calibration(cls, value: object) -> object:
        """A calibration's name (:data:`~bearing_rig_sim.dynamics.calibrations.NAMED`) as its file."""
        from bearing_rig_sim.dynamics.calibrations import named_as_config_path

        return named_as_config_path(value)

    def model_post_init(self, context: Any, /) -> None:
        self._spindle = SpindleConfig.from_yaml(self.rig_file)

    @property
    def max_spindle_speed_rad_s(self) -> float:
        """Highest spindle target speed accepted, rad/s (the rig file's ``spindle`` section)."""
        return self._spindle.max_speed_rad_s

    @property
    def max_spindle_acceleration_rad_s2(self) -> float:
        """Highest constant acceleration accepted, rad/s^2 (the rig file's ``spindle`` section)."""
        return self._spindle.max_acceleration_rad_s2


def shipped_parameters() -> dict[str, Any]:
    """The raw values of the shipped ``config/simulator.yaml`` (the node's declared defaults).

    Raises:
        ConfigError: the shipped file is missing or malformed.
    """
    return SimulatorSettings.shipped_parameters()
