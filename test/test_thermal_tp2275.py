"""The second bearing (NASA TP-2275's 35 mm bore, jet-lubricated with MIL-L-23699) predicted with
no tuning, and bearing or lubricant files with a value outside its range refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bearing_rig_sim.cli import main

CONFIG = Path(__file__).resolve().parents[1] / "config"
TP2275 = CONFIG / "bearings" / "tp2275.yaml"
MIL = CONFIG / "lubricants" / "mil_l_23699.yaml"


@pytest.mark.slow
def test_tp2275_heat_generation_rises_with_speed_and_the_oil_carries_it(capsys: pytest.CaptureFixture[str]) -> None:
    """28 000 and 72 000 rpm at 667 N, oil in at 394 K: the heat grows with speed; the jet
    carries at most all of it (housing and shaft lead the rest to the colder ambient), so the
    lubricant's rise over the inlet is below power / (rho Q c_p); at 72 000 rpm it is above the
    inlet; no calibration is laid over it (no interval)."""
    argv = ["predict", "--bearing", str(TP2275), "--lubricant", str(MIL), "--rpm", "28000", "72000", "--load", "667", "--thermal", "--json"]
    assert main(argv) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert rows[1]["power_loss_w"] > rows[0]["power_loss_w"] > 0.0
    jet = 1000.0 * 3.15e-5 * 2000.0  # rho Q c_p of the file's jet, W/K (density at 15 degC: an upper bound)
    for r in rows:
        assert "slip_pct_low" not in r
        rise = r["lubricant_temperature_c"] - 120.85
        assert rise < 1.05 * r["power_loss_w"] / jet
        assert sum(r["heat_w"].values()) == pytest.approx(r["power_loss_w"], rel=2e-3)
    assert rows[1]["lubricant_temperature_c"] > 120.85


@pytest.mark.parametrize(
    ("name", "old", "new", "key"),
    [
        ("bearings/tp2275.yaml", "    mass_kg: 5.0 ", "    mass_kg: 50.0 ", "thermal.housing.mass_kg"),
        ("bearings/tp2275.yaml", "  oil_inlet_temperature_c: 120.85", "  oil_inlet_temperature_c: 420.85", "thermal.oil_inlet_temperature_c"),
        ("lubricants/mil_l_23699.yaml", "  specific_heat_j_kg_k: {value: 2000.0,", "  specific_heat_j_kg_k: {value: 200.0,", "base_oil.specific_heat_j_kg_k"),
    ],
)
def test_a_value_outside_its_range_is_refused_naming_file_key_and_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, old: str, new: str, key: str
) -> None:
    bearing, lubricant = tmp_path / "tp2275.yaml", tmp_path / "mil.yaml"
    bearing.write_text(TP2275.read_text())
    lubricant.write_text(MIL.read_text())
    target = bearing if name.startswith("bearings") else lubricant
    text = target.read_text()
    assert old in text
    target.write_text(text.replace(old, new))
    assert main(["predict", "--bearing", str(bearing), "--lubricant", str(lubricant), "--rpm", "28000", "--load", "667", "--thermal"]) == 2
    err = capsys.readouterr().err
    assert target.name in err and key in err and ("<=" in err or ">=" in err or "range" in err or "[" in err), err
