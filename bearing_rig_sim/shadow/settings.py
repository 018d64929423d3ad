"""The shadow twin's validated parameters (``config/shadow.yaml``; the unit is in each name)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

from bearing_rig_sim.config import Section, config_path, load_yaml, ros_parameters
from bearing_rig_sim.simulation.settings import resolve_config_file

NODE_NAME = "shadow"
"""The shadow node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "shadow.yaml"
"""The shipped parameter file, under ``config/``."""


def _resolve(s: Section, key: str, *, empty_ok: bool = False) -> Path | None:
    """A file parameter (absolute or under ``config/``); ``""`` is None where ``empty_ok``."""
    raw = s.data.get(key)
    if not isinstance(raw, str) or (not raw and not empty_ok):
        raise s.error(key, f"must be a file name (absolute or relative to config/), got {raw!r}")
    path = resolve_config_file(raw)
    if path is not None and not path.is_file():
        raise s.error(key, f"file not found: {raw!r} (looked for {path})")
    return path


def _string_or_empty(s: Section, key: str) -> str:
    if key not in s:
        raise s.error(key, "missing")
    raw = s.data[key]
    if not isinstance(raw, str):
        raise s.error(key, f"must be a string (empty for the default), got {raw!r}")
    return raw


@dataclass(frozen=True)
class ShadowSettings:
    """The shadow twin's parameters (see ``config/shadow.yaml`` for each one's reason).

    Attributes:
        bearing_file: bearing data.
        calibration_file: calibration laid over it (None: the uncalibrated bearing file).
        model: the engine's model (``"reduced"`` for real time).
        chunk_s: engine advance per call, s.
        window_revolutions: whole cage revolutions per slip window (the monitor's).
        min_inner_ring_speed_rad_s: slower windows are not compared, rad/s.
        calibration_rms_slip_pct: the calibration's RMS slip error, percentage points; negative:
            read from the calibration file.
        timing_jitter_std_s: the bench sensors' pulse-timing jitter, s.
        band_coverage: band half-width in standard uncertainties (1).
        warn_after_s: residual outside the band longer than this: WARN, s.
        error_after_s: ... longer than this: ERROR, s.
        settle_s: windows starting sooner than this after an engine (re)start are not compared, s.
        max_speed_gap_s: speed points further apart restart the engine, s.
        load_average_s: averaging time of the load-cell force, s.
        load_timeout_s: no load-cell sample for this long is a dropout, s.
        recalibrate: track a calibration parameter online.
        recalibrate_parameter: the calibration file's parameter tracked (``section.key``); "" for its
            first one.
        forgetting_factor: of the recursive least squares, per compared steady window (1).
        probe_step_fraction: initial offset of the probe engine from the calibrated value (1).
        steady_speed_fraction: windows whose spindle speed is within this fraction of the previous
            one's are steady (1).
        status_rate_hz, diagnostics_rate_hz: publication rates of the node, wall Hz.
    """

    bearing_file: Path
    calibration_file: Path | None
    model: str
    chunk_s: float
    window_revolutions: int
    min_inner_ring_speed_rad_s: float
    calibration_rms_slip_pct: float
    timing_jitter_std_s: float
    band_coverage: float
    warn_after_s: float
    error_after_s: float
    settle_s: float
    max_speed_gap_s: float
    load_average_s: float
    load_timeout_s: float
    recalibrate: bool
    recalibrate_parameter: str
    forgetting_factor: float
    probe_step_fraction: float
    steady_speed_fraction: float
    status_rate_hz: float
    diagnostics_rate_hz: float

    @classmethod
    def from_section(cls, s: Section) -> ShadowSettings:
        """Validate the parameters in ``s`` (every key required, none unknown besides
        ``use_sim_time``).

        Raises:
            ConfigError: naming the source, the key and the allowed range.
        """
        s.reject_unknown([*cls.__dataclass_fields__, "use_sim_time"])
        bearing = _resolve(s, "bearing_file")
        assert bearing is not None
        warn = s.number("warn_after_s", gt=0.0)
        settings = cls(
            bearing_file=bearing,
            calibration_file=_resolve(s, "calibration_file", empty_ok=True),
            model=s.choice("model", ["reduced", "stiff"]),
            chunk_s=s.number("chunk_s", gt=0.0, le=0.1),
            window_revolutions=s.integer("window_revolutions", ge=1, le=1000),
            min_inner_ring_speed_rad_s=s.number("min_inner_ring_speed_rad_s", gt=0.0),
            calibration_rms_slip_pct=s.number("calibration_rms_slip_pct", lt=100.0),
            timing_jitter_std_s=s.number("timing_jitter_std_s", ge=0.0, le=1e-3),
            band_coverage=s.number("band_coverage", gt=0.0, le=10.0),
            warn_after_s=warn,
            error_after_s=s.number("error_after_s", gt=warn),
            settle_s=s.number("settle_s", ge=0.0, le=10.0),
            max_speed_gap_s=s.number("max_speed_gap_s", gt=0.0),
            load_average_s=s.number("load_average_s", gt=0.0, le=10.0),
            load_timeout_s=s.number("load_timeout_s", gt=0.0),
            recalibrate=s.boolean("recalibrate"),
            recalibrate_parameter=_string_or_empty(s, "recalibrate_parameter"),
            forgetting_factor=s.number("forgetting_factor", gt=0.5, le=1.0),
            probe_step_fraction=s.number("probe_step_fraction", gt=0.0, lt=1.0),
            steady_speed_fraction=s.number("steady_speed_fraction", ge=0.0, lt=1.0),
            status_rate_hz=s.number("status_rate_hz", gt=0.0),
            diagnostics_rate_hz=s.number("diagnostics_rate_hz", gt=0.0),
        )
        if settings.calibration_rms_slip_pct < 0.0:
            rms = calibration_rms(settings.calibration_file)
            if rms is None:
                raise s.error(
                    "calibration_rms_slip_pct",
                    "negative means 'read calibration.rms_slip_pct of the calibration file', but "
                    + ("no calibration file is given" if settings.calibration_file is None else f"{settings.calibration_file} has none"),
                )
            settings = dataclasses.replace(settings, calibration_rms_slip_pct=rms)
        return settings

    @classmethod
    def from_values(cls, values: dict[str, object], source: str = "shadow parameters") -> ShadowSettings:
        """Validate a flat mapping of parameter values (the node's ROS parameters)."""
        return cls.from_section(Section(dict(values), source))

    @classmethod
    def from_yaml(cls, path: str | Path | None = None) -> ShadowSettings:
        """Read ``shadow: ros__parameters:`` of a parameter file (default: the shipped one)."""
        return cls.from_section(ros_parameters(load_yaml(path or config_path(SHIPPED_FILE)), NODE_NAME))

    def replace(self, **changes: object) -> ShadowSettings:
        """A copy with some values changed (not re-validated: for tests and the command line)."""
        return dataclasses.replace(self, **changes)  # type: ignore[arg-type]  # keys checked against the dataclass fields above


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
    section = ros_parameters(load_yaml(config_path(SHIPPED_FILE)), NODE_NAME)
    ShadowSettings.from_section(section)
    return dict(section.data)
