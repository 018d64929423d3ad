"""The shadow node: the twin beside the bench (a thin shell around
:class:`~bearing_rig_sim.shadow.ShadowTwin`).

Subscribes the bench's own topics: ``/rig/spindle/pulses`` and ``/rig/cage/pulses``
(bearing_rig_msgs/FibreOpticPulse) and the load cell ``/rig/axial_load/force``
(geometry_msgs/WrenchStamped, ``force.z``). Publishes:

* ``/twin/residual`` (bearing_rig_msgs/ShadowResidual): one per slip window, measured and
  predicted slip, residual, band, anomaly;
* ``/twin/outer_ring/temperature_residual`` and ``/twin/housing/torque_residual``
  (geometry_msgs/Vector3Stamped): per window whose thermocouple or torque meter was compared, x
  the residual (measured minus predicted; K, N m), y its threshold (the band's half-width), z the
  twin's prediction (degC, N m);
* ``/twin/calibration_estimate`` (bearing_rig_msgs/ShadowEstimate): with ``recalibrate: true``,
  after each steady window used;
* ``/diagnostics``: ``diagnostics_rate_hz`` (wall) and on every change of level: OK, WARN (an
  anomaly past ``warn_after_s``, or an input problem), ERROR (past ``error_after_s``).

Time is the pulse stamps (the bench's clock); the node's timers run on the steady clock and give
the twin the latest stamp extrapolated by the wall time since it arrived, so a silent source is
noticed. Bad input never stops the node: it shows on ``/diagnostics``.

Lifecycle (:class:`~bearing_rig_sim.nodes.shell.ManagedNode`, like the simulator, the load
controller and the monitor): unconfigured at start; the twin and its entities are made at
configure and run while active. ``bearing-rig shadow`` (live) starts it with ``--autostart``.
"""

from __future__ import annotations

import math
import sys
import time
from typing import Any
from collections.abc import Sequence

from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Vector3Stamped, WrenchStamped
from rclpy.clock import Clock, ClockType
from sensor_msgs.msg import Temperature

from bearing_rig_msgs.msg import FibreOpticPulse, ShadowEstimate, ShadowResidual
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.health import HealthLevel
from bearing_rig_sim.interfaces import AXIAL_LOAD_FORCE, CAGE_PULSES, DIAGNOSTICS, SPINDLE_PULSES, TWIN_ESTIMATE, TWIN_RESIDUAL
from bearing_rig_sim.interfaces import HOUSING_TORQUE, OUTER_RING_TEMPERATURE, TWIN_TEMPERATURE_RESIDUAL, TWIN_TORQUE_RESIDUAL
from bearing_rig_sim.nodes.common import PULSE_READER_QOS, diagnostic_array, diagnostic_status, from_stamp, qos_profile, run_node, to_stamp
from bearing_rig_sim.nodes.shell import ManagedNode, declare_described, parameter_values, survives_shutdown
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.shadow import NODE_NAME, ResidualWindow, ShadowSettings, ShadowTwin, shipped_parameters


def residual_fields(row: ResidualWindow) -> dict[str, Any]:
    """The ShadowResidual.msg fields of a row (all but the header)."""
    return {
        "window_start": row.start_time,
        "inner_ring_speed": row.inner_ring_speed,
        "axial_load": row.axial_load,
        "measured_cage_speed": row.measured_cage_speed,
        "predicted_cage_speed": row.predicted_cage_speed,
        "measured_slip": row.measured_slip,
        "predicted_slip": row.predicted_slip,
        "residual": row.residual,
        "band": row.band,
        "compared": row.compared,
        "anomaly": row.anomaly,
        "level": int(row.level),
        "detail": row.note,
        "measured_temperature": row.measured_temperature,
        "predicted_temperature": row.predicted_temperature,
        "temperature_residual": row.temperature_residual,
        "temperature_band": row.temperature_band,
        "temperature_anomaly": row.temperature_anomaly,
        "measured_torque": row.measured_torque,
        "predicted_torque": row.predicted_torque,
        "torque_residual": row.torque_residual,
        "torque_band": row.torque_band,
        "torque_anomaly": row.torque_anomaly,
    }


