"""Each bearing quantity named once: every field of the engine's bearing records names the
bearing-file key it is read from (:mod:`bearing_rig_sim.bearing.file_record`), the records built
from the shipped files hold what those files write, and the names a calibration may set are
derived from the same declarations. The files are read here with PyYAML, not through the models,
so a value cannot agree with itself."""

from __future__ import annotations

import dataclasses
import glob
import math
import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
import yaml

from bearing_rig_sim.bearing.file_record import CONVERT, file_field, file_keys, file_record, file_values
from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.dynamics.bearing_file import CALIBRATABLE_KEYS, CalibrationFile
from bearing_rig_sim.dynamics.models import PAPER, model_parameters
from bearing_rig_sim.dynamics.parameters import CALIBRATABLE, BearingParameters
from bearing_rig_sim.settings_model import validate_mapping
from bearing_rig_sim.thermal.bearing import ThermalConfig

BEARINGS = [Path(p) for p in sorted(glob.glob(str(config_path("bearings", "*.yaml"))))]
RECORDS: dict[type, set[str]] = {BearingParameters: {"lubricant", "source"}, ThermalConfig: {"source"}}
"""Each record with the fields that name no key of their own (built by its ``from_file``)."""


def raw(path: Path) -> dict[str, Any]:
    return dict(yaml.safe_load(path.read_text(encoding="utf-8")))


def written(doc: dict[str, Any], key: str) -> tuple[bool, Any]:
    """(present, value) of a dotted key as the YAML writes it (a stated quantity's value; a
    YAML 1.1 exponent without a sign, such as ``208.0e9``, which PyYAML reads as text, as the
    number it is)."""
    node: Any = doc
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return False, None
        node = node[part]
    value = node["value"] if isinstance(node, dict) and "value" in node else node
    if isinstance(value, str) and re.fullmatch(r"[0-9.]+e[0-9]+", value):
        value = float(value)
    return True, value


def test_calibratable_names_and_keys_are_those_the_calibration_files_use() -> None:
    """The engine names and bearing-file keys a calibration may set, as written by hand before
    they were derived from the declarations (calibration files and ``--fit`` use them)."""
    assert CALIBRATABLE == {
        "stiction_velocity": ("friction", "stiction_velocity_m_s"),
        "static_friction": ("friction", "static_coefficient"),
        "ball_drag_scale": ("resistances", "ball_drag_scale"),
        "cage_land_viscous_scale": ("resistances", "cage_land_viscous_scale"),
        "cage_land_boundary_torque_scale": ("resistances", "cage_land_boundary_torque_scale"),
        "rolling_hysteresis_factor": ("resistances", "rolling_hysteresis_factor"),
        "oil_volume_fraction": ("lubricant", "oil_volume_fraction"),
        "yield_stress": ("lubricant", "yield_stress_pa"),
        "consistency": ("lubricant", "consistency_pa_sn"),
        "fill_fraction": ("lubricant", "fill_fraction"),
        "eyring_stress": ("lubricant", "eyring_stress_pa"),
        "consistency_temperature_exponent": ("lubricant", "consistency_temperature_exponent"),
        "ball_set_resistance": ("resistances", "ball_set_resistance_n"),
        "ball_set_resistance_speed_exponent": ("resistances", "ball_set_resistance_speed_exponent"),
    }
    assert sorted(CALIBRATABLE_KEYS) == sorted(f"{sec}.{key}" for sec, key in CALIBRATABLE.values())


def test_a_key_not_declared_calibratable_is_refused_in_a_calibration_file() -> None:
    with pytest.raises(ConfigError) as info:
        validate_mapping(CalibrationFile, {"parameters": {"friction.dynamic_coefficient": 0.1}}, "cal.yaml")
    assert str(info.value).startswith("cal.yaml: parameters.friction.dynamic_coefficient: not a calibratable parameter; allowed: friction.static_coefficient,")


@pytest.mark.parametrize("record", list(RECORDS), ids=lambda r: r.__name__)
def test_every_field_names_its_key_or_is_one_of_the_few_built_by_hand(record: type) -> None:
    names, keys = {f.name for f in dataclasses.fields(record)}, file_keys(record)
    assert names - set(keys) == RECORDS[record]
    assert len(set(keys.values())) == len(keys), "two fields read one key"


@pytest.mark.parametrize("path", BEARINGS, ids=lambda p: p.name)
def test_every_keyed_field_holds_the_value_its_file_writes(path: Path) -> None:
    """Each field whose key the file writes holds that value (nested sections, stated quantities,
    in SI through the field's declared conversion); keys the file leaves out hold the model's
    defaults and are not compared. Which key a field reads is checked by hand below."""
    doc = raw(path)
    records = [BearingParameters.from_yaml(path), ThermalConfig.from_yaml(path)]
    compared = 0
    for record in records:
        fields = {f.name: f for f in dataclasses.fields(record)}
        for name, key in file_keys(type(record)).items():
            present, value = written(doc, key)
            if present:
                convert = fields[name].metadata[CONVERT]
                expected = value if convert is None else convert(value)
                assert getattr(record, name) == expected, f"{path.name}: {key} -> {name}"
                compared += 1
    assert compared >= 60


