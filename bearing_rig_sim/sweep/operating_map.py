"""The operating map of a steady sweep: slip over inner-ring speed x axial load.

Two panels: slip against load for each speed (both branches where a continuation was run), and
the (load, speed) plane with the skid boundary of each branch (:func:`skid_boundary`) beside the
SKF minimum axial load rule (:func:`skf_minimum_axial_load`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any
from collections.abc import Sequence

import numpy as np

from bearing_rig_sim.sweep.points import KIND_CONTINUATION, KIND_ROLLING_START


def skf_minimum_axial_load(rpm: float | np.ndarray, factor_kn: float) -> float | np.ndarray:
    """SKF's minimum axial load of a single angular contact ball bearing, N.

    F_am = A (n / 1000)^2 in kN with A the minimum load factor (kN) of the product tables and n
    the speed in rpm (SKF rolling bearings catalogue, "Angular contact ball bearings: minimum
    load"). Below it, centrifugal and gyroscopic forces can make the balls slide.
    """
    n = np.asarray(rpm, dtype=float) / 1000.0
    result = 1000.0 * factor_kn * n * n
    return float(result) if np.ndim(result) == 0 else result


def skid_boundary(loads: Sequence[float], slips: Sequence[float], threshold_pct: float) -> float | None:
    """The smallest load (N) from which every larger load of the row has slip below
    ``threshold_pct``; ``None`` if the largest load still skids. NaN slips count as skidding.
    With several rows per load (sampled parameters) a load counts as rolling when all roll."""
    x = np.asarray(loads, dtype=float)
    y = np.asarray(slips, dtype=float)
    levels = np.unique(x)
    bad = np.array([not np.all(y[x == level] < threshold_pct) for level in levels])
    if bad[-1]:
        return None
    if not bad.any():
        return float(levels[0])
    return float(levels[int(np.flatnonzero(bad)[-1]) + 1])


def boundaries(table: Any, threshold_pct: float) -> dict[str, dict[float, float | None]]:
    """Skid boundary per branch and speed (rpm) of a result table (a pyarrow Table or a
    mapping of columns)."""
    cols = {k: np.asarray(table[k].to_pylist() if hasattr(table[k], "to_pylist") else table[k]) for k in ("branch", "rpm", "axial_load_n", "slip_pct")}
    out: dict[str, dict[float, float | None]] = {}
    for branch in (KIND_ROLLING_START, KIND_CONTINUATION):
        sel = cols["branch"] == branch
        if not sel.any():
            continue
        out[branch] = {}
        for rpm in sorted(set(cols["rpm"][sel].tolist())):
            row = sel & (cols["rpm"] == rpm)
            out[branch][float(rpm)] = skid_boundary(cols["axial_load_n"][row], cols["slip_pct"][row], threshold_pct)
    return out


def _slip_field(fig: Any, ax: Any, branch: np.ndarray, rpm: np.ndarray, load: np.ndarray, slip: np.ndarray) -> None:
    """Colour the (load, speed) plane by the rolling-start slip where the rows form a full grid
    (one row per speed and load)."""
    from matplotlib.colors import LogNorm

    sel = (branch == KIND_ROLLING_START) & np.isfinite(rpm) & np.isfinite(slip)
    speeds, loads = np.unique(rpm[sel]), np.unique(load[sel])
    if len(speeds) < 2 or len(loads) < 2 or int(sel.sum()) != len(speeds) * len(loads):
        return
    grid = np.full((len(speeds), len(loads)), np.nan)
    grid[np.searchsorted(speeds, rpm[sel]), np.searchsorted(loads, load[sel])] = slip[sel]
    if np.isnan(grid).any() or not np.all(grid > 0.0):
        return
    mesh = ax.pcolormesh(loads, speeds, grid, shading="nearest", cmap="viridis", norm=LogNorm(), alpha=0.6)
    fig.colorbar(mesh, ax=ax, label="slip from the rolling start S_c (%)")


def plot_operating_map(table: Any, path: str | Path, threshold_pct: float, factor_kn: float, title: str = "") -> Path:
    """Write the operating map of a steady sweep table as a PNG; return its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    branch = np.asarray(table["branch"].to_pylist())
    rpm = np.asarray(table["rpm"].to_pylist(), dtype=float)
    load = np.asarray(table["axial_load_n"].to_pylist(), dtype=float)
    slip = np.asarray(table["slip_pct"].to_pylist(), dtype=float)
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 4.8))
    speeds = sorted(set(rpm[np.isfinite(rpm)].tolist()))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, n in enumerate(speeds):
        c = colours[i % len(colours)]
        for b, style, label in ((KIND_ROLLING_START, "-", "from the rolling start"), (KIND_CONTINUATION, "--", "continued from lower loads")):
            sel = (branch == b) & (rpm == n)
            if sel.any():
                order = np.argsort(load[sel])
                # several rows per load (sampled parameters): points, not a line through them
                scatter = len(np.unique(load[sel])) < int(sel.sum())
                fmt = ("." if b == KIND_ROLLING_START else "x") if scatter else style
                left.plot(load[sel][order], slip[sel][order], fmt, color=c, lw=1.2, ms=4, label=f"{n:.0f} rpm, {label}")
    left.axhline(threshold_pct, color="grey", lw=0.8, ls=":")
    left.set_xlabel("axial load F_a (N)")
    left.set_ylabel("cage slip S_c (%)")
    if np.all(slip[np.isfinite(slip)] > 0):
        left.set_yscale("log")
    left.grid(alpha=0.3)
    left.legend(fontsize=6)
    left.set_title("slip against load")
    _slip_field(fig, right, branch, rpm, load, slip)
    found = boundaries(table, threshold_pct)
    for b, marker, label in (
        (KIND_ROLLING_START, "o-", "skid boundary, rolling start"),
        (KIND_CONTINUATION, "s--", "skid boundary, continued from lower loads"),
    ):
        if b in found:
            xs = [v if v is not None else math.nan for v in found[b].values()]
            right.plot(xs, list(found[b]), marker, label=label)
    if speeds:
        n = np.linspace(0.0, max(speeds) * 1.05, 100)
        right.plot(skf_minimum_axial_load(n, factor_kn), n, "k:", label=f"SKF minimum axial load, A = {factor_kn:g} kN")
    right.set_xlabel("axial load F_a (N)")
    right.set_ylabel("inner-ring speed n_i (rpm)")
    right.set_title(f"skid boundary: smallest load with slip < {threshold_pct:g} % above it")
    right.grid(alpha=0.3)
    right.legend(fontsize=7)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
