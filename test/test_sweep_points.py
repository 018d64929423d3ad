"""What a worker computes for a batch of points (no cluster)."""

from __future__ import annotations

import math

import pytest

from bearing_rig_sim.config import config_path
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.sweep.points import (
    INTEGRATE,
    KIND_ROLLING_START,
    KIND_TRANSIENT,
    SweepTask,
    evaluate,
    parameters_for,
    point_key,
)


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
