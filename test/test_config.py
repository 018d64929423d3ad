"""Validated configuration: every error names the file, the key and what was allowed."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import pytest

from pydantic import Field, create_model

from bearing_rig_sim.config import ConfigError, check_number, config_path, rad_s_to_rpm, read_mapping, ros_parameters, rpm_to_rad_s
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.settings_model import FileSection, Flag, Integer, Number, Text, one_of, quantity, validate_mapping


def write(tmp_path: Path, text: str, name: str = "rig.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def error_of(call, *args, **kwargs) -> ConfigError:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError) as info:
        call(*args, **kwargs)
    return info.value


# -- documents -------------------------------------------------------------------------------
def test_malformed_yaml_names_file_and_line(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry:\n  ball_diameter_m: 0.0063\n  pitch: [1, 2\n")
    err = error_of(read_mapping, path)
    assert err.source == str(path)
    assert err.key == ""
    message = str(err)
    assert message.startswith(f"{path}: not valid YAML at line ")
    assert "line 4" in message or "line 3" in message


def test_top_level_must_be_a_mapping(tmp_path: Path) -> None:
    path = write(tmp_path, "- 1\n- 2\n")
    assert str(error_of(read_mapping, path)) == f"{path}: top level must be a mapping, got list"


def test_empty_file_is_not_a_mapping(tmp_path: Path) -> None:
    path = write(tmp_path, "")
    assert str(error_of(read_mapping, path)) == f"{path}: top level must be a mapping, got NoneType"


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "absent.yaml"
    err = error_of(read_mapping, path)
    assert str(err).startswith(f"{path}: cannot read file")


def test_config_error_is_a_rig_error_and_a_value_error() -> None:
    err = ConfigError("a.yaml", "x.y", "must be > 0, got -1")
    assert isinstance(err, RigError) and isinstance(err, ValueError)
    assert (err.source, err.key, err.problem) == ("a.yaml", "x.y", "must be > 0, got -1")
    assert str(err) == "a.yaml: x.y: must be > 0, got -1"


# -- keys and values, through the declarative model ----------------------------------------------
class Geometry(FileSection):
    ball_diameter_m: Number = quantity("ball diameter", unit="m", source="test", gt=0)
    pitch_diameter_m: Number = quantity("pitch diameter", unit="m", source="test", gt=0, default=0.04)


class Bearing(FileSection):
    geometry: Geometry


def read(model: type[FileSection], path: Path) -> FileSection:
    return validate_mapping(model, read_mapping(path), str(path))


def test_missing_key_names_the_dotted_path(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry:\n  pitch_diameter_m: 0.0405\n")
    assert str(error_of(read, Bearing, path)) == f"{path}: geometry.ball_diameter_m: missing (required)"


def test_null_value_counts_as_missing_unless_defaulted(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry:\n  ball_diameter_m: ~\n  pitch_diameter_m: ~\n")
    assert str(error_of(read, Bearing, path)) == f"{path}: geometry.ball_diameter_m: missing (required)"
    path = write(tmp_path, "geometry:\n  ball_diameter_m: 0.0063\n  pitch_diameter_m: ~\n")
    assert read(Bearing, path) == Bearing(geometry=Geometry(ball_diameter_m=0.0063, pitch_diameter_m=0.04))


def test_out_of_range_names_file_key_and_bound(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry:\n  ball_diameter_m: -0.0063\n")
    assert str(error_of(read, Bearing, path)) == f"{path}: geometry.ball_diameter_m: must be > 0.0, got -0.0063"


@pytest.mark.parametrize(
    ("bounds", "value", "expected"),
    [
        ({"ge": 0.0}, -1.5, "must be >= 0.0, got -1.5"),
        ({"lt": 1.0}, 1.0, "must be < 1.0, got 1.0"),
        ({"le": 9000.0}, 9000.5, "must be <= 9000.0, got 9000.5"),
        ({"gt": 0.0, "le": 1.0}, 0.0, "must be > 0.0, got 0.0"),
    ],
)
def test_each_bound_is_enforced_and_reported(tmp_path: Path, bounds: dict, value: float, expected: str) -> None:
    limited = create_model("Limited", __base__=FileSection, value=(Number, quantity("a value", unit="1", source="test", **bounds)))
    path = write(tmp_path, f"limits:\n  value: {value}\n")
    assert str(error_of(validate_mapping, limited, read_mapping(path)["limits"], str(path), "limits")) == f"{path}: limits.value: {expected}"


def test_value_on_an_inclusive_bound_is_accepted() -> None:
    class Both(FileSection):
        a: Number = quantity("a", unit="1", source="test", ge=0)
        b: Number = quantity("b", unit="1", source="test", le=9000)

    assert validate_mapping(Both, {"a": 0, "b": 9000}, "test") == Both(a=0.0, b=9000.0)


class Load(FileSection):
    axial_load_n: Number = quantity("axial load", unit="N", source="test", ge=0)


@pytest.mark.parametrize("text", [".nan", ".NaN", ".inf", "-.inf"])
def test_non_finite_numbers_are_refused(tmp_path: Path, text: str) -> None:
    path = write(tmp_path, f"axial_load_n: {text}\n")
    err = error_of(read, Load, path)
    assert err.key == "axial_load_n"
    assert str(err).startswith(f"{path}: axial_load_n: must be finite, got ")


def test_nan_passed_directly_is_refused() -> None:
    err = error_of(check_number, math.nan, "cli", "--axial-load")
    assert str(err) == "cli: --axial-load: must be finite, got nan"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('"fast"', "axial_load_n: must be a number, got 'fast'"),
        ("true", "axial_load_n: must be a number, got True"),
        ("[1, 2]", "axial_load_n: must be a number, got [1, 2]"),
        # a mapping is a quantity written with its stated range (settings_model.StatedQuantity)
        ("{a: 1}", "axial_load_n.a: unknown key; allowed keys: range, source, unit, value"),
    ],
)
def test_wrong_type_for_a_number(tmp_path: Path, text: str, expected: str) -> None:
    path = write(tmp_path, f"axial_load_n: {text}\n")
    assert str(error_of(read, Load, path)) == f"{path}: {expected}"


def test_unsigned_exponent_reads_as_a_number(tmp_path: Path) -> None:
    # YAML 1.1 (PyYAML) reads "2.1e11" as a string; the model reads it as YAML 1.2 does.
    path = write(tmp_path, "axial_load_n: 2.1e11\n")
    assert read_mapping(path)["axial_load_n"] == "2.1e11"
    assert read(Load, path) == Load(axial_load_n=2.1e11)


def test_integer_flag_text_and_choice(tmp_path: Path) -> None:
    class Kinds(FileSection):
        ball_count: Integer = quantity("balls", unit="1", source="test", ge=1, le=8)
        enabled: Flag = Field(description="a flag")
        name: Text = Field(description="a name")
        criterion: Annotated[str, one_of(("time", "axial_load"))] = Field(description="a choice")

    good = {"ball_count": 3, "enabled": True, "name": "x", "criterion": "time"}
    for change, expected in [
        ({"ball_count": 15.5}, "ball_count: must be an integer, got 15.5"),
        ({"ball_count": True}, "ball_count: must be an integer, got True"),
        ({"ball_count": 0}, "ball_count: must be >= 1, got 0"),
        ({"enabled": "yes"}, "enabled: must be true or false, got 'yes'"),
        ({"name": ""}, "name: must be a non-empty string, got ''"),
        ({"criterion": "speed"}, "criterion: must be one of time, axial_load, got 'speed'"),
    ]:
        assert str(error_of(validate_mapping, Kinds, {**good, **change}, "k.yaml")) == f"k.yaml: {expected}"


def test_unknown_key_lists_the_allowed_keys(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry:\n  ball_diameter_m: 0.0063\n  ball_diametre_m: 0.0063\n")
    assert str(error_of(read, Bearing, path)) == (f"{path}: geometry.ball_diametre_m: unknown key; allowed keys: ball_diameter_m, pitch_diameter_m")


def test_section_must_be_a_mapping(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry: 3\n")
    assert str(error_of(read, Bearing, path)) == f"{path}: geometry: must be a mapping, got int"


def test_lists_name_the_element(tmp_path: Path) -> None:
    class Program(FileSection):
        loads_n: list[Load]

    path = write(tmp_path, "loads_n: [{axial_load_n: 100}, {axial_load_n: -50}, 7]\n")
    assert str(error_of(read, Program, path)) == f"{path}: loads_n[1].axial_load_n: must be >= 0.0, got -50.0"
    path = write(tmp_path, "loads_n: [{axial_load_n: 100}, 7]\n")
    assert str(error_of(read, Program, path)) == f"{path}: loads_n[1]: must be a mapping, got int"


def test_ros_parameters_block(tmp_path: Path) -> None:
    path = write(tmp_path, "monitor:\n  ros__parameters:\n    window_revolutions: 20\n")
    assert ros_parameters(read_mapping(path), "monitor", str(path)) == {"window_revolutions": 20}
    assert str(error_of(ros_parameters, read_mapping(path), "simulator", str(path))) == f"{path}: simulator: missing (required)"


# -- units and shipped files -----------------------------------------------------------------
def test_rpm_conversion() -> None:
    assert rpm_to_rad_s(60.0) == pytest.approx(2.0 * math.pi, rel=1e-15)
    assert rpm_to_rad_s(9000.0) == pytest.approx(942.4777960769379, rel=1e-15)
    assert rad_s_to_rpm(rpm_to_rad_s(2700.0)) == pytest.approx(2700.0, rel=1e-15)


def test_shipped_bearing_file_loads() -> None:
    path = config_path("bearings", "h7006c.yaml")
    assert path.is_file()
    assert isinstance(read_mapping(path), dict)


# -- hostile documents: bounded, safe parsing ------------------------------------------------
BILLION_LAUGHS = 'a: &a ["x","x","x","x","x","x","x","x","x"]\n' + "".join(
    f"{chr(98 + i)}: &{chr(98 + i)} [{','.join(['*' + chr(97 + i)] * 9)}]\n" for i in range(8)
)
"""The classic alias bomb: 9 levels of 9 references each, about 390 million strings once
expanded, from a document of a few hundred bytes."""


def test_alias_bomb_is_refused_quickly_and_without_memory(tmp_path: Path) -> None:
    import resource
    import time

    path = write(tmp_path, BILLION_LAUGHS)
    assert len(BILLION_LAUGHS) < 1024
    before_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    started = time.process_time()
    err = error_of(read_mapping, path)
    cpu_s = time.process_time() - started
    grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before_kb) / 1024
    assert "aliases (*name) are not accepted" in str(err)
    assert str(err).startswith(f"{path}: not valid YAML at line 2")
    assert cpu_s < 1.0  # CPU time, not wall time: the limit of the acceptance, unaffected by load
    assert grown_mb < 100.0


def test_a_single_alias_is_refused_too(tmp_path: Path) -> None:
    path = write(tmp_path, "base: &b {x: 1}\nother: *b\n")
    assert "aliases (*name) are not accepted" in str(error_of(read_mapping, path))


def test_deep_nesting_is_refused_with_one_line(tmp_path: Path) -> None:
    from bearing_rig_sim.config import MAX_YAML_DEPTH

    path = write(tmp_path, "a: " + "[" * 5000 + "]" * 5000 + "\n")
    message = str(error_of(read_mapping, path))
    assert f"nested deeper than {MAX_YAML_DEPTH} levels" in message
    assert "\n" not in message
    ok = write(tmp_path, "a: " + "[" * (MAX_YAML_DEPTH - 1) + "]" * (MAX_YAML_DEPTH - 1) + "\n", "ok.yaml")
    assert "a" in read_mapping(ok)


def test_non_utf8_is_one_line_naming_the_byte(tmp_path: Path) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes("name: caf\u00e9\n".encode("latin-1"))
    assert str(error_of(read_mapping, path)) == f"{path}: not UTF-8 text (byte 9)"


def test_oversized_document_is_refused(tmp_path: Path) -> None:
    from bearing_rig_sim.config import MAX_YAML_BYTES

    path = tmp_path / "big.yaml"
    path.write_bytes(b"#" * (MAX_YAML_BYTES + 10))
    assert f"larger than {MAX_YAML_BYTES} bytes" in str(error_of(read_mapping, path))


def test_python_tags_are_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "x: !!python/object/apply:os.system ['true']\n")
    assert "not valid YAML" in str(error_of(read_mapping, path))
