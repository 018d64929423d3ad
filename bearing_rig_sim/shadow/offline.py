"""Shadow mode over a recorded bag, without ROS and deterministic: ``residuals.csv``, a report and
plots.

The bag needs the two pulse topics and the load-cell topic (from the twin or from the physical
bench). Their messages are fed in log-time order into a :class:`~bearing_rig_sim.shadow.ShadowTwin`;
its time-based checks run every ``1 / status_rate_hz`` seconds of bench time, as the node's timer
does. Nothing depends on a wall clock: two runs over one bag give identical files.

Output in ``out_dir``:

* ``residuals.csv``: one row per slip window: ``time_s`` (window end, s from the first pulse),
  ``inner_ring_rpm``, ``axial_load_n``, ``measured_slip_pct``, ``predicted_slip_pct``,
  ``residual_pct``, ``band_pct``, ``anomaly`` (0/1), then ``compared`` (0/1), ``level``
  (0 OK, 1 WARN, 2 ERROR), ``note``, then the outer-ring thermocouple's and the housing torque
  meter's columns (``measured_temperature_c`` ... ``torque_anomaly``; empty where the bag has no
  such topic);
* ``report.md``: inputs, settings, counts, flagged stretches, the re-calibrated parameter;
* ``shadow.png``: measured and predicted slip, residual with its band, flagged stretches shaded.

Units: s, rpm, N, percent at this edge.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, cast

from bearing_rig_sim.bags.cdr import make_decoder
from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.reader import open_bag
from bearing_rig_sim.config import rad_s_to_rpm
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.health import HealthLevel
from bearing_rig_sim.interfaces import AXIAL_LOAD_FORCE, CAGE_PULSES, HOUSING_TORQUE, OUTER_RING_TEMPERATURE, SPINDLE_PULSES
from bearing_rig_sim.offline.analysis import decode_pulse
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.shadow.recalibration import ParameterEstimate
from bearing_rig_sim.shadow.settings import ShadowSettings
from bearing_rig_sim.shadow.twin import ResidualWindow, ShadowTwin

RESIDUALS_CSV = "residuals.csv"
REPORT_MD = "report.md"
PLOT_PNG = "shadow.png"
COLUMNS = (
    "time_s",
    "inner_ring_rpm",
    "axial_load_n",
    "measured_slip_pct",
    "predicted_slip_pct",
    "residual_pct",
    "band_pct",
    "anomaly",
    "compared",
    "level",
    "note",
    "measured_temperature_c",
    "predicted_temperature_c",
    "temperature_residual_k",
    "temperature_band_k",
    "temperature_anomaly",
    "measured_torque_nm",
    "predicted_torque_nm",
    "torque_residual_nm",
    "torque_band_nm",
    "torque_anomaly",
)
"""Columns of ``residuals.csv``, in order."""


@dataclass
class Stretch:
    """A flagged stretch: consecutive windows with the anomaly set (s from the first pulse)."""

    start_s: float
    end_s: float
    worst: HealthLevel
    mean_residual_pct: float
    detail: str


@dataclass
class ShadowResult:
    """What one pass over a bag gave.

    Attributes:
        bag: the bag directory.
        origin: bench time of the first pulse, s (``time_s`` counts from it).
        rows: every window.
        stretches: flagged stretches.
        counts: windows made, compared, inside the band, flagged.
        estimate: the re-calibrated parameter (None when off).
        files: files written.
    """

    bag: Path
    origin: float
    rows: list[ResidualWindow]
    stretches: list[Stretch]
    counts: dict[str, int]
    estimate: ParameterEstimate | None
    files: list[Path] = field(default_factory=list)

    @property
    def inside_fraction(self) -> float:
        """Compared windows with the residual inside its band, as a fraction of the compared (1)."""
        return self.counts["inside"] / self.counts["compared"] if self.counts["compared"] else math.nan


def _force_of(message: Any) -> tuple[float, float]:
    stamp = message.header.stamp
    return stamp.sec + stamp.nanosec * 1e-9, float(message.wrench.force.z)


def shadow_bag(
    bag_path: str | Path, out_dir: str | Path | None, settings: ShadowSettings | None = None, params: BearingParameters | None = None
) -> ShadowResult:
    """Run shadow mode over a bag; write the files when ``out_dir`` is given.

    Raises:
        BagError: the bag lacks a pulse topic or the load-cell topic.
        ConfigError: bad settings.
    """
    st = settings if settings is not None else ShadowSettings.from_yaml()
    twin = ShadowTwin(st, params)
    rows: list[ResidualWindow] = []
    period = 1.0 / st.status_rate_hz
    with open_bag(bag_path) as bag:
        needed = {SPINDLE_PULSES.name: SPINDLE_PULSES.msgtype, CAGE_PULSES.name: CAGE_PULSES.msgtype, AXIAL_LOAD_FORCE.name: AXIAL_LOAD_FORCE.msgtype}
        for name, msgtype in needed.items():
            info = bag.topics.get(name)
            if info is None:
                raise BagError(f"{bag.path}: no topic {name} ({msgtype}) in the bag; shadow mode needs both pulse topics and the load cell")
            if info.msgtype != msgtype:
                raise BagError(f"{bag.path}: topic {name} carries {info.msgtype}, not {msgtype}")
        optional = {OUTER_RING_TEMPERATURE.name: OUTER_RING_TEMPERATURE.msgtype, HOUSING_TORQUE.name: HOUSING_TORQUE.msgtype}
        present = [name for name, msgtype in optional.items() if name in bag.topics and bag.topics[name].msgtype == msgtype]
        decode_temperature = make_decoder(bag.typestore, OUTER_RING_TEMPERATURE.msgtype) if OUTER_RING_TEMPERATURE.name in present else None
        decode_torque = make_decoder(bag.typestore, HOUSING_TORQUE.msgtype) if HOUSING_TORQUE.name in present else None
        decode_force = make_decoder(bag.typestore, AXIAL_LOAD_FORCE.msgtype)
        decode_general = make_decoder(bag.typestore, SPINDLE_PULSES.msgtype)
        shaft_of = {SPINDLE_PULSES.name: "spindle", CAGE_PULSES.name: "cage"}
        origin: float | None = None
        tick = -math.inf
        for topic, _log_ns, _type, payload in bag.messages([*needed, *present], raw=True):
            data = cast(bytes, payload)
            if topic == OUTER_RING_TEMPERATURE.name and decode_temperature is not None:
                m_t: Any = decode_temperature(data)
                twin.add_temperature(m_t.header.stamp.sec + m_t.header.stamp.nanosec * 1e-9, float(m_t.temperature))
                continue
            if topic == HOUSING_TORQUE.name and decode_torque is not None:
                m_m: Any = decode_torque(data)
                twin.add_torque(m_m.header.stamp.sec + m_m.header.stamp.nanosec * 1e-9, float(m_m.wrench.torque.z))
                continue
            if topic == AXIAL_LOAD_FORCE.name:
                t, force = _force_of(decode_force(data))
                twin.add_force(t, force)
                continue
            if bytes(data[:2]) == b"\x00\x01":
                pulse = decode_pulse(data)
            else:
                m: Any = decode_general(data)
                pulse = Pulse(
                    m.header.stamp.sec + m.header.stamp.nanosec * 1e-9,
                    int(m.strip_id),
                    int(m.strip_count),
                    int(m.revolution),
                    int(m.pulse_index),
                    str(m.sensor_id),
                )
            t = pulse.time
            if math.isfinite(t):
                if origin is None:
                    origin, tick = t, t
                if t < tick - 1.0:  # the clock went back: restart the ticks
                    tick = t
                while tick <= t:
                    rows += twin.check(tick)
                    tick += period
            rows += twin.add_pulse(shaft_of[topic], pulse)
        rows += twin.check(tick + 10.0 * period)
    result = ShadowResult(
        Path(bag_path), origin if origin is not None else 0.0, rows, flagged_stretches(rows, origin or 0.0), dict(twin.counts), twin.estimate()
    )
    if out_dir is not None:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        result.files = [write_csv(out / RESIDUALS_CSV, rows, result.origin), write_report(out / REPORT_MD, result, st, twin.timing_jitter_std_s)]
        plot = write_plot(out / PLOT_PNG, result)
        if plot is not None:
            result.files.append(plot)
    return result


def flagged_stretches(rows: list[ResidualWindow], origin: float) -> list[Stretch]:
    """Runs of consecutive flagged windows, with the worst level and mean residual of each."""
    out: list[Stretch] = []
    current: list[ResidualWindow] = []
    for row in [*rows, None]:
        if row is not None and row.anomaly:
            current.append(row)
            continue
        if current:
            residuals = [r.residual for r in current if math.isfinite(r.residual)]
            worst = max(r.level for r in current)
            last = max((r for r in current if r.level == worst), key=lambda r: r.time)
            out.append(Stretch(current[0].time - origin, current[-1].time - origin, HealthLevel(worst), sum(residuals) / len(residuals), last.note))
            current = []
    return out


def _num(x: float, digits: int = 4) -> str:
    return "" if not math.isfinite(x) else f"{x:.{digits}f}"


def write_csv(path: Path, rows: list[ResidualWindow], origin: float) -> Path:
    """``residuals.csv`` (see the module docstring)."""
    with path.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(COLUMNS)
        for r in rows:
            w.writerow(
                [
                    f"{r.time - origin:.6f}",
                    _num(rad_s_to_rpm(r.inner_ring_speed), 2),
                    _num(r.axial_load, 2),
                    _num(r.measured_slip),
                    _num(r.predicted_slip),
                    _num(r.residual),
                    _num(r.band),
                    int(r.anomaly),
                    int(r.compared),
                    int(r.level),
                    r.note,
                    _num(r.measured_temperature, 3),
                    _num(r.predicted_temperature, 3),
                    _num(r.temperature_residual, 3),
                    _num(r.temperature_band, 3),
                    int(r.temperature_anomaly),
                    _num(r.measured_torque, 6),
                    _num(r.predicted_torque, 6),
                    _num(r.torque_residual, 6),
                    _num(r.torque_band, 6),
                    int(r.torque_anomaly),
                ]
            )
    return path


def write_report(path: Path, result: ShadowResult, st: ShadowSettings, jitter_std_s: float) -> Path:
    """``report.md``: inputs, rule, counts, flagged stretches, estimate (``jitter_std_s``: the
    rig file's pulse-timing jitter the band took, s)."""
    c = result.counts
    lines = [
        f"# Shadow mode: {result.bag.name}",
        "",
        f"Bearing `{st.bearing_file.name}`, calibration `{st.calibration_file.name if st.calibration_file else 'none'}`; "
        f"windows of {st.window_revolutions} cage revolution(s); time counted from the first pulse "
        f"({result.origin:.6f} s on the bench clock).",
        "",
        f"Band: {st.band_coverage:g} x sqrt((calibration RMS {st.calibration_rms_slip_pct:.4f} pp)^2 + "
        f"(100 x 2 x {jitter_std_s:.2g} s / window)^2). Anomaly: outside the band for more than "
        f"{st.warn_after_s:g} s: WARN, more than {st.error_after_s:g} s: ERROR.",
        "",
        "| windows | compared | inside the band | flagged |",
        "|---|---|---|---|",
        f"| {c['windows']} | {c['compared']} | {c['inside']} ({100.0 * result.inside_fraction:.2f} %) | {c['anomalous']} |"
        if c["compared"]
        else f"| {c['windows']} | 0 | - | {c['anomalous']} |",
        "",
        *_heat_lines(result.rows),
        "## Flagged stretches",
        "",
    ]
    if result.stretches:
        lines += ["| from (s) | to (s) | worst | mean residual (pp) | detail |", "|---|---|---|---|---|"]
        lines += [f"| {s.start_s:.3f} | {s.end_s:.3f} | {s.worst.name} | {s.mean_residual_pct:+.3f} | {s.detail} |" for s in result.stretches]
    else:
        lines.append("None: the bench stayed within the twin's band.")
    skipped: dict[str, int] = {}
    for r in result.rows:
        if not r.compared:
            key = r.note.split(" from ")[0].split(" (")[0].split(":")[0]
            skipped[key] = skipped.get(key, 0) + 1
    if skipped:
        lines += ["", "## Windows not compared", ""] + [f"* {why}: {n}" for why, n in sorted(skipped.items())]
    if result.estimate is not None:
        e = result.estimate
        lines += [
            "",
            "## Online re-calibration",
            "",
            f"`{e.name}`: {e.value:.6g} +- {e.std:.3g} (calibrated {e.calibrated:.6g}; ratio {e.ratio:.4f}) from {e.updates} steady windows. "
            "Not written to the calibration file.",
        ]
        if not e.in_range and e.range is not None:
            lines += [
                "",
                f"**Outside the parameter's stated plausible range {e.range[0]:g}-{e.range[1]:g}**: the bench has changed beyond what this parameter can explain.",
            ]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _heat_lines(rows: list[ResidualWindow]) -> list[str]:
    """The report's lines on the temperature and torque residuals (none without them)."""
    out = []
    for name, unit, residual, band, flag in (
        ("Outer-ring temperature", "K", "temperature_residual", "temperature_band", "temperature_anomaly"),
        ("Housing torque", "N m", "torque_residual", "torque_band", "torque_anomaly"),
    ):
        compared = [r for r in rows if math.isfinite(getattr(r, residual))]
        if not compared:
            continue
        inside = sum(abs(getattr(r, residual)) <= getattr(r, band) for r in compared)
        worst = max(compared, key=lambda r: abs(getattr(r, residual)))
        out += [
            f"{name}: {len(compared)} windows compared, {inside} inside the band, {sum(getattr(r, flag) for r in rows)} flagged; "
            f"largest residual {getattr(worst, residual):+.4g} {unit} (band +-{getattr(worst, band):.4g} {unit}).",
            "",
        ]
    return out


def write_plot(path: Path, result: ShadowResult) -> Path | None:
    """``shadow.png``; None when there is nothing to plot."""
    if not result.rows:
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = [r.time - result.origin for r in result.rows]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(10, 6))
    ax1.plot(t, [r.measured_slip for r in result.rows], ".", ms=3, label="measured (bench)")
    ax1.plot(t, [r.predicted_slip for r in result.rows], "-", lw=1, label="predicted (twin)")
    ax1.set_ylabel("slip (%)")
    ax1.legend(loc="best")
    ax2.plot(t, [r.residual for r in result.rows], ".", ms=3, label="residual")
    ax2.plot(t, [r.band for r in result.rows], "k--", lw=0.8, label="band")
    ax2.plot(t, [-r.band for r in result.rows], "k--", lw=0.8)
    ax2.set_ylabel("measured - predicted (pp)")
    ax2.set_xlabel("time from the first pulse (s)")
    for s in result.stretches:
        for ax in (ax1, ax2):
            ax.axvspan(s.start_s, s.end_s, color="red" if s.worst == HealthLevel.ERROR else "orange", alpha=0.2)
    ax2.legend(loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
