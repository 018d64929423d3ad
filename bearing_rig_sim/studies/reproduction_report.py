"""The reproduction's REPORT: the paper's method applied to the raw results of
:mod:`bearing_rig_sim.studies.reproduction`, CSVs, figures and ``report.md`` (with the SKF
frictional-moment model's estimate beside the twin's friction torque)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any
from collections.abc import Callable

import numpy as np

from bearing_rig_sim import __version__
from bearing_rig_sim.analysis.gaussian import GaussianFit, fit_gaussians, select_gaussian_fit
from bearing_rig_sim.analysis.stability import K1_AXIAL_LOAD, K2_TIME, stable_onset
from bearing_rig_sim.config import rad_s_to_rpm
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.lubrication import skf_frictional_moment
from bearing_rig_sim.studies.calibration import SteadyState
from bearing_rig_sim.studies.experiments import SWEEP_LOADS_N
from bearing_rig_sim.studies.reproduction import (
    K1_FRACTION_READING,
    PAPER_TABLE3,
    PAPER_TABLE4,
    PAPER_TABLE5_1000RPM,
    PAPER_TABLE6,
    PAPER_TABLE7,
    SKID_SLIP_PCT,
    Outputs,
    RawResults,
)

BORE_M = 0.030
"""H7006C bore d, m (paper Table 2); with D and the base-oil viscosity the SKF model's inputs."""
OUTSIDE_DIAMETER_M = 0.055
"""H7006C outside diameter D, m (paper Table 2)."""


def _fmt(x: float | None, digits: int = 3) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    return f"{x:.{digits}g}"


def _fit_or_none(fn: Callable[[], Any]) -> Any:
    try:
        return fn()
    except Exception:
        return None


