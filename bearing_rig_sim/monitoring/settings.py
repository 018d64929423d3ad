"""The monitor's parameters (``config/monitor.yaml``), validated; SI units, the unit in each name."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from bearing_rig_sim.analysis.slip import BearingKinematics
from bearing_rig_sim.config import Section, config_path, load_yaml, ros_parameters
from bearing_rig_sim.monitoring.windows import LossRules

NODE_NAME = "monitor"
"""The monitor node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "monitor.yaml"
"""The shipped parameter file, under ``config/``."""

SLIP_REFERENCES = ("nominal", "loaded")
"""Which slip the criterion judges: the paper's, against the pure-rolling cage speed at the
nominal contact angle, or the kinematic one at the contact angle of the measured axial load."""

CRITERIA = ("time", "axial_load")
"""Abscissae of the slope criterion: slip against time (k2) or against the measured axial load
(k1), as a test program's ``stability_criterion`` says."""


@dataclass(frozen=True)
class MonitorSettings:
    """The monitor's validated parameters (``config/monitor.yaml`` explains each).

    Attributes:
        bearing_file: bearing data file (geometry for the epicyclic cage speed).
        contact_angle_deg: contact angle of the slip formula, degrees; negative: nominal.
        window_revolutions: whole cage revolutions per slip window (>= 1).
        min_window_s: a slip window lasts at least this long: more whole revolutions at high
            speed (0: always ``window_revolutions``), s.
        criterion: "time" or "axial_load".
        slip_reference: "nominal" (the paper's slip, Eq. 11-12 at ``contact_angle_deg``) or
            "loaded" (the kinematic slip at the contact angle of the measured axial load,
            Harris's thrust equilibrium): the slip the criterion judges; both are reported.
        critical_slope_pct_per_s: k2, %/s.
        critical_slope_pct_per_n: k1, %/N.
        slope_span_s: trailing window of the slope against time, s.
        slope_max_span_s: longest stretch of a steady series the slope against time may rest on
            when the trailing window cannot decide, s (>= slope_span_s).
        load_step_n: with the load criterion, windows whose measured loads stay within half of
            this are one hold at one load, N (:mod:`~bearing_rig_sim.monitoring.load_sweep`).
        sweep_settle_s: a hold's windows count for its load point from this long after its
            first window, s.
        sweep_average_s: and are averaged over this long, s.
        min_slope_points: points needed for a slope (>= 3).
        slip_resolution_pct: least scatter of the slip believed, percentage points.
        change_threshold: prediction standard errors for a change in the slip (1).
        min_inner_ring_speed_rad_s: below it no slip point (the series restarts), rad/s.
        restart_speed_change_fraction: the spindle is steady in a window whose mean speed is
            within this fraction of the previous window's; the series restarts when it turns
            steady or changing (1); 0 never restarts on speed changes.
        loss_horizon_revolutions, max_lost_fraction, loss_silence_revolutions,
        loss_min_timeout_s, silent_shaft_revolutions: the sustained-loss rules
            (:class:`~bearing_rig_sim.monitoring.windows.LossRules`).
        fault_hold_s: a malformed pulse stays a fault, a loss a warning, this long, rig s.
        clock_jump_tolerance_s: a pulse further back than this is a clock jump, s.
        status_rate_hz: status checks and messages per second of rig time (and on each window).
        diagnostics_rate_hz: rate of /diagnostics (besides every change), wall Hz.
    """

    bearing_file: Path
    contact_angle_deg: float
    window_revolutions: int
    min_window_s: float
    criterion: str
    slip_reference: str
    critical_slope_pct_per_s: float
    critical_slope_pct_per_n: float
    slope_span_s: float
    slope_max_span_s: float
    load_step_n: float
    sweep_settle_s: float
    sweep_average_s: float
    min_slope_points: int
    slip_resolution_pct: float
    change_threshold: float
    min_inner_ring_speed_rad_s: float
    restart_speed_change_fraction: float
    loss_horizon_revolutions: float
    max_lost_fraction: float
    loss_silence_revolutions: float
    loss_min_timeout_s: float
    silent_shaft_revolutions: float
    fault_hold_s: float
    clock_jump_tolerance_s: float
    status_rate_hz: float
    diagnostics_rate_hz: float

    @classmethod
    def from_section(cls, s: Section) -> MonitorSettings:
        """Validate the parameters in ``s`` (every key required, none unknown besides
        ``use_sim_time``).

        Raises:
            ConfigError: naming the source, the key and the allowed range.
        """
        s.reject_unknown([*cls.__dataclass_fields__, "use_sim_time"])
        raw = s.string("bearing_file")
        bearing = Path(raw) if Path(raw).is_absolute() else config_path(*Path(raw).parts)
        if not bearing.is_file():
            raise s.error("bearing_file", f"file not found: {raw!r} (looked for {bearing})")
        criterion = s.string("criterion")
        if criterion not in CRITERIA:
            raise s.error("criterion", f"must be one of {', '.join(CRITERIA)}, got {criterion!r}")
        reference = s.string("slip_reference")
        if reference not in SLIP_REFERENCES:
            raise s.error("slip_reference", f"must be one of {', '.join(SLIP_REFERENCES)}, got {reference!r}")
        return cls(
            bearing_file=bearing,
            slip_reference=reference,
            contact_angle_deg=s.number("contact_angle_deg", lt=90.0),
            window_revolutions=s.integer("window_revolutions", ge=1, le=1000),
            min_window_s=s.number("min_window_s", ge=0.0, le=10.0),
            criterion=criterion,
            critical_slope_pct_per_s=s.number("critical_slope_pct_per_s"),
            critical_slope_pct_per_n=s.number("critical_slope_pct_per_n"),
            slope_span_s=s.number("slope_span_s", gt=0.0),
            slope_max_span_s=s.number("slope_max_span_s", gt=0.0),
            load_step_n=s.number("load_step_n", gt=0.0),
            sweep_settle_s=s.number("sweep_settle_s", ge=0.0),
            sweep_average_s=s.number("sweep_average_s", gt=0.0),
            min_slope_points=s.integer("min_slope_points", ge=3),
            slip_resolution_pct=s.number("slip_resolution_pct", gt=0.0),
            change_threshold=s.number("change_threshold", gt=0.0),
            min_inner_ring_speed_rad_s=s.number("min_inner_ring_speed_rad_s", gt=0.0),
            restart_speed_change_fraction=s.number("restart_speed_change_fraction", ge=0.0),
            loss_horizon_revolutions=s.number("loss_horizon_revolutions", gt=0.0),
            max_lost_fraction=s.number("max_lost_fraction", ge=0.0, le=1.0),
            loss_silence_revolutions=s.number("loss_silence_revolutions", gt=0.0),
            loss_min_timeout_s=s.number("loss_min_timeout_s", gt=0.0),
            silent_shaft_revolutions=s.number("silent_shaft_revolutions", gt=0.0),
            fault_hold_s=s.number("fault_hold_s", ge=0.0),
            clock_jump_tolerance_s=s.number("clock_jump_tolerance_s", gt=0.0),
            status_rate_hz=s.number("status_rate_hz", gt=0.0),
            diagnostics_rate_hz=s.number("diagnostics_rate_hz", gt=0.0),
        )

    @classmethod
    def from_values(cls, values: dict[str, object], source: str = "monitor parameters") -> MonitorSettings:
        """Validate a flat mapping of parameter values (the node's ROS parameters)."""
        return cls.from_section(Section(dict(values), source))

    @classmethod
    def from_yaml(cls, path: str | Path | None = None) -> MonitorSettings:
        """Read ``monitor: ros__parameters:`` of a parameter file (default: the shipped one)."""
        return cls.from_section(ros_parameters(load_yaml(path or config_path(SHIPPED_FILE)), NODE_NAME))

    def kinematics(self) -> BearingKinematics:
        """The bearing's kinematics at the configured (or nominal) contact angle."""
        nominal = BearingKinematics.from_config(self.bearing_file)
        if self.contact_angle_deg < 0.0:
            return nominal
        return nominal.at_contact_angle(math.radians(self.contact_angle_deg))

    def loss_rules(self) -> LossRules:
        """The sustained-loss rules."""
        return LossRules(
            loss_horizon_revolutions=self.loss_horizon_revolutions,
            max_lost_fraction=self.max_lost_fraction,
            loss_silence_revolutions=self.loss_silence_revolutions,
            loss_min_timeout_s=self.loss_min_timeout_s,
            silent_shaft_revolutions=self.silent_shaft_revolutions,
        )

    @property
    def critical_slope(self) -> float:
        """k of the configured criterion: %/s (time) or %/N (axial_load)."""
        return self.critical_slope_pct_per_s if self.criterion == "time" else self.critical_slope_pct_per_n


def shipped_parameters() -> dict[str, object]:
    """The raw values of the shipped ``config/monitor.yaml`` (the node's declared defaults)."""
    section = ros_parameters(load_yaml(config_path(SHIPPED_FILE)), NODE_NAME)
    MonitorSettings.from_section(section)
    return dict(section.data)
