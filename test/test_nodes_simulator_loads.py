"""A bench that loads radially drives the simulator through the topic contract.

``/rig/bearing/axial_force`` carries the axial load in force.z and the radial load's components
in force.x and force.y (its azimuth atan2(force.y, force.x) places the load zone), a moment
across the axis in torque.x and torque.y (it frees the inner ring's tilts; none holds them and
the reaction is reported). The rig file is the authority on what the loading chain can give: a
radial force or a moment above its ``combined_loading`` limits is refused (the paper's bench,
0 N and 0 N m, loads only axially; this test's bench states 800 N and 5 N m). The simulator runs
in its own process with ``--no-realtime`` on the test's isolated ROS domain; every wait is for a
message, bounded.

Expected values: under a pure axial load every ball carries the same load and the cage stays on
the axis (the bearing is axisymmetric); under F_a = 163 N, F_r = 500 N (F_a = 1.216 F_r tan a
with a = 15 deg: the half-loaded ring) the largest ball load is Stribeck/Sjovall's
Q_max = 4.37 F_r / (Z cos a) (Harris and Kotzalas vol. 1, ch. 7), 141.4 N for the H7006C's 16
balls, and the balls' pocket forces push the cage off the axis. The radial force here is
(300, 400) N: 500 N at atan2(400, 300) = 53.130 deg. With the tilts held the reaction moment is
that of the contact lines through the pressure centre, R_i tan a0 from the plane of the inner
groove's curvature centres (Harris and Kotzalas, vol. 1, ch. 1): F_r R_i tan a0 = 2.86 N m, about
the axis across the load (torque 2.86 (sin phi, -cos phi) for the load pushing the ring along +z).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
import yaml

pytestmark = pytest.mark.ros
rclpy = pytest.importorskip("rclpy")

from bearing_rig_msgs.msg import SimulatorTruth  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402

from bearing_rig_sim.config import config_path  # noqa: E402
from bearing_rig_sim.nodes.common import RELIABLE_QOS, RELIABLE_STREAM_QOS, from_stamp  # noqa: E402
from conftest import bearing_section  # noqa: E402

WAIT = 60.0
"""Longest wait for any one condition, wall s (node start-up takes a few seconds)."""

FORCE_TOPIC = "/rig/bearing/axial_force"
AXIAL_N = 163.0
RADIAL_X_N, RADIAL_Y_N = 300.0, 400.0
RADIAL_N = 500.0
"""|(300, 400)| N."""
RADIAL_LIMIT_N = 800.0
"""The test bench's radial loading chain: ``combined_loading.max_radial_setpoint_n``."""
MOMENT_LIMIT_N_M = 5.0
"""The test bench's moment limit: ``combined_loading.max_moment_setpoint_n_m``."""
TRUTH_PERIOD_S = 0.01
"""/rig/truth every 10 ms simulated (``truth_rate_hz`` 100 in config/simulator.yaml)."""


def stribeck_max_ball_load(radial: float) -> float:
    """Q_max = 4.37 F_r / (Z cos a), N, for the shipped bearing's ball count and contact angle."""
    g = bearing_section("geometry")
    return 4.37 * radial / (g["ball_count"] * math.cos(math.radians(g["contact_angle_deg"])))


ZONE_MODEL_REL = 0.03
"""Stribeck's 4.37 against the twin's contacts: the factor is the continuous load integral's
J_r(1/2) for a fixed contact angle; the twin's angles open under load (3 %, as for the equilibrium)."""


def heaviest_ball_band(radial: float) -> tuple[float, float]:
    """Where the load distribution puts the heaviest ball's load at any cage position, N (low, high).

    Q_max is the load of a ball on the load line. As the balls pass, the heaviest is at most half
    a ball spacing (pi/Z) off it (checked by :func:`check_per_ball_equilibrium`) and carries
    Q(psi) = Q_max [1 - (1 - cos psi) / (2 eps)]^1.5 = Q_max cos^1.5(psi) with eps = 1/2 (Harris
    and Kotzalas vol. 1, ch. 7): between Q_max cos^1.5(pi/Z) (0.971 Q_max for 16 balls, two balls
    astride the line) and Q_max, each widened by :data:`ZONE_MODEL_REL`. The balls pass the load line
    at Z times the cage speed, 16 x 0.5 (1 - D cos a / d_m) x 15 Hz = 103 Hz at 900 rpm without
    slip: the truth, every 10 ms, sees nearly the same ball positions for tenths of a second, so a
    run can see the balls astride the line throughout."""
    q_max = stribeck_max_ball_load(radial)
    astride = math.cos(math.pi / bearing_section("geometry")["ball_count"]) ** 1.5
    return q_max * astride * (1.0 - ZONE_MODEL_REL), q_max * (1.0 + ZONE_MODEL_REL)


