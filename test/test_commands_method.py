"""The method's command line: ``calibrate``, ``predict`` and ``reproduce`` (issue 4)."""

from __future__ import annotations

import math

import csv
import json
from pathlib import Path

import pytest

from bearing_rig_sim.cli import main
from bearing_rig_sim.config import config_path
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.studies.paper_data import PAPER_TABLE3


def test_predict_prints_one_json_object_per_point(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["predict", "--rpm", "1200", "2400", "--load", "100", "--calibration", "isothermal", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["rpm"] for r in rows] == [1200.0, 2400.0]
    assert set(rows[0]) == {
        "rpm",
        "axial_load_n",
        "cage_rpm",
        "slip_pct",
        "slip_pct_low",
        "slip_pct_high",
        "friction_torque_nm",
        "power_loss_w",
        "film_min_um",
        "lambda_ratio",
        "slip_loaded_pct",
        "loaded_contact_angle_deg",
        "gross_skid",
        "model",
    }
    assert {r["model"] for r in rows} == {"bench"} and not any(r["gross_skid"] for r in rows)
    assert all(r["slip_pct_low"] < r["slip_pct"] < r["slip_pct_high"] for r in rows)
    assert rows[1]["power_loss_w"] > rows[0]["power_loss_w"] > 0.0
    assert rows[0]["power_loss_w"] == pytest.approx(rows[0]["friction_torque_nm"] * 1200 * 2 * 3.141592653589793 / 60, rel=1e-3)
    assert 0.0 < rows[0]["film_min_um"]["inner"] < 1.0 and 0.0 < rows[0]["film_min_um"]["outer"] < 1.0
    g = BearingParameters.from_yaml()
    for r in rows:  # cage speed and slip are consistent with Eq. 11-12 at the nominal and the loaded angle
        ratio = g.epicyclic_ratio
        assert r["slip_pct"] == pytest.approx((1 - r["cage_rpm"] / (ratio * r["rpm"])) * 100, abs=2e-3)
        loaded = 0.5 * (1.0 - g.ball_diameter * math.cos(math.radians(r["loaded_contact_angle_deg"])) / g.pitch_diameter)
        assert r["slip_loaded_pct"] == pytest.approx((1 - r["cage_rpm"] / (loaded * r["rpm"])) * 100, abs=2e-3)
        # the loaded angle at 100 N: 16.3 deg (docs/method.md, Harris's thrust equilibrium, hand-checked there)
        assert r["loaded_contact_angle_deg"] == pytest.approx(16.3, abs=0.05)


def test_predict_takes_several_loads_at_one_speed_and_the_paper_model(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["predict", "--model", "paper", "--rpm", "1000", "--load", "50", "100", "700", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(r["rpm"], r["axial_load_n"], r["model"]) for r in rows] == [(1000.0, 50.0, "paper"), (1000.0, 100.0, "paper"), (1000.0, 700.0, "paper")]
    assert all("slip_pct_low" not in r for r in rows)  # a model of a model: no bench interval
    assert rows[0]["slip_pct"] > rows[1]["slip_pct"] > rows[2]["slip_pct"]


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["--rpm", "1000", "--load", "nan"], "--load"),
        (["--rpm", "-5", "--load", "100"], "--rpm"),
        (["--rpm", "1000", "2000", "--load", "1", "2", "3"], "one per speed"),
    ],
)
def test_predict_refuses_bad_values(capsys: pytest.CaptureFixture[str], argv: list[str], needle: str) -> None:
    assert main(["predict", *argv]) == 2
    err = capsys.readouterr().err
    assert needle in err and len(err.strip().splitlines()) == 1


def test_calibrate_writes_a_usable_file_and_prints_the_rms(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "cal.yaml"
    assert main(["calibrate", str(config_path("calibration", "h7006c_table3.csv")), "--out", str(out), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["rms_slip_pct"] < 0.15 and set(result["fitted"]) == {"yield_stress", "consistency"}
    params = BearingParameters.from_yaml(None, out)
    assert params.lubricant is not None
    assert params.lubricant.consistency == pytest.approx(result["fitted"]["consistency"], rel=1e-5)


def test_calibrate_refuses_a_fit_outside_the_physical_range(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Bench slip far above what any plausible grease gives: non-zero exit naming the parameter,
    no file written."""
    data = tmp_path / "skid.csv"
    data.write_text("inner_ring_rpm,axial_load_n,slip_pct\n900,700,30\n2700,700,40\n")
    out = tmp_path / "cal.yaml"
    assert main(["calibrate", str(data), "--out", str(out)]) != 0
    err = capsys.readouterr().err
    assert ("yield_stress" in err or "consistency" in err) and "range" in err
    assert not out.exists()


def test_reproduce_writes_csvs_figures_and_report_then_reuses_its_cache(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["reproduce", "--out", str(tmp_path), "--quiet"]) == 0
    assert "ran the experiments" in capsys.readouterr().out
    both = (tmp_path / "report.md").read_text()  # the two models beside the paper's tables
    for rpm, (bench, paper) in PAPER_TABLE3.items():
        assert f"| {rpm} | {bench:.2f} | {paper:.2f} |" in both
    for heading in ("## Table 3", "## Table 5", "## Load sweep", "## Table 7", "## Run-up slip at equal", "## Where and why"):
        assert heading in both
    for model in ("bench", "paper"):
        for name in ("validation.csv", "load_sweep.csv", "acceleration.csv", "report.md"):
            assert (tmp_path / model / name).stat().st_size > 100
    tmp_path = tmp_path / "bench"  # the bench twin's own report
    for k in range(5, 11):
        png = next(tmp_path.glob(f"fig{k:02d}_*.png"))
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    with (tmp_path / "validation.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [round(float(r["rpm"])) for r in rows] == [900, 1200, 1500, 1800, 2100, 2400, 2700]
    report = (tmp_path / "report.md").read_text()
    for rpm, (bench, paper) in PAPER_TABLE3.items():  # the paper's numbers stand beside the twin's
        assert f"| {rpm} | {bench:.3g} | {paper:.3g} |" in report
    with (tmp_path / "acceleration.csv").open() as fh:
        assert {float(r["acceleration_rad_s2"]) for r in csv.DictReader(fh)} == {20.0, 40.0, 60.0, 80.0}
    assert main(["reproduce", "--out", str(tmp_path.parent), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert printed.count("reused cached results") == 2
    # no fit outside the gates: every row of the acceleration table has lambda below 100 % or says why
    section = report.split("## Constant acceleration", 1)[1].split("###", 1)[0]
    rows = [line.split(" | ") for line in section.splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert len(rows) == 4
    for cells in rows:
        assert cells[4].startswith("no fit: ") or 0.0 < float(cells[4]) < 100.0
    for line in printed.splitlines():
        if "rad/s^2" in line:
            assert "stable from" in line or "no fit: " in line
