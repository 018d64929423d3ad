"""The bearing, lubricant and calibration files as declarative models: every physical parameter
with a unit, the source of its range and the range; one-line errors naming the file, the dotted
key and the allowed range; a value written with its stated range refused outside it."""

from __future__ import annotations

import copy
import glob
from pathlib import Path
from typing import Any

import pytest
from pydantic import BaseModel

from bearing_rig_sim.config import ConfigError, config_path, read_mapping
from bearing_rig_sim.dynamics.bearing_file import BearingFile, CalibrationFile, LubricantFile
from bearing_rig_sim.dynamics.lubrication import Lubricant
from bearing_rig_sim.dynamics.parameters import BearingParameters
from bearing_rig_sim.settings_model import read_file, validate_mapping

BEARING = config_path("bearings", "h7006c.yaml")
GREASE = config_path("lubricants", "nlgi2_grease.yaml")
OIL_AIR = config_path("lubricants", "vg32_oil_air.yaml")


def models(model: type[BaseModel]) -> list[type[BaseModel]]:
    """``model`` and every model nested in it."""
    out = [model]
    for info in model.model_fields.values():
        for kind in (info.annotation, *getattr(info.annotation, "__args__", ())):
            if isinstance(kind, type) and issubclass(kind, BaseModel) and kind not in out:
                out.extend(m for m in models(kind) if m not in out)
    return out


@pytest.mark.parametrize("model", [BearingFile, LubricantFile])
def test_every_physical_parameter_states_its_unit_and_the_source_of_its_range(model: type[BaseModel]) -> None:
    quantities = 0
    for part in models(model):
        for name, info in part.model_fields.items():
            extra = info.json_schema_extra
            if info.annotation in (int, float) or (isinstance(extra, dict) and "unit" in extra):
                assert isinstance(extra, dict) and extra["unit"] and extra["source"], f"{part.__name__}.{name}"
                quantities += 1
    assert quantities > 15


def test_every_shipped_data_file_is_valid() -> None:
    for path in sorted(glob.glob(str(config_path("bearings", "*.yaml")))):
        read_file(BearingFile, path)
    for path in sorted(glob.glob(str(config_path("lubricants", "*.yaml")))):
        read_file(LubricantFile, path)
    for path in sorted(glob.glob(str(config_path("calibration", "*.yaml")))):
        read_file(CalibrationFile, path)


def bearing_error(change: Any, source: str = "h7006c.yaml") -> str:
    data = read_mapping(BEARING)
    change(data)
    with pytest.raises(ConfigError) as info:
        BearingParameters.from_mapping(data, source)
    return str(info.value)


def test_bearing_errors_name_the_file_the_key_and_the_range() -> None:
    # the shipped H7006C: Dw 6.3 mm, dm 42.45 mm (paper Table 2)
    assert bearing_error(lambda d: d["geometry"].update(ball_diameter_m=-0.0063)) == "h7006c.yaml: geometry.ball_diameter_m: must be > 0.0, got -0.0063"
    assert bearing_error(lambda d: d["cage"].update(pocket_diameter_m=0.006)) == "h7006c.yaml: cage.pocket_diameter_m: must be > 0.0063, got 0.006"
    assert bearing_error(lambda d: d["cage"].update(outer_diameter_m=0.09)) == "h7006c.yaml: cage.outer_diameter_m: must be < 0.0849, got 0.09"
    assert bearing_error(lambda d: d["geometry"].update(pitch_diameter_m=0.006)) == "h7006c.yaml: geometry.pitch_diameter_m: must be > 0.0063, got 0.006"
    assert bearing_error(lambda d: d["friction"].update(transition_velocity_m_s=0.05)) == (
        "h7006c.yaml: friction.transition_velocity_m_s: must be > 0.1, got 0.05"
    )
    assert bearing_error(lambda d: d["geometry"].pop("ball_count")) == "h7006c.yaml: geometry.ball_count: missing (required)"
    assert bearing_error(lambda d: d["geometry"].update(ball_count=15.5)) == "h7006c.yaml: geometry.ball_count: must be an integer, got 15.5"
    assert bearing_error(lambda d: d["friction"].update(model="stribeck")) == (
        "h7006c.yaml: friction.model: must be one of paper, coulomb_step, ehl_traction, rheology, got 'stribeck'"
    )


def test_a_misspelt_optional_key_is_refused_not_left_at_its_default() -> None:
    message = bearing_error(lambda d: d["cage"].update(land_cout=2))
    assert message.startswith("h7006c.yaml: cage.land_cout: unknown key; allowed keys: guidance, inner_diameter_m, land_count,")