def write_report(raw: RawResults, out: Path, params: BearingParameters, cached: bool) -> Outputs:
    """Analyse ``raw`` with the paper's method and write every output file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files: list[Path] = []
    lines: list[str] = [
        "# Reproduction of Yang et al. (2023) with the bearing-rig-sim twin",
        "",
        f"Project version {__version__}; bearing `{params.name}` from `{params.source}`.",
        "Slip S_c = (1 - n_c/n_s) x 100 % with n_s at the nominal contact angle (paper Eq. 11-12).",
        "Every twin number is simulated by the engine; nothing is taken from the paper except where a column says so.",
        "",
    ]

    # -- 1. validation table ----------------------------------------------------------------
    rows = [s.as_row() for s in raw.validation]
    path = out / "validation.csv"
    _write_csv(path, ["rpm", "axial_load_n", "cage_rpm", "slip_pct"], [[r[k] for k in ("rpm", "axial_load_n", "cage_rpm", "slip_pct")] for r in rows])
    files.append(path)
    errs = [r["slip_pct"] - PAPER_TABLE3[int(round(r["rpm"]))][0] for r in rows if int(round(r["rpm"])) in PAPER_TABLE3]
    rms = float(np.sqrt(np.mean(np.square(errs)))) if errs else float("nan")
    lines += ["## Validation at 100 N (Table 3 analogue)", "", "| n_i (rpm) | bench S_c (%) | paper's model (%) | twin (%) | twin - bench (pp) |", "|---|---|---|---|---|"]
    for r in rows:
        n = int(round(r["rpm"]))
        bench, paper = PAPER_TABLE3.get(n, (None, None))
        diff = r["slip_pct"] - bench if bench is not None else None
        lines.append(f"| {n} | {_fmt(bench)} | {_fmt(paper)} | {r['slip_pct']:.2f} | {_fmt(diff, 2)} |")
    lines += ["", f"RMS twin - bench over the four calibration rows: **{rms:.3f} pp** (the paper's model: 0.11 pp over seven speeds).",
              "The 1200, 1800 and 2400 rpm rows are blind predictions: the bench values are withheld.", ""]
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([r["rpm"] for r in rows], [r["slip_pct"] for r in rows], "o-", label="twin")
    ax.plot(list(PAPER_TABLE3), [v[0] for v in PAPER_TABLE3.values()], "s", label="bench (paper Table 3)")
    ax.plot(list(PAPER_TABLE3), [v[1] for v in PAPER_TABLE3.values()], "x", label="paper's model")
    files.append(_finish(ax, fig, out / "fig05_validation_slip.png", "inner-ring speed n_i (rpm)", "cage slip rate S_c (%)", "Fig. 5 analogue: slip at 100 N"))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot([r["rpm"] for r in rows], [r["cage_rpm"] for r in rows], "o-", label="twin cage speed")
    ax.plot([r["rpm"] for r in rows], [params.epicyclic_ratio * r["rpm"] for r in rows], "--", label="epicyclic n_s (Eq. 12)")
    files.append(_finish(ax, fig, out / "fig06_validation_cage_speed.png", "inner-ring speed n_i (rpm)", "cage speed n_c (rpm)", "Fig. 6 analogue: cage speed at 100 N"))

    # -- 2. load sweep ----------------------------------------------------------------------
    path = out / "load_sweep.csv"
    _write_csv(path, ["rpm", "axial_load_n", "cage_rpm", "slip_pct"], [[s.as_row()[k] for k in ("rpm", "axial_load_n", "cage_rpm", "slip_pct")] for v in raw.sweep.values() for s in v])
    files.append(path)
    load_onsets: dict[float, float | None] = {}
    lines += ["## Load sweep (Figures 7-8; Tables 4-5 analogues)", "",
              f"Slip against axial load {min(SWEEP_LOADS_N):.0f}-{max(SWEEP_LOADS_N):.0f} N. Points in gross skid (S_c > {SKID_SLIP_PCT:.0f} %) are listed "
              "but not fitted: the Gaussian-slope method presumes a smooth slip curve. Gaussian sums fitted by nonlinear least squares to the rolling points; "
              f"stable where the fitted slope >= k1, read as {K1_AXIAL_LOAD:g} %/N (slip in percent) and, second reading, {K1_FRACTION_READING:g} %/N (slip as a fraction).", "",
              "| n_i (rpm) | skids up to (N) | 1-term SSE / R^2 / RMSE | 2-term SSE / R^2 / RMSE | kept | a1 | a2 | b1 (N) | b2 (N) | c1 (N) | c2 (N) | stable from (N), k1 %/N | stable from (N), k1 fraction/N |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    fig7, ax7 = plt.subplots(figsize=(6, 4))
    fig8, ax8 = plt.subplots(figsize=(6, 4))
    for rpm, states in raw.sweep.items():
        x_all = np.array([s.axial_load for s in states])
        y_all = np.array([s.slip_pct for s in states])
        ax7.plot(x_all, [rad_s_to_rpm(s.cage_speed) for s in states], "o-", ms=3, label=f"{rpm:.0f} rpm")
        rolling = y_all <= SKID_SLIP_PCT
        skid_to = float(x_all[~rolling].max()) if np.any(~rolling) else None
        (pts,) = ax8.plot(x_all[rolling], y_all[rolling], "o", ms=3, label=f"{rpm:.0f} rpm")
        ax8.plot(x_all[~rolling], y_all[~rolling], "x", ms=5, color=pts.get_color())
        x, y = x_all[rolling], y_all[rolling]
        chosen_fits = _fit_or_none(lambda: select_gaussian_fit(x, y, max_terms=2)) if len(x) >= 7 else None  # noqa: B023 - called at once
        if chosen_fits is None:
            lines.append(f"| {rpm:.0f} | {_fmt(skid_to, 4)} | too few rolling points to fit | | | | | | | | | - | - |")
            load_onsets[rpm] = None
            continue
        chosen, fits = chosen_fits
        two = fits[1]
        xf = np.linspace(x.min(), x.max(), 200)
        ax8.plot(xf, chosen(xf), "-", lw=1, color=pts.get_color())
        onset = stable_onset(chosen, float(x.min()), float(x.max()), K1_AXIAL_LOAD)
        onset_fraction = stable_onset(chosen, float(x.min()), float(x.max()), K1_FRACTION_READING)
        load_onsets[rpm] = onset.onset
        if onset_fraction.onset is not None:
            ax8.axvline(onset_fraction.onset, color=pts.get_color(), ls=":", lw=0.8)
        p = two.params
        lines.append(
            f"| {rpm:.0f} | {_fmt(skid_to, 4)} | {_fmt(fits[0].sse)} / {_fmt(fits[0].r_square, 4)} / {_fmt(fits[0].rmse)} | {_fmt(two.sse)} / {_fmt(two.r_square, 4)} / {_fmt(two.rmse)} | "
            f"{chosen.n_terms} | {p[0, 0]:.3g} | {p[1, 0]:.3g} | {p[0, 1]:.4g} | {p[1, 1]:.4g} | {p[0, 2]:.4g} | {p[1, 2]:.4g} | {_fmt(onset.onset, 4)} | {_fmt(onset_fraction.onset, 4)} |"
        )
    a = PAPER_TABLE5_1000RPM
    lines += ["", f"The paper (Table 4, fits pooled): 1-term SSE {PAPER_TABLE4[1][0]}, R^2 {PAPER_TABLE4[1][1]}, RMSE {PAPER_TABLE4[1][2]}; "
              f"2-term SSE {PAPER_TABLE4[2][0]}, R^2 {PAPER_TABLE4[2][1]}, RMSE {PAPER_TABLE4[2][2]} (2 terms kept). "
              f"Table 5 at 1000 rpm: a1 {a[0]}, a2 {a[1]}, b1 {a[2]}, b2 {a[3]}, c1 {a[4]}, c2 {a[5]}; its other rows are garbled in the source.", ""]
    files.append(_finish(ax7, fig7, out / "fig07_load_sweep_cage_speed.png", "axial load F_a (N)", "cage speed n_c (rpm)", "Fig. 7 analogue: cage speed against axial load"))
    files.append(_finish(ax8, fig8, out / "fig08_load_sweep_slip.png", "axial load F_a (N)", "cage slip rate S_c (%)", "Fig. 8 analogue: slip against load (x: skid; lines: fits)", log_if_positive=True))

    # -- 3. acceleration sweep --------------------------------------------------------------
    path = out / "acceleration.csv"
    _write_csv(
        path,
        ["acceleration_rad_s2", "time_s", "inner_rpm", "cage_rpm", "slip_pct"],
        [[a.acceleration, float(t), rad_s_to_rpm(float(wi)), rad_s_to_rpm(float(wc)), float(s)] for a in raw.acceleration for t, wi, wc, s in zip(a.time, a.inner_ring_speed, a.cage_speed, a.slip_pct)],
    )
    files.append(path)
    acc_onsets: dict[float, float | None] = {}
    lines += ["## Constant acceleration at 200 N (Figures 9-10; Tables 6-7 analogues)", "",
              f"Slip against time from rest; one-term Gaussian y = lambda exp(-((t - k)/d)^2) as in the paper; stable where the slope >= k2 = {K2_TIME:g} %/s.", "",
              "| alpha (rad/s^2) | 1-term SSE / R^2 / RMSE | 2-term SSE / R^2 / RMSE | lambda (%) | k (s) | d (s) | stable from (s) | paper lambda / k / d | paper onset (s) |",
              "|---|---|---|---|---|---|---|---|---|"]
    fig9, ax9 = plt.subplots(figsize=(6, 4))
    fig10, ax10 = plt.subplots(figsize=(6, 4))
    for series in raw.acceleration:
        t, y = series.time, series.slip_pct
        ax9.plot(t, np.asarray(series.cage_speed) * (30.0 / math.pi), "-", label=f"{series.acceleration:.0f} rad/s^2")
        ax10.plot(t, y, ".", ms=2, label=f"{series.acceleration:.0f} rad/s^2")
        one: GaussianFit | None = _fit_or_none(lambda: fit_gaussians(t, y, 1))  # noqa: B023 - called at once
        two_terms: GaussianFit | None = _fit_or_none(lambda: fit_gaussians(t, y, 2))  # noqa: B023 - called at once
        lam, kk, dd = PAPER_TABLE7.get(series.acceleration, (None, None, None))
        paper_onset = None
        if lam is not None and kk is not None and dd is not None:
            paper_onset = stable_onset(_gaussian(lam, kk, dd), 0.0, 5.0, K2_TIME).onset
        if one is None:
            lines.append(f"| {series.acceleration:.0f} | fit failed | | | | | - | {lam} / {kk} / {dd} | {_fmt(paper_onset)} |")
            acc_onsets[series.acceleration] = None
            continue
        ax10.plot(t, one(t), "-", lw=1, color=ax10.lines[-1].get_color())
        onset = stable_onset(one, float(t.min()), float(t.max()), K2_TIME)
        acc_onsets[series.acceleration] = onset.onset
        q = one.params[0]
        two_txt = f"{_fmt(two_terms.sse)} / {_fmt(two_terms.r_square, 4)} / {_fmt(two_terms.rmse)}" if two_terms is not None else "-"
        lines.append(
            f"| {series.acceleration:.0f} | {_fmt(one.sse)} / {_fmt(one.r_square, 4)} / {_fmt(one.rmse)} | {two_txt} | {q[0]:.3g} | {q[1]:.3g} | {q[2]:.3g} | "
            f"{_fmt(onset.onset)} | {lam} / {kk} / {dd} | {_fmt(paper_onset)} |"
        )
    lines += ["", f"The paper (Table 6): 1-term SSE {PAPER_TABLE6[1][0]}, R^2 {PAPER_TABLE6[1][1]}, RMSE {PAPER_TABLE6[1][2]}; "
              f"2-term SSE {PAPER_TABLE6[2][0]}, R^2 {PAPER_TABLE6[2][1]}, RMSE {PAPER_TABLE6[2][2]} (1 term kept).", ""]
    files.append(_finish(ax9, fig9, out / "fig09_acceleration_cage_speed.png", "time t (s)", "cage speed n_c (rpm)", "Fig. 9 analogue: cage speed under constant acceleration"))
    files.append(_finish(ax10, fig10, out / "fig10_acceleration_slip.png", "time t (s)", "cage slip rate S_c (%)", "Fig. 10 analogue: slip under constant acceleration (lines: 1-term fit)"))
    plt.close("all")
    lines += friction_section(raw, params)

    report = out / "report.md"
    report.write_text("\n".join(lines) + "\n", encoding="utf-8")
    files.append(report)
    return Outputs(out, files, rms, load_onsets, acc_onsets, cached)


def _gaussian(lam: float, k: float, d: float) -> Callable[[Any], Any]:
    """y = lam exp(-((t - k)/d)^2), the paper's one-term fit."""

    def curve(t: Any) -> Any:
        return lam * np.exp(-(((np.asarray(t) - k) / d) ** 2))

    return curve


