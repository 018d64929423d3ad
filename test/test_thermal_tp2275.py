"""The second bearing (NASA TP-2275's 35 mm bore, jet-lubricated with MIL-L-23699) predicted with
no tuning, and bearing or lubricant files with a value outside its range refused."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path
from typing import Any

import pytest

from bearing_rig_sim.cli import main

CONFIG = Path(__file__).resolve().parents[1] / "config"
TP2275 = CONFIG / "bearings" / "tp2275.yaml"
MIL = CONFIG / "lubricants" / "mil_l_23699.yaml"


REPORT = {28000.0: (350.0, 413.0), 48000.0: (700.0, 425.0), 64000.0: (1100.0, 435.0), 72000.0: (1400.0, 443.0)}
"""Measured heat generation (W) and outer-ring temperature (K) of the 35 mm bore bearing at
667 N thrust, MIL-L-23699 in at 394 K, by shaft speed (rpm): R. J. Parker, NASA TP-2275
(1984), Fig. 3, as digitised (about +-3 %) in the ADORE manuscript of the public repository
YUXinluhk/BallBearing-Dynamics (paper/manuscript.tex at commit 6953d26, table "Selected NASA
TP-2275 experimental measurements", which gives the outer-ring temperatures, "extracted from
Figs. 3, 6, and 13" of the report; the heat values also in paper/data/nasa_validation.csv). A
secondary source: the report itself could not be read. The same repository's later manuscript
(paper/manuscript_applsci.tex, commit dd2220c) says instead that per-node temperatures are not
available in TP-2275 for the 35 mm bearing, so the outer-ring values are the weaker of the two."""

HOUSING_DEFICIT_K = (20.0, 35.0)
"""How much cooler than the report's outer ring the twin's runs, K, at every speed: the assumed
housing and shaft (config/bearings/tp2275.yaml, thermal:) lead heat to 22 degC air, while the
report's rig is not described in anything read here (its jet oil at 394 K, its heat exchanger;
the laboratory's 35 mm rig of TP-1732 had provisions for outer-ring cooling). Measured: 22.9-28.8 K. The
band is that deficit, stated, with +-7 K for reading temperatures off the report's figures
(about 1 % of 420 K, twice) and the secant steady-state solver; it is not agreement."""
TREND_K = 8.5
"""The deficit may vary by at most this much over 28 000-72 000 rpm, K: the twin's outer ring
rises with speed as the report's does (measured 30 K, the twin 34.4 K), whatever the housing's
offset; a housing-independent check of the heat's growth with speed reaching the outer ring.
The bound is the reading uncertainty alone: two temperatures read off the report's figures, each
to about 1 % of 420 K (4.2 K)."""


@pytest.fixture(scope="module")
def predictions() -> list[dict[str, Any]]:
    """The twin at the report's four speeds, 667 N, thermal steady state (one run for the module)."""
    speeds = [f"{rpm:.0f}" for rpm in REPORT]
    argv = ["predict", "--bearing", str(TP2275), "--lubricant", str(MIL), "--rpm", *speeds, "--load", "667", "--thermal", "--json"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(argv) == 0
    return [json.loads(line) for line in out.getvalue().splitlines()]


@pytest.mark.slow
def test_tp2275_heat_generation_against_the_reports_measurements(predictions: list[dict[str, Any]]) -> None:
    """28 000-72 000 rpm at 667 N, oil in at 394 K, no tuning and no calibration: the heat is
    within a factor of 2 of the report's measured heat generation at every speed (SHABERTH's own
    comparison in the report is of that order; the twin gives 0.6-1.6 x, docs/thermal.md), it
    grows with speed, and the jet carries at most all of it (housing and shaft lead the rest to
    the colder ambient), so the lubricant's rise over the inlet is below power / (rho Q c_p)."""
    rows = predictions
    powers = [r["power_loss_w"] for r in rows]
    assert powers == sorted(powers) and powers[0] > 0.0
    jet = 1000.0 * 3.15e-5 * 2000.0  # rho Q c_p of the file's jet, W/K (density at 15 degC: an upper bound)
    for r in rows:
        measured_w, _ = REPORT[r["rpm"]]
        assert 0.5 <= r["power_loss_w"] / measured_w <= 2.0, (r["rpm"], r["power_loss_w"], measured_w)
        assert "slip_pct_low" not in r
        rise = r["lubricant_temperature_c"] - 120.85
        assert rise < 1.05 * r["power_loss_w"] / jet
        assert sum(r["heat_w"].values()) == pytest.approx(r["power_loss_w"], rel=2e-3)
    assert rows[-1]["lubricant_temperature_c"] > 120.85


@pytest.mark.slow
def test_tp2275_outer_ring_temperature_against_the_reports_measurements(predictions: list[dict[str, Any]]) -> None:
    """The outer ring at thermal steady state against the report's measured outer-ring
    temperatures (413 / 425 / 435 / 443 K): cooler by the assumed housing's deficit
    (:data:`HOUSING_DEFICIT_K`) at every speed, and rising with speed as the measured one does
    (:data:`TREND_K`)."""
    deficits = []
    for r in predictions:
        _, measured_k = REPORT[r["rpm"]]
        deficit = measured_k - (r["outer_ring_temperature_c"] + 273.15)
        assert HOUSING_DEFICIT_K[0] <= deficit <= HOUSING_DEFICIT_K[1], (r["rpm"], r["outer_ring_temperature_c"], measured_k)
        deficits.append(deficit)
    assert max(deficits) - min(deficits) <= TREND_K, deficits


@pytest.mark.parametrize(
    ("name", "old", "new", "key"),
    [
        ("bearings/tp2275.yaml", "    mass_kg: {value: 5.0,", "    mass_kg: {value: 50.0,", "thermal.housing.mass_kg"),
        ("bearings/tp2275.yaml", "  oil_inlet_temperature_c: {value: 120.85,", "  oil_inlet_temperature_c: {value: 160.85,", "thermal.oil_inlet_temperature_c"),
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
