"""Contracts of the dynamics engine: inputs, determinism, snapshots, configuration errors."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters, DynamicsInputError

RPM = 2.0 * math.pi / 60.0


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.calibrated()


@pytest.mark.parametrize(
    "call",
    [
        lambda e: e.advance(0.01, axial_load=float("nan")),
        lambda e: e.advance(0.01, axial_load=-10.0),
        lambda e: e.advance(float("inf")),
        lambda e: e.advance(-0.1),
        lambda e: e.advance(0.01, inner_ring_acceleration=float("nan")),
        lambda e: e.initialise(float("nan"), 100.0),
        lambda e: e.initialise(-1.0, 100.0),
        lambda e: e.set_inner_ring_speed(float("inf")),
    ],
)
def test_bad_inputs_are_refused_with_a_named_reason(params: BearingParameters, call) -> None:
    engine = BearingDynamics(params)
    engine.initialise(900 * RPM, 100.0)
    before = engine.snapshot()
    with pytest.raises(DynamicsInputError) as err:
        call(engine)
    assert any(word in str(err.value) for word in ("axial_load", "duration", "acceleration", "speed"))
    np.testing.assert_array_equal(engine.ball, before.ball)  # state untouched


def test_unknown_model_and_strip_segment_are_refused(params: BearingParameters) -> None:
    with pytest.raises(DynamicsInputError, match="model"):
        BearingDynamics(params, model="rigid")
    with pytest.raises(DynamicsInputError, match="strip_segment"):
        BearingDynamics(params, strip_segment=params.ball_count)


def test_same_inputs_give_bitwise_identical_results(params: BearingParameters) -> None:
    runs = []
    for _ in range(2):
        e = BearingDynamics(params)
        e.initialise(2700 * RPM, 100.0)
        e.advance(0.05, inner_ring_acceleration=40.0)
        e.advance(0.05, axial_load=250.0)
        runs.append((e.ball.copy(), e.cage.copy(), e.ring.copy()))
    for a, b in zip(*runs):
        np.testing.assert_array_equal(a, b)


def test_snapshot_and_restore_replay_the_same_future(params: BearingParameters) -> None:
    e = BearingDynamics(params)
    e.initialise(1500 * RPM, 100.0)
    e.advance(0.02)
    snap = e.snapshot()
    first = e.advance(0.03, axial_load=300.0)
    state = e.cage.copy()
    e.restore(snap)
    assert e.time == pytest.approx(snap.ring[4])
    second = e.advance(0.03, axial_load=300.0)
    assert first == second
    np.testing.assert_array_equal(e.cage, state)
    other = BearingDynamics(params, model="stiff")
    with pytest.raises(DynamicsInputError):
        other.restore(snap)


def test_constant_acceleration_moves_the_inner_ring_by_alpha_t(params: BearingParameters) -> None:
    e = BearingDynamics(params)
    e.initialise(100.0, 200.0)
    e.advance(0.5, inner_ring_acceleration=20.0)
    assert e.inner_ring_speed == pytest.approx(110.0, rel=1e-9)
    e.advance(10.0, inner_ring_acceleration=-50.0)  # braking stops at zero, never reverses
    assert 0.0 <= e.inner_ring_speed < 50.0 * e.time_step + 1e-9


def test_ehl_traction_option_runs_and_slips_less_with_more_load(params: BearingParameters) -> None:
    ehl = params.replace(friction_model="ehl_traction", reduced_time_step=2e-5)  # below its step limit (dynamics/step_limit.py)
    slips = []
    for load in (100.0, 700.0):
        e = BearingDynamics(ehl)
        e.initialise(3000 * RPM, load)
        e.advance(0.1)
        avg = e.advance(0.05)
        slips.append(1.0 - avg.cage_speed / (avg.inner_ring_speed * ehl.epicyclic_ratio))
    assert np.all(np.isfinite(slips)) and slips[1] < slips[0]


def _write_bearing(tmp_path: Path, edit) -> Path:
    doc = yaml.safe_load(config_path("bearings", "h7006c.yaml").read_text())
    edit(doc)
    path = tmp_path / "bearing.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


@pytest.mark.parametrize(
    "edit,key",
    [
        (lambda d: d["geometry"].update(ball_diameter_m=-0.0063), "geometry.ball_diameter_m"),
        (lambda d: d["geometry"].update(ball_count=2), "geometry.ball_count"),
        (lambda d: d["geometry"].pop("pitch_diameter_m"), "geometry.pitch_diameter_m"),
        (lambda d: d["friction"].update(model="dry"), "friction.model"),
        (lambda d: d["cage"].update(pocket_diameter_m=0.006), "cage.pocket_diameter_m"),
        (lambda d: d["materials"]["ball"].update(youngs_modulus_pa="steel"), "materials.ball.youngs_modulus_pa"),
    ],
)
def test_malformed_bearing_file_names_file_and_key(tmp_path: Path, edit, key: str) -> None:
    path = _write_bearing(tmp_path, edit)
    with pytest.raises(ConfigError) as err:
        BearingParameters.from_yaml(path)
    assert str(path) in str(err.value) and key in str(err.value)


def test_calibration_file_may_only_set_calibratable_parameters(tmp_path: Path) -> None:
    bad = tmp_path / "cal.yaml"
    bad.write_text("calibration: {}\nparameters:\n  geometry.ball_count: 12\n")
    with pytest.raises(ConfigError, match="geometry.ball_count"):
        BearingParameters.from_yaml(None, bad)
    good = tmp_path / "ok.yaml"
    good.write_text("calibration: {}\nparameters:\n  resistances.ball_drag_scale: 7.0\n")
    assert BearingParameters.from_yaml(None, good).ball_drag_scale == 7.0
