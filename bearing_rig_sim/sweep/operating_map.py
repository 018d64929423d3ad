"""The operating map of a steady sweep: slip over inner-ring speed x axial load.

The map is the (load, speed) plane coloured by the slip from the rolling start (a colour bar,
logarithmic in both signs: :data:`SLIP_LINEAR_PCT`), with the skid boundary of each branch (:func:`skid_boundary`) and the SKF minimum axial
load rule (:func:`skf_minimum_axial_load`) drawn over it. With a handful of speeds
(:data:`HANDFUL_OF_SPEEDS`) a second panel beside it shows slip against load, one line per speed
and branch; beyond that the lines would be a tangle and their legend a list, so the continued
branch (where a continuation was run) gets a map of its own instead.
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
    branches, speeds, loads, slips = _columns(table)
    out: dict[str, dict[float, float | None]] = {}
    for branch in (KIND_ROLLING_START, KIND_CONTINUATION):
        sel = branches == branch
        if not sel.any():
            continue
        out[branch] = {}
        for rpm in sorted(set(speeds[sel].tolist())):
            row = sel & (speeds == rpm)
            out[branch][float(rpm)] = skid_boundary(loads[row], slips[row], threshold_pct)
    return out


HANDFUL_OF_SPEEDS = 6
"""Most speeds drawn as lines of slip against load (each with a legend entry); more are a map only."""

SLIP_LINEAR_PCT = 0.1
"""Slip below which (in magnitude) the colour scale is linear, %: above it logarithmic, so that
20 % and 0.2 % differ as much as 2 % and 0.02 % would not; a negative slip (a cage ahead of its
speed at the nominal contact angle, under large loads) keeps its sign."""


def _columns(table: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """branch, rpm, axial load and slip of a result table (a pyarrow Table or a mapping of columns)."""
    get = {k: table[k].to_pylist() if hasattr(table[k], "to_pylist") else table[k] for k in ("branch", "rpm", "axial_load_n", "slip_pct")}
    return (
        np.asarray(get["branch"]),
        np.asarray(get["rpm"], dtype=float),
        np.asarray(get["axial_load_n"], dtype=float),
        np.asarray(get["slip_pct"], dtype=float),
    )


def slip_grid(branch: np.ndarray, rpm: np.ndarray, load: np.ndarray, slip: np.ndarray, which: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The slip of branch ``which`` on the grid of the sweep's speeds x loads: (speeds, loads,
    slip[speed, load]), the median where several rows share a point (sampled parameters) and NaN
    where a point is missing or failed."""
    sel = (branch == which) & np.isfinite(rpm) & np.isfinite(load)
    speeds, loads = np.unique(rpm[sel]), np.unique(load[sel])
    grid = np.full((len(speeds), len(loads)), np.nan)
    i, j = np.searchsorted(speeds, rpm[sel]), np.searchsorted(loads, load[sel])
    for (a, b), value in _medians(i, j, slip[sel]).items():
        grid[a, b] = value
    return speeds, loads, grid


def _medians(i: np.ndarray, j: np.ndarray, values: np.ndarray) -> dict[tuple[int, int], float]:
    groups: dict[tuple[int, int], list[float]] = {}
    for a, b, v in zip(i.tolist(), j.tolist(), values.tolist()):
        if math.isfinite(v):
            groups.setdefault((a, b), []).append(v)
    return {key: float(np.median(vs)) for key, vs in groups.items()}


def _map_panel(ax: Any, speeds: np.ndarray, loads: np.ndarray, grid: np.ndarray, norm: Any) -> Any:
    """The slip map of one branch (NaN cells left blank); returns the mesh for the colour bar."""
    mesh = ax.pcolormesh(loads, speeds, np.ma.masked_invalid(grid), shading="nearest", cmap="viridis", norm=norm)
    ax.set_xlabel("axial load F_a (N)")
    ax.set_ylabel("inner-ring speed n_i (rpm)")
    return mesh


