"""The slip monitor without ROS: cage slip and its stability from the fibre-optic pulses alone.

:class:`SlipMonitor` reads only what the bench's sensors give (per pulse: time, strip id, strip
count, pulse index; docs/paper.md section 8) and the bearing's kinematics, so it runs unchanged on the
real bench's pulses.

**Slip over whole cage revolutions** (paper Eq. 11-12), incrementally, as
:func:`~bearing_rig_sim.analysis.slip.whole_revolution_slip` does in one batch: the cage pulses
are cut into consecutive windows of ``window_revolutions`` whole cage revolutions, each starting
and ending on a passage of the same strip, so the mean cage speed ``2 pi R / (t1 - t0)`` is exact
whatever the strips' spacing. The spindle's revolution count is interpolated linearly in its
pulse index at ``t0`` and ``t1`` (equally spaced spindle strips), and the mean inner-ring speed is
its difference over the same interval. A window waits until a spindle pulse at or after its end
has arrived (the two topics arrive interleaved). Each window's (end time, slip %) feeds the
streaming slope criterion (:class:`~bearing_rig_sim.analysis.streaming.StreamingStability`,
criterion "time"); the time axis starts at the first window's end after each reset, so
wall-clock stamps of a bench (about 1.7e9 s) do not spoil the fit.

**Bad data is reported, never raised:**

* a gap in ``pulse_index`` (lost pulses), or a malformed pulse (strip id out of range, strip ids
  inconsistent with the indices, a non-finite time): a fault, held for ``fault_hold_s`` of rig
  time after the last occurrence; malformed pulses are discarded;
* sensor loss (:meth:`SlipMonitor.check`): no pulse from a shaft for more than
  ``loss_period_factor`` times its last pulse period (and at least ``loss_min_timeout_s``), or a
  shaft silent since the start while the other turned ``silent_shaft_revolutions``, found at two
  consecutive checks (a monitor that was itself held up takes in its backlog of pulses between
  the two, instead of reporting its own stall as the sensor's); a fault while it lasts. A shaft that has stopped cannot be told from a lost sensor by its pulses alone: both
  are reported;
* an out-of-order pulse (index or time not after the previous one of its shaft, by less than
  ``clock_jump_tolerance_s``): discarded, that shaft's counting restarts with its next pulse,
  and a note is shown;
* a clock jump backwards (a pulse more than ``clock_jump_tolerance_s`` before its shaft's
  previous one, or :meth:`SlipMonitor.clock_jump` from the node): everything is reset, state
  unknown.

**A stop is not a sensor loss.** When both shafts have fallen silent and each one's last pulse
period was longer than the one before by more than :data:`STOP_PERIOD_GROWTH` (both were slowing
down), the rig has stopped: state unknown, no fault. A shaft that falls silent at a steady or
rising speed, or while the other keeps turning steadily, is lost.

**The slip series restarts with each new operating phase**, so that the verdict answers for the
present phase and not for the whole run. The spindle is *steady* in a window whose mean speed
is within ``restart_speed_change_fraction`` of the previous window's, *changing* otherwise; the
series restarts when it turns from one to the other (the start and the end of a ramp), and after
the spindle has been below ``min_inner_ring_speed_rad_s`` (a stop). A run-up from rest is thus
one series, as in the paper's slip-against-time fits under acceleration (docs/paper.md section 7), and
a hold at constant speed after a ramp is another, judged on its own. A 1-term Gaussian cannot
describe a ramp and the plateau after it (a rise then a flat) without a spurious fall.

Units: s, rad/s; slip, slopes in percent and percent per second.
"""

from __future__ import annotations

import bisect
import math
from collections import deque
from dataclasses import dataclass, field
from enum import IntEnum
from pathlib import Path

from bearing_rig_sim.analysis.inputs import AnalysisError
from bearing_rig_sim.analysis.slip import BearingKinematics
from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.analysis.streaming import StreamingStability
from bearing_rig_sim.config import Section, config_path, load_yaml, ros_parameters
from bearing_rig_sim.rig.fibre_optic import TWO_PI, Pulse

