"""What a worker computes for a batch of points (no cluster)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from bearing_rig_sim.config import config_path
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.sweep.points import (
    INTEGRATE,
    KIND_CONTINUATION,
    KIND_ROLLING_START,
    KIND_TRANSIENT,
    SweepTask,
    evaluate,
    parameters_for,
    point_key,
)
from bearing_rig_sim.sweep.runner import base_parameters, plan_tasks
from bearing_rig_sim.sweep.spec import load_spec


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.from_yaml(None, config_path("calibration", "h7006c_table3.yaml"))


def task(params: BearingParameters, kind: str, points: list[dict[str, float]], **kw: object) -> SweepTask:
    keys = tuple(point_key(p, kind) for p in points)
    return SweepTask("t", kind, params, tuple(points), keys, frozenset(keys), **kw)  # type: ignore[arg-type]


def test_point_keys_depend_on_values_and_branch_not_on_order() -> None:
    a = point_key({"inner_ring_speed_rpm": 1000.0, "axial_load_n": 100.0}, "rolling_start")
    assert a == point_key({"axial_load_n": 100.0, "inner_ring_speed_rpm": 1000.0}, "rolling_start")
    assert a != point_key({"inner_ring_speed_rpm": 1000.0, "axial_load_n": 110.0}, "rolling_start")
    assert a != point_key({"inner_ring_speed_rpm": 1000.0, "axial_load_n": 100.0}, "continuation")


def test_parameter_axes_set_their_bearing_field(params: BearingParameters) -> None:
    changed = parameters_for(params, {"inner_ring_speed_rpm": 1000.0, "axial_load_n": 100.0, "ball_drag_scale": 7.0, "oil_viscosity_pa_s": 0.05})
    assert changed.ball_drag_scale == 7.0 and changed.oil_viscosity == 0.05
    assert changed.cage_land_viscous_scale == params.cage_land_viscous_scale
    grease = parameters_for(params, {"inner_ring_speed_rpm": 1000.0, "axial_load_n": 100.0, "yield_stress_pa": 321.0})
    assert grease.lubricant is not None and grease.lubricant.yield_stress == 321.0


def test_more_ball_drag_means_more_slip_at_the_same_point(params: BearingParameters) -> None:
    """A resistance to the balls' orbit holds the cage back: slip grows with the drag scale."""
    base = params.ball_drag_scale
    points = [{"inner_ring_speed_rpm": 2700.0, "axial_load_n": 100.0, "ball_drag_scale": base * f} for f in (0.5, 1.0, 1.5)]
    rows = evaluate(task(params, KIND_ROLLING_START, points))
    slips = [r["slip_pct"] for r in rows]
    assert all(r["error"] == "" for r in rows)
    assert slips[0] < slips[1] < slips[2]


def test_heat_under_a_radial_load_exceeds_the_axial_only_heat_and_grows_with_it(params: BearingParameters) -> None:
    """900 rpm, 163 N axial, radial loads 0, 250 and 500 N (163 N = 1.216 x 500 N x tan 15 deg:
    at 500 N Stribeck's half-loaded ring, the loaded balls carrying up to 141 N against 35 N
    each under the axial load alone): more contact load and a cage pushed into its land
    dissipate more, so the power (the friction torque times the speed, at the same axial load)
    rises with the radial load. The radial points are periodic steady states, averaged over
    whole ball-pass periods; the axial one is the direct solve's."""
    points = [{"inner_ring_speed_rpm": 900.0, "axial_load_n": 163.0, "radial_load_n": f} for f in (0.0, 250.0, 500.0)]
    rows = evaluate(task(params, KIND_ROLLING_START, points))
    assert all(r["error"] == "" for r in rows)
    assert [r["method"] for r in rows] == ["newton", "integration-periodic", "integration-periodic"]
    power = [r["power_w"] for r in rows]
    assert power[0] < power[1] < power[2]
    # the load distribution: at 500 N Stribeck/Sjovall's half-loaded ring, Q_max = 4.37 F_r /
    # (Z cos 15 deg) = 141.4 N within 3 %, 7 to 9 of the 16 balls loaded (the two at 90 deg
    # from the load on the zone's edge); under the axial load alone every ball alike
    assert rows[2]["ball_load_max_n"] == pytest.approx(4.37 * 500.0 / (16 * math.cos(math.radians(15.0))), rel=0.03)
    assert 7 <= rows[2]["loaded_balls"] <= 9 and rows[0]["loaded_balls"] == 16
    assert all(r["torque_n_m"] * 900.0 * math.pi / 30.0 == pytest.approx(r["power_w"], rel=1e-9) for r in rows)