def _boundaries_over(ax: Any, found: dict[str, dict[float, float | None]], branches: Sequence[str], speeds: Sequence[float], factor_kn: float) -> None:
    """The skid boundary of each of ``branches`` and the SKF minimum axial load over a map (its
    load range kept)."""
    from matplotlib import patheffects

    xlim = ax.get_xlim()
    for b, style, label in (
        (KIND_ROLLING_START, "w-", "skid boundary, rolling start"),
        (KIND_CONTINUATION, "r--", "skid boundary, continued from lower loads"),
    ):
        if b in found and b in branches:
            xs = [v if v is not None else math.nan for v in found[b].values()]
            outline = [patheffects.withStroke(linewidth=3.2, foreground="black")] if b == KIND_ROLLING_START else []
            ax.plot(xs, list(found[b]), style, lw=1.6, label=label, path_effects=outline)
    if len(speeds):
        n = np.linspace(min(speeds), max(speeds), 100)
        ax.plot(skf_minimum_axial_load(n, factor_kn), n, "k:", lw=1.4, label=f"SKF minimum axial load, A = {factor_kn:g} kN")
    ax.set_xlim(xlim)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, frameon=False)


def _lines_panel(ax: Any, branch: np.ndarray, rpm: np.ndarray, load: np.ndarray, slip: np.ndarray, speeds: Sequence[float], threshold_pct: float) -> None:
    """Slip against load, one line per speed and branch (a handful of speeds only)."""
    import matplotlib.pyplot as plt

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
                ax.plot(load[sel][order], slip[sel][order], fmt, color=c, lw=1.2, ms=4, label=f"{n:.0f} rpm, {label}")
    ax.axhline(threshold_pct, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("axial load F_a (N)")
    ax.set_ylabel("cage slip S_c (%)")
    if np.all(slip[np.isfinite(slip)] > 0):
        ax.set_yscale("log")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6)
    ax.set_title("slip against load")


def operating_map_figure(table: Any, threshold_pct: float, factor_kn: float, title: str = "") -> Any:
    """The operating map of a steady sweep table (see the module documentation) as a matplotlib
    figure (Agg backend)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import SymLogNorm

    branch, rpm, load, slip = _columns(table)
    speeds = sorted(set(rpm[np.isfinite(rpm)].tolist()))
    present = [b for b in (KIND_ROLLING_START, KIND_CONTINUATION) if bool((branch == b).any())]
    lines = len(speeds) <= HANDFUL_OF_SPEEDS
    maps = present[:1] if lines else present
    fig, axes = plt.subplots(1, len(maps) + int(lines), figsize=(6.5 * (len(maps) + int(lines)), 4.8), squeeze=False, layout="constrained")
    if lines:
        _lines_panel(axes[0, 0], branch, rpm, load, slip, speeds, threshold_pct)
    finite = slip[np.isfinite(slip)]
    low, high = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    norm = SymLogNorm(linthresh=SLIP_LINEAR_PCT, linscale=0.5, vmin=low, vmax=max(high, low + SLIP_LINEAR_PCT), base=10)
    found = boundaries(table, threshold_pct)
    mesh = None
    for k, (ax, which) in enumerate(zip(axes[0, int(lines) :], maps)):
        mesh = _map_panel(ax, *slip_grid(branch, rpm, load, slip, which), norm)
        ax.set_ylim(max(0.0, ax.get_ylim()[0]), ax.get_ylim()[1])
        if k:  # the maps side by side share the speed axis
            ax.set_ylabel("")
            ax.tick_params(labelleft=False)
        _boundaries_over(ax, found, [which] if not lines else present, speeds, factor_kn)
        name = "from the rolling start" if which == KIND_ROLLING_START else "continued from lower loads"
        ax.set_title(f"slip {name}; skid boundary: slip < {threshold_pct:g} % above it", fontsize=9)
    if mesh is not None:
        fig.colorbar(mesh, ax=list(axes[0, int(lines) :]), label="cage slip S_c (%)")
    if title:
        fig.suptitle(title)
    return fig


def plot_operating_map(table: Any, path: str | Path, threshold_pct: float, factor_kn: float, title: str = "") -> Path:
    """Write the operating map of a steady sweep table as a PNG (:func:`operating_map_figure`);
    return its path."""
    import matplotlib.pyplot as plt

    fig = operating_map_figure(table, threshold_pct, factor_kn, title)
    out = Path(path)
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
