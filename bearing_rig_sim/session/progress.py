"""Live progress line and final summary table of a session (no ROS).

Speeds are converted to rpm and slip shown in percent here, at the edge; everything handed in is
SI (rad/s, s, N).

Progress line (one per second, or refreshed in place on a terminal)::

    [3/8 n1200 hold] t=14.2 s  inner 1200.1 rpm  cage 494.3 rpm  slip 3.512 %  slipping  rtf 0.98

Summary table (one row per segment)::

     #  segment  speed rpm  load N  F_bearing N  slip % meas  slip % truth  verdict  t_stable s
     1  load_up          0     100        100.0            -             -  unknown           -
     2  n0900          900     100         99.9        3.215         3.220  stable         2.31
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import TextIO
from collections.abc import Mapping, Sequence

from bearing_rig_sim.config import rad_s_to_rpm
from bearing_rig_sim.session.runner import SegmentOutcome, StatusState

__all__ = [
    "ProgressPrinter",
    "ProgressSnapshot",
    "RealTimeFactor",
    "format_delivery",
    "format_progress",
    "format_summary",
]

STATE_LABELS = {
    StatusState.UNKNOWN: "unknown",
    StatusState.SLIPPING: "slipping",
    StatusState.STABLE: "stable",
    StatusState.FAULT: "FAULT",
}


@dataclass(frozen=True)
class ProgressSnapshot:
    """What the progress line shows (SI units; None where nothing is known yet)."""

    segment_number: int
    """1-based; 0 before the first segment."""
    segment_count: int
    segment_name: str
    phase: str
    """``"ramp"``, ``"hold"``, ``"starting"`` or ``"done"``."""
    sim_time: float
    """s."""
    inner_ring_speed: float | None
    """rad/s, from the speed topic."""
    cage_speed: float | None
    """rad/s, from the speed topic."""
    slip_rate: float | None
    """%, the monitor's."""
    slip_state: StatusState | None
    real_time_factor: float | None


def _number(value: float | None, fmt: str, unit: str = "") -> str:
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:{fmt}}{unit}"


def format_progress(snap: ProgressSnapshot) -> str:
    """The progress line for a snapshot."""
    inner = None if snap.inner_ring_speed is None else rad_s_to_rpm(snap.inner_ring_speed)
    cage = None if snap.cage_speed is None else rad_s_to_rpm(snap.cage_speed)
    state = STATE_LABELS[snap.slip_state] if snap.slip_state is not None else "-"
    return (
        f"[{snap.segment_number}/{snap.segment_count} {snap.segment_name} {snap.phase}] "
        f"t={snap.sim_time:.1f} s  inner {_number(inner, '.1f', ' rpm')}  cage {_number(cage, '.1f', ' rpm')}  "
        f"slip {_number(snap.slip_rate, '.3f', ' %')}  {state}  rtf {_number(snap.real_time_factor, '.2f')}"
    )


SUMMARY_COLUMNS = (
    "#",
    "segment",
    "speed rpm",
    "meas rpm",
    "load N",
    "F_bearing N",
    "slip % meas",
    "slip % truth",
    "verdict",
    "t_stable s",
    "conditions",
)
_LEFT = {"segment", "verdict", "conditions"}


def condition_marks(outcome: SegmentOutcome) -> str:
    """The ``conditions`` cell: ``ok``, or what was off (``speed``, ``load``, ``disturbed``)."""
    marks = [kind for kind in ("speed", "load", "disturbed") if any(c.startswith(kind) for c in outcome.conditions)]
    return ",".join(marks) or "ok"


def format_summary(outcomes: Sequence[SegmentOutcome], sweeps: Mapping[int, str] | None = None) -> str:
    """The summary table, one row per segment, columns aligned (numbers right, words left).

    ``speed rpm`` is the segment's target speed, ``meas rpm`` the monitor's measured speed after
    the ramp; ``load N`` its set-point, ``F_bearing N`` the mean force on the bearing once settled;
    the slips are the monitor's and the simulator's truth over the same window; ``t_stable s`` the
    time from the ramp end to the stable verdict (from a run-up's start: a run-up is judged during
    its acceleration, a line under the table says so and at which speed); ``conditions`` ``ok``,
    or what was off (the lines under the table say how). ``sweeps`` (rpm -> verdict, :attr:`ProgramRunner.sweeps`) adds
    the load sweep's verdict per speed under the table.
    """
    rows = [
        [
            str(o.index + 1),
            o.name,
            f"{rad_s_to_rpm(o.target_speed):.0f}",
            _number(None if o.measured_speed is None else rad_s_to_rpm(o.measured_speed), ".0f"),
            f"{o.axial_load:g}",
            _number(o.bearing_force, ".1f"),
            _number(o.measured_slip, ".3f"),
            _number(o.truth_slip, ".3f"),
            o.verdict.value,
            _number(o.time_to_stable, ".2f"),
            condition_marks(o),
        ]
        for o in outcomes
    ]
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(SUMMARY_COLUMNS)]

    def line(cells: Sequence[str]) -> str:
        return "  ".join(c.ljust(w) if h in _LEFT else c.rjust(w) for c, w, h in zip(cells, widths, SUMMARY_COLUMNS)).rstrip()

    out = [line(SUMMARY_COLUMNS), "  ".join("-" * w for w in widths)]
    out.extend(line(r) for r in rows)
    if not rows:
        out.append("(no segment ran)")
    run_ups = [o for o in outcomes if o.run_up and o.time_to_stable is not None]
    if run_ups:
        at = ", ".join(f"{o.name} {_number(None if o.stable_speed is None else rad_s_to_rpm(o.stable_speed), '.0f')} rpm" for o in run_ups)
        out += [
            "",
            f"run-ups are judged during their acceleration (the paper's section 4.2): t_stable from the run-up's start, slip at the stable status ({at})",
        ]
    off = [o for o in outcomes if o.conditions]
    if off:
        out.append("")
        out.extend(f"conditions not met in segment {o.index + 1} {o.name}: {'; '.join(o.conditions)}" for o in off)
    if sweeps:
        out += ["", "load sweep by the paper's method (slip against load per speed, Gaussian fit, k1):"]
        out.extend(f"  {rpm} rpm: {text}" for rpm, text in sweeps.items())
    return "\n".join(out)