class Bench:
    """A test node: publishes the force on the bearing, records truth and diagnostics."""

    def __init__(self, ros_graph: Any) -> None:
        self.graph = ros_graph
        self.node = ros_graph.node("radial_bench")
        self.executor = ros_graph.executor([self.node])
        self.truth: list[SimulatorTruth] = []
        self.diagnostics: list[DiagnosticStatus] = []
        # reliable, as the session's recorder reads it: the simulator waits for its acknowledgements
        self.node.create_subscription(SimulatorTruth, "/rig/truth", self.truth.append, RELIABLE_STREAM_QOS)
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diagnostics, RELIABLE_QOS)
        self.force = self.node.create_publisher(WrenchStamped, FORCE_TOPIC, RELIABLE_QOS)

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        self.diagnostics += [s for s in msg.status if s.name.startswith("simulator")]

    def wait(self, condition: Any, what: str) -> None:
        assert self.graph.spin_until(condition, WAIT, executor=self.executor), f"timed out waiting for {what}"

    def time(self) -> float:
        return from_stamp(self.truth[-1].header.stamp) if self.truth else -1.0

    def send(self, z: float, x: float = 0.0, y: float = 0.0, torque: tuple[float, float] = (0.0, 0.0)) -> None:
        self.wait(lambda: self.force.get_subscription_count() > 0, "the simulator's force subscription")
        msg = WrenchStamped()
        msg.header.frame_id = "bearing"
        msg.wrench.force.z, msg.wrench.force.x, msg.wrench.force.y = z, x, y
        msg.wrench.torque.x, msg.wrench.torque.y = torque
        self.force.publish(msg)

    def status_with(self, level: bytes, text: str) -> bool:
        return any(d.level == level and text in d.message for d in self.diagnostics)

    def pair(self, key: str) -> tuple[float, float]:
        """The latest report's two-number value of ``key`` ((nan, nan) before any)."""
        text = self.value(key).split()
        return (float(text[0]), float(text[1])) if len(text) == 2 else (math.nan, math.nan)

    def value(self, key: str) -> str:
        """The latest report's value of ``key`` ('' before any)."""
        for status in reversed(self.diagnostics):
            for kv in status.values:
                if kv.key == key:
                    return str(kv.value)
        return ""


def hand_reaction_moment(radial: float) -> float:
    """F_r R_i tan a0, N m, R_i = d_m/2 + (f_i - 1/2) D_w cos a0 for the shipped bearing."""
    g = bearing_section("geometry")
    a0 = math.radians(g["contact_angle_deg"])
    r_i = 0.5 * g["pitch_diameter_m"] + (g["inner_groove_curvature_ratio"] - 0.5) * g["ball_diameter_m"] * math.cos(a0)
    return radial * r_i * math.tan(a0)


