"""The monitor's parameters (``config/monitor.yaml``), validated; SI units, the unit in each name
(rpm and percent only where the name says so)."""

from __future__ import annotations

import math
from typing import Annotated, ClassVar, Self
from collections.abc import Mapping

from bearing_rig_sim.analysis.slip import BearingKinematics
from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.interfaces import DIAGNOSTICS
from bearing_rig_sim.monitoring.windows import LossRules
from bearing_rig_sim.settings_model import ConfigFile, Integer, NodeSettings, Number, one_of, param

NODE_NAME = "monitor"
"""The monitor node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "monitor.yaml"
"""The shipped parameter file, under ``config/``."""

DIAGNOSTIC_NAME = f"{NODE_NAME}: cage slip"
"""Name of the monitor's status in ``/diagnostics``."""

PARAMETER_KEY_PREFIX = "parameter/"
"""The monitor's ``/diagnostics`` status carries each of its running parameter values under this
prefix and the parameter's name (:meth:`MonitorSettings.published_parameters`)."""

SLIP_REFERENCES = ("nominal", "loaded")
"""Which slip the criterion judges: the paper's, against the pure-rolling cage speed at the
nominal contact angle, or the kinematic one at the contact angle of the measured axial load."""

CRITERIA = ("time", "axial_load")
"""Abscissae of the slope criterion: slip against time (k2) or against the measured axial load
(k1), as a test program's ``stability_criterion`` says."""


