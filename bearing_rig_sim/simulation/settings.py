"""The simulator's parameters, validated (``config/simulator.yaml``, ``simulator: ros__parameters:``).

The node declares its ROS parameters with the shipped file's values as defaults and hands the
values it got to :meth:`SimulatorSettings.from_section`, so the same checks, with the same
messages naming the key and the allowed range, apply to the file, to a user's parameter file and
to ``-p name:=value`` overrides.

File parameters (bearing, calibration, rig) are relative to ``config/`` unless absolute.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, ClassVar

from bearing_rig_sim.config import NodeSettingsFile, Section, config_path
from bearing_rig_sim.dynamics.engine import MODELS
from bearing_rig_sim.rig.spindle import SpindleConfig

NODE_NAME = "simulator"
"""The simulator node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "simulator.yaml"
"""The shipped parameter file, under ``config/``."""


def resolve_config_file(value: str) -> Path | None:
    """A file parameter as a path: None for ``""``, as given if absolute, else under ``config/``."""
    if not value:
        return None
    path = Path(value)
    return path if path.is_absolute() else config_path(*path.parts)


@dataclass(frozen=True)
class SimulatorSettings(NodeSettingsFile):
    """The simulator node's validated parameters (SI units; the unit is in each name).

    Attributes:
        bearing_file: bearing data file.
        calibration_file: calibration laid over the bearing data; None: none.
        rig_file: rig data file; its ``sensors`` section gives the strip counts, phases, seeds,
            timing jitter, drop probability and the counter's window.
        model: the engine's model (``reduced`` runs in real time).
        chunk_s: simulated time per chunk, s; a whole number of engine steps; /clock and the
            loop advance by one chunk.
        realtime: lock the simulated time to the wall clock (false: as fast as possible).
        rate: simulated seconds per wall second in real time (1 = real time).
        loop_period_s: period of the loop's timer in real time, wall s.
        max_batch_chunks: most chunks per timer call (the batch size without real time).
        overrun_margin_s: lag behind the wall clock counted as an overrun, wall s.
        resync_lag_s: lag beyond which the debt is dropped, wall s.
        rtf_window_s: sliding window of the real-time factor, wall s.
        initial_speed_rad_s: spindle speed at the start, rad/s.
        initial_axial_load_n: axial load until the first force message, N.
        max_spindle_speed_rad_s: highest spindle target speed accepted, rad/s (from the rig
            file's ``spindle`` section, not a node parameter).
        max_spindle_acceleration_rad_s2: highest constant acceleration accepted, rad/s^2 (from
            the rig file's ``spindle`` section).
        max_command_lead_s: how far ahead of the rig clock a command's stamp may be, s.
        counter_timeout_s: the counters show 0 after this long without a pulse, s.
        speeds_rate_hz: rate of /rig/speeds, in simulated time, Hz (at most one per chunk).
        truth_rate_hz: rate of /rig/truth, in simulated time, Hz.
        diagnostics_rate_hz: rate of /diagnostics (besides every change), wall Hz.
        fault_hold_s: a refused command or force keeps /diagnostics at ERROR this long, wall s.
    """

    NODE_NAME: ClassVar[str] = NODE_NAME
    SHIPPED_FILE: ClassVar[str] = SHIPPED_FILE

    bearing_file: Path
    calibration_file: Path | None
    rig_file: Path
    model: str
    chunk_s: float
    realtime: bool
    rate: float
    loop_period_s: float
    max_batch_chunks: int
    overrun_margin_s: float
    resync_lag_s: float
    rtf_window_s: float
    initial_speed_rad_s: float
    initial_axial_load_n: float
    max_spindle_speed_rad_s: float
    max_spindle_acceleration_rad_s2: float
    max_command_lead_s: float
    counter_timeout_s: float
    speeds_rate_hz: float
    truth_rate_hz: float
    diagnostics_rate_hz: float
    fault_hold_s: float

    @classmethod
    def from_section(cls, s: Section) -> SimulatorSettings:
        """Validate the parameters in ``s`` (every key required, none unknown).

        Raises:
            ConfigError: naming the source, the key and the allowed range.
        """
        from_rig = ("max_spindle_speed_rad_s", "max_spindle_acceleration_rad_s2")
        names = [f.name for f in fields(cls) if f.name not in from_rig]
        s.reject_unknown([*names, "use_sim_time"])
        files = {}
        for key in ("bearing_file", "calibration_file", "rig_file"):
            raw = s.data.get(key)
            if not isinstance(raw, str) or (not raw and key != "calibration_file"):
                raise s.error(key, f"must be a file name (absolute or relative to config/), got {raw!r}")
            path = resolve_config_file(raw)
            if path is not None and not path.is_file():
                raise s.error(key, f"file not found: {raw!r} (looked for {path})")
            files[key] = path
        bearing_file, rig_file = files["bearing_file"], files["rig_file"]
        assert bearing_file is not None and rig_file is not None  # only calibration_file may be ""
        spindle = SpindleConfig.from_yaml(rig_file)
        max_speed = spindle.max_speed_rad_s
        return cls(
            bearing_file=bearing_file,
            calibration_file=files["calibration_file"],
            rig_file=rig_file,
            model=s.choice("model", MODELS),
            chunk_s=s.number("chunk_s", gt=0.0, le=0.1),
            realtime=s.boolean("realtime"),
            rate=s.number("rate", gt=0.0, le=100.0),
            loop_period_s=s.number("loop_period_s", gt=0.0, le=0.1),
            max_batch_chunks=s.integer("max_batch_chunks", ge=1, le=10_000),
            overrun_margin_s=s.number("overrun_margin_s", gt=0.0),
            resync_lag_s=s.number("resync_lag_s", gt=0.0),
            rtf_window_s=s.number("rtf_window_s", gt=0.0),
            initial_speed_rad_s=s.number("initial_speed_rad_s", ge=0.0, le=max_speed),
            initial_axial_load_n=s.number("initial_axial_load_n", ge=0.0),
            max_spindle_speed_rad_s=max_speed,
            max_spindle_acceleration_rad_s2=spindle.max_acceleration_rad_s2,
            max_command_lead_s=s.number("max_command_lead_s", ge=0.0),
            counter_timeout_s=s.number("counter_timeout_s", gt=0.0),
            speeds_rate_hz=s.number("speeds_rate_hz", gt=0.0),
            truth_rate_hz=s.number("truth_rate_hz", gt=0.0),
            diagnostics_rate_hz=s.number("diagnostics_rate_hz", gt=0.0),
            fault_hold_s=s.number("fault_hold_s", ge=0.0),
        )


def shipped_parameters() -> dict[str, Any]:
    """The raw values of the shipped ``config/simulator.yaml`` (the node's declared defaults).

    Raises:
        ConfigError: the shipped file is missing or malformed.
    """
    return SimulatorSettings.shipped_parameters()
