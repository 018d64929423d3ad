"""The rig file's ``mounting`` section (bearing_rig_sim/rig/mounting.py), the twin that builds its
engine with it, and ``bearing-rig predict``'s mounting options (docs/model.md, "Mounting")."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from bearing_rig_sim.cli import main
from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.dynamics import Mounting
from bearing_rig_sim.rig.mounting import MountingConfig
from bearing_rig_sim.simulation.twin import RigTwin


def _rig_with(tmp_path: Path, mounting: object) -> Path:
    data = yaml.safe_load(config_path("rig.yaml").read_text())
    if mounting is None:
        del data["mounting"]
    else:
        data["mounting"] = mounting
    path = tmp_path / "rig.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_shipped_and_absent_sections_are_all_zero(tmp_path: Path) -> None:
    zero = MountingConfig(clearance_change_m=0.0, misalignment_rad=(0.0, 0.0), preload_n=0.0, preload_displacement_m=0.0)
    assert MountingConfig.from_rig_file() == zero
    assert MountingConfig.from_rig_file(_rig_with(tmp_path, None)) == zero


@pytest.mark.parametrize(
    "mounting,key,problem",
    [
        ({"clearance_change_m": 4e-5}, "mounting.clearance_change_m", "must be <= 3e-05, got 4e-05"),
        ({"misalignment_rad": [0.0, -0.004]}, "mounting.misalignment_rad[1]", "must be >= -0.003, got -0.004"),
        ({"misalignment_rad": [0.001]}, "mounting.misalignment_rad[1]", "missing"),
        ({"preload_n": -5.0}, "mounting.preload_n", "must be >= 0.0, got -5.0"),
        ({"preload_displacement_m": 5e-5}, "mounting.preload_displacement_m", "must be <= 3e-05, got 5e-05"),
        ({"preload": 5.0}, "mounting.preload", "unknown key"),
    ],
)
def test_out_of_range_is_refused_naming_file_key_and_range(tmp_path: Path, mounting: dict[str, object], key: str, problem: str) -> None:
    path = _rig_with(tmp_path, mounting)
    with pytest.raises(ConfigError) as err:
        MountingConfig.from_rig_file(path)
    assert str(path) in str(err.value) and key in str(err.value) and problem in str(err.value)


def test_the_twin_builds_its_engine_mounted(tmp_path: Path) -> None:
    stated = {"clearance_change_m": 5e-6, "misalignment_rad": [2e-4, -1e-4], "preload_n": 40.0, "preload_displacement_m": 3e-6}
    twin = RigTwin.from_files(rig_file=_rig_with(tmp_path, stated))
    assert twin.engine.mounting == Mounting(5e-6, (2e-4, -1e-4), 40.0, 3e-6)


def test_predict_refuses_a_mounting_out_of_range(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["predict", "--rpm", "900", "--load", "100", "--misalignment", "0.01", "0"]) != 0
    assert "misalignment_rad[0]: must be <= 0.003, got 0.01" in capsys.readouterr().err
    assert main(["predict", "--rpm", "900", "--load", "100", "--preload-n", "-1"]) != 0
    assert "preload_n: must be >= 0.0, got -1.0" in capsys.readouterr().err
    assert main(["predict", "--rpm", "900", "--load", "100", "--clearance", "1e-6", "--thermal"]) != 0
    assert "non-thermal path only" in capsys.readouterr().err


def test_predicts_spring_preload_is_axial_load(capsys: pytest.CaptureFixture[str]) -> None:
    """A 60 N spring under a 140 N lever load is the bearing under 200 N: the same steady slip
    and torque; the row states the mounting and the external load."""
    assert main(["predict", "--rpm", "2000", "--load", "200", "--calibration", "isothermal", "--json"]) == 0
    plain = json.loads(capsys.readouterr().out)
    assert main(["predict", "--rpm", "2000", "--load", "140", "--preload-n", "60", "--calibration", "isothermal", "--json"]) == 0
    sprung = json.loads(capsys.readouterr().out)
    assert sprung["axial_load_n"] == 140.0 and sprung["preload_n"] == 60.0
    assert sprung["slip_pct"] == pytest.approx(plain["slip_pct"], abs=1e-3)
    assert sprung["friction_torque_nm"] == pytest.approx(plain["friction_torque_nm"], rel=1e-4)


def test_the_shadow_twin_builds_its_engine_mounted_and_keeps_it_on_recalibration(tmp_path: Path) -> None:
    from bearing_rig_sim.shadow.settings import ShadowSettings
    from bearing_rig_sim.shadow.twin import ShadowTwin

    stated = {"clearance_change_m": -4e-6, "misalignment_rad": [0.0, 3e-4], "preload_n": 25.0, "preload_displacement_m": 0.0}
    twin = ShadowTwin(ShadowSettings.from_yaml().replace(rig_file=str(_rig_with(tmp_path, stated))))
    expected = Mounting(-4e-6, (0.0, 3e-4), 25.0, 0.0)
    assert twin.drive.engine.mounting == expected
    twin.drive.swap_parameters(twin.params)  # the online re-calibration's engine swap
    assert twin.drive.engine.mounting == expected