def _write_csv(path: Path, header: list[str], rows: list[list[Any]]) -> None:
    import csv

    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for row in rows:
            w.writerow([f"{v:.6g}" if isinstance(v, float) else v for v in row])


def _finish(ax: Any, fig: Any, path: Path, xlabel: str, ylabel: str, title: str, log_if_positive: bool = False) -> Path:
    """Label, grid and legend a figure's axes, then save it as PNG."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if log_if_positive and all(v > 0 for line in ax.lines for v in np.asarray(line.get_ydata(), dtype=float)):
        ax.set_yscale("log")
    return _save(fig, path)


def _save(fig: Any, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def friction_section(raw: RawResults, params: BearingParameters) -> list[str]:
    """Markdown lines: the twin's friction torque and power beside the SKF model's estimate
    (oil at the lubricant's base-oil viscosity and the bearing temperature)."""
    lub = params.lubricant
    if lub is None:
        return []
    nu = lub.kinematic_viscosity(params.lubricant_temperature)
    lines = ["## Friction torque: the twin beside the SKF model", "",
             f"Twin: power dissipated in the bearing over the inner-ring speed (lubricant `{lub.name}`). SKF: catalogue model "
             f"M = phi_ish phi_rs M_rr + M_sl for a single-row angular contact ball bearing, oil of {nu * 1e6:.1f} mm^2/s (the base oil at "
             f"{params.lubricant_temperature:.0f} degC), no drag term. With grease in its running-in state the twin's torque is expected "
             "above the oil estimate (docs/model.md, section Calibration).", "",
             "| n_i (rpm) | F_a (N) | slip (%) | twin torque (N mm) | twin power (W) | SKF torque (N mm) | twin / SKF |", "|---|---|---|---|---|---|---|"]
    states: list[SteadyState] = list(raw.validation)
    picks = {min(SWEEP_LOADS_N), 400.0, max(SWEEP_LOADS_N)}
    states += [s for v in raw.sweep.values() for s in v if s.axial_load in picks]
    for s in states:
        if not math.isfinite(s.friction_torque):
            continue
        rpm = rad_s_to_rpm(s.inner_ring_speed)
        m_skf = skf_frictional_moment(rpm, s.axial_load, BORE_M, OUTSIDE_DIAMETER_M, nu).total
        lines.append(f"| {rpm:.0f} | {s.axial_load:.0f} | {s.slip_pct:.2f} | {s.friction_torque * 1e3:.2f} | {s.power_loss:.2f} | {m_skf * 1e3:.2f} | {s.friction_torque / m_skf:.2f} |")
    return lines + [""]
