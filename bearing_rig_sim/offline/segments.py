"""Program segments and constant-speed stretches of a run, accumulated from the status rows.

:class:`SegmentTracker` cuts the run as it streams:

* **program segments**, when the bag has spindle commands: each command starts a segment; its
  ramp ends ``ramp_time`` after the command's stamp (STEP profile) or after
  ``|target - previous target| / acceleration`` (constant acceleration); names come from the run's
  test program when it has as many segments as there were commands;
* **constant-speed stretches** otherwise (bench bags): consecutive slip windows whose inner-ring
  speed stays within :data:`STRETCH_TOLERANCE` of the stretch's mean, kept when they last at
  least :data:`STRETCH_MIN_DURATION_S`; the ramp end is the stretch's start.

A segment's means are taken over the rows from its ramp end on whose slip window started after
it; its verdicts are the last state
in it; its time to stable follows the one rule the live session summary also uses
(:class:`~bearing_rig_sim.monitoring.schedule.TimeToStable`), for the offline statuses and the
recorded ones alike. A status belongs to the segment its window ended in, as the live summary
judges it: one made or read after the next command took effect, on a window that ended before,
counts for the previous segment's verdict and time to stable.

Units: s, rad/s, N; slip in percent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.config import ConfigError, parse_yaml
from bearing_rig_sim.monitoring.schedule import TimeToStable, evidence_start
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.offline.series import CsvWriter, StatusRow, csv_columns
from bearing_rig_sim import picklable

SEGMENTS_CSV = "segments.csv"
STRETCH_TOLERANCE = 0.01
"""A window further than this fraction from its stretch's mean inner-ring speed ends it (1)."""
STRETCH_MIN_DURATION_S = 2.0
"""Shorter constant-speed stretches (ramps, hesitations) are not reported, s."""
PROFILE_CONSTANT_ACCELERATION = 1
"""SpindleCommand.msg's ``PROFILE_CONSTANT_ACCELERATION``."""

_NAN = math.nan


@dataclass(frozen=True)
class SegmentSummary:
    """A program segment or a constant-speed stretch.

    Attributes:
        name: program segment name, ``segment <n>`` or ``stretch <n>``.
        start_time / ramp_end / end_time: rig time, s (the means cover ``ramp_end .. end_time``);
            a program segment ends where the next one starts (the last one, and a stretch, at
            its last status row), so one without a status row still spans its time.
        target_speed: commanded inner-ring speed, rad/s (NaN for a stretch).
        inner_ring_speed: mean measured inner-ring speed (monitor windows), rad/s.
        axial_load: mean axial load (:attr:`StatusRow.axial_load`), N.
        slip_rate / recorded_slip_rate / truth_slip_rate: mean slip, offline monitor / recorded
            status / simulator truth, %.
        final_state: the offline monitor's state at the segment's last status row.
        final_recorded_state: the state of the latest-stamped recorded status stamped in the
            segment (-1 if none), as the live session summary judges: at rest, where no pulse
            makes a row, the monitor's own verdict of the silence, which can reach the bag after
            the next segment's command (stamped within the segment all the same).
        time_to_stable / recorded_time_to_stable: by :class:`TimeToStable`, s (None without one):
            from the ramp's end, or for a run-up (constant acceleration) from its start.
        rows: status rows after the ramp end (1).
    """

    name: str
    start_time: float
    ramp_end: float
    end_time: float
    target_speed: float
    inner_ring_speed: float
    axial_load: float
    slip_rate: float
    recorded_slip_rate: float
    truth_slip_rate: float
    final_state: int
    final_recorded_state: int
    time_to_stable: float | None
    recorded_time_to_stable: float | None
    rows: int


