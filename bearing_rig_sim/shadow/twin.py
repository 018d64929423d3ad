"""The shadow twin's core (no ROS): the engine beside the bench, its prediction, the residual.

:class:`ShadowTwin` takes the bench's topics one message at a time, as the node receives them or
as a bag delivers them:

* spindle pulses -> whole-revolution speed points (:mod:`.inputs`) -> the engine follows them
  (:mod:`.predictor`); the same pulses, with the cage pulses, make the monitor's slip windows
  (:mod:`.measured`);
* load-cell samples -> the engine's axial force;
* each measured window, once the engine has run past its end, becomes a
  :class:`ResidualWindow`: measured slip (monitor), predicted slip (engine, same interval), the
  residual and its band (:mod:`.residual`), and whether the anomaly rule flags it.

A window is *compared* only when nothing in the inputs spoils it; otherwise its ``note`` says why
and it cannot build up an anomaly: an input fault the monitor's counter reports (sustained loss
or silence, malformed pulses; an isolated lost pulse is no fault), a load-cell dropout (no sample for ``load_timeout_s``) overlapping it, the engine
(re)started less than ``settle_s`` before it, a spindle below ``min_inner_ring_speed_rad_s``.
Nothing is dropped: every window gives a row.

The status (:meth:`ShadowTwin.health`) is OK, WARN or ERROR: the anomaly rule's level, or WARN
for an input problem (faults, dropout, stopped rig, waiting for inputs), with the reasons.

**Temperature and torque.** With the bearing's thermal network (the bearing file's ``thermal:``
section; ``thermal`` setting) the engine is coupled to it both ways, as the rig session's is
(:class:`~bearing_rig_sim.shadow.predictor.MeasuredDrive`). Beside the slip, each window then
compares, when the bench has the sensor:

* the outer-ring thermocouple (``/rig/outer_ring/temperature``): its latest reading at the
  window's end against the twin's outer ring through the thermocouple's lag; band
  :func:`~bearing_rig_sim.shadow.residual.temperature_band_k`;
* the housing torque meter (``/rig/housing/torque``): the mean of its samples inside the window
  against the twin's mean friction torque; band :func:`~bearing_rig_sim.shadow.residual.torque_band_nm`.

Each has its own anomaly rule (the same warn and error times); a compared slip window is required
(the same input faults spoil all three). The twin's network starts at the bench thermocouple's
first reading when one came before the engine's first start, else at ambient.

Units: s, rad/s, N, N m, degC; slip, residual and band in percentage points; temperature
residual and band in K.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Any

from bearing_rig_sim.analysis.slip import BearingKinematics
from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.dynamics import BearingParameters, Mounting
from bearing_rig_sim.health import Health, HealthLevel
from bearing_rig_sim.instruments.fibre_optic import FibreOpticSettings, Pulse
from bearing_rig_sim.instruments.first_order import ThermocoupleSettings, TorqueMeterSettings
from bearing_rig_sim.instruments.registry import InstrumentSet
from bearing_rig_sim.interfaces import CAGE_PULSES, HOUSING_TORQUE, OUTER_RING_TEMPERATURE, SPINDLE_PULSES
from bearing_rig_sim.rig.mounting import MountingConfig
from bearing_rig_sim.shadow.inputs import LoadCellTrack, SpindleSpeedTrack
from bearing_rig_sim.shadow.measured import MeasuredWindow, MeasuredWindows
from bearing_rig_sim.shadow.predictor import MeasuredDrive, Prediction
from bearing_rig_sim.shadow.recalibration import CalibrationParameter, OnlineCalibration, ParameterEstimate, RecalibrationError
from bearing_rig_sim.shadow.residual import AnomalyRule, band_pct, temperature_band_k, torque_band_nm
from bearing_rig_sim.shadow.settings import ShadowSettings
from bearing_rig_sim.thermal.bearing import ThermalConfig

STALE_WINDOW_S = 2.0
"""A measured window the engine has not reached this long after its end (bench time) is given
up: its row says so (s)."""

MAX_PENDING = 1000
"""Most measured windows waiting for the engine (1)."""


@dataclass(frozen=True)
class ResidualWindow:
    """One slip window, measured and predicted (one row of ``residuals.csv``).

    Attributes:
        start_time, time: the window, s (bench clock; ``time`` its end).
        inner_ring_speed: measured mean spindle speed, rad/s.
        axial_load: mean axial force the engine applied over the window (load cell), N; NaN if
            not predicted.
        measured_cage_speed: measured mean cage speed, rad/s.
        measured_slip: percent.
        predicted_slip: percent (NaN if not predicted).
        predicted_cage_speed: rad/s (NaN if not predicted).
        residual: measured minus predicted slip, pp (NaN if not compared).
        band: half-width of the residual's band, pp.
        compared: whether the window entered the anomaly rule.
        anomaly: whether the anomaly rule stood at WARN or ERROR after it.
        level: the anomaly rule's level after it.
        note: why it was not compared, or the anomaly's detail; empty otherwise.
        measured_temperature: the bench thermocouple's latest reading at the window's end, degC
            (NaN: none).
        predicted_temperature: the twin's outer ring at the window's end through the
            thermocouple's lag, degC (NaN: no network).
        temperature_residual: measured minus predicted, K (NaN if not compared).
        temperature_band: its band's half-width, K (NaN without a prediction).
        temperature_anomaly: the temperature rule stood at WARN or ERROR after the window.
        measured_torque: mean of the bench torque meter's samples inside the window, N m (NaN: none).
        predicted_torque: the twin's mean friction torque over the window, N m (NaN if not predicted).
        torque_residual: measured minus predicted, N m (NaN if not compared).
        torque_band: its band's half-width, N m (NaN without a prediction).
        torque_anomaly: the torque rule stood at WARN or ERROR after the window.
    """

    start_time: float
    time: float
    inner_ring_speed: float
    axial_load: float
    measured_cage_speed: float
    measured_slip: float
    predicted_slip: float
    predicted_cage_speed: float
    residual: float
    band: float
    compared: bool
    anomaly: bool
    level: HealthLevel
    note: str
    measured_temperature: float = math.nan
    predicted_temperature: float = math.nan
    temperature_residual: float = math.nan
    temperature_band: float = math.nan
    temperature_anomaly: bool = False
    measured_torque: float = math.nan
    predicted_torque: float = math.nan
    torque_residual: float = math.nan
    torque_band: float = math.nan
    torque_anomaly: bool = False


@dataclass
class _Pending:
    window: MeasuredWindow
    faults: tuple[str, ...]


class ShadowTwin:
    """The twin beside the bench (see the module docstring).

    Args:
        settings: the shadow's parameters.
        params: bearing parameters to run (default: the settings' bearing and calibration files).
        measured: the measured windows (default: the monitor's, with the shipped monitor file).
    """

    def __init__(self, settings: ShadowSettings, params: BearingParameters | None = None, measured: MeasuredWindows | None = None) -> None:
        self.settings = settings
        self.params = params if params is not None else BearingParameters.from_yaml(settings.bearing_file, settings.calibration_file)
        self.kinematics = BearingKinematics.from_config(settings.bearing_file)
        self.measured = measured if measured is not None else MeasuredWindows(settings.window_revolutions)
        self.speed = SpindleSpeedTrack(self.measured.clock_jump_tolerance_s)
        self.load = LoadCellTrack(settings.load_average_s)
        self.thermal_config: ThermalConfig | None = None
        """The bearing's thermal network data (None: isothermal; no temperature prediction)."""
        if settings.thermal:
            try:
                self.thermal_config = ThermalConfig.from_yaml(settings.bearing_file)
            except ConfigError:
                self.thermal_config = None  # a bearing file without a thermal: section
        self.mounting = Mounting.of(MountingConfig.from_rig_file(settings.rig_file))
        instruments = InstrumentSet.from_rig_file(settings.rig_file)
        self.thermocouple = instruments.on_topic(OUTER_RING_TEMPERATURE.name, ThermocoupleSettings)
        """The rig file's outer-ring thermocouple, whose lag the predicted reading follows."""
        self.torque_meter = instruments.on_topic(HOUSING_TORQUE.name, TorqueMeterSettings)
        """The rig file's housing torque meter, whose noise enters the torque band."""
        self.timing_jitter_std_s = max(instruments.on_topic(topic.name, FibreOpticSettings).timing_jitter_std_s for topic in (SPINDLE_PULSES, CAGE_PULSES))
        """Pulse-timing jitter of the bench's fibre-optic sensors (the rig file's, the larger of the two), s."""
        """The test bearing's mounting, from the rig file (as the simulator's engine has it)."""
        self.drive = self._make_drive(self.params)
        self.rule = AnomalyRule(settings.warn_after_s, settings.error_after_s)
        self.temperature_rule = AnomalyRule(settings.warn_after_s, settings.error_after_s)
        self.torque_rule = AnomalyRule(settings.warn_after_s, settings.error_after_s)
        self._temperatures: deque[tuple[float, float]] = deque()
        self._torques: deque[tuple[float, float]] = deque()
        self.calibration: OnlineCalibration | None = None
        if settings.recalibrate:
            if settings.calibration_file is None:
                raise RecalibrationError("recalibrate: needs a calibration file (calibration_file is empty)")
            self.calibration = OnlineCalibration(
                CalibrationParameter(settings.bearing_file, settings.calibration_file, settings.recalibrate_parameter),
                forgetting_factor=settings.forgetting_factor,
                probe_step_fraction=settings.probe_step_fraction,
                make_drive=self._make_drive,
            )
        self._pending: deque[_Pending] = deque()
        self._dropouts: deque[tuple[float, float]] = deque()
        self._jumps = 0
        self._now = -math.inf
        self._previous_inner: float | None = None
        self.latest: ResidualWindow | None = None
        """The latest row (None before the first)."""
        self.counts = {"windows": 0, "compared": 0, "inside": 0, "anomalous": 0}
        """Rows made, compared, compared inside the band, flagged (1)."""

    def _make_drive(self, params: BearingParameters) -> MeasuredDrive:
        st = self.settings
        return MeasuredDrive(
            params,
            model=st.model,
            chunk=st.chunk_s,
            max_speed_gap=st.max_speed_gap_s,
            load_at=self.load.force_at,
            thermal=self.thermal_config,
            lubricant_feedback=st.lubricant_feedback,
            mounting=self.mounting,
            thermocouple=self.thermocouple,
        )

    # -- input ---------------------------------------------------------------------------------
    def add_force(self, time: float, force: float) -> None:
        """One load-cell sample: bench time (s), axial force (N). Bad samples are ignored."""
        last = self.load.last_time
        if self.load.add(time, force) and last is not None and time - last > self.settings.load_timeout_s:
            self._dropouts.append((last, time))
        self._now = max(self._now, time) if math.isfinite(time) else self._now

    def add_temperature(self, time: float, temperature_c: float) -> None:
        """One outer-ring thermocouple reading: bench time (s), degC. Non-finite ones are ignored."""
        if not (math.isfinite(time) and math.isfinite(temperature_c)):
            return
        drives = [self.drive] + ([self.calibration.probe] if self.calibration is not None else [])
        for drive in drives:
            if not drive.thermal_started and drive.thermal_start_c is None:
                drive.thermal_start_c = float(temperature_c)  # the twin's bearing starts where the bench's is
        self._temperatures.append((time, float(temperature_c)))

    def add_torque(self, time: float, torque_nm: float) -> None:
        """One housing torque-meter sample: bench time (s), torque about the axis (N m)."""
        if math.isfinite(time) and math.isfinite(torque_nm):
            self._torques.append((time, float(torque_nm)))

    def _measured_temperature(self, end: float) -> float:
        """The latest thermocouple reading at or before ``end`` (within a second), degC."""
        latest = math.nan
        for t, value in self._temperatures:
            if t > end:
                break
            latest = value if end - t <= 1.0 else math.nan
        return latest

    def _measured_torque(self, start: float, end: float) -> tuple[float, int]:
        """Mean of the torque samples inside ``[start, end]``, N m, and their number."""
        inside = [v for t, v in self._torques if start <= t <= end]
        return (sum(inside) / len(inside), len(inside)) if inside else (math.nan, 0)

    def add_pulse(self, shaft: str, pulse: Pulse) -> list[ResidualWindow]:
        """One pulse of ``"spindle"`` or ``"cage"``; the rows completed by it (never raises on
        bad data)."""
        fresh = self.measured.add_pulse(shaft, pulse)
        if fresh:
            faults = self.measured.faults()
            for w in fresh:
                self._pending.append(_Pending(w, faults))
            while len(self._pending) > MAX_PENDING:
                self._resolve(self._pending.popleft(), None, "no prediction: too many windows waiting for the engine")
        if shaft == "spindle":
            point = self.speed.add(pulse)
            if self.speed.jumps != self._jumps:
                self._jumps = self.speed.jumps
                self._clock_jump()
            if point is not None:
                self.drive.follow(point)
                if self.calibration is not None:
                    self.calibration.follow(point)
        if math.isfinite(pulse.time):
            self._now = max(self._now, pulse.time)
        return self._resolve_ready()

    def _clock_jump(self) -> None:
        while self._pending:
            self._resolve(self._pending.popleft(), None, "no prediction: the bench clock jumped back")
        self.drive.jump_back()
        if self.calibration is not None:
            self.calibration.jump_back()
        self.load.reset()
        self._dropouts.clear()
        self._temperatures.clear()
        self._torques.clear()
        self._now = -math.inf
        self.rule.reset()
        self.temperature_rule.reset()
        self.torque_rule.reset()

    def check(self, now: float) -> list[ResidualWindow]:
        """Time-based checks at bench time ``now`` (s): the monitor's sensor-loss and stop checks,
        windows the engine will not reach. Returns the rows given up."""
        self.measured.check(now)
        out: list[ResidualWindow] = []
        while self._pending and self._pending[0].window.end_time < now - STALE_WINDOW_S:
            out.append(self._resolve(self._pending.popleft(), None, "no prediction: the engine did not reach the window (no spindle speed)"))
        return out

    # -- windows -------------------------------------------------------------------------------
    def _resolve_ready(self) -> list[ResidualWindow]:
        out: list[ResidualWindow] = []
        drive = self.drive
        while self._pending:
            item = self._pending[0]
            w = item.window
            if w.end_time > drive.time and w.start_time >= drive.started_at:
                break
            self._pending.popleft()
            prediction = drive.predict(w.start_time, w.end_time)
            out.append(self._resolve(item, prediction, "" if prediction is not None else "no prediction: the engine restarted inside the window"))
        keep = self._pending[0].window.start_time if self._pending else drive.time
        drive.forget_before(keep - 1.0)
        if self.calibration is not None:
            self.calibration.forget_before(keep - 1.0)
        while self._dropouts and self._dropouts[0][1] < keep - 10.0:
            self._dropouts.popleft()
        for track in (self._temperatures, self._torques):
            while len(track) > 1 and track[1][0] < keep - 2.0:
                track.popleft()
        return out

    def _why_not(self, item: _Pending) -> str:
        w, st = item.window, self.settings
        if item.faults:
            return "input fault: " + "; ".join(item.faults)
        if w.inner_ring_speed < st.min_inner_ring_speed_rad_s:
            return f"spindle below {st.min_inner_ring_speed_rad_s:g} rad/s"
        if w.start_time < self.drive.started_at + st.settle_s:
            return f"engine settling ({st.settle_s:g} s after its start at {self.drive.started_at:.6f} s)"
        for a, b in self._dropouts:
            if a < w.end_time and b > w.start_time:
                return f"load-cell dropout from {a:.6f} s to {b:.6f} s"
        if self.load.silent_for(w.end_time) > st.load_timeout_s and (self.load.last_time is None or self.load.last_time < w.end_time):
            return "load-cell dropout (no sample)"
        return ""

    def _resolve(self, item: _Pending, prediction: Prediction | None, why: str) -> ResidualWindow:
        w, st = item.window, self.settings
        kin = self.kinematics
        measured = float(kin.slip_rate(w.cage_speed, w.inner_ring_speed)) if w.inner_ring_speed > 0.0 else math.nan
        band = band_pct(
            w.end_time - w.start_time, calibration_rms_pct=st.calibration_rms_slip_pct, jitter_std_s=self.timing_jitter_std_s, coverage=st.band_coverage
        )
        predicted = cage = load = math.nan
        if prediction is not None and prediction.inner_ring_speed > 0.0:
            predicted = float(kin.slip_rate(prediction.cage_speed, prediction.inner_ring_speed))
            cage, load = prediction.cage_speed, prediction.axial_load
        if not why:
            why = self._why_not(item)
        compared = not why and math.isfinite(predicted) and math.isfinite(measured)
        residual = measured - predicted if compared else math.nan
        state = self.rule.add(w.start_time, w.end_time, residual if compared else None, band)
        anomaly = state.level != HealthLevel.OK
        steady = self._steady(w.inner_ring_speed)
        if compared and steady and self.calibration is not None:
            self.calibration.update(w.start_time, w.end_time, measured, predicted, lambda c, i: float(kin.slip_rate(c, i)))
        heat = self._heat_residuals(w, prediction if compared else None)
        row = ResidualWindow(
            start_time=w.start_time,
            time=w.end_time,
            inner_ring_speed=w.inner_ring_speed,
            axial_load=load,
            measured_cage_speed=w.cage_speed,
            measured_slip=measured,
            predicted_slip=predicted,
            predicted_cage_speed=cage,
            residual=residual,
            band=band,
            compared=compared,
            anomaly=anomaly,
            level=state.level,
            note=state.detail if anomaly else why,
            **heat,
        )
        self.latest = row
        self.counts["windows"] += 1
        self.counts["compared"] += int(compared)
        self.counts["inside"] += int(compared and abs(residual) <= band)
        self.counts["anomalous"] += int(anomaly)
        return row

    def _heat_residuals(self, w: MeasuredWindow, prediction: Prediction | None) -> dict[str, Any]:
        """The temperature and torque columns of a window (see the module docstring)."""
        st = self.settings
        t_meas = self._measured_temperature(w.end_time)
        m_meas, samples = self._measured_torque(w.start_time, w.end_time)
        t_pred = prediction.outer_ring_temperature if prediction is not None else math.nan
        m_pred = prediction.friction_torque if prediction is not None else math.nan
        coupling = self.drive.coupling
        start = math.nan
        if coupling is not None:
            net = coupling.network
            start = float(net.initial_temperatures[list(net.names).index("outer_ring")])
        t_band = temperature_band_k(
            t_pred, start, model_fraction=st.temperature_model_fraction, sensor_k=st.thermocouple_uncertainty_k, coverage=st.band_coverage
        )
        m_band = torque_band_nm(m_pred, samples, model_fraction=st.torque_model_fraction, noise_nm=self.torque_meter.noise_std_n_m, coverage=st.band_coverage)
        t_res = t_meas - t_pred if math.isfinite(t_meas) and math.isfinite(t_pred) else math.nan
        m_res = m_meas - m_pred if math.isfinite(m_meas) and math.isfinite(m_pred) else math.nan
        t_state = self.temperature_rule.add(w.start_time, w.end_time, t_res if math.isfinite(t_res) else None, t_band, unit="K")
        m_state = self.torque_rule.add(w.start_time, w.end_time, m_res if math.isfinite(m_res) else None, m_band, unit="N m")
        return {
            "measured_temperature": t_meas,
            "predicted_temperature": t_pred,
            "temperature_residual": t_res,
            "temperature_band": t_band,
            "temperature_anomaly": t_state.level != HealthLevel.OK,
            "measured_torque": m_meas,
            "predicted_torque": m_pred,
            "torque_residual": m_res,
            "torque_band": m_band,
            "torque_anomaly": m_state.level != HealthLevel.OK,
        }

    def _steady(self, inner: float) -> bool:
        previous, self._previous_inner = self._previous_inner, inner
        return previous is not None and abs(inner - previous) <= self.settings.steady_speed_fraction * previous

    # -- output --------------------------------------------------------------------------------
    def estimate(self) -> ParameterEstimate | None:
        """The re-calibrated parameter (None when re-calibration is off)."""
        return self.calibration.estimate() if self.calibration is not None else None

    def health(self, now: float | None = None) -> Health:
        """OK, WARN or ERROR with the reasons (see the module docstring)."""
        t = self._now if now is None else now
        reasons: list[str] = []
        level = self.rule.state.level
        if level != HealthLevel.OK:
            reasons.append(self.rule.state.detail)
        for name, rule in (("outer-ring temperature", self.temperature_rule), ("housing torque", self.torque_rule)):
            if rule.state.level != HealthLevel.OK:
                level = max(level, rule.state.level)
                reasons.append(f"{name}: {rule.state.detail}")
        problems = list(self.measured.faults())
        stopped = self.measured.stopped()
        if stopped:
            problems.append(stopped)
        silent = self.load.silent_for(t)
        if silent > self.settings.load_timeout_s and math.isfinite(t):
            problems.append("load cell: no sample yet" if self.load.last_time is None else f"load cell: no sample for {silent:.3g} s (last force held)")
        if self.drive.origin is None:
            problems.append("waiting for a whole spindle revolution and a load-cell sample")
        if problems:
            level = max(level, HealthLevel.WARN)
            reasons.extend(problems)
        if not reasons and self.latest is not None:
            r = self.latest
            reasons.append(f"residual {r.residual:+.3f} pp within +-{r.band:.3f} pp" if r.compared else f"last window not compared: {r.note}")
        return Health(level, tuple(reasons))
