"""The operating map's skid boundary and the SKF minimum axial load rule, and a map that scales:
a 100 x 100 sweep is a coloured map with its boundaries, not 200 lines."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pyarrow as pa
import pytest
from matplotlib.collections import QuadMesh

from bearing_rig_sim.sweep.operating_map import boundaries, operating_map_figure, plot_operating_map, skf_minimum_axial_load, skid_boundary


def test_skf_minimum_axial_load_by_hand() -> None:
    """F_am = A (n/1000)^2 kN: A = 0.0025 kN at 9000 rpm gives 0.0025 x 81 kN = 202.5 N, and a
    quarter of that at half the speed."""
    assert skf_minimum_axial_load(9000.0, 0.0025) == pytest.approx(202.5)
    assert skf_minimum_axial_load(4500.0, 0.0025) == pytest.approx(202.5 / 4)


def test_skid_boundary_is_the_smallest_load_from_which_slip_stays_low() -> None:
    loads = [50, 100, 150, 200, 250]
    assert skid_boundary(loads, [80, 60, 5, 3, 2], 20.0) == 150
    assert skid_boundary(loads[::-1], [2, 3, 5, 60, 80], 20.0) == 150  # order of the rows does not matter
    assert skid_boundary(loads, [5, 60, 5, 3, 2], 20.0) == 150  # a skidding load above a rolling one counts
    assert skid_boundary(loads, [5, 4, 3, 2, 1], 20.0) == 50
    assert skid_boundary(loads, [80, 70, 60, 50, 40], 20.0) is None
    assert skid_boundary(loads, [80, 5, float("nan"), 3, 2], 20.0) == 200
    # several rows per load (sampled parameters): a load rolls when every row at it rolls
    assert skid_boundary([200, 200, 300, 300, 300, 400, 400], [70, 3, 2, 64, 2, 2, 1], 20.0) == 400


def test_the_map_is_drawn_from_a_table(tmp_path: Path) -> None:
    table = pa.table(
        {
            "branch": ["rolling_start"] * 3 + ["continuation"] * 3,
            "rpm": [5000.0] * 6,
            "axial_load_n": [100.0, 200.0, 300.0] * 2,
            "slip_pct": [70.0, 4.0, 2.7, 70.0, 65.0, 55.0],
        }
    )
    assert boundaries(table, 20.0) == {"rolling_start": {5000.0: 200.0}, "continuation": {5000.0: None}}
    out = plot_operating_map(table, tmp_path / "map.png", 20.0, 0.0025, "test")
    assert out.stat().st_size > 1000 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def synthetic_table(speeds: np.ndarray, loads: np.ndarray, continuation: bool = False) -> pa.Table:
    """A steady sweep whose slip falls with load as S = 60 exp(-F / L(n)) + 0.5 %, L = 20 N +
    0.05 N/rpm n: the skid boundary at 20 % lies at F = L ln(60 / 19.5) (by hand)."""
    n, f = (a.ravel() for a in np.meshgrid(speeds, loads, indexing="ij"))
    slip = 60.0 * np.exp(-f / (20.0 + 0.05 * n)) + 0.5
    branches = ["rolling_start"] + (["continuation"] if continuation else [])
    return pa.table(
        {
            "branch": [b for b in branches for _ in range(n.size)],
            "rpm": np.tile(n, len(branches)),
            "axial_load_n": np.tile(f, len(branches)),
            "slip_pct": np.tile(slip, len(branches)),
        }
    )


def test_a_100_by_100_sweep_is_a_map_with_a_colour_bar_and_its_boundaries(tmp_path: Path) -> None:
    speeds, loads = np.arange(100, 10_001, 100, dtype=float), np.arange(10, 1001, 10, dtype=float)
    table = synthetic_table(speeds, loads)
    fig = operating_map_figure(table, 20.0, 0.0025)
    try:
        maps = [ax for ax in fig.axes if ax.get_xlabel() == "axial load F_a (N)" and any(isinstance(c, QuadMesh) for c in ax.collections)]
        assert len(maps) == 1, "one map; no panel of 100 lines"
        (ax,) = maps
        (mesh,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
        assert mesh.get_array().size == 100 * 100 and mesh.colorbar is not None
        assert mesh.colorbar.ax.get_ylabel() == "cage slip S_c (%)"
        legend = ax.get_legend()
        assert legend is not None and len(legend.get_texts()) <= 3, [t.get_text() for t in legend.get_texts()]
        assert all(other.get_legend() is None for other in fig.axes if other is not ax), "no other legend"
        (boundary,) = [line for line in ax.get_lines() if line.get_label() == "skid boundary, rolling start"]
        crossing = (20.0 + 0.05 * speeds) * np.log(60.0 / 19.5)
        expected = loads[np.searchsorted(loads, crossing, side="right")]  # the first grid load above the crossing
        assert np.array_equal(np.asarray(boundary.get_xdata(), dtype=float), expected)
        assert np.array_equal(np.asarray(boundary.get_ydata(), dtype=float), speeds)
    finally:
        plt.close(fig)
    out = plot_operating_map(synthetic_table(speeds, loads, continuation=True), tmp_path / "map.png", 20.0, 0.0025, "100 x 100")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_handful_of_speeds_keeps_its_lines_beside_the_map() -> None:
    speeds, loads = np.array([1000.0, 5000.0, 9000.0]), np.arange(50, 701, 10, dtype=float)
    fig = operating_map_figure(synthetic_table(speeds, loads, continuation=True), 20.0, 0.0025)
    try:
        lines = [ax for ax in fig.axes if ax.get_title() == "slip against load"]
        assert len(lines) == 1 and len(lines[0].get_legend().get_texts()) == 2 * len(speeds)
        assert sum(ax.get_xlabel() == "axial load F_a (N)" and any(isinstance(c, QuadMesh) for c in ax.collections) for ax in fig.axes) == 1
    finally:
        plt.close(fig)
