"""The declarative parameter model: one declaration per parameter gives the YAML checks, the
one-line errors (file, key, range) and what the node declares to ROS."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, ClassVar

import pytest
import yaml

from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.load_control.settings import LoadControllerSettings
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.settings_model import (
    ConfigFile,
    Flag,
    Integer,
    NodeSettings,
    Number,
    OptionalConfigFile,
    ParameterField,
    one_of,
    param,
)
from bearing_rig_sim.shadow.settings import ShadowSettings
from bearing_rig_sim.simulation.settings import SimulatorSettings


class Toy(NodeSettings):
    NODE_NAME: ClassVar[str] = "toy"
    SHIPPED_FILE: ClassVar[str] = "toy.yaml"
    OTHER_KEYS: ClassVar[tuple[str, ...]] = ("use_sim_time",)

    rate_hz: Number = param("how often", unit="Hz", gt=0.0, le=1000.0)
    count: Integer = param("how many", unit="1", ge=1, le=10)
    gain: Number = param("how much", unit="1", ge=-1.0, lt=1.0, live=True)
    enabled: Flag = param("whether")


GOOD = {"rate_hz": 100, "count": 3, "gain": 0.5, "enabled": True}


def error_of(values: dict[str, object]) -> str:
    with pytest.raises(ConfigError) as caught:
        Toy.from_mapping(values, "config/toy.yaml", "toy.ros__parameters")
    return str(caught.value)


def test_valid_values_are_taken_in_si_and_frozen() -> None:
    toy = Toy.from_values({**GOOD, "rate_hz": "2.0e2", "use_sim_time": True})
    assert (toy.rate_hz, toy.count, toy.gain, toy.enabled) == (200.0, 3, 0.5, True)
    assert isinstance(toy.rate_hz, float)
    with pytest.raises(Exception, match="frozen"):
        toy.rate_hz = 1.0  # type: ignore[misc]  # the model is frozen: assignment is what is tested


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"rate_hz": 0}, "config/toy.yaml: toy.ros__parameters.rate_hz: must be > 0.0, got 0.0"),
        ({"rate_hz": 1000.5}, "toy.ros__parameters.rate_hz: must be <= 1000.0, got 1000.5"),
        ({"rate_hz": "fast"}, "rate_hz: must be a number, got 'fast'"),
        ({"rate_hz": True}, "rate_hz: must be a number, got True"),
        ({"rate_hz": float("inf")}, "rate_hz: must be finite, got inf"),
        ({"count": 2.5}, "count: must be an integer, got 2.5"),
        ({"count": 0}, "count: must be >= 1, got 0"),
        ({"gain": 1.0}, "gain: must be < 1.0, got 1.0"),
        ({"enabled": "yes"}, "enabled: must be true or false, got 'yes'"),
        ({"enabled": None}, "enabled: missing (required)"),
        ({"speed": 3}, "toy.ros__parameters.speed: unknown key; allowed keys: count, enabled, gain, rate_hz, use_sim_time"),
    ],
)
def test_errors_are_one_line_naming_file_key_and_range(change: dict[str, object], message: str) -> None:
    text = error_of({**GOOD, **change})
    assert message in text and "\n" not in text


def test_a_missing_key_is_named_and_the_first_problem_in_field_order_wins() -> None:
    values = dict(GOOD)
    del values["gain"]
    assert error_of(values).endswith("gain: missing (required)")
    assert error_of({**GOOD, "rate_hz": -1, "count": 99}).endswith("rate_hz: must be > 0.0, got -1.0")


def test_parameter_fields_state_the_declared_ranges() -> None:
    fields = {f.name: f for f in Toy.parameter_fields()}
    assert [f.name for f in Toy.parameter_fields()] == ["rate_hz", "count", "gain", "enabled"]
    rate = fields["rate_hz"]
    assert (rate.description, rate.unit, rate.low, rate.high, rate.low_exclusive, rate.high_exclusive) == ("how often", "Hz", 0.0, 1000.0, True, False)
    assert fields["count"].integer and not fields["rate_hz"].integer
    assert (fields["gain"].low, fields["gain"].high, fields["gain"].high_exclusive, fields["gain"].live) == (-1.0, 1.0, True, True)
    assert (fields["enabled"].low, fields["enabled"].high, fields["enabled"].live) == (None, None, False)


NODE_SETTINGS: tuple[type[NodeSettings], ...] = (LoadControllerSettings, MonitorSettings, ShadowSettings, SimulatorSettings)

DEPENDENT = {
    ("simulator", "initial_speed_rad_s"): "at most the rig file's spindle speed limit",
    ("load_controller", "axial_load_setpoint_n"): "at most the rig file's loading_chain.max_setpoint_n",
    ("shadow", "warn_after_s"): "below error_after_s",
    ("shadow", "error_after_s"): "above warn_after_s",
}
"""Bounds checked also against another value (their top may be refused for that reason)."""

RANGED = [
    (settings, field)
    for settings in NODE_SETTINGS
    for field in settings.parameter_fields()
    if field.low is not None and field.high is not None and (settings.NODE_NAME, field.name) not in DEPENDENT
]


def test_every_number_of_every_node_has_a_unit_and_a_range_at_both_ends() -> None:
    """What a ROS range can state, and the house rule for physical parameters: a unit and a
    plausible range on every number a node takes."""
    for settings in NODE_SETTINGS:
        shipped = settings.shipped_parameters()
        for field in settings.parameter_fields():
            value = shipped[field.name]
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                assert field.unit and field.numeric, (settings.NODE_NAME, field.name)
                assert field.integer == isinstance(value, int), (settings.NODE_NAME, field.name, value)
            else:
                assert not field.numeric and field.unit == "", (settings.NODE_NAME, field.name)


@pytest.mark.parametrize(("settings", "field"), RANGED, ids=lambda x: getattr(x, "name", getattr(x, "NODE_NAME", "")))
def test_file_checks_are_the_declared_ranges(settings: type[NodeSettings], field: ParameterField) -> None:
    """The range a node declares to ROS is the one its YAML is checked against: each end is
    accepted (or refused when exclusive) and a value beyond the top is refused, naming both."""
    assert field.low is not None and field.high is not None
    shipped = settings.shipped_parameters()
    cast = int if field.integer else float
    settings.from_values({**shipped, field.name: cast(field.high)})
    beyond = cast(field.high * 1.5 + 1.0)
    high = cast(field.high)
    with pytest.raises(ConfigError, match=rf"{field.name}: must be <= {high}, got {beyond}"):
        settings.from_values({**shipped, field.name: beyond})
    assert settings.check_value(field.name, beyond) == f"{field.name}: must be <= {high}, got {beyond!r}"
    if field.low_exclusive:
        with pytest.raises(ConfigError, match=rf"{field.name}: must be > {cast(field.low)}"):
            settings.from_values({**shipped, field.name: cast(field.low)})
    else:
        settings.from_values({**shipped, field.name: cast(field.low)})
        assert settings.check_value(field.name, cast(field.low)) == ""


RIG_LIMITED = [
    (LoadControllerSettings, "axial_load_setpoint_n", ("loading_chain", "max_setpoint_n")),
    (SimulatorSettings, "initial_speed_rad_s", ("spindle", "max_speed_rad_s")),
]
"""Parameters whose upper bound is a limit written in the rig file: settings, parameter, rig key."""


@pytest.mark.parametrize(("settings", "name", "rig_key"), RIG_LIMITED, ids=lambda x: x if isinstance(x, str) else "")
def test_a_limit_of_the_rig_file_is_the_bound_checked_and_declared(settings: type[NodeSettings], name: str, rig_key: tuple[str, str], tmp_path: Path) -> None:
    """The bound the node declares to ROS and the one its values are checked against are the rig
    file's value (read here with PyYAML), for the shipped rig file and for another one."""
    doc = yaml.safe_load(config_path("rig.yaml").read_text(encoding="utf-8"))
    shipped_limit = float(doc[rig_key[0]][rig_key[1]])
    doc[rig_key[0]][rig_key[1]] = shipped_limit / 2.0
    other = tmp_path / "other_rig.yaml"
    other.write_text(yaml.safe_dump(doc), encoding="utf-8")
    for rig_file, limit in ((settings.shipped_parameters()["rig_file"], shipped_limit), (str(other), shipped_limit / 2.0)):
        values = {**settings.shipped_parameters(), "rig_file": rig_file}
        field = {f.name: f for f in settings.parameter_fields(values)}[name]
        assert (field.high, field.high_exclusive) == (limit, False)
        assert f"({'.'.join(rig_key)} in " in field.constraints()
        assert getattr(settings.from_values(values | {name: limit}), name) == limit
        with pytest.raises(ConfigError, match=rf"{name}: must be <= .*the rig's limit \({'.'.join(rig_key)} in .*, got {limit * 1.01!r}"):
            settings.from_values(values | {name: limit * 1.01})
    plausible = {f.name: f for f in settings.parameter_fields()}[name]
    assert plausible.high is not None and plausible.high > shipped_limit and plausible.limit_source == ""  # without the values in force: any bench's bound