def check_per_ball_equilibrium(truth: SimulatorTruth, radial: tuple[float, float]) -> None:
    """The per-ball truth balances the loads on the inner ring (its quasi-static equilibrium,
    Harris and Kotzalas vol. 1, ch. 7: sum Q sin a = F_a, sum Q cos a (cos psi, sin psi) = F_r's
    components, with centrifugal and ring-inertia terms negligible at 900 rpm), and the most
    loaded ball sits under the radial load, within half a ball spacing of its azimuth."""
    g = bearing_section("geometry")
    z = g["ball_count"]
    q = list(truth.ball_inner_contact_load)
    a = list(truth.ball_inner_contact_angle)
    psi = list(truth.ball_azimuth)
    assert len(q) == len(a) == len(psi) == len(truth.ball_outer_contact_load) == len(truth.ball_pocket_load) == z
    assert all(0.0 <= p < 2.0 * math.pi for p in psi)
    assert min(q) >= 0.0
    axial = sum(qj * math.sin(aj) for qj, aj in zip(q, a, strict=True))
    fx = sum(qj * math.cos(aj) * math.cos(pj) for qj, aj, pj in zip(q, a, psi, strict=True))
    fy = sum(qj * math.cos(aj) * math.sin(pj) for qj, aj, pj in zip(q, a, psi, strict=True))
    assert axial == pytest.approx(truth.axial_load, rel=0.02)
    magnitude = math.hypot(*radial)
    assert fx == pytest.approx(radial[0], abs=0.03 * magnitude)
    assert fy == pytest.approx(radial[1], abs=0.03 * magnitude)
    heaviest = psi[q.index(max(q))]
    off = abs(math.remainder(heaviest - math.atan2(radial[1], radial[0]), 2.0 * math.pi))
    assert off <= math.pi / z + 1e-9
    assert max(q) == pytest.approx(truth.inner_contact_load_max, rel=1e-12)
    assert math.hypot(truth.cage_centre_x, truth.cage_centre_y) * 1e6 == pytest.approx(truth.cage_whirl_radius_um, rel=1e-9)


