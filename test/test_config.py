"""Validated configuration: every error names the file, the key and what was allowed."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from bearing_rig_sim.config import (
    ConfigError,
    Section,
    check_number,
    config_path,
    load_yaml,
    rad_s_to_rpm,
    ros_parameters,
    rpm_to_rad_s,
)
from bearing_rig_sim.errors import RigError


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
    err = error_of(load_yaml, path)
    assert err.source == str(path)
    assert err.key == ""
    message = str(err)
    assert message.startswith(f"{path}: not valid YAML at line ")
    assert "line 4" in message or "line 3" in message


def test_top_level_must_be_a_mapping(tmp_path: Path) -> None:
    path = write(tmp_path, "- 1\n- 2\n")
    assert str(error_of(load_yaml, path)) == f"{path}: top level must be a mapping, got list"


def test_empty_file_is_not_a_mapping(tmp_path: Path) -> None:
    path = write(tmp_path, "")
    assert str(error_of(load_yaml, path)) == f"{path}: top level must be a mapping, got NoneType"


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "absent.yaml"
    err = error_of(load_yaml, path)
    assert str(err).startswith(f"{path}: cannot read file")


def test_config_error_is_a_rig_error_and_a_value_error() -> None:
    err = ConfigError("a.yaml", "x.y", "must be > 0, got -1")
    assert isinstance(err, RigError) and isinstance(err, ValueError)
    assert (err.source, err.key, err.problem) == ("a.yaml", "x.y", "must be > 0, got -1")
    assert str(err) == "a.yaml: x.y: must be > 0, got -1"


# -- keys and values -------------------------------------------------------------------------
def test_missing_key_names_the_dotted_path(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry:\n  pitch_diameter_m: 0.0405\n")
    geometry = load_yaml(path).section("geometry")
    assert str(error_of(geometry.number, "ball_diameter_m", gt=0)) == (f"{path}: geometry.ball_diameter_m: missing (required)")


def test_null_value_counts_as_missing_unless_defaulted(tmp_path: Path) -> None:
    doc = load_yaml(write(tmp_path, "speed_rpm: ~\n"))
    assert "missing (required)" in str(error_of(doc.number, "speed_rpm"))
    assert doc.number("speed_rpm", default=900.0) == 900.0


def test_out_of_range_names_file_key_and_bound(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry:\n  ball_diameter_m: -0.0063\n")
    geometry = load_yaml(path).section("geometry")
    assert str(error_of(geometry.number, "ball_diameter_m", gt=0)) == (f"{path}: geometry.ball_diameter_m: must be > 0, got -0.0063")


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
    path = write(tmp_path, f"limits:\n  value: {value}\n")
    limits = load_yaml(path).section("limits")
    assert str(error_of(limits.number, "value", **bounds)) == f"{path}: limits.value: {expected}"


def test_value_on_an_inclusive_bound_is_accepted(tmp_path: Path) -> None:
    doc = load_yaml(write(tmp_path, "a: 0\nb: 9000\n"))
    assert doc.number("a", ge=0) == 0.0
    assert doc.number("b", le=9000) == 9000.0


@pytest.mark.parametrize("text", [".nan", ".NaN", ".inf", "-.inf"])
def test_non_finite_numbers_are_refused(tmp_path: Path, text: str) -> None:
    path = write(tmp_path, f"axial_load_n: {text}\n")
    err = error_of(load_yaml(path).number, "axial_load_n", ge=0)
    assert err.key == "axial_load_n"
    assert str(err).startswith(f"{path}: axial_load_n: must be finite, got ")


def test_nan_passed_directly_is_refused() -> None:
    err = error_of(check_number, math.nan, "cli", "--axial-load")
    assert str(err) == "cli: --axial-load: must be finite, got nan"


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ('"fast"', "must be a number, got 'fast'"),
        ("true", "must be a number, got True"),
        ("[1, 2]", "must be a number, got [1, 2]"),
        ("{a: 1}", "must be a number, got {'a': 1}"),
    ],
)
def test_wrong_type_for_a_number(tmp_path: Path, text: str, expected: str) -> None:
    path = write(tmp_path, f"speed_rpm: {text}\n")
    assert str(error_of(load_yaml(path).number, "speed_rpm", gt=0)) == f"{path}: speed_rpm: {expected}"


def test_unsigned_exponent_reads_as_a_number(tmp_path: Path) -> None:
    # YAML 1.1 (PyYAML) reads "2.1e11" as a string; the loader reads it as YAML 1.2 does.
    doc = load_yaml(write(tmp_path, "youngs_modulus_pa: 2.1e11\n"))
    assert doc.data["youngs_modulus_pa"] == "2.1e11"
    assert doc.number("youngs_modulus_pa", gt=0) == 2.1e11


def test_integer_type_and_range(tmp_path: Path) -> None:
    path = write(tmp_path, "ball_count: 15.5\nstrips: 0\nflag: true\n")
    doc = load_yaml(path)
    assert str(error_of(doc.integer, "ball_count", ge=1)) == f"{path}: ball_count: must be an integer, got 15.5"
    assert str(error_of(doc.integer, "strips", ge=1, le=8)) == f"{path}: strips: must be >= 1, got 0"
    assert str(error_of(doc.integer, "flag")) == f"{path}: flag: must be an integer, got True"


def test_boolean_string_and_choice(tmp_path: Path) -> None:
    path = write(tmp_path, 'enabled: "yes"\nname: ""\ncriterion: speed\n')
    doc = load_yaml(path)
    assert str(error_of(doc.boolean, "enabled")) == f"{path}: enabled: must be true or false, got 'yes'"
    assert str(error_of(doc.string, "name")) == f"{path}: name: must be a non-empty string, got ''"
    assert str(error_of(doc.choice, "criterion", ("time", "axial_load"))) == (f"{path}: criterion: must be one of time, axial_load, got 'speed'")


def test_unknown_key_lists_the_allowed_keys(tmp_path: Path) -> None:
    path = write(tmp_path, "rig:\n  brake_gain: 1.0\n  brake_gian: 2.0\n")
    rig = load_yaml(path).section("rig")
    assert str(error_of(rig.reject_unknown, ["brake_gain", "lever_ratio"])) == (f"{path}: rig.brake_gian: unknown key; allowed keys: brake_gain, lever_ratio")
    rig_ok = load_yaml(write(tmp_path, "rig:\n  brake_gain: 1.0\n", "ok.yaml")).section("rig")
    rig_ok.reject_unknown(["brake_gain", "lever_ratio"])


def test_section_must_be_a_mapping(tmp_path: Path) -> None:
    path = write(tmp_path, "geometry: 3\n")
    assert str(error_of(load_yaml(path).section, "geometry")) == f"{path}: geometry: must be a mapping, got int"


def test_number_list_names_the_element(tmp_path: Path) -> None:
    path = write(tmp_path, "program:\n  loads_n: [100, -50, 300]\n  speeds: []\n")
    program = load_yaml(path).section("program")
    assert str(error_of(program.number_list, "loads_n", ge=0)) == f"{path}: program.loads_n[1]: must be >= 0, got -50"
    assert "program.speeds: must be a list of at least 1 number(s)" in str(error_of(program.number_list, "speeds"))
    assert program.number_list("loads_n") == [100.0, -50.0, 300.0]


def test_sections_name_the_index(tmp_path: Path) -> None:
    path = write(tmp_path, "steps:\n  - {speed_rpm: 900}\n  - {speed_rpm: -1}\n  - 7\n")
    doc = load_yaml(path)
    err = error_of(doc.sections, "steps")
    assert str(err) == f"{path}: steps[2]: must be a mapping"
    steps = Section({"steps": [{"speed_rpm": 900}, {"speed_rpm": -1}]}, str(path)).sections("steps")
    assert str(error_of(steps[1].number, "speed_rpm", gt=0)) == f"{path}: steps[1].speed_rpm: must be > 0, got -1"


def test_ros_parameters_block(tmp_path: Path) -> None:
    path = write(tmp_path, "monitor:\n  ros__parameters:\n    window_revolutions: 20\n")
    params = ros_parameters(load_yaml(path), "monitor")
    assert params.integer("window_revolutions", ge=1) == 20
    assert str(error_of(ros_parameters, load_yaml(path), "simulator")) == f"{path}: simulator: missing (required)"


# -- units and shipped files -----------------------------------------------------------------
def test_rpm_conversion() -> None:
    assert rpm_to_rad_s(60.0) == pytest.approx(2.0 * math.pi, rel=1e-15)
    assert rpm_to_rad_s(9000.0) == pytest.approx(942.4777960769379, rel=1e-15)
    assert rad_s_to_rpm(rpm_to_rad_s(2700.0)) == pytest.approx(2700.0, rel=1e-15)


def test_shipped_bearing_file_loads() -> None:
    path = config_path("bearings", "h7006c.yaml")
    assert path.is_file()
    assert isinstance(load_yaml(path), Section)


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
    err = error_of(load_yaml, path)
    cpu_s = time.process_time() - started
    grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before_kb) / 1024
    assert "aliases (*name) are not accepted" in str(err)
    assert str(err).startswith(f"{path}: not valid YAML at line 2")
    assert cpu_s < 1.0  # CPU time, not wall time: the limit of the acceptance, unaffected by load
    assert grown_mb < 100.0


def test_a_single_alias_is_refused_too(tmp_path: Path) -> None:
    path = write(tmp_path, "base: &b {x: 1}\nother: *b\n")
    assert "aliases (*name) are not accepted" in str(error_of(load_yaml, path))


def test_deep_nesting_is_refused_with_one_line(tmp_path: Path) -> None:
    from bearing_rig_sim.config import MAX_YAML_DEPTH

    path = write(tmp_path, "a: " + "[" * 5000 + "]" * 5000 + "\n")
    message = str(error_of(load_yaml, path))
    assert f"nested deeper than {MAX_YAML_DEPTH} levels" in message
    assert "\n" not in message
    ok = write(tmp_path, "a: " + "[" * (MAX_YAML_DEPTH - 1) + "]" * (MAX_YAML_DEPTH - 1) + "\n", "ok.yaml")
    assert "a" in load_yaml(ok)


def test_non_utf8_is_one_line_naming_the_byte(tmp_path: Path) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes("name: caf\u00e9\n".encode("latin-1"))
    assert str(error_of(load_yaml, path)) == f"{path}: not UTF-8 text (byte 9)"


def test_oversized_document_is_refused(tmp_path: Path) -> None:
    from bearing_rig_sim.config import MAX_YAML_BYTES

    path = tmp_path / "big.yaml"
    path.write_bytes(b"#" * (MAX_YAML_BYTES + 10))
    assert f"larger than {MAX_YAML_BYTES} bytes" in str(error_of(load_yaml, path))


def test_python_tags_are_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "x: !!python/object/apply:os.system ['true']\n")
    assert "not valid YAML" in str(error_of(load_yaml, path))