class _Segment:
    """Accumulates one segment's figures from the status rows after its ramp end."""

    def __init__(self, name: str, start: float, ramp_end: float, target: float, settings: MonitorSettings, run_up: bool = False) -> None:
        self.name, self.start, self.ramp_end, self.target = name, start, ramp_end, target
        self.end = start
        self.sums: dict[str, list[float]] = {}
        self.rows = 0
        self.final_state = int(SlipState.UNKNOWN)
        self.final_recorded = -1
        self.final_recorded_stamp = -math.inf
        self.settings = settings
        commanded = target if math.isfinite(target) else None  # a stretch found by speed has no command
        start_of_run_up = start if run_up else None
        confidence = settings.stable_confidence  # the running monitor's when the bag recorded it (offline.analysis)
        self.stable = TimeToStable(ramp_end, commanded, start_of_run_up, min_confidence=confidence)
        self.recorded_stable = TimeToStable(ramp_end, commanded, start_of_run_up, min_confidence=confidence)

    def _add(self, key: str, value: float) -> None:
        if math.isfinite(value):
            entry = self.sums.setdefault(key, [0.0, 0])
            entry[0] += value
            entry[1] += 1

    def mean(self, key: str) -> float:
        total, count = self.sums.get(key, (0.0, 0))
        return total / count if count else _NAN

    def add_row(self, row: StatusRow) -> None:
        self.end = row.time
        self.add_late_row(row)  # its verdict; then its figures
        if row.time < self.ramp_end:
            return
        self.rows += 1
        if math.isfinite(row.window_start) and row.window_start < self.ramp_end:
            return  # the slip window reaches back into the ramp: not a figure of the segment's speed
        for key in ("inner_ring_speed", "slip_rate", "recorded_slip_rate", "truth_slip_rate", "axial_load"):
            self._add(key, getattr(row, key))

    def add_late_row(self, row: StatusRow) -> None:
        """A status row's verdict (the final state and the time to stable): all that counts of
        a row on a window that ended in this segment, made after the next segment began (see
        :meth:`SegmentTracker.row`); its figures do not (the means are over the rows made in the
        segment, :meth:`add_row`)."""
        self.final_state = row.state
        if math.isfinite(row.window_end):
            self.stable.observe(row.window_end, self.evidence(row.window_end, row.cage_speed), row.state, row.confidence, row.inner_ring_speed)

    def evidence(self, stamp: float, cage_speed: float) -> float:
        st = self.settings
        return evidence_start(stamp, cage_speed, st.window_revolutions, st.slope_span_s, st.min_slope_points, st.min_window_s)

    def add_recorded(self, stamp: float, cage_speed: float, state: int, confidence: float, inner_ring_speed: float = _NAN) -> None:
        self.take_final_recorded(stamp, state)
        self.recorded_stable.observe(stamp, self.evidence(stamp, cage_speed), state, confidence, inner_ring_speed)

    def take_final_recorded(self, stamp: float, state: int) -> None:
        """A recorded status's state, if it is the latest stamped so far (a status stamped before
        the segment's start, in a program, is the previous segment's)."""
        if stamp >= self.final_recorded_stamp and (stamp >= self.start or not math.isfinite(self.target)):
            self.final_recorded, self.final_recorded_stamp = state, stamp

    def summary(self) -> SegmentSummary:
        return SegmentSummary(
            name=self.name,
            start_time=self.start,
            ramp_end=self.ramp_end,
            end_time=self.end,
            target_speed=self.target,
            inner_ring_speed=self.mean("inner_ring_speed"),
            axial_load=self.mean("axial_load"),
            slip_rate=self.mean("slip_rate"),
            recorded_slip_rate=self.mean("recorded_slip_rate"),
            truth_slip_rate=self.mean("truth_slip_rate"),
            final_state=self.final_state,
            final_recorded_state=self.final_recorded,
            time_to_stable=self.stable.time_to_stable,
            recorded_time_to_stable=self.recorded_stable.time_to_stable,
            rows=self.rows,
        )


def program_segment_names(run_metadata: dict[str, str]) -> list[str]:
    """Segment names of the run's test program (run context key ``program``); [] when absent or
    unreadable."""
    try:
        doc = parse_yaml(run_metadata.get("program", "") or "", "run context: program")
        return [str(s.get("name", "")) for s in doc["segments"]]
    except (ConfigError, TypeError, KeyError, AttributeError):
        return []


def program_criterion(run_metadata: dict[str, str]) -> str:
    """The run's test program's ``stability_criterion`` ("" when absent or unreadable)."""
    try:
        doc = parse_yaml(run_metadata.get("program", "") or "", "run context: program")
        return str(doc.get("stability_criterion", "") or "")
    except (ConfigError, AttributeError):
        return ""


def write_segments_csv(path: Path, segments: list[SegmentSummary]) -> Path:
    """The segment table as CSV (speeds in rpm); returns ``path``."""
    sink = CsvWriter(path, csv_columns(SegmentSummary))
    try:
        for segment in segments:
            sink.write(segment)
    finally:
        sink.close()
    return path