NODE_NAME = "monitor"
"""The monitor node's name: the key of its block in a ROS 2 parameter file."""

SHIPPED_FILE = "monitor.yaml"
"""The shipped parameter file, under ``config/``."""

CRITERION = "time"
"""Abscissa of the monitor's slope criterion: slip against time (k2, docs/paper.md section 7)."""

MAX_PENDING_WINDOWS = 1000
"""Most cage windows kept waiting for spindle pulses; older ones are dropped (1)."""

SHAFTS = ("spindle", "cage")

STOP_PERIOD_GROWTH = 0.01
"""A pulse period longer than the shaft's previous one by more than this fraction means the
shaft was slowing down (1). The timing jitter of config/rig.yaml (1 us) changes a period by less
than 0.1 % at the highest test speed (a 5.5 ms spindle period at 2700 rpm with 4 strips)."""


class MonitorState(IntEnum):
    """The monitor's state; the values are SlipStatus.msg's ``STATE_*`` constants."""

    UNKNOWN = 0
    SLIPPING = 1
    STABLE = 2
    FAULT = 3


@dataclass(frozen=True)
class MonitorSettings:
    """The monitor's validated parameters (``config/monitor.yaml``; the unit is in each name).

    Attributes:
        bearing_file: bearing data file (geometry for the epicyclic cage speed).
        contact_angle_deg: contact angle of the slip formula, degrees; negative: the bearing
            file's nominal angle.
        window_revolutions: whole cage revolutions per slip window (>= 1).
        critical_slope_pct_per_s: k2 of the slope criterion, %/s.
        refit_interval: refit the Gaussian after this many windows.
        stability_window_points: most windows the fit keeps.
        max_fit_age_s: also refit when this much rig time has passed since the last fit, s.
        min_inner_ring_speed_rad_s: windows with a lower mean spindle speed give no slip point
            (the slip rate is undefined at rest and meaningless near it) and restart the slip
            series, rad/s.
        restart_speed_change_fraction: the spindle is steady in a window whose mean speed is
            within this fraction of the previous window's; the slip series restarts when it turns
            steady or changing (1); 0 never restarts on speed changes.
        loss_period_factor: sensor loss after this many times a shaft's last pulse period (1).
        loss_min_timeout_s: ... but never sooner than this, s.
        silent_shaft_revolutions: a shaft silent since the start is lost once the other has
            turned this many revolutions (1).
        fault_hold_s: a gap or malformed pulse keeps the fault this long, rig s.
        clock_jump_tolerance_s: a pulse further back than this before its shaft's previous one
            is a clock jump (reset all); less far back, an out-of-order pulse, s.
        status_rate_hz: rate of the status message (besides every state change), wall Hz.
        diagnostics_rate_hz: rate of /diagnostics (besides every change), wall Hz.
    """

    bearing_file: Path
    contact_angle_deg: float
    window_revolutions: int
    critical_slope_pct_per_s: float
    refit_interval: int
    stability_window_points: int
    max_fit_age_s: float
    min_inner_ring_speed_rad_s: float
    restart_speed_change_fraction: float
    loss_period_factor: float
    loss_min_timeout_s: float
    silent_shaft_revolutions: float
    fault_hold_s: float
    clock_jump_tolerance_s: float
    status_rate_hz: float
    diagnostics_rate_hz: float

    @classmethod
    def from_section(cls, s: Section) -> MonitorSettings:
        """Validate the parameters in ``s`` (every key required, none unknown besides
        ``use_sim_time``).

        Raises:
            ConfigError: naming the source, the key and the allowed range.
        """
        s.reject_unknown([*cls.__dataclass_fields__, "use_sim_time"])
        raw = s.string("bearing_file")
        bearing = Path(raw) if Path(raw).is_absolute() else config_path(*Path(raw).parts)
        if not bearing.is_file():
            raise s.error("bearing_file", f"file not found: {raw!r} (looked for {bearing})")
        return cls(
            bearing_file=bearing,
            contact_angle_deg=s.number("contact_angle_deg", lt=90.0),
            window_revolutions=s.integer("window_revolutions", ge=1, le=1000),
            critical_slope_pct_per_s=s.number("critical_slope_pct_per_s"),
            refit_interval=s.integer("refit_interval", ge=1),
            stability_window_points=s.integer("stability_window_points", ge=20),
            max_fit_age_s=s.number("max_fit_age_s", gt=0.0),
            min_inner_ring_speed_rad_s=s.number("min_inner_ring_speed_rad_s", gt=0.0),
            restart_speed_change_fraction=s.number("restart_speed_change_fraction", ge=0.0),
            loss_period_factor=s.number("loss_period_factor", gt=1.0),
            loss_min_timeout_s=s.number("loss_min_timeout_s", gt=0.0),
            silent_shaft_revolutions=s.number("silent_shaft_revolutions", gt=0.0),
            fault_hold_s=s.number("fault_hold_s", ge=0.0),
            clock_jump_tolerance_s=s.number("clock_jump_tolerance_s", gt=0.0),
            status_rate_hz=s.number("status_rate_hz", gt=0.0),
            diagnostics_rate_hz=s.number("diagnostics_rate_hz", gt=0.0),
        )

    @classmethod
    def from_values(cls, values: dict[str, object], source: str = "monitor parameters") -> MonitorSettings:
        """Validate a flat mapping of parameter values (the node's ROS parameters)."""
        return cls.from_section(Section(dict(values), source))

    @classmethod
    def from_yaml(cls, path: str | Path | None = None) -> MonitorSettings:
        """Read ``monitor: ros__parameters:`` of a parameter file (default: the shipped one)."""
        return cls.from_section(ros_parameters(load_yaml(path or config_path(SHIPPED_FILE)), NODE_NAME))

    def kinematics(self) -> BearingKinematics:
        """The bearing's kinematics at the configured (or nominal) contact angle."""
        nominal = BearingKinematics.from_config(self.bearing_file)
        if self.contact_angle_deg < 0.0:
            return nominal
        return nominal.at_contact_angle(math.radians(self.contact_angle_deg))


