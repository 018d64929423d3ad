"""The simulator's parameters: the shipped file is valid, and every bad value is refused with the
key and the allowed range; the command line's --no-realtime becomes the realtime parameter."""

from __future__ import annotations

import pytest
import yaml

from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.simulation.settings import SimulatorSettings, resolve_config_file, shipped_parameters


def shipped() -> dict:
    return dict(yaml.safe_load(config_path("simulator.yaml").read_text())["simulator"]["ros__parameters"])


def test_the_shipped_file_is_valid_and_resolves_its_files():
    s = SimulatorSettings.from_yaml()
    assert s.bearing_file == config_path("bearings", "h7006c.yaml")
    assert s.calibration_file == config_path("calibration", "h7006c_coupled.yaml")  # the named default, coupled
    assert s.lubricant_feedback  # the coupled calibration runs with the lubricant following the network
    assert s.rig_file == config_path("rig.yaml")
    assert (s.chunk_s, s.realtime, s.speeds_rate_hz, s.truth_rate_hz) == (0.001, True, 1000.0, 100.0)
    assert shipped_parameters() == shipped()


def test_a_calibration_is_named_or_a_file():
    assert SimulatorSettings.from_values(shipped() | {"calibration_file": "isothermal"}).calibration_file == config_path("calibration", "h7006c_table3.yaml")
    path = "calibration/h7006c_table3.yaml"
    assert SimulatorSettings.from_values(shipped() | {"calibration_file": path}).calibration_file == config_path("calibration", "h7006c_table3.yaml")
    with pytest.raises(ConfigError, match="calibration_file"):
        SimulatorSettings.from_values(shipped() | {"calibration_file": "warm"})


def test_integers_are_accepted_for_numbers_and_an_empty_calibration_means_none():
    values = shipped() | {"rate": 2, "calibration_file": ""}
    s = SimulatorSettings.from_values(values)
    assert s.rate == 2.0 and s.calibration_file is None


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("chunk_s", -0.001, "chunk_s: must be > 0"),
        ("rate", 0.0, "rate: must be > 0"),
        ("realtime", "yes", "realtime: must be true or false"),
        ("max_batch_chunks", 0, "max_batch_chunks: must be >= 1"),
        ("initial_speed_rad_s", 2000.0, "initial_speed_rad_s: must be <= 1047.19"),  # rig.yaml: 10 000 rpm
        ("initial_speed_rad_s", 1e4, "initial_speed_rad_s: must be <= 4000.0"),  # any bench spindle: about 38 000 rpm
        ("initial_axial_load_n", float("nan"), "initial_axial_load_n: must be finite"),
        ("model", "fast", "model: must be one of reduced, stiff"),
        ("bearing_file", "bearings/none.yaml", "bearing_file: file not found"),
        ("rig_file", "", "rig_file: must be a file name"),
        ("speeds_rate_hz", -1.0, "speeds_rate_hz: must be > 0"),
    ],
)
def test_bad_values_name_the_key_and_the_range(key, value, message):
    with pytest.raises(ConfigError, match=message.replace("(", r"\(")) as info:
        SimulatorSettings.from_values(shipped() | {key: value}, "simulator parameters")
    assert str(info.value).startswith("simulator parameters: ")


def test_unknown_and_missing_keys_are_refused():
    with pytest.raises(ConfigError, match="chunk_size: unknown key"):
        SimulatorSettings.from_values(shipped() | {"chunk_size": 0.001})
    values = shipped()
    del values["truth_rate_hz"]
    with pytest.raises(ConfigError, match="truth_rate_hz: missing"):
        SimulatorSettings.from_values(values)


def test_a_malformed_parameter_file_names_the_file(tmp_path):
    bad = tmp_path / "simulator.yaml"
    bad.write_text(yaml.safe_dump({"simulator": {"ros__parameters": shipped() | {"chunk_s": [1]}}}))
    with pytest.raises(ConfigError, match=f"{bad}: simulator.ros__parameters.chunk_s: must be a number"):
        SimulatorSettings.from_yaml(bad)


def test_file_parameters_are_relative_to_config_unless_absolute(tmp_path):
    assert resolve_config_file("rig.yaml") == config_path("rig.yaml")
    assert resolve_config_file(str(tmp_path / "x.yaml")) == tmp_path / "x.yaml"
    assert resolve_config_file("") is None


def test_no_realtime_flag_becomes_a_parameter_override():
    pytest.importorskip("rclpy")
    from bearing_rig_sim.nodes.simulator import node_arguments

    assert node_arguments(["simulator"]) == ["simulator"]
    assert node_arguments(["simulator", "--no-realtime", "--ros-args", "-p", "rate:=2.0"]) == [
        "simulator",
        "--ros-args",
        "-p",
        "rate:=2.0",
        "--ros-args",
        "-p",
        "realtime:=false",
    ]


def test_spindle_limits_come_from_the_rig_file_not_the_node_parameters(tmp_path):
    """The drive's limits are the rig's (config/rig.yaml, section spindle), so a program checked
    against the rig file is checked against what the simulator will accept."""
    import math

    from bearing_rig_sim.config import config_path

    settings = SimulatorSettings.from_yaml()
    assert settings.max_spindle_speed_rad_s == pytest.approx(10000 * 2 * math.pi / 60)
    assert settings.max_spindle_acceleration_rad_s2 == 1000.0
    rig = tmp_path / "rig.yaml"
    rig.write_text(
        config_path("rig.yaml").read_text().replace("max_speed_rad_s: 1047.1975511965977", "max_speed_rad_s: 314.159"),
        encoding="utf-8",
    )
    values = {**shipped_parameters(), "rig_file": str(rig)}
    assert SimulatorSettings.from_values(values).max_spindle_speed_rad_s == 314.159
    with pytest.raises(ConfigError, match="max_spindle_speed_rad_s: unknown key"):
        SimulatorSettings.from_values({**shipped_parameters(), "max_spindle_speed_rad_s": 1.0})