def test_load_controller_reads_the_shipped_file_and_refuses_sim_time_off(tmp_path: Path) -> None:
    settings = LoadControllerSettings.from_yaml()
    assert settings.rig_file.name == "rig.yaml" and settings.rig_file.is_file()
    bad = tmp_path / "lc.yaml"
    bad.write_text("load_controller:\n  ros__parameters:\n    use_sim_time: false\n")
    with pytest.raises(ConfigError, match=r"lc.yaml: load_controller.ros__parameters.use_sim_time: .*must be true"):
        LoadControllerSettings.from_yaml(bad)


def test_shadow_settings_bounds_that_depend_on_another_value() -> None:
    """error_after_s is checked against warn_after_s, and a negative calibration RMS is read from
    the calibration file (0.1084 pp in the shipped h7006c_table3.yaml, calibration.rms_slip_pct)."""
    shipped = ShadowSettings.shipped_parameters()
    with pytest.raises(ConfigError, match=r"error_after_s: must be > 2.0 \(warn_after_s\), got 1.5"):
        ShadowSettings.from_values({**shipped, "warn_after_s": 2.0, "error_after_s": 1.5})
    settings = ShadowSettings.from_values({**shipped, "calibration_file": "calibration/h7006c_table3.yaml", "calibration_rms_slip_pct": -1.0})
    assert settings.calibration_rms_slip_pct == pytest.approx(0.1084)
    with pytest.raises(ConfigError, match="calibration_rms_slip_pct: negative means .* no calibration file is given"):
        ShadowSettings.from_values({**shipped, "calibration_file": "", "calibration_rms_slip_pct": -1.0})
    with pytest.raises(ConfigError, match="model: must be one of reduced, stiff, got 'fast'"):
        ShadowSettings.from_values({**shipped, "model": "fast"})