class RealTimeFactor:
    """Simulated seconds per wall-clock second over a sliding window of (wall, sim) samples.

    Args:
        window_s: wall-clock span of the window, s.
    """

    def __init__(self, window_s: float = 2.0) -> None:
        self.window = window_s
        self._samples: deque[tuple[float, float]] = deque()

    def add(self, wall_time: float, sim_time: float) -> None:
        """A sample: wall time (s, monotonic) and sim time (s)."""
        samples = self._samples
        if samples and sim_time < samples[-1][1]:  # the clock went back: start again
            samples.clear()
        samples.append((wall_time, sim_time))
        while len(samples) > 2 and samples[1][0] <= wall_time - self.window:
            samples.popleft()

    @property
    def value(self) -> float | None:
        """The factor, None until the window spans some wall time."""
        if len(self._samples) < 2:
            return None
        (w0, s0), (w1, s1) = self._samples[0], self._samples[-1]
        if w1 - w0 <= 0.0:
            return None
        return (s1 - s0) / (w1 - w0)


class ProgressPrinter:
    """Prints progress lines: refreshed in place on a terminal, one per line otherwise; nothing
    when quiet. :meth:`done` ends a line left open on a terminal.

    Args:
        out: where to print.
        quiet: print nothing.
        refresh: overwrite the line in place (default: ``out`` is a terminal).
    """

    def __init__(self, out: TextIO, *, quiet: bool = False, refresh: bool | None = None) -> None:
        self.out = out
        self.quiet = quiet
        self.refresh = out.isatty() if refresh is None else refresh
        self._open = False

    def show(self, line: str) -> None:
        """Print one progress line."""
        if self.quiet:
            return
        if self.refresh:
            self.out.write("\r" + line + "\x1b[K")
            self._open = True
        else:
            self.out.write(line + "\n")
        self.out.flush()

    def message(self, text: str) -> None:
        """Print a line of its own (an event), not overwritten by the next progress line."""
        self.done()
        self.out.write(text + "\n")
        self.out.flush()

    def done(self) -> None:
        """End an open refreshing line."""
        if self._open:
            self.out.write("\n")
            self.out.flush()
            self._open = False


def format_delivery(published: Mapping[str, int], recorded: Mapping[str, int], unreported: Sequence[str] = ()) -> str:
    """The delivery table of the summary: per topic, the messages published (the nodes' own
    counts, from their delivery reports, and the session's) and those recorded; every topic
    recorded short of what was published is named again under the table in capitals, and so is
    each node that sent no delivery report (``unreported``: its topics' counts are unknown)."""
    topics = sorted(set(published) | {t for t, n in recorded.items() if n})
    name_width = max([len("topic"), *(len(t) for t in topics)])
    lines = [f"{'topic'.ljust(name_width)}  {'published':>10}  {'recorded':>10}"]
    short = []
    for topic in topics:
        sent = published.get(topic)
        got = recorded.get(topic, 0)
        lines.append(f"{topic.ljust(name_width)}  {'?' if sent is None else sent:>10}  {got:>10}")
        if sent is not None and got < sent:
            short.append(f"NOT ALL RECORDED: {topic}: {sent - got} of {sent} published messages missing from the bag")
    lines.extend(short)
    lines.extend(f"NO DELIVERY REPORT from {name}: what it published is unknown" for name in unreported)
    unknown = [t for t in topics if t not in published]
    if unknown and not unreported:
        lines.append(f"published counts unknown for {len(unknown)} topic(s): their publishers sent no delivery report (nodes managed elsewhere)")
    elif not short and not unreported:
        lines.append("every published message recorded")
    return "\n".join(lines)
