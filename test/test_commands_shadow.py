"""``bearing-rig shadow --bag BAG --out DIR``: residuals.csv, report and plot from a bag of the
bench's three topics, deterministic; bad bags are one-line errors. And ``--recalibrate``."""

from __future__ import annotations

import csv
import re
from pathlib import Path

import pytest

from bearing_rig_sim.bags import BagWriter
from bearing_rig_sim.cli import main
from bearing_rig_sim.shadow import ShadowSettings
from bearing_rig_sim.interfaces import CAGE_PULSES, SPINDLE_PULSES
from bearing_rig_sim.shadow.offline import COLUMNS, PLOT_PNG, REPORT_MD, RESIDUALS_CSV
from bearing_rig_sim.synthetic.twin_bench import Hold, scaled_calibration, twin_bench_run, write_bench_bag

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def bench_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    run = twin_bench_run([Hold(900.0, 3.0), Hold(1800.0, 2.5)], clock_offset_s=1.7e9)
    return write_bench_bag(run, tmp_path_factory.mktemp("bags") / "bench")


def read_rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as stream:
        return list(csv.DictReader(stream))


def test_shadow_bag_writes_residuals_report_and_plot(bench_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    assert main(["shadow", "--bag", str(bench_bag), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "0 flagged" in printed
    with (out / RESIDUALS_CSV).open(newline="") as stream:
        header = next(csv.reader(stream))
    required = ["time_s", "inner_ring_rpm", "axial_load_n", "measured_slip_pct", "predicted_slip_pct", "residual_pct", "band_pct", "anomaly"]
    assert header[: len(required)] == required and tuple(header) == COLUMNS
    rows = read_rows(out / RESIDUALS_CSV)
    # one row per slip window: one cage revolution at 900 rpm is 0.156 s, at 1800 rpm 0.078 s
    assert 3.0 / 0.156 + 2.0 / 0.078 - 5 < len(rows) < 3.0 / 0.156 + 2.5 / 0.078 + 5
    compared = [r for r in rows if r["compared"] == "1"]
    assert len(compared) > 0.8 * len(rows)
    for r in compared:
        assert float(r["residual_pct"]) == pytest.approx(float(r["measured_slip_pct"]) - float(r["predicted_slip_pct"]), abs=2e-4)
        assert abs(float(r["residual_pct"])) <= float(r["band_pct"])
        assert float(r["axial_load_n"]) == pytest.approx(100.0, abs=1.0)
        assert r["anomaly"] == "0"
    assert float(rows[-1]["inner_ring_rpm"]) == pytest.approx(1800.0, rel=1e-3)
    assert float(rows[0]["time_s"]) < 1.0  # counted from the first pulse, not the epoch
    report = (out / REPORT_MD).read_text()
    assert "None: the bench stayed within the twin's band." in report
    # the band's law as residual.band_pct computes it: coverage x the two terms in quadrature, each in pp
    assert re.search(r"Band: [\d.]+ x sqrt\(\(calibration RMS [\d.]+ pp\)\^2 \+ \(100 x 2 x [\d.e-]+ s / window\)\^2\)", report), report[:800]
    assert (out / PLOT_PNG).read_bytes().startswith(PNG_SIGNATURE)


def test_shadow_bag_is_deterministic(bench_bag: Path, tmp_path: Path) -> None:
    for name in ("a", "b"):
        assert main(["shadow", "--bag", str(bench_bag), "--out", str(tmp_path / name)]) == 0
    assert (tmp_path / "a" / RESIDUALS_CSV).read_bytes() == (tmp_path / "b" / RESIDUALS_CSV).read_bytes()
    assert (tmp_path / "a" / REPORT_MD).read_text() == (tmp_path / "b" / REPORT_MD).read_text()


def test_shadow_flags_a_bench_with_other_drag_and_recalibrates(bench_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import yaml

    # the twin assumes a grease 30 % less consistent than the bench's: less drag, slip higher than predicted
    key = "lubricant.consistency_pa_sn"
    shipped = ShadowSettings.from_yaml().calibration_file  # the twin playing the bench runs it too
    assert shipped is not None
    bench_value = yaml.safe_load(shipped.read_text())["parameters"][key]["value"]
    cal = scaled_calibration(shipped, key, 1.0 / 1.3, tmp_path / "low.yaml")
    out = tmp_path / "out"
    saved = tmp_path / "recalibrated.yaml"
    argv = ["shadow", "--bag", str(bench_bag), "--out", str(out), "--calibration", str(cal), "--recalibrate", key, "--save-calibration", str(saved)]
    assert main(argv) == 1
    printed = capsys.readouterr().out
    assert "slip higher than predicted" in printed and f"re-calibrated {key}" in printed
    rows = read_rows(out / RESIDUALS_CSV)
    assert any(r["anomaly"] == "1" and r["level"] == "2" for r in rows)
    report = (out / REPORT_MD).read_text()
    assert "| ERROR |" in report and "Not written to the calibration file." in report
    line = next(x for x in report.splitlines() if x.startswith(f"`{key}`"))
    value = float(line.split(": ", 1)[1].split(" ")[0])
    assert value == pytest.approx(bench_value, rel=0.03)  # the bench's calibrated consistency
    assert yaml.safe_load(shipped.read_text())["parameters"][key]["value"] == bench_value
    # written only where asked, and loadable as a calibration
    assert yaml.safe_load(cal.read_text())["parameters"][key]["value"] == pytest.approx(bench_value / 1.3)
    assert yaml.safe_load(saved.read_text())["parameters"][key]["value"] == pytest.approx(value, rel=1e-5)
    from bearing_rig_sim.dynamics import BearingParameters

    assert BearingParameters.from_yaml(None, saved).lubricant is not None


def test_shadow_bag_without_the_load_cell_is_a_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with BagWriter(tmp_path / "pulses") as bag:
        for topic in (SPINDLE_PULSES, CAGE_PULSES):
            bag.add_topic(topic.name, topic.msgtype, topic.qos)
    assert main(["shadow", "--bag", str(tmp_path / "pulses"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("bearing-rig: error: ") and "/rig/axial_load/force" in err[0]
    assert not (tmp_path / "out" / RESIDUALS_CSV).exists()


def test_shadow_missing_calibration_file_is_a_one_line_error(bench_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["shadow", "--bag", str(bench_bag), "--calibration", str(tmp_path / "none.yaml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "none.yaml" in err[0] and "not found" in err[0]


def test_bench_shadow_reports_its_figures(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    assert main(["bench", "shadow", "--json", "--rpm", "1800", "--bench-seconds", "1", "--repeats", "1", "--recalibrate", "off"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(rows) == 1
    row = rows[0]
    keys = {"rtf", "rtf_min", "message_p99_ms", "residual_wait_p50_ms", "residual_wait_p99_ms", "residual_latency_p99_ms", "windows"}
    assert keys <= row.keys()
    # 1.5 s of bench at up to 1800 rpm: a cage revolution every 0.078 s at speed
    assert 8 <= row["windows"] <= 1.5 / 0.078 + 1
    # the residual waits for the engine, which runs half a spindle revolution (16.7 ms) behind
    assert row["residual_wait_p50_ms"] >= 16.0
