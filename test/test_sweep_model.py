"""A sweep spec names its bearing model (``sweep.model``, docs/paper.md section 13): the paper
model with its own calibration (or none), the bench twin by default, and one-line errors for an
unknown model or a bearing file beside a named model."""

from __future__ import annotations

from pathlib import Path

import pytest

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.sweep.runner import base_parameters
from bearing_rig_sim.sweep.spec import spec_from_mapping


def spec(**head: object):
    return spec_from_mapping({"sweep": {"name": "probe", **head}, "grid": {"inner_ring_speed_rpm": [1000], "axial_load_n": [100]}}, "probe.yaml")


def test_a_spec_takes_the_paper_model_and_its_calibration() -> None:
    params = base_parameters(spec(model="paper"))
    assert params.friction_model == "paper" and params.dry and params.ball_set_resistance > 0.0
    uncalibrated = base_parameters(spec(model="paper", calibration="none"))
    assert uncalibrated.ball_set_resistance != params.ball_set_resistance  # the model file's start, not the fit


def test_the_bench_model_is_the_default() -> None:
    params = base_parameters(spec())
    assert params.friction_model == "rheology" and not params.dry


def test_an_unknown_model_or_a_bearing_file_beside_a_named_model_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"sweep.model: must be one of"):
        spec(model="adams")
    with pytest.raises(ConfigError, match=r"sweep.bearing: the paper model names its own bearing file"):
        base_parameters(spec(model="paper", bearing="bearings/h7006c.yaml"))
