"""The offline analysis of a bag as a report: markdown, PNG plots against time, CSV series.

:func:`write_report` turns an :class:`~bearing_rig_sim.offline.analysis.OfflineResult` into
``report.md`` and five plots in the output folder (the CSV series are written there by the
analysis itself, as it streams):

* ``speeds.png``: inner ring, cage and epicyclic cage speed (the monitor's windows), with the
  pulse counter's speeds (``/rig/speeds``) and the simulator's truth when the bag has them, rpm;
* ``slip.png``: slip from the sensors (offline monitor; the paper's, and the kinematic slip at the
  loaded contact angle), as recorded (``/rig/slip_status``) and true (``/rig/truth``), %;
* ``axial_load.png``: set-point, load cell, force on the bearing (and the truth's), N;
* ``thermal.png``: the outer-ring thermocouple (``/rig/outer_ring/temperature``, degC) and the
  housing torque meter (``/rig/housing/torque``, N mm) when the bag has them;
* ``status.png``: the monitor's state offline and as recorded.

Time on every plot and in the report's tables runs from the first pulse of the bag (s), so bench
bags stamped with the wall clock read the same as simulated ones; the CSV files keep rig time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from collections.abc import Sequence


import bearing_rig_sim
from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.config import RPM_TO_RAD_S, ConfigError, parse_yaml
from bearing_rig_sim.offline.analysis import (
    BEARING_FORCE,
    COMMAND,
    HOUSING_TORQUE,
    CONTEXT_TOPICS,
    LOAD_CELL,
    LOAD_SETPOINT,
    LOAD_STATE,
    OUTER_RING_TEMPERATURE,
    PULSE_TOPICS,
    PULSE_TYPE,
    SPEEDS,
    STATUS,
    TRUTH,
    OfflineResult,
)
from bearing_rig_sim.offline.segments import SEGMENTS_CSV, SegmentSummary
from bearing_rig_sim.offline.series import STATUS_CSV, WINDOWS_CSV
from bearing_rig_sim.monitoring.load_sweep import sweep_key

REPORT_FILE = "report.md"
PLOT_FILES = ("speeds.png", "slip.png", "axial_load.png", "status.png")

_RPM = 1.0 / RPM_TO_RAD_S
_STATE_NAMES = {int(s): s.name.lower() for s in SlipState}
_RUN_KEYS = ("run_id", "started_utc", "program_file", "command_line", "project_version", "realtime", "ros_domain_id")
_TOPIC_USE = {
    **{topic: "slip windows and verdicts (offline monitor)" for topic in PULSE_TOPICS.values()},
    SPEEDS: "pulse counter's speeds (plot)",
    TRUTH: "true speeds, slip and load (plots, segment means)",
    STATUS: "recorded verdicts (comparison)",
    COMMAND: "program segments",
    LOAD_STATE: "set-point, load cell and bearing force",
    LOAD_SETPOINT: "axial-load set-point",
    LOAD_CELL: "load cell",
    BEARING_FORCE: "force on the bearing",
    OUTER_RING_TEMPERATURE: "outer-ring thermocouple (plot)",
    HOUSING_TORQUE: "housing torque meter (plot)",
}


@dataclass(frozen=True)
class ReportFiles:
    """What :func:`write_report` wrote."""

    report: Path
    plots: tuple[Path, ...]
    csv: tuple[Path, ...]


def state_name(state: int) -> str:
    """``stable``, ``slipping``, ``unknown``, ``fault``; ``-`` for none (-1)."""
    return _STATE_NAMES.get(state, "-")


def _fixed(value: float | None, decimals: int) -> str:
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:.{decimals}f}"


# ---------------------------------------------------------------------------------------------
# Plots
# ---------------------------------------------------------------------------------------------
def _column(result: OfflineResult, attr: str, scale: float = 1.0) -> tuple[list[float], list[float]]:
    """(time from the first pulse, value * scale) of every row, NaN where the value is not
    finite, so that a line breaks where there is no value (the sensors' slip of a stopped rig)
    rather than joining the values on either side; ([], []) when no value is finite."""
    t0 = result.first_time
    xs, ys = [], []
    finite = False
    for row in result.rows:
        value = getattr(row, attr)
        xs.append(row.time - t0)
        if math.isfinite(value):
            ys.append(value * scale)
            finite = True
        else:
            ys.append(math.nan)
    return (xs, ys) if finite else ([], [])


def _plot_lines(ax: Any, result: OfflineResult, lines: Sequence[tuple[str, str, float, dict[str, Any]]]) -> bool:
    drawn = False
    for attr, label, scale, style in lines:
        xs, ys = _column(result, attr, scale)
        if xs:
            ax.plot(xs, ys, label=label, **style)
            drawn = True
    return drawn


def _shade_segments(ax: Any, result: OfflineResult) -> None:
    for index, segment in enumerate(result.segments):
        ax.axvspan(segment.ramp_end - result.first_time, segment.end_time - result.first_time, color="0.92" if index % 2 else "0.86", zorder=0)


def _finish(fig: Any, ax: Any, path: Path, title: str, ylabel: str, drawn: bool, missing: str) -> Path:
    ax.set_title(title)
    ax.set_xlabel("time since the first pulse (s)")
    ax.set_ylabel(ylabel)
    if drawn:
        ax.legend(loc="best", fontsize="small")
    else:
        ax.text(0.5, 0.5, missing, transform=ax.transAxes, ha="center", va="center")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def _origin(first_time: float) -> str:
    """Where the report's time starts on the rig clock, for reading the CSV files beside it."""
    return f", at {first_time:.6f} s of rig time; the CSV files keep rig time" if math.isfinite(first_time) else ""


def _step(transitions: list[tuple[float, int]], t0: float, t_end: float) -> tuple[list[float], list[int]]:
    xs = [t - t0 for t, _s in transitions]
    ys = [s for _t, s in transitions]
    if xs:
        xs.append(max(t_end - t0, xs[-1]))
        ys.append(ys[-1])
    return xs, ys


def _thermal_plot(result: OfflineResult, out_dir: Path, plt: Any) -> Path:
    """Outer-ring temperature (left axis) and housing torque (right axis) against time."""
    fig, ax = plt.subplots(figsize=(10, 4.5))
    try:
        _shade_segments(ax, result)
        drawn = _plot_lines(ax, result, [("outer_ring_temperature", "outer-ring thermocouple (degC)", 1.0, {"color": "tab:red", "linewidth": 1.2})])
        t, torque = _column(result, "housing_torque", 1e3)
        if t:
            right = ax.twinx()
            right.plot(t, torque, color="tab:blue", linewidth=0.8, label="housing torque meter (N mm)")
            right.set_ylabel("torque (N mm)")
            right.legend(loc="lower right", fontsize="small")
            drawn = True
        return _finish(
            fig,
            ax,
            out_dir / "thermal.png",
            "Outer-ring temperature and friction torque",
            "temperature (degC)",
            drawn,
            "no thermocouple or torque meter in the bag",
        )
    finally:
        plt.close(fig)


def write_plots(result: OfflineResult, out_dir: Path) -> tuple[Path, ...]:
    """The five PNG plots of the module documentation; returns their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    thin: dict[str, Any] = {"linewidth": 0.8}
    figures: tuple[tuple[str, str, str, list[tuple[str, str, float, dict[str, Any]]], str], ...] = (
        (
            "speeds.png",
            "Speeds",
            "speed (rpm)",
            [
                ("inner_ring_speed", "inner ring (spindle pulses)", _RPM, {"linewidth": 1.4}),
                ("cage_speed", "cage (cage pulses)", _RPM, {"linewidth": 1.4}),
                ("theoretical_cage_speed", "epicyclic cage speed", _RPM, {"linestyle": "--", "linewidth": 1.0}),
                ("counter_inner_ring_speed", f"inner ring ({SPEEDS})", _RPM, {"linestyle": ":", **thin}),
                ("counter_cage_speed", f"cage ({SPEEDS})", _RPM, {"linestyle": ":", **thin}),
                ("truth_cage_speed", "cage (truth)", _RPM, {"linestyle": "-.", **thin}),
            ],
            "no slip window in the bag",
        ),
        (
            "slip.png",
            "Cage slip rate",
            "slip (%)",
            [
                ("slip_rate", "from the sensors (offline monitor)", 1.0, {"linewidth": 1.4}),
                ("kinematic_slip_rate", "kinematic, at the loaded contact angle (offline monitor)", 1.0, {"linewidth": 1.0}),
                ("recorded_slip_rate", f"recorded {STATUS}", 1.0, {"linestyle": "--", "linewidth": 1.0}),
                ("truth_slip_rate", f"truth ({TRUTH})", 1.0, {"linestyle": ":", "linewidth": 1.0}),
            ],
            "no slip window in the bag",
        ),
        (
            "axial_load.png",
            "Axial load",
            "force (N)",
            [
                ("axial_load_setpoint", "set-point", 1.0, {"linestyle": "--", "linewidth": 1.0}),
                ("load_cell_force", "load cell", 1.0, thin),
                ("bearing_force", "force on the bearing", 1.0, {"linewidth": 1.2}),
                ("truth_axial_load", f"truth ({TRUTH})", 1.0, {"linestyle": ":", "linewidth": 1.0}),
            ],
            "no axial-load topic in the bag",
        ),
    )
    for name, title, ylabel, lines, missing in figures:
        fig, ax = plt.subplots(figsize=(10, 4.5))
        try:
            _shade_segments(ax, result)
            drawn = _plot_lines(ax, result, lines)
            paths.append(_finish(fig, ax, out_dir / name, title, ylabel, drawn, missing))
        finally:
            plt.close(fig)
    paths.append(_thermal_plot(result, out_dir, plt))
    fig, ax = plt.subplots(figsize=(10, 3.5))
    try:
        _shade_segments(ax, result)
        drawn = False
        for transitions, label, style in (
            (result.transitions, "offline monitor", {"linewidth": 1.6}),
            (result.recorded_transitions, f"recorded {STATUS}", {"linestyle": "--", "linewidth": 1.0}),
        ):
            xs, ys = _step(transitions, result.first_time, result.last_time)
            if xs:
                ax.step(xs, ys, where="post", label=label, **style)
                drawn = True
        ax.set_yticks(sorted(_STATE_NAMES), [_STATE_NAMES[s] for s in sorted(_STATE_NAMES)])
        ax.set_ylim(-0.5, max(_STATE_NAMES) + 0.5)
        paths.append(_finish(fig, ax, out_dir / "status.png", "Monitor state", "state", drawn, "no status in the bag"))
    finally:
        plt.close(fig)
    return tuple(paths)


# ---------------------------------------------------------------------------------------------
# Markdown
# ---------------------------------------------------------------------------------------------
def _program_name(metadata: dict[str, str]) -> str:
    try:
        doc = parse_yaml(metadata.get("program", "") or "", "run context: program")
    except ConfigError:
        return ""
    return str(doc.get("name", "")) if isinstance(doc, dict) else ""


def _segment_table(result: OfflineResult) -> list[str]:
    t0 = result.first_time
    head = (
        "| # | segment | start (s) | ramp end (s) | end (s) | target (rpm) | inner ring (rpm) | axial load (N) "
        "| slip (%) | recorded slip (%) | true slip (%) | verdict | recorded verdict | time to stable (s) | recorded time to stable (s) |"
    )
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for index, s in enumerate(result.segments, 1):
        lines.append(
            f"| {index} | {s.name} | {_fixed(s.start_time - t0, 2)} | {_fixed(s.ramp_end - t0, 2)} | {_fixed(s.end_time - t0, 2)} "
            f"| {_fixed(s.target_speed * _RPM, 1)} | {_fixed(s.inner_ring_speed * _RPM, 1)} | {_fixed(s.axial_load, 1)} "
            f"| {_fixed(s.slip_rate, 3)} | {_fixed(s.recorded_slip_rate, 3)} | {_fixed(s.truth_slip_rate, 3)} "
            f"| {state_name(s.final_state)} | {state_name(s.final_recorded_state)} "
            f"| {_fixed(s.time_to_stable, 2)} | {_fixed(s.recorded_time_to_stable, 2)} |"
        )
    return lines


def _agreement(segments: Sequence[SegmentSummary]) -> str:
    compared = [s for s in segments if s.final_recorded_state >= 0]
    if not compared:
        return "no recorded verdict to compare with"
    reached = sum(s.time_to_stable is not None for s in compared)
    recorded = sum(s.recorded_time_to_stable is not None for s in compared)
    same = sum(s.final_state == s.final_recorded_state for s in compared)
    return (
        f"a stable verdict after the ramp in {reached} of {len(compared)} offline, {recorded} recorded; "
        f"the last state agrees in {same} (the recorded statuses follow the node's timing)"
    )


def _sweep_section(result: OfflineResult) -> list[str]:
    """The load sweep by the paper's method, per speed (docs/method.md); [] when the run had none."""
    if not result.sweeps and not result.recorded_sweeps:
        return []
    lines = [
        "## Load sweep (paper section 4.1)",
        "",
        "Per spindle speed: the settled slip of each load point, a Gaussian sum fitted to slip against load "
        "(1 and 2 terms, the better kept), and the load from which the fitted slope is at or above k1 "
        "(docs/method.md).",
        "",
        "| speed (rpm) | load points (N) | slip (%) | verdict offline | verdict recorded |",
        "|---|---|---|---|---|",
    ]
    for verdict in result.sweeps:
        key = sweep_key(verdict.inner_ring_speed)
        loads = ", ".join(f"{x:.0f}" for x in verdict.loads)
        slips = ", ".join(f"{y:.3f}" for y in verdict.slips)
        lines.append(f"| {key} | {loads} | {slips} | {verdict.describe()} | {result.recorded_sweeps.get(key, '-')} |")
    return [*lines, ""]


def report_markdown(result: OfflineResult, plots: Sequence[Path], csv_files: Sequence[Path]) -> str:
    """The report's markdown text (see the module documentation)."""
    meta = result.run_metadata
    span = result.last_time - result.first_time if math.isfinite(result.first_time) else 0.0
    lines = [f"# Offline analysis of `{result.path.name}`", ""]
    if not result.complete:
        lines += [
            "> **Incomplete results.** The bag is damaged, truncated or partly unusable (see *Problems*): "
            f"the analysis covers the {span:.3f} s of pulses that could be read, "
            f"the bag's log time spans {result.bag_end - result.bag_start:.3f} s.",
            "",
        ]
    lines += ["## Run", "", f"* bag: `{result.path}`"]
    program = _program_name(meta)
    if program:
        lines.append(f"* program: {program}")
    for key in _RUN_KEYS:
        if meta.get(key):
            lines.append(f"* {key.replace('_', ' ')}: `{meta[key]}`")
    lines += [
        f"* analysed with bearing_rig_sim {bearing_rig_sim.__version__}; monitor parameters from {result.settings_source}",
        "",
        "## Summary",
        "",
        f"* pulses: {result.pulses['spindle']} spindle, {result.pulses['cage']} cage, over {span:.3f} s of rig time (time below runs from the first pulse{_origin(result.first_time)})",
        f"* slip windows: {result.windows}; status rows: {result.status_rows} (one per check at the monitor's status rate and per closed window)",
    ]
    final = result.final_status
    if final is not None:
        lines.append(
            f"* final verdict offline: **{state_name(int(final.state))}**, slip {_fixed(final.slip_rate, 3)} % at "
            f"{_fixed(final.inner_ring_speed * _RPM, 1)} rpm (confidence {_fixed(final.confidence, 2)})"
        )
    else:
        lines.append("* final verdict offline: none (no pulse could be read)")
    if result.recorded_statuses:
        lines.append(f"* final verdict recorded: **{state_name(result.final_recorded_state)}** ({result.recorded_statuses} status messages)")
    else:
        lines.append(f"* recorded verdicts: none (the bag has no {STATUS})")
    total = sum(result.state_durations.values())
    if total > 0.0:
        shares = ", ".join(f"{state_name(s)} {d:.2f} s ({100.0 * d / total:.1f} %)" for s, d in sorted(result.state_durations.items()))
        lines.append(f"* time in each state (offline): {shares}")
    lines.append(f"* state changes: {max(len(result.transitions) - 1, 0)} offline, {max(len(result.recorded_transitions) - 1, 0)} recorded")
    if result.transitions_dropped:
        lines.append(f"* {result.transitions_dropped} further state changes were counted but not kept for the status plot")
    stable = sum(s.final_state == SlipState.STABLE for s in result.segments)
    source = f"program segments (from {COMMAND})" if result.segment_source == "program" else "constant-speed stretches (no spindle command in the bag)"
    lines += [f"* {len(result.segments)} {source}: {stable} end stable; {_agreement(result.segments)}", ""]
    lines += ["## Segments", ""]
    if result.segments:
        lines += [
            "Means are taken from the ramp's end to the segment's end; verdicts are the last state in the segment; "
            f"time to stable counts from the ramp's end to the first stable status (P(slope >= k) >= {result.stable_confidence:g}, the monitor's stable_confidence) whose "
            "slip windows all follow the ramp's end, the rule the live session summary uses; a run-up (a constant-acceleration segment) is judged "
            "during its acceleration, as the paper does (section 4.2), so its time to stable counts from its start and may come before the target speed.",
            "",
            *_segment_table(result),
            "",
        ]
    else:
        lines += ["No segment: no spindle command, and no constant-speed stretch long enough.", ""]
    lines += _sweep_section(result)
    lines += ["## Plots", ""]
    lines += [f"![{p.stem}]({p.name})" for p in plots]
    lines += ["", "## Topics", "", "| topic | type | messages | used for |", "|---|---|---|---|"]
    for name, (msgtype, count) in result.topics.items():
        expected = PULSE_TYPE if name in PULSE_TOPICS.values() else CONTEXT_TOPICS.get(name)
        used = _TOPIC_USE[name] if msgtype == expected else "-"
        lines.append(f"| `{name}` | `{msgtype}` | {count} | {used} |")
    lines += ["", "## Problems", ""]
    lines += [f"* {p}" for p in result.problems] if result.problems else ["None: the bag was read completely."]
    lines += ["", "## Files", ""]
    descriptions = {
        STATUS_CSV: "every status row: the monitor's fields and the other topics' latest values (rig time s, rpm, %, N)",
        WINDOWS_CSV: "every slip window of the monitor (rig time s, rpm, %)",
        SEGMENTS_CSV: "the segment table (rig time s, rpm, %, N)",
    }
    lines += [f"* `{p.name}`: {descriptions.get(p.name, '')}" for p in csv_files]
    lines += [f"* `{p.name}`" for p in plots]
    return "\n".join(lines) + "\n"


def write_report(result: OfflineResult, out_dir: str | Path) -> ReportFiles:
    """Write ``report.md`` and the plots into ``out_dir`` (created); the CSV files named in the
    report are the ones the analysis wrote (``result.csv_files``)."""
    folder = Path(out_dir)
    folder.mkdir(parents=True, exist_ok=True)
    plots = write_plots(result, folder)
    report = folder / REPORT_FILE
    report.write_text(report_markdown(result, plots, result.csv_files), encoding="utf-8")
    return ReportFiles(report, plots, tuple(result.csv_files))