def test_combined_load_rows_are_not_followed_by_continuation(tmp_path: Path) -> None:
    """A continuation row starts each load from the previous steady state of the four-number
    solve: only the axial points of a spec with a radial-load axis are followed."""
    text = "sweep: {name: t, continuation: true}\ngrid: {inner_ring_speed_rpm: [900], axial_load_n: [100, 200], radial_load_n: [0, 300]}\n"
    path = tmp_path / "spec.yaml"
    path.write_text(text, encoding="utf-8")
    spec = load_spec(path)
    tasks = plan_tasks(spec, base_parameters(spec), set())
    followed = [p for t in tasks if t.kind == KIND_CONTINUATION for p in t.points]
    assert len(followed) == 2 and all(p["radial_load_n"] == 0.0 for p in followed)
    assert sum(len(t.points) for t in tasks if t.kind == KIND_ROLLING_START) == 4


def test_integrate_method_rows_say_how_they_were_computed(params: BearingParameters) -> None:
    rows = evaluate(task(params, KIND_ROLLING_START, [{"inner_ring_speed_rpm": 1000.0, "axial_load_n": 100.0}], method=INTEGRATE))
    assert rows[0]["method"] == "integration" and rows[0]["branch"] == "rolling_start"


def test_a_transient_point_runs_up_from_rest(params: BearingParameters) -> None:
    """80 rad/s^2 for 0.5 s in 0.02 s windows: the last window's mean speed is the speed at its
    centre, 80 x 0.49 = 39.2 rad/s = 374.33 rpm, within one time step's speed change (the
    engine's running mean samples each 40 us step at its end: +80 x 20 us)."""
    rows = evaluate(task(params, KIND_TRANSIENT, [{"inner_ring_acceleration_rad_s2": 80.0, "axial_load_n": 200.0}], transient_duration=0.5))
    row = rows[0]
    assert row["error"] == ""
    to_rpm = 60.0 / (2.0 * math.pi)
    assert row["rpm"] == pytest.approx(39.2 * to_rpm, abs=80.0 * params.reduced_time_step * to_rpm)
    assert row["peak_slip_pct"] >= row["slip_pct"]
    assert math.isnan(row["time_to_stable_s"]) == (not row["stable"])


def test_a_point_that_cannot_be_computed_is_a_row_with_its_error(params: BearingParameters) -> None:
    rows = evaluate(task(params, KIND_ROLLING_START, [{"inner_ring_speed_rpm": 1000.0, "axial_load_n": 100.0, "pocket_diameter_m": 0.001}]))
    assert rows[0]["error"] and math.isnan(rows[0]["slip_pct"])


def test_a_run_up_under_a_radial_load_runs_to_its_end_with_stribecks_largest_ball_load(params: BearingParameters) -> None:
    """A run-up from rest at 80 rad/s^2 for 0.5 s under F_r = 500 N and
    F_a = 1.216 F_r tan 15 deg = 163 N (tilt held): it runs to its end (the last window's mean
    speed 80 x 0.49 = 39.2 rad/s, as the axial run-up's) and the largest ball load at its end,
    374 rpm (centrifugal force 0.005 N), is Stribeck/Sjovall's half-loaded ring,
    Q_max = 4.37 F_r / (Z cos 15 deg) = 141.4 N, within 3 %."""
    point = {"inner_ring_acceleration_rad_s2": 80.0, "axial_load_n": 163.0, "radial_load_n": 500.0}
    row = evaluate(task(params, KIND_TRANSIENT, [point], transient_duration=0.5))[0]
    assert row["error"] == ""
    to_rpm = 60.0 / (2.0 * math.pi)
    assert row["rpm"] == pytest.approx(39.2 * to_rpm, abs=80.0 * params.reduced_time_step * to_rpm)
    assert row["branch"] == "transient" and row["method"] == "integration"
    assert row["peak_slip_pct"] >= row["slip_pct"] and math.isfinite(row["slip_pct"])
    assert row["ball_load_max_n"] == pytest.approx(4.37 * 500.0 / (16 * math.cos(math.radians(15.0))), rel=0.03)
    assert row["radial_load_n"] == 500.0


def test_a_combined_load_row_carries_the_cage_whirl(params: BearingParameters) -> None:
    """The steady row under 163 N axial and 500 N radial at 900 rpm has the cage centre held
    off the axis within its 100 um clearance and no whirl frequency, with the reason (the load
    zone is fixed in space: docs/model.md, Cage whirl); an axial row has none of these."""
    points = [{"inner_ring_speed_rpm": 900.0, "axial_load_n": 163.0, "radial_load_n": f} for f in (0.0, 500.0)]
    rows = evaluate(task(params, KIND_ROLLING_START, points))
    assert all(r["error"] == "" for r in rows)
    assert math.isnan(rows[0]["cage_whirl_radius_um"]) and rows[0]["cage_whirl_reason"] == ""
    assert 50.0 < rows[1]["cage_whirl_radius_um"] < 100.0
    assert math.isnan(rows[1]["cage_whirl_frequency_hz"]) and math.isnan(rows[1]["cage_whirl_ratio"])
    assert "no orbit" in rows[1]["cage_whirl_reason"]