class MonitorSettings(NodeSettings):
    """The monitor's validated parameters (``config/monitor.yaml`` explains each), declared once
    (:mod:`bearing_rig_sim.settings_model`): the YAML checks, the errors and the node's ROS
    descriptors come from these fields.

    ``slip_reference`` "nominal" is the paper's slip (Eq. 11-12 at ``contact_angle_deg``),
    "loaded" the kinematic slip at the contact angle of the measured axial load (Harris's thrust
    equilibrium); both are reported, the time criterion judges the one named and the load sweep
    the one ``sweep_slip_reference`` names. The sustained-loss rules
    are :class:`~bearing_rig_sim.monitoring.windows.LossRules`; the load sweep
    :mod:`~bearing_rig_sim.monitoring.load_sweep`.
    """

    NODE_NAME: ClassVar[str] = NODE_NAME
    SHIPPED_FILE: ClassVar[str] = SHIPPED_FILE

    bearing_file: ConfigFile = param("bearing data file: geometry for the epicyclic cage speed (relative to config/)")
    contact_angle_deg: Number = param("contact angle of the slip formula (negative: the bearing file's nominal)", unit="deg", ge=-1.0, le=89.0)
    window_revolutions: Integer = param("whole cage revolutions per slip window", unit="1", ge=1, le=1000)
    min_window_s: Number = param("a slip window lasts at least this long (more whole cage revolutions at high speed; 0: never)", unit="s", ge=0.0, le=10.0)
    criterion: Annotated[str, one_of(CRITERIA)] = param("abscissa of the slope criterion: 'time' (k2) or 'axial_load' (k1, against the load cell)")
    slip_reference: Annotated[str, one_of(SLIP_REFERENCES)] = param(
        "slip the criterion judges: 'nominal' (the paper's, at the nominal contact angle) or 'loaded' (kinematic, at the measured load's angle)"
    )
    sweep_slip_reference: Annotated[str, one_of(SLIP_REFERENCES)] = param(
        "slip the load sweep judges (axial_load criterion): 'nominal' (the paper's) or 'loaded' (kinematic, at the measured load's angle)"
    )
    critical_slope_pct_per_s: Number = param("critical slope k2 of the stability criterion (slip against time)", unit="%/s", ge=-10.0, le=0.0)
    critical_slope_pct_per_n: Number = param("critical slope k1 of the stability criterion (slip against axial load)", unit="%/N", ge=-1.0, le=0.0)
    stable_confidence: Number = param(
        "one-sided confidence of the STABLE test: STABLE when the slope's lower bound at this confidence is at or above k", unit="1", ge=0.5, le=0.999
    )
    slope_span_s: Number = param("trailing window of the slope against time", unit="s", gt=0.0, le=600.0)
    slope_max_span_s: Number = param(
        "longest steady stretch the slope against time may rest on when the trailing window cannot decide", unit="s", gt=0.0, le=3600.0
    )
    load_step_n: Number = param("with the load criterion: windows whose loads stay within half of this are one load hold", unit="N", gt=0.0, le=1000.0)
    sweep_settle_s: Number = param(
        "with the load criterion: a hold's windows count for its load point from this long after its start", unit="s", ge=0.0, le=600.0
    )
    sweep_average_s: Number = param("with the load criterion: and are averaged over this long", unit="s", gt=0.0, le=600.0)
    min_slope_points: Integer = param("points needed for a slope", unit="1", ge=3, le=100_000)
    slip_resolution_pct: Number = param("least scatter of the slip believed", unit="%", gt=0.0, le=10.0)
    change_threshold: Number = param("prediction standard errors that make a change in the slip", unit="1", gt=0.0, le=100.0)
    min_inner_ring_speed_rad_s: Number = param("no slip point below this spindle speed (the series restarts)", unit="rad/s", gt=0.0, le=1000.0)
    restart_speed_change_fraction: Number = param("window-to-window speed change that restarts the slip series (0: never)", unit="1", ge=0.0, le=1.0)
    loss_horizon_revolutions: Number = param("revolutions over which lost pulses are counted", unit="1", gt=0.0, le=1e5)
    max_lost_fraction: Number = param("fraction of pulses lost over the horizon that is a sustained loss", unit="1", ge=0.0, le=1.0)
    loss_silence_revolutions: Number = param("a shaft silent for this many of its revolutions is lost", unit="1", gt=0.0, le=1e4)
    loss_min_timeout_s: Number = param("sensor loss never sooner than this without a pulse", unit="s", gt=0.0, le=600.0)
    silent_shaft_revolutions: Number = param(
        "a shaft silent from the start (or not yet running) is lost once the other turned this many revolutions since its last pulse",
        unit="1",
        gt=0.0,
        le=1e4,
    )
    fault_hold_s: Number = param("a malformed pulse stays a fault, a loss a warning, this long (rig time)", unit="s", ge=0.0, le=600.0)
    clock_jump_tolerance_s: Number = param("a pulse this far before its predecessor is a clock jump (reset all)", unit="s", gt=0.0, le=600.0)
    status_rate_hz: Number = param("status checks and messages per second of rig time, plus one per slip window", unit="Hz", gt=0.0, le=1000.0)
    diagnostics_rate_hz: Number = param(f"rate of {DIAGNOSTICS.name} besides every change (wall clock)", unit="Hz", gt=0.0, le=100.0)

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

    def published_parameters(self) -> dict[str, str]:
        """The running values as the monitor's diagnostics carry them: every parameter but the
        bearing file (whose path is the node's machine's; a bag records the file's text) under
        :data:`PARAMETER_KEY_PREFIX`. Whoever judges the monitor's statuses needs them: the time
        to stable counts a STABLE only at ``stable_confidence`` and on windows its verdict can
        reach back to (``window_revolutions``, ``min_window_s``, ``slope_span_s``,
        ``min_slope_points``), and ``analyze`` reruns the monitor with all of them."""
        return {PARAMETER_KEY_PREFIX + name: str(value) for name, value in self.model_dump().items() if name != "bearing_file"}

    def with_published(self, values: Mapping[str, str], source: str = "the monitor's published parameters") -> tuple[Self, str]:
        """These settings with the running values found in ``values`` (a monitor's diagnostic
        key/values, :meth:`published_parameters`), validated as a whole; returns (settings,
        problem): on a value refused, these settings unchanged and the reason."""
        raw = {name: str(value) if name == "bearing_file" else value for name, value in self.model_dump().items()}
        changed = False
        for name, current in raw.items():
            text = values.get(PARAMETER_KEY_PREFIX + name)
            if text is None or name == "bearing_file":
                continue
            try:
                value: object = text if isinstance(current, str) else float(text) if isinstance(current, float) else int(text)
            except ValueError:
                return self, f"{name}: {text!r} is not a number"
            changed = changed or value != current
            raw[name] = value
        if not changed:
            return self, ""
        try:
            return type(self).from_values(raw, source), ""
        except ConfigError as exc:
            return self, str(exc)

    @property
    def critical_slope(self) -> float:
        """k of the configured criterion: %/s (time) or %/N (axial_load)."""
        return self.critical_slope_pct_per_s if self.criterion == "time" else self.critical_slope_pct_per_n


def shipped_parameters() -> dict[str, object]:
    """The raw values of the shipped ``config/monitor.yaml`` (the node's declared defaults)."""
    return MonitorSettings.shipped_parameters()