def test_rheology_needs_a_lubricant_file() -> None:
    def inline(d: dict[str, Any]) -> None:
        d["lubricant"] = {"air_density_kg_m3": 1.2, "air_viscosity_pa_s": 1.8e-5, "oil_density_kg_m3": 860.0, "oil_viscosity_pa_s": 0.02}

    assert bearing_error(inline) == "h7006c.yaml: lubricant.oil_volume_fraction: missing (required)"

    def inline_complete(d: dict[str, Any]) -> None:
        inline(d)
        d["lubricant"]["oil_volume_fraction"] = 0.01

    assert bearing_error(inline_complete) == "h7006c.yaml: friction.model: rheology needs a lubricant file (lubricant.file)"


def stated(value: float, unit: str, low: float, high: float) -> dict[str, Any]:
    return {"value": value, "unit": unit, "range": [low, high], "source": "lab bench, light load"}


def test_a_value_written_with_its_stated_range_is_refused_outside_it() -> None:
    """The bearing file states the lubricant temperature [25, 60] degC (h7006c.yaml): written as
    a quantity with that range, 35 degC gives the same bearing as the plain number, 70 degC is
    refused naming the file, the key and the range, and a wrong unit is refused."""
    plain = BearingParameters.from_mapping(read_mapping(BEARING), "h7006c.yaml")
    data = read_mapping(BEARING)
    data["lubricant"]["temperature_c"] = stated(35.0, "degC", 25.0, 60.0)
    assert BearingParameters.from_mapping(data, "h7006c.yaml") == plain
    assert bearing_error(lambda d: d["lubricant"].update(temperature_c=stated(70.0, "degC", 25.0, 60.0))) == (
        "h7006c.yaml: lubricant.temperature_c.value: must be <= 60.0, got 70.0"
    )
    assert bearing_error(lambda d: d["lubricant"].update(temperature_c=stated(308.15, "K", 298.15, 333.15))) == (
        "h7006c.yaml: lubricant.temperature_c.unit: must be 'degC', the unit of this key, got 'K'"
    )
    # the stated range does not widen the model's plausible range: [-40, 200] degC
    assert bearing_error(lambda d: d["lubricant"].update(temperature_c=stated(250.0, "degC", 0.0, 300.0))) == (
        "h7006c.yaml: lubricant.temperature_c: must be <= 200.0, got 250.0"
    )


def lubricant_error(path: Path, change: Any) -> str:
    data = copy.deepcopy(read_mapping(path))
    change(data)
    with pytest.raises(ConfigError) as info:
        Lubricant.from_file(validate_mapping(LubricantFile, data, path.name), path.name)
    return str(info.value)


def test_lubricant_errors_name_the_file_the_key_and_the_range() -> None:
    # nlgi2_grease.yaml: base oil 25 mm^2/s at 40 degC
    assert lubricant_error(GREASE, lambda d: d["base_oil"].update(viscosity_100c_mm2_s=30.0)) == (
        "nlgi2_grease.yaml: base_oil.viscosity_100c_mm2_s: must be < 25.0, got 30.0"
    )
    assert lubricant_error(GREASE, lambda d: d.pop("grease")) == "nlgi2_grease.yaml: grease: missing (required)"
    assert lubricant_error(OIL_AIR, lambda d: d["supply"].pop("oil_volume_fraction")) == "vg32_oil_air.yaml: supply.oil_volume_fraction: missing (required)"
    assert lubricant_error(GREASE, lambda d: d["film"].update(eyring_stress_pa=stated(5.0e6, "Pa", 2e6, 4e6))) == (
        "nlgi2_grease.yaml: film.eyring_stress_pa.value: must be <= 4000000.0, got 5000000.0"
    )


def test_a_stated_lubricant_value_inside_its_range_gives_the_same_lubricant() -> None:
    plain = Lubricant.from_yaml(GREASE)
    data = read_mapping(GREASE)
    data["base_oil"]["viscosity_40c_mm2_s"] = stated(25.0, "mm^2/s", 15.0, 100.0)
    assert Lubricant.from_file(validate_mapping(LubricantFile, data, str(GREASE)), str(GREASE)) == plain


def test_a_calibration_value_outside_its_range_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "cal.yaml"
    path.write_text("parameters:\n  lubricant.yield_stress_pa: {value: 10.0, unit: Pa, range: [50.0, 2000.0], source: fit}\n")
    with pytest.raises(ConfigError) as info:
        BearingParameters.from_yaml(None, path)
    assert str(info.value) == f"{path}: parameters.lubricant.yield_stress_pa.value: must be >= 50.0, got 10.0"