class Files(NodeSettings):
    NODE_NAME: ClassVar[str] = "files"
    SHIPPED_FILE: ClassVar[str] = "files.yaml"

    data_file: ConfigFile = param("a file that must exist")
    extra_file: OptionalConfigFile = param("a file that may be ''")
    mode: Annotated[str, one_of(("fast", "slow"))] = param("a word")


def test_file_and_word_checks_are_shared(tmp_path: Path) -> None:
    """One file check and one word check for every settings class: a relative name is under
    config/, '' is None only where allowed, a missing file names where it was looked for."""
    good = Files.from_values({"data_file": "rig.yaml", "extra_file": "", "mode": "slow"})
    assert good.data_file == config_path("rig.yaml") and good.extra_file is None
    absolute = tmp_path / "x.yaml"
    absolute.write_text("{}\n")
    assert Files.from_values({"data_file": str(absolute), "extra_file": str(absolute), "mode": "fast"}).extra_file == absolute
    with pytest.raises(ConfigError, match=r"files parameters: data_file: must be a file name .*got ''"):
        Files.from_values({"data_file": "", "extra_file": "", "mode": "fast"})
    with pytest.raises(ConfigError, match=r"extra_file: file not found: 'nope.yaml' \(looked for .*config/nope.yaml\)"):
        Files.from_values({"data_file": "rig.yaml", "extra_file": "nope.yaml", "mode": "fast"})
    with pytest.raises(ConfigError, match=r"mode: must be one of fast, slow, got 'quick'"):
        Files.from_values({"data_file": "rig.yaml", "extra_file": "", "mode": "quick"})
