"""The shadow twin's validated parameters (``config/shadow.yaml``; the unit is in each name)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, ClassVar

from pydantic import ValidationInfo, field_validator

from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.dynamics.calibrations import named_as_config_path
from bearing_rig_sim.interfaces import DIAGNOSTICS
from bearing_rig_sim.dynamics.engine import MODELS
from bearing_rig_sim.settings_model import ConfigFile, Flag, Integer, NodeSettings, Number, OptionalConfigFile, one_of, param, read_file

NODE_NAME = "shadow"
"""The shadow node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "shadow.yaml"
"""The shipped parameter file, under ``config/``."""


class ShadowSettings(NodeSettings):
    """The shadow twin's parameters (see ``config/shadow.yaml`` for each one's reason), declared
    once (:mod:`bearing_rig_sim.settings_model`). ``calibration_file`` may name a calibration
    (``coupled``, ``isothermal``). ``calibration_rms_slip_pct`` below zero is
    replaced by the calibration file's ``calibration.rms_slip_pct``; ``error_after_s`` must
    exceed ``warn_after_s``."""

    NODE_NAME: ClassVar[str] = NODE_NAME
    SHIPPED_FILE: ClassVar[str] = SHIPPED_FILE

    bearing_file: ConfigFile = param("bearing data file (absolute, or relative to config/)")
    calibration_file: OptionalConfigFile = param(
        "calibration laid over the bearing data: a named one ('coupled', 'isothermal') or a file ('' = the uncalibrated bearing file)"
    )
    rig_file: ConfigFile = param(
        "rig data file: the test bearing's mounting (clearance, misalignment, preload) the twin's engine is built with, as the simulator's"
    )
    model: Annotated[str, one_of(MODELS)] = param("engine model: 'reduced' (runs in real time) or 'stiff' (slow reference)")
    chunk_s: Number = param("engine advance per call (whole steps of the bearing file's model)", unit="s", gt=0.0, le=0.1)
    window_revolutions: Integer = param("whole cage revolutions per slip window (the monitor's)", unit="1", ge=1, le=1000)
    min_inner_ring_speed_rad_s: Number = param("windows slower than this are not compared", unit="rad/s", gt=0.0, le=1000.0)
    calibration_rms_slip_pct: Number = param("calibration RMS of the slip (negative: the calibration file's rms_slip_pct)", unit="%", ge=-1.0, le=10.0)
    band_coverage: Number = param("band half-width in combined standard uncertainties", unit="1", gt=0.0, le=10.0)
    warn_after_s: Number = param("a residual outside its band longer than this is a WARN (bench time)", unit="s", gt=0.0, le=600.0)
    error_after_s: Number = param("a residual outside its band longer than this is an ERROR; > warn_after_s", unit="s", gt=0.0, le=3600.0)
    thermal: Flag = param("couple the twin's engine to the bearing's thermal network (the bearing file's thermal: section) and compare temperature and torque")
    lubricant_feedback: Flag = param("with thermal: the engine's lubricant follows the network's lubricant temperature (false: the calibration's)")
    temperature_model_fraction: Number = param("relative uncertainty of the network's outer-ring rise since its start", unit="1", ge=0.0, le=1.0)
    thermocouple_uncertainty_k: Number = param("standard uncertainty of the bench's outer-ring thermocouple", unit="K", ge=0.0, le=20.0)
    torque_model_fraction: Number = param("relative uncertainty of the twin's friction torque", unit="1", ge=0.0, le=1.0)
    settle_s: Number = param("windows starting sooner than this after an engine (re)start are not compared", unit="s", ge=0.0, le=10.0)
    max_speed_gap_s: Number = param("spindle speed points further apart restart the engine", unit="s", gt=0.0, le=60.0)
    load_average_s: Number = param("averaging time of the load-cell force", unit="s", gt=0.0, le=10.0)
    load_timeout_s: Number = param("no load-cell sample for this long is a dropout", unit="s", gt=0.0, le=60.0)
    recalibrate: Flag = param("track a calibration parameter online (recursive least squares)")
    recalibrate_parameter: str = param("the calibration file's parameter tracked ('section.key'; '' = the first one it fitted)")
    forgetting_factor: Number = param("forgetting factor of the recursive least squares, per compared steady window", unit="1", gt=0.5, le=1.0)
    probe_step_fraction: Number = param("initial offset of the probe engine from the calibrated value", unit="1", gt=0.0, le=0.5)
    steady_speed_fraction: Number = param("windows within this fraction of the previous one's spindle speed are steady", unit="1", ge=0.0, le=0.5)
    status_rate_hz: Number = param("checks of the twin per second (wall clock), plus each change of level", unit="Hz", gt=0.0, le=1000.0)
    diagnostics_rate_hz: Number = param(f"rate of {DIAGNOSTICS.name} besides every change (wall clock)", unit="Hz", gt=0.0, le=100.0)

    @field_validator("calibration_file", mode="before")
    @classmethod
    def _named_calibration(cls, value: object) -> object:
        """A calibration's name (:data:`~bearing_rig_sim.dynamics.calibrations.NAMED`) as its file."""
        return named_as_config_path(value)

    @field_validator("recalibrate_parameter", mode="before")
    @classmethod
    def _string_or_empty(cls, raw: object) -> str:
        if not isinstance(raw, str):
            raise ValueError(f"must be a string (empty for the default), got {raw!r}")
        return raw

    @field_validator("error_after_s")
    @classmethod
    def _after_warn(cls, value: float, info: ValidationInfo) -> float:
        warn = info.data.get("warn_after_s")
        if warn is not None and not value > warn:
            raise ValueError(f"must be > {warn} (warn_after_s), got {value!r}")
        return value

    @field_validator("calibration_rms_slip_pct")
    @classmethod
    def _rms_from_calibration(cls, value: float, info: ValidationInfo) -> float:
        if value >= 0.0 or "calibration_file" not in info.data:
            return value
        calibration = info.data["calibration_file"]
        rms = calibration_rms(calibration)
        if rms is None:
            raise ValueError(
                "negative means 'read calibration.rms_slip_pct of the calibration file', but "
                + ("no calibration file is given" if calibration is None else f"{calibration} has none")
            )
        return rms


def calibration_rms(path: Path | None) -> float | None:
    """``calibration.rms_slip_pct`` of a calibration file, percentage points (None if absent)."""
    if path is None:
        return None
    return read_file(CalibrationFile, path).calibration.rms_slip_pct


def shipped_parameters() -> dict[str, object]:
    """The raw values of the shipped ``config/shadow.yaml`` (the node's declared defaults)."""
    return ShadowSettings.shipped_parameters()