SHIPPED: list[tuple[type[BaseModel], Path]] = [
    *((BearingFile, Path(p)) for p in sorted(glob.glob(str(config_path("bearings", "*.yaml"))))),
    *((LubricantFile, Path(p)) for p in sorted(glob.glob(str(config_path("lubricants", "*.yaml"))))),
]
"""Every shipped bearing and lubricant file with its model."""


def stated_entries(data: Any, key: str = "") -> list[tuple[str, dict[str, Any]]]:
    """The values a file writes as ``{value, unit, range, source}``, by dotted key, read from the
    YAML itself (not through the model)."""
    if isinstance(data, dict) and set(data) == {"value", "unit", "range", "source"}:
        return [(key, data)]
    if isinstance(data, dict):
        return [entry for k, v in data.items() for entry in stated_entries(v, f"{key}.{k}" if key else str(k))]
    return []


def test_the_shipped_files_state_the_ranges_of_their_values_and_lie_inside_them() -> None:
    """The H7006C bearing file and every lubricant file write their values with the plausible
    range their comments used to state (each range is checked here from the YAML itself)."""
    counts = {}
    for model, path in SHIPPED:
        read_file(model, path)
        entries = stated_entries(read_mapping(path))
        for key, entry in entries:
            low, high = (float(x) for x in entry["range"])
            assert low <= float(entry["value"]) <= high, f"{path.name}: {key}"
            assert entry["unit"] and entry["source"], f"{path.name}: {key}"
        counts[path.name] = len(entries)
    lubricants = [p.name for _, p in SHIPPED if p.parent.name == "lubricants"]
    assert len(lubricants) >= 4
    assert all(counts[name] >= 10 for name in ["h7006c.yaml", *lubricants]), counts


@pytest.mark.parametrize(("model", "path"), [pytest.param(m, p, id=p.name) for m, p in SHIPPED if stated_entries(read_mapping(p))])
def test_a_shipped_file_with_a_stated_value_moved_outside_its_range_is_refused(model: type[BaseModel], path: Path) -> None:
    """Each stated value of each shipped file, moved just beyond either end of its range, is
    refused naming the file, the dotted key and the bound of the range it crossed."""
    for key, entry in stated_entries(read_mapping(path)):
        low, high = (float(x) for x in entry["range"])
        for bound, bad, problem in ((high, high + 0.5 * (high - low), "<="), (low, low - 0.5 * (high - low), ">=")):
            data = read_mapping(path)
            target = data
            for part in key.split("."):
                target = target[part]
            target["value"] = bad
            with pytest.raises(ConfigError) as info:
                validate_mapping(model, data, str(path))
            assert str(info.value) == f"{path}: {key}.value: must be {problem} {bound}, got {bad!r}"


def test_the_calibration_lies_inside_the_range_the_lubricant_file_states(tmp_path: Path) -> None:
    """The bench calibration overlays the grease's yield stress and consistency: their stated
    ranges in the calibration file lie inside those of the grease file (0.05-2 kPa, 1-100 Pa s^n),
    the calibrated values replace the grease file's (589.964 Pa and 50.1178 Pa s^n as written in
    config/calibration/h7006c_table3.yaml), and a calibrated value beyond its range is refused
    naming the calibration file, the key and the range."""
    calibration = read_mapping(config_path("calibration", "h7006c_table3.yaml"))["parameters"]
    grease = read_mapping(GREASE)["grease"]
    for key in ("yield_stress_pa", "consistency_pa_sn"):
        cal_low, cal_high = calibration[f"lubricant.{key}"]["range"]
        low, high = grease[key]["range"]
        assert low <= cal_low <= cal_high <= high
    lubricant = BearingParameters.calibrated().lubricant
    assert lubricant is not None
    assert (lubricant.yield_stress, lubricant.consistency) == (589.964, 50.1178)
    path = tmp_path / "cal.yaml"
    path.write_text("parameters:\n  lubricant.yield_stress_pa: {value: 2500.0, unit: Pa, range: [50.0, 2000.0], source: fit}\n")
    with pytest.raises(ConfigError) as info:
        BearingParameters.from_yaml(None, path)
    assert str(info.value) == f"{path}: parameters.lubricant.yield_stress_pa.value: must be <= 2000.0, got 2500.0"