def radial_rig_file(directory: Path) -> Path:
    """The shipped rig file with a radial loading chain of :data:`RADIAL_LIMIT_N` and
    :data:`MOMENT_LIMIT_N_M`."""
    doc = yaml.safe_load(config_path("rig.yaml").read_text())
    doc["combined_loading"]["max_radial_setpoint_n"] = RADIAL_LIMIT_N
    doc["combined_loading"]["max_moment_setpoint_n_m"] = MOMENT_LIMIT_N_M
    path = directory / "rig.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def test_radial_force_on_the_topic_loads_the_twin_within_the_rig_files_limit(ros_graph, tmp_path):
    rig_file = radial_rig_file(tmp_path)
    parameters = {"initial_speed_rad_s": repr(900 * math.pi / 30), "rig_file": str(rig_file)}
    overrides = [arg for key, value in parameters.items() for arg in ("-p", f"{key}:={value}")]
    process = ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime", "--ros-args", *overrides)
    bench = Bench(ros_graph)
    bench.wait(lambda: bench.time() > 0.05, "the simulator")

    # axial only: every ball loaded alike, the cage on the axis
    bench.send(AXIAL_N, 0.0)
    bench.wait(lambda: bench.truth[-1].axial_load == AXIAL_N, "the axial load of 163 N")
    start = len(bench.truth) - 1
    applied = bench.time()
    bench.wait(lambda: bench.time() > applied + 0.2, "0.2 s simulated under the axial load")
    axial_only = bench.truth[start:]
    assert all(t.cage_whirl_radius_um == 0.0 for t in axial_only)
    assert all(t.inner_contact_load_max == pytest.approx(t.inner_contact_load_mean, rel=1e-9) for t in axial_only)

    # (300, 400) N: a load zone (Stribeck's Q_max) at 53.13 deg and the cage pushed off the axis
    bench.send(AXIAL_N, RADIAL_X_N, RADIAL_Y_N)
    bench.wait(lambda: bench.truth[-1].cage_whirl_radius_um > 1.0, "the cage off the axis under the radial load")
    loaded = bench.time()
    bench.wait(lambda: bench.time() > loaded + 0.1, "0.1 s simulated under the radial load")
    last = bench.truth[-1]
    assert last.axial_load == AXIAL_N
    band_low, band_high = heaviest_ball_band(RADIAL_N)
    assert band_low <= last.inner_contact_load_max <= band_high, last.inner_contact_load_max
    assert last.inner_contact_load_max > 2.0 * last.inner_contact_load_mean  # balls outside the zone unloaded
    check_per_ball_equilibrium(last, (RADIAL_X_N, RADIAL_Y_N))
    bench.wait(lambda: bench.value("radial_load_n") == "500", "the radial load in the report")
    assert float(bench.value("radial_load_azimuth_deg")) == pytest.approx(math.degrees(math.atan2(RADIAL_Y_N, RADIAL_X_N)), abs=1e-3)

    # no moment: the tilts held and the reaction moment reported, across the load direction
    phi = math.atan2(RADIAL_Y_N, RADIAL_X_N)
    reaction = hand_reaction_moment(RADIAL_N)
    assert bench.value("moment_n_m") == "0 0"
    held = bench.pair("ring_moment_n_m")
    assert held == pytest.approx((reaction * math.sin(phi), -reaction * math.cos(phi)), abs=0.03 * reaction)

    # a moment within the rig file's limit frees the tilts: the balls' moment on the ring balances it
    torque = (2.0, -1.5)
    bench.send(AXIAL_N, RADIAL_X_N, RADIAL_Y_N, torque)
    bench.wait(lambda: bench.value("moment_n_m") == "2 -1.5", "the moment in the report")
    bench.wait(lambda: bench.pair("ring_moment_n_m") == pytest.approx(torque, abs=1e-3), "the ring balancing the moment")
    assert process.poll() is None
    assert bench.truth[-1].cage_whirl_radius_um > 1.0  # the radial load still applied

    # a moment above the rig file's limit is refused naming it; the moment in force is kept
    bench.send(AXIAL_N, RADIAL_X_N, RADIAL_Y_N, (6.0, 0.0))
    moment_refusal = (
        f"moment refused: moment: 6 N m is above the rig's limit of {MOMENT_LIMIT_N_M:g} N m (combined_loading.max_moment_setpoint_n_m in rig.yaml)"
    )
    bench.wait(lambda: bench.status_with(DiagnosticStatus.ERROR, moment_refusal), "ERROR for 6 N m above the 5 N m limit")
    assert bench.value("moment_n_m") == "2 -1.5"

    # the moment released: the tilts held again, the reaction as before
    bench.send(AXIAL_N, RADIAL_X_N, RADIAL_Y_N)
    bench.wait(lambda: bench.pair("ring_moment_n_m") == pytest.approx(held, abs=0.01 * reaction), "the held reaction again")
    q_max = stribeck_max_ball_load(RADIAL_N)

    def settled() -> bool:  # the balls' transient after the release over: 0.1 s simulated at Stribeck's Q_max
        recent = bench.truth[-round(0.1 / TRUTH_PERIOD_S) :]
        return len(recent) > 1 and all(band_low <= t.inner_contact_load_max <= band_high for t in recent)

    bench.wait(settled, "Stribeck's Q_max held for 0.1 s after the moment's release")

    # above the rig file's radial limit: refused naming the limit and the value, the node stays
    # up and keeps the last accepted loads (axial and radial), and the truth goes on unbroken
    bench.send(250.0, 900.0, 0.0)
    refusal = f"radial force refused: radial force: 900 N is above the rig's limit of {RADIAL_LIMIT_N:g} N (combined_loading.max_radial_setpoint_n in rig.yaml)"
    bench.wait(lambda: bench.status_with(DiagnosticStatus.ERROR, refusal), "ERROR for 900 N above the 800 N limit")
    refused = bench.time()
    bench.wait(lambda: bench.time() > refused + 0.05, "the simulation going on after the refusal")
    assert process.poll() is None
    after = [t for t in bench.truth if from_stamp(t.header.stamp) > refused]
    assert all(t.axial_load == AXIAL_N for t in after)
    loads = [t.inner_contact_load_max for t in after]
    assert all(band_low <= q <= band_high for q in loads), (min(loads), max(loads), q_max)
    assert bench.value("radial_load_n") == "500"
    stamps = [from_stamp(t.header.stamp) for t in bench.truth]
    assert all(b - a == pytest.approx(TRUTH_PERIOD_S, abs=1e-6) for a, b in zip(stamps, stamps[1:], strict=False))

    # a non-finite radial component is refused like a non-finite axial force
    bench.send(AXIAL_N, math.nan)
    bench.wait(
        lambda: bench.status_with(DiagnosticStatus.ERROR, "radial force refused: radial force: force.x must be a finite number"), "ERROR for NaN force.x"
    )
    assert process.poll() is None