def test_a_few_fields_against_the_values_the_files_write() -> None:
    """By hand, from config/bearings/h7006c.yaml: Dw 6.3 mm, dm 42.45 mm, 16 balls, 15 deg =
    pi/12 rad; cage 41.9 / 45.7 mm, pockets 6.5 mm, two lands; polyimide 1120 kg/m^3, 2.62 GPa,
    Poisson 0.34; inner ring 0.05 kg; mu_s 0.10, pocket mu 0.08, EHL mu_max 0.06; lubricant at
    35 degC; reduced step 40 us; vertical spindle; d 30 mm, D 55 mm, shoulders 36.9 / 48.0 mm;
    ambient 22 degC, housing 2.5 kg, shaft 30 mm, no jet inlet temperature (the ambient stands
    in). From tp2275.yaml: 24 deg = 2 pi/15 rad, a jet inlet at 120.85 degC."""
    h7006c, tp2275 = config_path("bearings", "h7006c.yaml"), config_path("bearings", "tp2275.yaml")
    p = BearingParameters.from_yaml(h7006c)
    assert (p.name, p.ball_diameter, p.pitch_diameter, p.ball_count) == ("H7006C", 0.0063, 0.04245, 16)
    assert p.contact_angle == pytest.approx(math.pi / 12.0, rel=1e-15)
    assert (p.cage_inner_diameter, p.cage_outer_diameter, p.pocket_diameter, p.land_count) == (0.0419, 0.0457, 0.0065, 2)
    assert (p.cage_density, p.cage_modulus, p.cage_poisson, p.inner_ring_axial_mass) == (1120.0, 2.62e9, 0.34, 0.05)
    assert (p.static_friction, p.pocket_friction, p.ehl_max_coefficient) == (0.10, 0.08, 0.06)
    assert (p.lubricant_temperature, p.reduced_time_step, p.spindle_axis) == (35.0, 4.0e-5, "vertical")
    t = ThermalConfig.from_yaml(h7006c)
    assert (t.bore, t.outside_diameter, t.inner_shoulder, t.outer_shoulder) == (0.030, 0.055, 0.0369, 0.0480)
    assert (t.ambient, t.housing_mass, t.shaft_diameter, t.oil_inlet) == (22.0, 2.5, 0.030, 22.0)
    assert BearingParameters.from_yaml(tp2275).contact_angle == pytest.approx(2.0 * math.pi / 15.0, rel=1e-15)
    assert ThermalConfig.from_yaml(tp2275).oil_inlet == 120.85


CALIBRATIONS = [
    (config_path("calibration", "h7006c_table3.yaml"), lambda path: BearingParameters.from_yaml(None, path)),
    (config_path("calibration", "h7006c_coupled.yaml"), lambda path: BearingParameters.from_yaml(None, path)),
    (config_path("calibration", "paper_table3.yaml"), lambda path: model_parameters(PAPER, calibration=path)),
]


@pytest.mark.parametrize(("path", "build"), CALIBRATIONS, ids=lambda c: c.name if isinstance(c, Path) else "")
def test_each_calibrated_value_lands_in_the_field_of_its_name(path: Path, build: Any) -> None:
    """Every entry of a shipped calibration file sets the record's field (or the lubricant's) of
    the name :data:`CALIBRATABLE` gives its key, to the value the file writes."""
    names = {f"{sec}.{key}": name for name, (sec, key) in CALIBRATABLE.items()}
    params = build(path)
    entries = raw(path)["parameters"]
    for key, entry in entries.items():
        name = names[key]
        holder = params if name in {f.name for f in dataclasses.fields(BearingParameters)} else params.lubricant
        assert getattr(holder, name) == entry["value"], f"{path.name}: {key} -> {name}"
    assert entries


def test_file_values_reads_nested_keys_converts_and_lets_explicit_values_win() -> None:
    @file_record
    class Toy:
        angle: float = file_field("geometry.angle_deg", convert=math.radians)
        mass: float = file_field("materials.ball.mass_kg")
        fraction: float = file_field("lubricant.fraction")
        label: str = "<memory>"

    doc = SimpleNamespace(
        geometry=SimpleNamespace(angle_deg=90.0), materials=SimpleNamespace(ball=SimpleNamespace(mass_kg=0.002)), lubricant=SimpleNamespace(fraction=None)
    )
    toy = Toy(**file_values(Toy, doc, fraction=0.0, label="toy.yaml"))
    assert toy == Toy(angle=math.pi / 2.0, mass=0.002, fraction=0.0, label="toy.yaml")
    assert file_keys(Toy) == {"angle": "geometry.angle_deg", "mass": "materials.ball.mass_kg", "fraction": "lubricant.fraction"}
    with pytest.raises(dataclasses.FrozenInstanceError):
        toy.mass = 1.0  # type: ignore[misc]  # the record is frozen: mypy refuses this too
