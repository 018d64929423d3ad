"""The shadow twin's validated parameters (``config/shadow.yaml``; the unit is in each name)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, ClassVar

from pydantic import ValidationInfo, field_validator

from bearing_rig_sim.config import load_yaml
from bearing_rig_sim.interfaces import DIAGNOSTICS
from bearing_rig_sim.settings_model import Flag, Integer, NodeSettings, Number, param
from bearing_rig_sim.simulation.settings import existing_config_file

NODE_NAME = "shadow"
"""The shadow node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "shadow.yaml"
"""The shipped parameter file, under ``config/``."""

MODELS = ("reduced", "stiff")
"""The engine's models (``reduced`` runs in real time)."""


class ShadowSettings(NodeSettings):
    """The shadow twin's parameters (see ``config/shadow.yaml`` for each one's reason), declared
    once (:mod:`bearing_rig_sim.settings_model`). ``calibration_rms_slip_pct`` below zero is
    replaced by the calibration file's ``calibration.rms_slip_pct``; ``error_after_s`` must
    exceed ``warn_after_s``."""

    NODE_NAME: ClassVar[str] = NODE_NAME
    SHIPPED_FILE: ClassVar[str] = SHIPPED_FILE
    OTHER_KEYS: ClassVar[tuple[str, ...]] = ("use_sim_time",)

    bearing_file: Path = param("bearing data file (absolute, or relative to config/)")
    calibration_file: Path | None = param("calibration laid over the bearing data ('' = the uncalibrated bearing file)")
    model: str = param("engine model: 'reduced' (runs in real time) or 'stiff' (slow reference)")
    chunk_s: Number = param("engine advance per call", unit="s", gt=0.0, le=0.1)
    window_revolutions: Integer = param("whole cage revolutions per slip window (the monitor's)", unit="1", ge=1, le=1000)
    min_inner_ring_speed_rad_s: Number = param("slower windows are not compared", unit="rad/s", gt=0.0)
    calibration_rms_slip_pct: Number = param(
        "the calibration's RMS slip error (negative: read from the calibration file)", unit="percentage points", lt=100.0
    )
    timing_jitter_std_s: Number = param("the bench sensors' pulse-timing jitter", unit="s", ge=0.0, le=1e-3)
    band_coverage: Number = param("band half-width in standard uncertainties", unit="1", gt=0.0, le=10.0)
    thermal: Flag = param("couple the twin's engine to the bearing's thermal network (the bearing file's thermal: section) and compare temperature and torque")
    temperature_model_fraction: Number = param("relative uncertainty of the network's outer-ring rise since its start", unit="1", ge=0.0, le=1.0)
    thermocouple_uncertainty_k: Number = param("standard uncertainty of the bench's outer-ring thermocouple", unit="K", ge=0.0, le=20.0)
    torque_model_fraction: Number = param("relative uncertainty of the twin's friction torque", unit="1", ge=0.0, le=1.0)
    torque_meter_noise_nm: Number = param("noise of one torque-meter sample (standard deviation)", unit="N m", ge=0.0, le=1.0)
    warn_after_s: Number = param("a residual outside the band longer than this is a WARN", unit="s", gt=0.0)
    error_after_s: Number = param("... longer than this an ERROR (more than warn_after_s)", unit="s")
    settle_s: Number = param("windows starting sooner than this after an engine (re)start are not compared", unit="s", ge=0.0, le=10.0)
    max_speed_gap_s: Number = param("speed points further apart restart the engine", unit="s", gt=0.0)
    load_average_s: Number = param("averaging time of the load-cell force", unit="s", gt=0.0, le=10.0)
    load_timeout_s: Number = param("no load-cell sample for this long is a dropout", unit="s", gt=0.0)
    recalibrate: Flag = param("track a calibration parameter online")
    recalibrate_parameter: str = param("the calibration file's parameter tracked (section.key; '' = its first)")
    forgetting_factor: Number = param("of the recursive least squares, per compared steady window", unit="1", gt=0.5, le=1.0)
    probe_step_fraction: Number = param("initial offset of the probe engine from the calibrated value", unit="1", gt=0.0, lt=1.0)
    steady_speed_fraction: Number = param(
        "windows whose spindle speed is within this fraction of the previous one's are steady", unit="1", ge=0.0, lt=1.0
    )
    status_rate_hz: Number = param("status publication rate of the node (wall clock)", unit="Hz", gt=0.0)
    diagnostics_rate_hz: Number = param(f"rate of {DIAGNOSTICS.name} besides every change (wall clock)", unit="Hz", gt=0.0)

    @field_validator("bearing_file", mode="before")
    @classmethod
    def _bearing_file(cls, raw: object) -> Path | None:
        return existing_config_file(raw)

    @field_validator("calibration_file", mode="before")
    @classmethod
    def _calibration_file(cls, raw: object) -> Path | None:
        return existing_config_file(raw, empty_ok=True)

    @field_validator("model", mode="before")
    @classmethod
    def _model(cls, raw: object) -> str:
        if raw not in MODELS:
            raise ValueError(f"must be one of {', '.join(MODELS)}, got {raw!r}")
        return str(raw)

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

    def replace(self, **changes: Any) -> ShadowSettings:
        """A copy with some values changed (not re-validated: for tests and the command line)."""
        return self.model_copy(update=changes)


def calibration_rms(path: Path | None) -> float | None:
    """``calibration.rms_slip_pct`` of a calibration file, percentage points (None if absent)."""
    if path is None:
        return None
    doc = load_yaml(path)
    if "calibration" not in doc:
        return None
    cal = doc.section("calibration")
    if "rms_slip_pct" not in cal:
        return None
    value = cal.number("rms_slip_pct", ge=0.0)
    return value if math.isfinite(value) else None


def shipped_parameters() -> dict[str, object]:
    """The raw values of the shipped ``config/shadow.yaml`` (the node's declared defaults)."""
    return ShadowSettings.shipped_parameters()