class SegmentTracker:
    """Segments of a run from its status rows (see the module documentation).

    Args:
        by_program: cut at spindle commands (:meth:`command`); else find constant-speed stretches.
        names: the test program's segment names (used when their count matches).
    """

    def __init__(self, by_program: bool, names: list[str], settings: MonitorSettings | None = None) -> None:
        self.by_program = by_program
        self.names = names
        self.settings = settings if settings is not None else MonitorSettings.from_yaml()
        self.segments: list[SegmentSummary] = []
        self._open: _Segment | None = None
        self._last_closed: _Segment | None = None
        """The segment of ``segments[-1]`` (the late recorded statuses stamped in it)."""
        self._previous_target = _NAN
        self._windows = 0
        self._stretch_sum = 0.0
        self._stretch_windows = 0

    def command(self, start: float, target: float, profile: int, ramp_time: float, acceleration: float, speed_now: float) -> None:
        """A spindle command stamped ``start`` (s): ``target`` (rad/s) reached by a STEP ramp of
        ``ramp_time`` (s) or at ``acceleration`` (rad/s^2) from the previous target (the first
        time: from ``speed_now``, rad/s)."""
        previous = self._previous_target if math.isfinite(self._previous_target) else speed_now
        run_up = profile == PROFILE_CONSTANT_ACCELERATION and acceleration > 0.0 and target != previous
        if profile == PROFILE_CONSTANT_ACCELERATION and acceleration > 0.0:
            ramp = abs(target - previous) / acceleration
        else:
            ramp = max(ramp_time, 0.0)
        self._previous_target = target
        index = len(self.segments) + (self._open is not None)
        if self._open is not None and start > self._open.end:  # a segment lasts until the next one begins
            self._open.end = start
        self._close()
        self._open = _Segment(f"segment {index + 1}", start, start + ramp, target, self.settings, run_up)

    def row(self, row: StatusRow) -> None:
        """One status row, in time order.

        In a program, a row on a window that ended before the open segment's start is the
        previous segment's, as the live summary judges a status by its stamp: the next command
        takes effect when the bag's log reaches its stamp, and a pulse that closed that window
        may have reached the recorder later (without real time the recorder runs behind the
        simulator), so the row was made after the switch. Its verdict then counts for the
        previous segment (:meth:`_Segment.add_late_row`).
        """
        late = self._late(row.window_end)
        if late is not None:
            late.add_late_row(row)
            self.segments[-1] = late.summary()
            return
        if not self.by_program and row.windows != self._windows:
            self._windows = row.windows
            inner = row.inner_ring_speed
            if not math.isfinite(inner):
                self._close()
            else:
                mean = self._stretch_sum / self._stretch_windows if self._stretch_windows else _NAN
                if self._open is None or abs(inner - mean) > STRETCH_TOLERANCE * mean:
                    self._close()
                    self._open = _Segment("", row.time, row.time, _NAN, self.settings)
                    self._stretch_sum, self._stretch_windows = 0.0, 0
                self._stretch_sum += inner
                self._stretch_windows += 1
        if self._open is not None:
            self._open.add_row(row)

    def recorded(self, stamp: float, cage_speed: float, state: int, confidence: float, inner_ring_speed: float = _NAN) -> None:
        """A recorded slip status: its stamp (window end, s), cage speed (rad/s), state,
        confidence and inner-ring speed (rad/s). One stamped in the previous segment and read
        after the next began is the previous segment's (its final state and time to stable)."""
        if self._open is not None:
            self._open.add_recorded(stamp, cage_speed, state, confidence, inner_ring_speed)
        last = self._late(stamp)
        if last is not None:
            last.take_final_recorded(stamp, state)  # the previous segment's, read after the next began
            last.recorded_stable.observe(stamp, last.evidence(stamp, cage_speed), state, confidence, inner_ring_speed)
            self.segments[-1] = replace(
                self.segments[-1], final_recorded_state=last.final_recorded, recorded_time_to_stable=last.recorded_stable.time_to_stable
            )

    def _late(self, window_end: float) -> _Segment | None:
        """The previous segment, when a window that ended at ``window_end`` (s) belongs to it and
        not to the open one (see :meth:`row`), or to none open; else None."""
        last = self._last_closed
        if not self.by_program or last is None or not math.isfinite(window_end):
            return None
        return last if last.start <= window_end < (self._open.start if self._open is not None else math.inf) else None

    def finish(self) -> list[SegmentSummary]:
        """Close the last segment; returns every segment."""
        self._close()
        if self.by_program and len(self.names) == len(self.segments):
            self.segments = [replace(segment, name=name) for segment, name in zip(self.segments, self.names)]
        return self.segments

    def _close(self) -> None:
        segment, self._open = self._open, None
        if segment is None:
            return
        if not self.by_program:
            if segment.end - segment.start < STRETCH_MIN_DURATION_S:
                return
            segment.name = f"stretch {len(self.segments) + 1}"
        self.segments.append(segment.summary())
        self._last_closed = segment


picklable.by_fields(SegmentSummary)