def shipped_parameters() -> dict[str, object]:
    """The raw values of the shipped ``config/monitor.yaml`` (the node's declared defaults)."""
    section = ros_parameters(load_yaml(config_path(SHIPPED_FILE)), NODE_NAME)
    MonitorSettings.from_section(section)
    return dict(section.data)


@dataclass(frozen=True)
class SlipWindow:
    """One completed window of whole cage revolutions.

    Attributes:
        start_time, end_time: its cage pulses, s.
        cage_speed: mean cage speed, rad/s.
        inner_ring_speed: mean spindle speed over the same interval, rad/s.
        slip_rate: percent; NaN when the spindle was below the minimum speed.
    """

    start_time: float
    end_time: float
    cage_speed: float
    inner_ring_speed: float
    slip_rate: float


@dataclass(frozen=True)
class MonitorStatus:
    """The monitor's status (the fields of SlipStatus.msg, SI units, slip in percent).

    ``time`` is the end of the latest window (None before the first); speeds, slip and slope
    are NaN when not known; ``faults`` lists the active faults' reasons, ``notes`` the recent
    resets and refusals.
    """

    state: MonitorState
    time: float | None
    inner_ring_speed: float
    cage_speed: float
    theoretical_cage_speed: float
    slip_rate: float
    fitted_slope: float
    critical_slope: float
    criterion: str
    confidence: float
    window_revolutions: int
    detail: str
    faults: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    windows: int = 0

    def message_fields(self) -> dict[str, object]:
        """The SlipStatus.msg fields of this status (all but the header), for any message class
        of that type (rclpy's or a bag typestore's)."""
        return {
            "inner_ring_speed": self.inner_ring_speed,
            "cage_speed": self.cage_speed,
            "theoretical_cage_speed": self.theoretical_cage_speed,
            "slip_rate": self.slip_rate,
            "fitted_slope": self.fitted_slope,
            "critical_slope": self.critical_slope,
            "state": int(self.state),
            "criterion": self.criterion,
            "confidence": self.confidence,
            "window_revolutions": self.window_revolutions,
            "detail": self.detail,
        }


