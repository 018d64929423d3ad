"""Sweep specifications: axes with units, grids and random samples, errors naming the key."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.sweep.spec import load_spec


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "spec.yaml"
    path.write_text(text, encoding="utf-8")
    return path


HEAD = "sweep: {name: t}\n"


def test_the_shipped_paper_grid_has_330_points() -> None:
    spec = load_spec(config_path("sweeps", "paper_load_grid.yaml"))
    points = spec.points()
    assert len(points) == 5 * 66 == 330
    assert spec.grid["inner_ring_speed_rpm"] == (1000, 3000, 5000, 7000, 9000)
    loads = spec.grid["axial_load_n"]
    assert loads[0] == 50.0 and loads[-1] == 700.0 and np.allclose(np.diff(loads), 10.0)
    assert len({(p["inner_ring_speed_rpm"], p["axial_load_n"]) for p in points}) == 330
    assert not spec.transient


@pytest.mark.parametrize(
    ("grid", "key", "problem"),
    [
        ("{inner_ring_speed_rpm: [1000], axial_load_n: [100], ball_size_m: [0.006]}", "grid.ball_size_m", "unknown axis"),
        ("{inner_ring_speed_rpm: [1000], axial_load_n: [100, -5]}", "grid.axial_load_n[1]", ">= 1.0"),
        ("{inner_ring_speed_rpm: [1000], axial_load_n: [.nan]}", "grid.axial_load_n[0]", "finite"),
        ("{inner_ring_speed_rpm: [1000], axial_load_n: {from: 700, to: 50, step: 10}}", "grid.axial_load_n.to", "empty"),
        ("{inner_ring_speed_rpm: [], axial_load_n: [100]}", "grid.inner_ring_speed_rpm", "empty"),
        ("{inner_ring_speed_rpm: [1000], axial_load_n: {from: 50, to: 700, step: 0}}", "grid.axial_load_n.step", "> 0"),
        ("{inner_ring_speed_rpm: [1000, 1000], axial_load_n: [100]}", "grid.inner_ring_speed_rpm", "repeated"),
    ],
)
def test_a_bad_axis_is_refused_naming_the_key(tmp_path: Path, grid: str, key: str, problem: str) -> None:
    path = write(tmp_path, HEAD + f"grid: {grid}\n")
    with pytest.raises(ConfigError) as info:
        load_spec(path)
    assert info.value.key == key
    assert problem in info.value.problem
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_speed_and_acceleration_together_are_refused(tmp_path: Path) -> None:
    path = write(tmp_path, HEAD + "grid: {inner_ring_speed_rpm: [1000], inner_ring_acceleration_rad_s2: [20], axial_load_n: [200]}\n")
    with pytest.raises(ConfigError, match="exactly one of"):
        load_spec(path)


def test_a_run_up_takes_a_combined_load(tmp_path: Path) -> None:
    """Transient points cross the radial-load and moment axes as steady ones do."""
    path = write(tmp_path, HEAD + "grid: {inner_ring_acceleration_rad_s2: [20], axial_load_n: [200], radial_load_n: [0, 100], moment_n_m: [1]}\n")
    spec = load_spec(path)
    assert spec.transient
    assert sorted(p["radial_load_n"] for p in spec.points()) == [0.0, 100.0]
    assert all(p["moment_n_m"] == 1.0 for p in spec.points())


def test_radial_load_and_moment_axes_cross_the_grid(tmp_path: Path) -> None:
    text = HEAD + "grid: {inner_ring_speed_rpm: [900, 2700], axial_load_n: [163], radial_load_n: [0, 250, 500]}\n"
    text += "samples: {method: sobol, count: 2, ranges: {moment_n_m: [-2, 2]}}\n"
    spec = load_spec(write(tmp_path, text))
    assert len(spec.points()) == 2 * 3 * 2
    assert spec.axis_names == ("inner_ring_speed_rpm", "axial_load_n", "radial_load_n", "moment_n_m")
    assert not spec.transient
    bad = HEAD + "grid: {inner_ring_speed_rpm: [900], axial_load_n: [163], radial_load_n: [-1]}\n"
    with pytest.raises(ConfigError) as info:
        load_spec(write(tmp_path, bad))
    assert info.value.key == "grid.radial_load_n[0]"


def test_a_bad_sample_range_is_refused_naming_the_key(tmp_path: Path) -> None:
    text = HEAD + "grid: {inner_ring_speed_rpm: [1000], axial_load_n: [100]}\n"
    text += "samples: {method: sobol, count: 4, ranges: {ball_diameter_m: [0.0063, 0.0063]}}\n"
    with pytest.raises(ConfigError) as info:
        load_spec(write(tmp_path, text))
    assert info.value.key == "samples.ranges.ball_diameter_m" and "empty" in info.value.problem


def test_latin_hypercube_samples_fill_each_stratum_once_and_cross_the_grid(tmp_path: Path) -> None:
    """The defining property of a Latin hypercube (McKay, Beckman and Conover 1979): with n
    samples, each of the n equal intervals of every axis holds exactly one sample."""
    n = 8
    lo, hi = 0.0062, 0.0064
    text = HEAD + "grid: {inner_ring_speed_rpm: [1000, 2000], axial_load_n: [100]}\n"
    text += f"samples: {{method: latin_hypercube, count: {n}, seed: 3, ranges: {{ball_diameter_m: [{lo}, {hi}], oil_volume_fraction: [0.005, 0.02]}}}}\n"
    spec = load_spec(write(tmp_path, text))
    assert len(spec.samples) == n
    dw = np.array([s["ball_diameter_m"] for s in spec.samples])
    assert sorted(np.floor((dw - lo) / (hi - lo) * n).astype(int).tolist()) == list(range(n))
    points = spec.points()
    assert len(points) == 2 * n
    assert set(spec.axis_names) == {"inner_ring_speed_rpm", "axial_load_n", "ball_diameter_m", "oil_volume_fraction"}


def test_sobol_samples_stay_in_their_range_and_are_reproducible(tmp_path: Path) -> None:
    text = HEAD + "grid: {inner_ring_speed_rpm: [1000], axial_load_n: [100]}\n"
    text += "samples: {method: sobol, count: 16, seed: 5, ranges: {ball_drag_scale: [100, 5000]}}\n"
    a = load_spec(write(tmp_path, text))
    b = load_spec(write(tmp_path, text))
    values = [s["ball_drag_scale"] for s in a.samples]
    assert all(100.0 <= v <= 5000.0 for v in values) and len(set(values)) == 16
    assert a.samples == b.samples and a.spec_hash == b.spec_hash
    assert not any(math.isnan(v) for v in values)


def test_the_command_refuses_a_bad_spec_in_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from bearing_rig_sim.cli import main

    path = write(tmp_path, HEAD + "grid: {inner_ring_speed_rpm: [1000], axial_load_n: [-5]}\n")
    assert main(["sweep", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("bearing-rig: error:") and "grid.axial_load_n[0]" in err and "\n" not in err
    assert not (tmp_path / "out").exists()


def test_every_shipped_sweep_spec_is_valid() -> None:
    specs = sorted(config_path("sweeps", "paper_load_grid.yaml").parent.glob("*.yaml"))
    assert len(specs) >= 2
    for path in specs:
        spec = load_spec(path)
        assert spec.points(), path
    scatter = load_spec(config_path("sweeps", "tolerance_scatter.yaml"))
    assert len(scatter.points()) == 3 * 64
