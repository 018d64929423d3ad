"""The operating map's skid boundary and the SKF minimum axial load rule."""

from __future__ import annotations

from pathlib import Path

import pyarrow as pa
import pytest

from bearing_rig_sim.sweep.operating_map import boundaries, plot_operating_map, skf_minimum_axial_load, skid_boundary


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