@dataclass
class _Shaft:
    """What the monitor keeps of one shaft's pulses since its last reset."""

    name: str
    strip_count: int | None = None
    offset: int | None = None
    last_time: float | None = None
    last_index: int | None = None
    last_period: float | None = None
    previous_period: float | None = None
    pulses: int = 0
    times: list[float] = field(default_factory=list)
    indices: list[int] = field(default_factory=list)
    window_start: tuple[int, float] | None = None

    def revolutions(self) -> float:
        """Revolutions counted since the shaft's reset."""
        return self.pulses / self.strip_count if self.strip_count else 0.0

    def slowing(self) -> bool:
        """Whether the last pulse period was longer than the one before (see STOP_PERIOD_GROWTH)."""
        if self.last_period is None or self.previous_period is None:
            return False
        return self.last_period > self.previous_period * (1.0 + STOP_PERIOD_GROWTH)


class SlipMonitor:
    """Online cage slip and stability from the two pulse streams (see the module docstring).

    Args:
        kinematics: the bearing's geometry (nominal contact angle by default).
        settings: the monitor's parameters.
    """

    def __init__(self, kinematics: BearingKinematics, settings: MonitorSettings) -> None:
        self.kinematics = kinematics
        self.settings = settings
        self.stability = StreamingStability(
            criterion=CRITERION,
            critical_slope=settings.critical_slope_pct_per_s,
            refit_interval=settings.refit_interval,
            window=settings.stability_window_points,
            max_fit_age=settings.max_fit_age_s,
            defer_refit=True,  # refits run in check(), off the pulse path (status latency)
        )
        self._notes: deque[tuple[float | None, str]] = deque(maxlen=5)
        self.reset()
        self._notes.clear()

    # -- state ---------------------------------------------------------------------------------
    def reset(self, reason: str = "") -> None:
        """Forget every pulse, window, fit and fault (state unknown); ``reason`` becomes a note."""
        self._shafts = {name: _Shaft(name) for name in SHAFTS}
        self._pending: deque[tuple[float, float]] = deque()
        self.stability.reset()
        self._origin: float | None = None
        self._latest: SlipWindow | None = None
        self._latched: dict[str, tuple[float | None, str]] = {}
        self._loss: dict[str, str] = {}
        self._suspect: set[str] = set()
        self._stopped = ""
        self._steady: bool | None = None
        self._previous_inner: float | None = None
        self._now: float | None = None
        self.windows = 0
        """Windows completed since the last reset (1)."""
        self._notes.clear()
        if reason:
            self._notes.append((None, reason))

    @property
    def latest_window(self) -> SlipWindow | None:
        """The latest completed window (None before the first)."""
        return self._latest

    def last_pulse_time(self) -> float | None:
        """Time of the latest pulse of either shaft, s (None before any)."""
        times = [s.last_time for s in self._shafts.values() if s.last_time is not None]
        return max(times) if times else None

    def _note(self, time: float | None, text: str) -> None:
        """A note shown in the status for ``fault_hold_s`` after ``time`` (None: after the next
        :meth:`check`)."""
        self._notes.append((time, text))

    def _latch(self, key: str, time: float | None, reason: str) -> None:
        """A fault held for ``fault_hold_s`` after ``time`` (None: after the next :meth:`check`)."""
        self._latched[key] = (time, reason)

    # -- input ---------------------------------------------------------------------------------
    def clock_jump(self, previous: float, now: float) -> None:
        """The rig clock went back from ``previous`` to ``now`` (s): reset everything."""
        self.reset(f"reset: the clock jumped back from {previous:.6g} s to {now:.6g} s")

    def add_pulse(self, shaft: str, pulse: Pulse) -> bool:
        """Take one pulse of ``shaft`` (``"spindle"`` or ``"cage"``).

        Never raises on bad data: faults and notes go to the status.

        Returns:
            Whether a slip window was completed (the status may have changed).
        """
        if shaft not in self._shafts:
            self._note(None, f"pulse of unknown shaft {shaft!r} ignored")
            return False
        problem = _malformed(pulse)
        if problem:
            self._latch(f"{shaft}-invalid", self._now, f"{shaft}: invalid pulse discarded ({problem})")
            return False
        s = self._shafts[shaft]
        t, index = float(pulse.time), int(pulse.pulse_index)
        if s.last_time is not None and s.last_index is not None:
            if t < s.last_time - self.settings.clock_jump_tolerance_s:
                self.reset(f"reset: {shaft} pulse at {t:.6g} s after one at {s.last_time:.6g} s (clock jumped back)")
                s = self._shafts[shaft]
            elif t <= s.last_time or index <= s.last_index:
                self._note(
                    t,
                    f"{shaft}: out-of-order pulse (index {index} at {t:.9g} s after index {s.last_index} at "
                    f"{s.last_time:.9g} s) discarded; {shaft} counting restarted",
                )
                self._restart_shaft(shaft)
                return False
            elif pulse.strip_count != s.strip_count:
                self._note(t, f"{shaft}: strip_count changed from {s.strip_count} to {pulse.strip_count}; counting restarted")
                self._restart_shaft(shaft)
                s = self._shafts[shaft]
            elif (pulse.strip_id - index) % pulse.strip_count != s.offset:
                self._latch(
                    f"{shaft}-invalid",
                    t,
                    f"{shaft}: strip {pulse.strip_id} at pulse_index {index} does not match the earlier strips "
                    "(strip ids inconsistent with the indices); counting restarted",
                )
                self._restart_shaft(shaft)
                s = self._shafts[shaft]
        if s.last_index is not None and s.last_time is not None:
            step = index - s.last_index
            if step > 1:
                self._latch(f"{shaft}-gap", t, f"{shaft}: {step - 1} pulse(s) lost before pulse_index {index} (gap in pulse_index)")
            s.previous_period = s.last_period
            s.last_period = (t - s.last_time) / step
        else:
            s.strip_count = pulse.strip_count
            s.offset = (pulse.strip_id - index) % pulse.strip_count
        s.last_time, s.last_index = t, index
        s.pulses += 1
        self._now = t if self._now is None else max(self._now, t)
        if shaft == "spindle":
            s.times.append(t)
            s.indices.append(index)
            return self._process_pending()
        return self._add_cage_pulse(s, t, index)

    def _restart_shaft(self, shaft: str) -> None:
        self._shafts[shaft] = _Shaft(shaft)
        self._loss.pop(shaft, None)
        self._suspect.discard(shaft)

    def _add_cage_pulse(self, cage: _Shaft, t: float, index: int) -> bool:
        assert cage.strip_count is not None
        span = self.settings.window_revolutions * cage.strip_count
        if cage.window_start is None:
            cage.window_start = (index, t)
            return False
        start_index, start_time = cage.window_start
        if index - start_index < span:
            return False
        if index - start_index == span:
            self._pending.append((start_time, t))
            if len(self._pending) > MAX_PENDING_WINDOWS:
                self._pending.popleft()
        # else: the pulse closing the window was lost (already a gap fault); start afresh here
        cage.window_start = (index, t)
        return self._process_pending()

    # -- windows -------------------------------------------------------------------------------
    def _spindle_revolutions(self, spindle: _Shaft, t: float) -> float:
        """Spindle revolutions (in pulse-index units / strips) at ``t``, interpolated."""
        assert spindle.strip_count is not None
        k = bisect.bisect_right(spindle.times, t) - 1
        if k >= len(spindle.times) - 1:
            return spindle.indices[-1] / spindle.strip_count
        t0, t1 = spindle.times[k], spindle.times[k + 1]
        i0, i1 = spindle.indices[k], spindle.indices[k + 1]
        return (i0 + (t - t0) / (t1 - t0) * (i1 - i0)) / spindle.strip_count

    def _process_pending(self) -> bool:
        spindle = self._shafts["spindle"]
        completed = False
        while self._pending and spindle.times and spindle.times[-1] >= self._pending[0][1]:
            t0, t1 = self._pending.popleft()
            if spindle.times[0] > t0:
                continue  # the spindle's pulses start after the window: cannot be measured
            duration = t1 - t0
            inner = TWO_PI * (self._spindle_revolutions(spindle, t1) - self._spindle_revolutions(spindle, t0)) / duration
            cage = TWO_PI * self.settings.window_revolutions / duration
            slip = self._add_point(t1, cage, inner)
            self._latest = SlipWindow(t0, t1, cage, inner, slip)
            self.windows += 1
            completed = True
        self._prune_spindle()
        return completed

    def _restart_series(self, time: float, why: str) -> None:
        if self.stability.n_points:
            self._note(time, f"slip series restarted at {time:.6g} s: {why}")
        self.stability.reset()
        self._origin = None

    def _add_point(self, t1: float, cage: float, inner: float) -> float:
        """The slip of a window, added to the series (NaN below the minimum speed)."""
        st = self.settings
        if inner < st.min_inner_ring_speed_rad_s:
            if self._previous_inner is not None:
                self._restart_series(t1, f"spindle below {st.min_inner_ring_speed_rad_s:g} rad/s")
            self._previous_inner, self._steady = None, None
            return math.nan
        previous = self._previous_inner
        steady = None if previous is None else abs(inner - previous) <= st.restart_speed_change_fraction * previous
        if None not in (steady, self._steady) and steady != self._steady and st.restart_speed_change_fraction > 0.0:
            change = f"steady at {inner:.6g} rad/s" if steady else f"changing, {previous:.6g} -> {inner:.6g} rad/s"
            self._restart_series(t1, f"spindle speed {change}")
        self._steady = steady
        self._previous_inner = inner
        slip = float(self.kinematics.slip_rate(cage, inner))
        if self._origin is None:
            self._origin = t1
        try:
            self.stability.add(t1 - self._origin, slip)
        except AnalysisError as exc:  # cannot happen with ordered windows; never crash
            self._restart_series(t1, str(exc))
        return slip

    def _prune_spindle(self) -> None:
        spindle, cage = self._shafts["spindle"], self._shafts["cage"]
        starts = [t0 for t0, _ in self._pending]
        if cage.window_start is not None:
            starts.append(cage.window_start[1])
        keep_from = min(starts) if starts else math.inf
        # keep the last pulse at or before keep_from (the left bracket of the earliest window)
        k = bisect.bisect_right(spindle.times, keep_from) - 1
        k = min(k, len(spindle.times) - 1)
        if k > 0:
            del spindle.times[:k]
            del spindle.indices[:k]

    # -- time-based checks ---------------------------------------------------------------------
    def check(self, now: float) -> None:
        """Sensor-loss checks and the expiry of held faults at the rig time ``now`` (s).

        ``now`` may run ahead of the pulses (e.g. extrapolated by the wall clock when the
        source has stopped); it is not used to detect clock jumps. A shaft is lost when it is
        found silent at this check and at the previous one.
        """
        if not math.isfinite(now):
            return
        self.stability.refit_if_due()
        st = self.settings
        for key, (when, reason) in list(self._latched.items()):
            if when is None:
                self._latched[key] = (now, reason)
            elif now - when > st.fault_hold_s:
                del self._latched[key]
        kept = [(now if when is None else when, text) for when, text in self._notes]
        self._notes.clear()
        self._notes.extend((when, text) for when, text in kept if now - when <= st.fault_hold_s)
        silent: dict[str, str] = {}
        for name in SHAFTS:
            s = self._shafts[name]
            other = self._shafts["cage" if name == "spindle" else "spindle"]
            if s.last_time is None:
                turned = other.revolutions()
                if turned >= st.silent_shaft_revolutions:
                    silent[name] = f"{name}: no pulse since the start while the {other.name} turned {turned:.3g} revolutions"
                continue
            limit = st.loss_min_timeout_s
            if s.last_period is not None:
                limit = max(limit, st.loss_period_factor * s.last_period)
            quiet = now - s.last_time
            if quiet > limit:
                period = f"{s.last_period:.3g} s" if s.last_period is not None else "unknown"
                silent[name] = f"{name}: no pulse for {quiet:.3g} s (limit {limit:.3g} s; last period {period})"
        confirmed = {name: reason for name, reason in silent.items() if name in self._suspect}
        self._suspect = set(silent)
        silent = confirmed
        spindle, cage = self._shafts["spindle"], self._shafts["cage"]
        if len(silent) == 2 and spindle.slowing() and cage.slowing():
            self._stopped = "spindle and cage stopped (their pulse periods grew before the pulses ceased)"
            self._loss = {}
        else:
            self._stopped = ""
            self._loss = {name: f"{reason}: sensor loss" for name, reason in silent.items()}
        if self._stopped:
            self._restart_series(now, "the rig stopped")
            self._previous_inner, self._steady = None, None

    # -- output --------------------------------------------------------------------------------
    def faults(self) -> tuple[str, ...]:
        """Reasons of the active faults (sensor loss first)."""
        return tuple(self._loss[n] for n in SHAFTS if n in self._loss) + tuple(r for _, r in self._latched.values())

    def status(self) -> MonitorStatus:
        """The current status (never raises)."""
        verdict = self.stability.verdict()
        faults = self.faults()
        notes = tuple(text for _, text in self._notes)
        latest = self._latest
        if faults:
            state, confidence, detail = MonitorState.FAULT, 0.0, "; ".join(faults)
        else:
            state = {SlipState.STABLE: MonitorState.STABLE, SlipState.SLIPPING: MonitorState.SLIPPING}.get(
                verdict.state, MonitorState.UNKNOWN
            )
            confidence = verdict.confidence
            detail = verdict.detail if latest is not None else "waiting for whole cage revolutions"
            if self._stopped:
                state, confidence, detail = MonitorState.UNKNOWN, 0.0, self._stopped
        if notes:
            detail = f"{detail}; note: {notes[-1]}"
        inner = latest.inner_ring_speed if latest is not None else math.nan
        return MonitorStatus(
            state=state,
            time=latest.end_time if latest is not None else None,
            inner_ring_speed=inner,
            cage_speed=latest.cage_speed if latest is not None else math.nan,
            theoretical_cage_speed=self.kinematics.epicyclic_ratio() * inner,
            slip_rate=latest.slip_rate if latest is not None else math.nan,
            fitted_slope=verdict.slope if verdict.slope is not None else math.nan,
            critical_slope=verdict.critical_slope,
            criterion=CRITERION,
            confidence=confidence,
            window_revolutions=self.settings.window_revolutions,
            detail=detail,
            faults=faults,
            notes=notes,
            windows=self.windows,
        )


def _malformed(pulse: Pulse) -> str:
    """Why a pulse cannot be used ("" if it can)."""
    t = pulse.time
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        return f"time {t!r} is not a finite number"
    for name in ("strip_id", "strip_count", "pulse_index"):
        value = getattr(pulse, name)
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            return f"{name} {value!r} is not an integer >= 0"
    if pulse.strip_count < 1:
        return "strip_count is 0"
    if pulse.strip_id >= pulse.strip_count:
        return f"strip_id {pulse.strip_id} is not below strip_count {pulse.strip_count}"
    return ""
