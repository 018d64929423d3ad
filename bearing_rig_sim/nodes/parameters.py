"""What every ROS parameter of the rig's nodes is: its meaning, unit, range and whether it may
change while the node runs (no ROS; :mod:`bearing_rig_sim.nodes.shell` turns these into
``rcl_interfaces/ParameterDescriptor`` values, so ``ros2 param describe`` tells a user what to set).

The values themselves (defaults) live only in the shipped parameter files
``config/<node>.yaml``; the validation that counts is the node's settings class, run in
``on_configure``. The ranges here are the plausible ones for the rig: inside what the settings
classes accept (a test checks each bound against them), so a value the ROS layer lets through is
never refused later for being out of range.

Read-only: everything a node reads in ``on_configure`` (files, models, rates, periods): a live
change would leave the running node inconsistent with its parameters, and ``ros2 param set``
refuses it with "read-only". They are set at start (parameter file, ``-p``). Only the load
controller's set-point is live.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bearing_rig_sim.interfaces import CLOCK, DIAGNOSTICS, SPEEDS, TRUTH
from bearing_rig_sim.load_control.settings import LoadControllerSettings
from bearing_rig_sim.settings_model import NodeSettings

__all__ = ["NODE_PARAMETERS", "STANDARD_PARAMETERS", "STANDARD_PREFIXES", "ParameterSpec", "is_standard", "spec_for"]

STANDARD_PARAMETERS = ("use_sim_time", "start_type_description_service")
"""Parameters every ROS 2 Jazzy node declares by itself (rclpy and rclcpp alike): ``ros2 param
dump`` writes them for every node."""

STANDARD_PREFIXES = ("qos_overrides.",)
"""Prefixes of the parameters a node declares by itself for the QoS of its publishers and
subscriptions that allow overriding (``qos_overrides./parameter_events.publisher.depth``)."""


def is_standard(name: str) -> bool:
    """Whether ``name`` is one of the parameters every ROS 2 node has (not one of the rig's)."""
    return name in STANDARD_PARAMETERS or name.startswith(STANDARD_PREFIXES)


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter of a node.

    Attributes:
        name: parameter name (the unit is in the name where it has one).
        description: what it is, in the rig's words.
        unit: SI unit, ``"1"`` for a pure number, ``""`` for text, files and flags.
        low, high: plausible range, inclusive (numbers only; None for text and flags).
        integer: an integer parameter (``IntegerRange``), else a floating-point one.
        read_only: refused by ``set_parameters`` once declared (read at configure).
        low_exclusive: the lower bound itself is refused (by the settings class, at configure);
            ROS ranges are inclusive, so the descriptor's text says ``> low``.
    """

    name: str
    description: str
    unit: str = ""
    low: float | None = None
    high: float | None = None
    integer: bool = False
    read_only: bool = True
    low_exclusive: bool = False

    @property
    def numeric(self) -> bool:
        return self.low is not None and self.high is not None

    def constraints(self) -> str:
        """The descriptor's ``additional_constraints`` text: unit, range, when it applies."""
        parts = []
        if self.unit:
            parts.append(f"unit: {self.unit}")
        if self.numeric:
            assert self.low is not None and self.high is not None
            low = "> " if self.low_exclusive else ">= "
            parts.append(f"range: {low}{self.low:g} and <= {self.high:g}")
        parts.append("read-only: set at start (parameter file or -p), read at configure" if self.read_only else "may be set live")
        return "; ".join(parts)

    def check(self, value: object) -> str:
        """Why ``value`` is out of this parameter's range ("" when it is in range or not a number)."""
        if not self.numeric or isinstance(value, bool) or not isinstance(value, (int, float)):
            return ""
        assert self.low is not None and self.high is not None
        v = float(value)
        if not math.isfinite(v):
            return f"{self.name}: must be a finite number, got {value!r}"
        if v < self.low or v > self.high or (self.low_exclusive and v == self.low):
            low = ">" if self.low_exclusive else ">="
            return f"{self.name}: must be {low} {self.low:g} and <= {self.high:g} {self.unit}".rstrip() + f", got {value!r}"
        return ""


def _files(*specs: tuple[str, str]) -> list[ParameterSpec]:
    return [ParameterSpec(name, text) for name, text in specs]


def specs_of(settings: type[NodeSettings]) -> list[ParameterSpec]:
    """The specs of a settings class declared with :mod:`bearing_rig_sim.settings_model`: its
    YAML checks and its ROS descriptors come from the same fields (the load controller's)."""
    return [
        ParameterSpec(
            f.name, f.description, f.unit, f.low, f.high, integer=f.integer, read_only=not f.live, low_exclusive=f.low_exclusive
        )
        for f in settings.parameter_fields()
    ]


SIMULATOR = [
    *_files(
        ("bearing_file", "bearing data file (absolute, or relative to the package's config/)"),
        ("calibration_file", "calibration laid over the bearing data ('' = none; relative to config/)"),
        ("rig_file", "rig data file: sensors (strip counts, jitter, drop probability) and loading chain"),
        ("model", "engine model: 'reduced' (runs in real time) or 'stiff' (slow reference)"),
    ),
    ParameterSpec("chunk_s", f"simulated time per engine call and per {CLOCK.name} message (whole engine steps of 40 us)", "s", 4e-5, 0.1),
    ParameterSpec("realtime", "lock the simulated time to the wall clock (false: as fast as possible)"),
    ParameterSpec("rate", "simulated seconds per wall second when in real time", "1", 0.0, 100.0, low_exclusive=True),
    ParameterSpec("loop_period_s", "period of the loop timer in real time (wall clock)", "s", 1e-4, 0.1),
    ParameterSpec("max_batch_chunks", "most chunks computed per loop call", "1", 1, 10_000, integer=True),
    ParameterSpec("overrun_margin_s", "lag behind the wall clock counted as an overrun", "s", 0.0, 10.0, low_exclusive=True),
    ParameterSpec("resync_lag_s", "lag behind the wall clock beyond which the debt is dropped", "s", 0.0, 60.0, low_exclusive=True),
    ParameterSpec("rtf_window_s", "sliding window of the reported real-time factor (wall clock)", "s", 0.0, 600.0, low_exclusive=True),
    ParameterSpec("initial_speed_rad_s", "spindle speed at start", "rad/s", 0.0, 1000.0),
    ParameterSpec("initial_axial_load_n", "axial load until the loading chain's first force message", "N", 0.0, 10_000.0),
    ParameterSpec(
        "initial_temperature_rise_k", "start temperature of the bearing's thermal network above the bearing file's ambient (0: a cold start)", "K", 0.0, 150.0
    ),
    ParameterSpec("max_command_lead_s", "how far ahead of the rig clock a command's stamp may be", "s", 0.0, 3600.0),
    ParameterSpec("counter_timeout_s", "the pulse counters show 0 after this long without a pulse", "s", 0.0, 60.0, low_exclusive=True),
    ParameterSpec("speeds_rate_hz", f"rate of {SPEEDS.name} in simulated time (at most one per chunk)", "Hz", 0.0, 100_000.0, low_exclusive=True),
    ParameterSpec("truth_rate_hz", f"rate of {TRUTH.name} in simulated time", "Hz", 0.0, 100_000.0, low_exclusive=True),
    ParameterSpec("diagnostics_rate_hz", f"rate of {DIAGNOSTICS.name} besides every change (wall clock)", "Hz", 0.0, 100.0, low_exclusive=True),
    ParameterSpec("fault_hold_s", f"a refused command or force keeps {DIAGNOSTICS.name} at ERROR this long (wall clock)", "s", 0.0, 600.0),
]

LOAD_CONTROLLER = specs_of(LoadControllerSettings)

MONITOR = [
    ParameterSpec("bearing_file", "bearing data file: geometry for the epicyclic cage speed (relative to config/)"),
    ParameterSpec("contact_angle_deg", "contact angle of the slip formula (negative: the bearing file's nominal)", "deg", -1.0, 89.0),
    ParameterSpec("window_revolutions", "whole cage revolutions per slip window", "1", 1, 1000, integer=True),
    ParameterSpec("min_window_s", "a slip window lasts at least this long (more whole cage revolutions at high speed; 0: never)", "s", 0.0, 10.0),
    ParameterSpec("criterion", "abscissa of the slope criterion: 'time' (k2) or 'axial_load' (k1, against the load cell)"),
    ParameterSpec("slip_reference", "slip the criterion judges: 'nominal' (the paper's, at the nominal contact angle) or 'loaded' (kinematic, at the measured load's angle)"),
    ParameterSpec("critical_slope_pct_per_s", "critical slope k2 of the stability criterion (slip against time)", "%/s", -10.0, 0.0),
    ParameterSpec("critical_slope_pct_per_n", "critical slope k1 of the stability criterion (slip against axial load)", "%/N", -1.0, 0.0),
    ParameterSpec("slope_span_s", "trailing window of the slope against time", "s", 0.0, 600.0, low_exclusive=True),
    ParameterSpec("slope_max_span_s", "longest steady stretch the slope against time may rest on when the trailing window cannot decide", "s", 0.0, 3600.0, low_exclusive=True),
    ParameterSpec("load_step_n", "with the load criterion: windows whose loads stay within half of this are one load hold", "N", 0.0, 1000.0, low_exclusive=True),
    ParameterSpec("sweep_settle_s", "with the load criterion: a hold's windows count for its load point from this long after its start", "s", 0.0, 600.0),
    ParameterSpec("sweep_average_s", "with the load criterion: and are averaged over this long", "s", 0.0, 600.0, low_exclusive=True),
    ParameterSpec("min_slope_points", "points needed for a slope", "1", 3, 100_000, integer=True),
    ParameterSpec("slip_resolution_pct", "least scatter of the slip believed", "%", 0.0, 10.0, low_exclusive=True),
    ParameterSpec("change_threshold", "prediction standard errors that make a change in the slip", "1", 0.0, 100.0, low_exclusive=True),
    ParameterSpec("min_inner_ring_speed_rad_s", "no slip point below this spindle speed", "rad/s", 0.0, 1000.0, low_exclusive=True),
    ParameterSpec("restart_speed_change_fraction", "window-to-window speed change that restarts the slip series (0: never)", "1", 0.0, 1.0),
    ParameterSpec("loss_horizon_revolutions", "revolutions over which lost pulses are counted", "1", 0.0, 1e5, low_exclusive=True),
    ParameterSpec("max_lost_fraction", "fraction of pulses lost over the horizon that is a sustained loss", "1", 0.0, 1.0),
    ParameterSpec("loss_silence_revolutions", "a shaft silent for this many of its revolutions is lost", "1", 0.0, 1e4, low_exclusive=True),
    ParameterSpec("loss_min_timeout_s", "sensor loss never sooner than this without a pulse", "s", 0.0, 600.0, low_exclusive=True),
    ParameterSpec("silent_shaft_revolutions", "a shaft silent from the start (or not yet running) is lost once the other turned this many revolutions since its last pulse", "1", 0.0, 1e4, low_exclusive=True),
    ParameterSpec("fault_hold_s", "a malformed pulse stays a fault, a loss a warning, this long (rig time)", "s", 0.0, 600.0),
    ParameterSpec("clock_jump_tolerance_s", "a pulse this far before its predecessor is a clock jump (reset all)", "s", 0.0, 600.0, low_exclusive=True),
    ParameterSpec("status_rate_hz", "status checks and messages per second of rig time, plus one per slip window", "Hz", 0.0, 1000.0, low_exclusive=True),
    ParameterSpec("diagnostics_rate_hz", f"rate of {DIAGNOSTICS.name} besides every change (wall clock)", "Hz", 0.0, 100.0, low_exclusive=True),
]

SHADOW = [
    *_files(
        ("bearing_file", "bearing data file (absolute, or relative to the package's config/)"),
        ("calibration_file", "calibration laid over the bearing data ('' = none; relative to config/)"),
        ("model", "engine model: 'reduced' (runs in real time) or 'stiff' (slow reference)"),
        ("recalibrate", "track a calibration parameter online (recursive least squares)"),
        ("recalibrate_parameter", "the calibration file's parameter tracked ('section.key'; '' = its first one)"),
        ("thermal", "couple the twin's engine to the bearing's thermal network and compare temperature and torque"),
    ),
    ParameterSpec("temperature_model_fraction", "relative uncertainty of the network's outer-ring rise since its start", "1", 0.0, 1.0),
    ParameterSpec("thermocouple_uncertainty_k", "standard uncertainty of the bench's outer-ring thermocouple", "K", 0.0, 20.0),
    ParameterSpec("torque_model_fraction", "relative uncertainty of the twin's friction torque", "1", 0.0, 1.0),
    ParameterSpec("torque_meter_noise_nm", "noise of one torque-meter sample (standard deviation)", "N m", 0.0, 1.0),
    ParameterSpec("chunk_s", "engine advance per call (whole engine steps of 40 us)", "s", 4e-5, 0.1),
    ParameterSpec("window_revolutions", "whole cage revolutions per slip window (the monitor's)", "1", 1, 1000, integer=True),
    ParameterSpec("min_inner_ring_speed_rad_s", "windows slower than this are not compared", "rad/s", 0.0, 1000.0, low_exclusive=True),
    ParameterSpec("calibration_rms_slip_pct", "calibration RMS of the slip (negative: the calibration file's rms_slip_pct)", "%", -1.0, 10.0),
    ParameterSpec("timing_jitter_std_s", "pulse-timing jitter of the bench's fibre-optic sensors", "s", 0.0, 1e-3),
    ParameterSpec("band_coverage", "band half-width in combined standard uncertainties", "1", 0.0, 10.0, low_exclusive=True),
    ParameterSpec("warn_after_s", "a residual outside its band longer than this is a WARN (bench time)", "s", 0.0, 600.0, low_exclusive=True),
    ParameterSpec("error_after_s", "a residual outside its band longer than this is an ERROR; > warn_after_s", "s", 0.0, 3600.0, low_exclusive=True),
    ParameterSpec("settle_s", "windows starting sooner than this after an engine (re)start are not compared", "s", 0.0, 10.0),
    ParameterSpec("max_speed_gap_s", "spindle speed points further apart restart the engine", "s", 0.0, 60.0, low_exclusive=True),
    ParameterSpec("load_average_s", "averaging time of the load-cell force", "s", 0.0, 10.0, low_exclusive=True),
    ParameterSpec("load_timeout_s", "no load-cell sample for this long is a dropout", "s", 0.0, 60.0, low_exclusive=True),
    ParameterSpec("forgetting_factor", "forgetting factor of the recursive least squares, per compared steady window", "1", 0.5, 1.0, low_exclusive=True),
    ParameterSpec("probe_step_fraction", "initial offset of the probe engine from the calibrated value", "1", 0.0, 0.5, low_exclusive=True),
    ParameterSpec("steady_speed_fraction", "windows within this fraction of the previous one's spindle speed are steady", "1", 0.0, 0.5),
    ParameterSpec("status_rate_hz", "checks of the twin per second (wall clock), plus each change of level", "Hz", 0.0, 1000.0, low_exclusive=True),
    ParameterSpec("diagnostics_rate_hz", f"rate of {DIAGNOSTICS.name} besides every change (wall clock)", "Hz", 0.0, 100.0, low_exclusive=True),
]

NODE_PARAMETERS: dict[str, dict[str, ParameterSpec]] = {
    "simulator": {p.name: p for p in SIMULATOR},
    "load_controller": {p.name: p for p in LOAD_CONTROLLER},
    "monitor": {p.name: p for p in MONITOR},
    "shadow": {p.name: p for p in SHADOW},
}
"""Every parameter of every node (besides rclpy's own ``use_sim_time``), by node name."""


def spec_for(node: str, name: str) -> ParameterSpec:
    """The spec of ``node``'s parameter ``name``.

    Raises:
        KeyError: naming the parameter that has no spec (every declared one must have one).
    """
    try:
        return NODE_PARAMETERS[node][name]
    except KeyError:
        raise KeyError(f"{node}: parameter {name!r} has no description in bearing_rig_sim/nodes/parameters.py") from None