def sensor_residuals(row: ResidualWindow) -> dict[str, tuple[float, float, float]]:
    """The thermocouple's and the torque meter's residual of a row, by topic name, as
    (residual, threshold, prediction): K, K, degC and N m, N m, N m; only those compared (a
    finite residual)."""
    out: dict[str, tuple[float, float, float]] = {}
    if math.isfinite(row.temperature_residual):
        out[TWIN_TEMPERATURE_RESIDUAL.name] = (row.temperature_residual, row.temperature_band, row.predicted_temperature)
    if math.isfinite(row.torque_residual):
        out[TWIN_TORQUE_RESIDUAL.name] = (row.torque_residual, row.torque_band, row.predicted_torque)
    return out


class ShadowNode(ManagedNode):
    """The shadow node (see the module docstring): a managed node like the rig's other three.

    Its parameters are declared with their descriptors at start; the settings, the twin, the
    publishers, subscriptions and timers are made at configure (a bad parameter or file fails the
    transition with the reason), and the twin is fed and published only while active.

    Raises:
        RigError: a parameter given at start out of its range.
    """

    def __init__(self, **node_options: Any) -> None:
        super().__init__(NODE_NAME, **node_options)
        self._defaults = shipped_parameters()
        declare_described(self, NODE_NAME, self._defaults)
        self.twin: ShadowTwin | None = None

    def configure(self) -> None:
        """Validate the parameters; make the twin, its inputs, outputs and timers."""
        self.settings = ShadowSettings.from_values(parameter_values(self, self._defaults), f"{NODE_NAME} parameters")
        self.twin = ShadowTwin(self.settings)
        self._last_stamp = -math.inf
        self._last_wall: float | None = None
        self._last_level: HealthLevel | None = None
        self._received = {"spindle": 0, "cage": 0, "force": 0}
        self._estimate_updates = 0
        self._residual_pub = self.publisher(ShadowResidual, TWIN_RESIDUAL.name, qos_profile(TWIN_RESIDUAL))
        self._sensor_pubs = {t.name: self.publisher(Vector3Stamped, t.name, qos_profile(t)) for t in (TWIN_TEMPERATURE_RESIDUAL, TWIN_TORQUE_RESIDUAL)}
        self._estimate_pub = self.publisher(ShadowEstimate, TWIN_ESTIMATE.name, qos_profile(TWIN_ESTIMATE))
        self._diag_pub = self.publisher(DiagnosticArray, DIAGNOSTICS.name, qos_profile(DIAGNOSTICS))
        sensor = PULSE_READER_QOS  # best effort: matches a bench counter publishing sensor data, and the twin's reliable streams
        self.subscription(FibreOpticPulse, SPINDLE_PULSES.name, lambda m: self._on_pulse("spindle", m), sensor)
        self.subscription(FibreOpticPulse, CAGE_PULSES.name, lambda m: self._on_pulse("cage", m), sensor)
        self.subscription(WrenchStamped, AXIAL_LOAD_FORCE.name, self._on_force, sensor)  # the load cell: best effort, as the pulses
        self.subscription(Temperature, OUTER_RING_TEMPERATURE.name, self._on_temperature, qos_profile(OUTER_RING_TEMPERATURE))
        self.subscription(WrenchStamped, HOUSING_TORQUE.name, self._on_torque, qos_profile(HOUSING_TORQUE))
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.timer(1.0 / self.settings.status_rate_hz, self._on_check_timer, clock=steady)
        self.timer(1.0 / self.settings.diagnostics_rate_hz, self._publish_diagnostics, clock=steady)
        cal = self.settings.calibration_file
        self.get_logger().info(
            f"shadowing the bench with {self.settings.bearing_file.name} and calibration {cal.name if cal else 'none'} "
            f"(band +-{self.settings.band_coverage:g} u, u >= {self.settings.calibration_rms_slip_pct:.4f} pp)"
        )

    def cleanup(self) -> None:
        """Drop the twin."""
        self.twin = None

    # -- inputs --------------------------------------------------------------------------------
    def _stamp_seen(self, t: float) -> None:
        if math.isfinite(t) and t >= self._last_stamp:
            self._last_stamp = t
            self._last_wall = time.monotonic()

    @survives_shutdown
    def _on_pulse(self, shaft: str, msg: FibreOpticPulse) -> None:
        try:
            assert self.twin is not None  # fed only while active
            pulse = Pulse(from_stamp(msg.header.stamp), int(msg.strip_id), int(msg.strip_count), int(msg.revolution), int(msg.pulse_index), msg.sensor_id)
            self._received[shaft] += 1
            self._stamp_seen(pulse.time)
            self._publish_rows(self.twin.add_pulse(shaft, pulse))
        except Exception as exc:
            if not self.context.ok():
                raise
            self.get_logger().error(f"{shaft} pulse not processed: {exc}", throttle_duration_sec=1.0)

    @survives_shutdown
    def _on_force(self, msg: WrenchStamped) -> None:
        assert self.twin is not None  # fed only while active
        t = from_stamp(msg.header.stamp)
        self._received["force"] += 1
        self._stamp_seen(t)
        self.twin.add_force(t, float(msg.wrench.force.z))

    @survives_shutdown
    def _on_temperature(self, msg: Temperature) -> None:
        assert self.twin is not None  # fed only while active
        self.twin.add_temperature(from_stamp(msg.header.stamp), float(msg.temperature))

    @survives_shutdown
    def _on_torque(self, msg: WrenchStamped) -> None:
        assert self.twin is not None  # fed only while active
        self.twin.add_torque(from_stamp(msg.header.stamp), float(msg.wrench.torque.z))

    # -- periodic ------------------------------------------------------------------------------
    def _bench_now(self) -> float | None:
        if self._last_wall is None:
            return None
        return self._last_stamp + (time.monotonic() - self._last_wall)

    @survives_shutdown
    def _on_check_timer(self) -> None:
        if self.twin is None:
            return
        now = self._bench_now()
        if now is not None:
            self._publish_rows(self.twin.check(now))
        if self.twin.health(now).level != self._last_level:
            self._publish_diagnostics()

    # -- outputs -------------------------------------------------------------------------------
    def _publish_rows(self, rows: list[ResidualWindow]) -> None:
        assert self.twin is not None  # rows come from the twin
        for row in rows:
            msg = ShadowResidual(**residual_fields(row))
            msg.header.stamp = to_stamp(max(row.time, 0.0))
            msg.header.frame_id = "bearing"
            self._residual_pub.publish(msg)
            for name, (residual, threshold, predicted) in sensor_residuals(row).items():
                vec = Vector3Stamped()
                vec.header = msg.header
                vec.vector.x, vec.vector.y, vec.vector.z = residual, threshold, predicted
                self._sensor_pubs[name].publish(vec)
        if rows and self.twin.calibration is not None and self.twin.calibration.updates != self._estimate_updates:
            e = self.twin.calibration.estimate()
            self._estimate_updates = e.updates
            est = ShadowEstimate(parameter=e.name, calibrated=e.calibrated, value=e.value, std=e.std, updates=e.updates)
            est.header.stamp = to_stamp(max(rows[-1].time, 0.0))
            self._estimate_pub.publish(est)
        if rows and rows[-1].level != self._last_level:
            self._publish_diagnostics()

    @survives_shutdown
    def _publish_diagnostics(self) -> None:
        if self.twin is None:
            return
        health = self.twin.health(self._bench_now())
        self._last_level = health.level
        counts = self.twin.counts
        values: dict[str, object] = {
            "windows": counts["windows"],
            "compared": counts["compared"],
            "inside_band": counts["inside"],
            "flagged": counts["anomalous"],
            "spindle_pulses_received": self._received["spindle"],
            "cage_pulses_received": self._received["cage"],
            "load_cell_samples_received": self._received["force"],
        }
        latest = self.twin.latest
        if latest is not None:
            values.update(residual_pct=f"{latest.residual:.4g}", band_pct=f"{latest.band:.4g}", predicted_slip_pct=f"{latest.predicted_slip:.4g}")
            values.update(
                temperature_residual_k=f"{latest.temperature_residual:.4g}",
                temperature_band_k=f"{latest.temperature_band:.4g}",
                torque_residual_nm=f"{latest.torque_residual:.4g}",
                torque_band_nm=f"{latest.torque_band:.4g}",
            )
        stamp = to_stamp(max(self._last_stamp, 0.0) if math.isfinite(self._last_stamp) else 0.0)
        status = diagnostic_status(f"{NODE_NAME}: bench against twin", int(health.level), health.message, values)
        self._diag_pub.publish(diagnostic_array(stamp, [status]))


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``shadow`` / ``bearing-rig-shadow``: spin the node until Ctrl-C. It starts
    unconfigured (``lifecycle_msgs`` services); ``--autostart`` configures and activates it.

    ROS arguments (``--ros-args -p name:=value``, ``--params-file``) set the parameters of
    ``config/shadow.yaml``.
    """
    try:
        return run_node(NODE_NAME, ShadowNode, list(sys.argv if argv is None else argv))
    except RigError as exc:
        print(f"{NODE_NAME}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
