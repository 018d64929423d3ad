"""The slip monitor without ROS: cage slip and its stability from the fibre-optic pulses alone.

:class:`SlipMonitor` reads only what the bench's sensors give (per pulse: time, strip id, strip
count, pulse index; and, for the load criterion, the load cell's force) and the bearing's
kinematics, so it runs unchanged on the real bench's topics.

* **Windows** come from :class:`~bearing_rig_sim.monitoring.windows.SlipWindows`: whole cage
  revolutions counted by pulse index, the spindle's angle interpolated at both ends, lost pulses
  accounted for (an isolated loss is a warning, a sustained one a fault).
* **Slip** of each window: Eq. 11 of the paper (docs/paper.md), percent.
* **Verdict**: the paper's slope criterion on the slip series, against time (k2) or against the
  measured axial load (k1), by :class:`~bearing_rig_sim.analysis.streaming.TrailingSlope`: the
  slope of a trailing least-squares line, decided only when its one-sided bound is on one side of k
  (``stable_confidence`` for STABLE, 95 % and a clear fall for SLIPPING),
  and a change in the slip itself (whatever caused it) restarts the slope's window. Against time
  (nominal slip), the slope and its standard error come from the cage's phase over every pulse
  (:class:`~bearing_rig_sim.analysis.phase.PhaseSlope`, :data:`PHASE_WHITE_SHARE`), far less
  scattered than a line through whole windows' slips (docs/method.md, run-ups).
* **Speed changes**: at the start and the end of one (a window's mean spindle speed more than
  ``restart_speed_change_fraction`` from the previous window's, or back within it) the slip's
  scatter is estimated afresh; the verdict is kept, its trailing window forgets the ramp within
  ``slope_span_s``. Below ``min_inner_ring_speed_rad_s`` (and at a stop) the series restarts:
  state unknown until new points decide.

**Bad data is reported, never raised**: a malformed pulse is a fault held ``fault_hold_s``; an
out-of-order pulse restarts its shaft's counting (a note); a clock jump back resets everything.

Units: s, rad/s, N; slip and slopes in percent, percent per second or per newton.
"""

from __future__ import annotations

import bisect
import math
from collections import deque
from dataclasses import dataclass

from bearing_rig_sim.analysis.inputs import AnalysisError
from bearing_rig_sim.analysis.phase import PhaseSlope
from bearing_rig_sim.analysis.slip import BearingKinematics, ThrustContact, loaded_slip_rate
from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.analysis.streaming import TrailingSlope
from bearing_rig_sim.monitoring.load_sweep import SPEED_TOLERANCE as SWEEP_SPEED_TOLERANCE
from bearing_rig_sim.monitoring.load_sweep import LoadSweep
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.monitoring.windows import SHAFTS, SlipWindow, SlipWindows, pulse_stamp
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim import picklable

MonitorState = SlipState
"""The monitor's state: the project's one state enum (values are SlipStatus.msg's)."""

PHASE_WHITE_SHARE = 0.5
"""The cage's phase decides the slope against time on its own standard error when at least this
share of its variance is the pulses' own white noise (timing jitter); below it the slip itself
wanders (or the parabola misfits), and the standard error is taken as at least that of the whole
windows' line, whose scatter is pooled over 64 windows (1)."""

PHASE_MIN_PULSES = 20
"""... and it has at least this many cage pulses: on fewer, a wandering phase cannot be told from
jitter (a scattered slip's first nine pulses, judged alone, made a false SLIPPING) (1); the
trailing stretch reaches back to this many (a slow cage early in a run-up gives some 8 a second,
and its two revolutions alone left 10 us of jitter undecided for up to 1.8 s) ..."""

PHASE_FULL_SPAN = 0.95
"""... over at least this fraction of ``slope_span_s`` (1): at the start of a hold the first
spindle spacing estimate is one revolution's, as scattered as the jitter, and shorter stretches
of 50 us jitter at 900 rpm made false SLIPPING verdicts."""

PHASE_LOOKS_PER_STATUS = 10.0
"""Before the first verdict, the phase slope is looked at on the cage pulses, at most this many
times per status period (1 / ``status_rate_hz``): a first STABLE then waits for no window, and at
9000 rpm (260 cage pulses a second) it costs some 100 looks a second, not 260 (at 4, a look every
25 ms, 3000 rpm holds lost up to 0.13 s against a look at every pulse)."""

LOAD_HISTORY = 16384
"""Load-cell samples kept for the windows' mean load (16 s at the load cell's 1 kHz)."""

LOAD_WAIT_S = 8.0
"""With the load criterion, a window waits for the load cell's samples up to its end (the load
cell's topic can run seconds behind the pulses' without real time) at most this long after its
end, rig s; then it is judged on the samples at hand (half the kept history)."""


def _stamp(sample: tuple[float, float]) -> float:
    """A load-cell sample's time, s."""
    return sample[0]


@dataclass(frozen=True)
class MonitorStatus:
    """The monitor's status (the fields of SlipStatus.msg, SI units, slip in percent).

    ``time`` is the end of the latest window (None before the first); speeds, slip and slope
    are NaN when not known. Once the rig has stopped (the pulses slowed, then ceased), the status
    describes the rig as it is, not its last window: ``time`` and ``window_start`` None (a node
    stamps it at the rig time of its check), both speeds 0, the slip and the window's load and
    angles NaN; run up again, it has no window until its first whole one. ``faults`` lists the
    active faults' reasons, ``warnings`` the recent losses (lost pulses, skipped windows),
    ``notes`` the recent resets and refusals; ``lost`` the pulses lost per shaft since the start,
    ``windows_skipped`` the cage windows skipped and ``duplicates`` the exact repeats of a pulse
    dropped per shaft (spindle, cage).
    ``confidence`` is P(slope >= k) (0 while no slope is known). ``axial_load`` is the latest
    window's mean measured load (N, NaN without load-cell samples). With the ``axial_load``
    criterion, ``sweep_speed`` (rad/s), ``sweep_stable_from`` (N) and ``sweep_verdict`` are the
    latest load-sweep verdict's (:mod:`~bearing_rig_sim.monitoring.load_sweep`; NaN and "" before
    one).
    """

    state: SlipState
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
    warnings: tuple[str, ...] = ()
    lost: tuple[int, int] = (0, 0)
    windows_skipped: int = 0
    duplicates: tuple[int, int] = (0, 0)
    window_start: float | None = None
    axial_load: float = math.nan
    kinematic_slip_rate: float = math.nan
    loaded_contact_angle: float = math.nan
    sweep_speed: float = math.nan
    sweep_stable_from: float = math.nan
    sweep_verdict: str = ""

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
            "axial_load": self.axial_load,
            "kinematic_slip_rate": self.kinematic_slip_rate,
            "loaded_contact_angle": self.loaded_contact_angle,
            "sweep_speed": self.sweep_speed,
            "sweep_stable_from": self.sweep_stable_from,
            "sweep_verdict": self.sweep_verdict,
        }


@dataclass(frozen=True)
class MonitorWindow:
    """A completed window and its slip (the paper's, at the nominal angle; NaN below the minimum
    speed), mean load (NaN if no load-cell sample fell in it, N), the contact angle of that load
    (rad) and the kinematic slip against the pure-rolling speed at that angle (%; NaN without a
    load)."""

    window: SlipWindow
    slip_rate: float
    axial_load: float
    loaded_contact_angle: float = math.nan
    kinematic_slip_rate: float = math.nan

    @property
    def start_time(self) -> float:
        return self.window.start_time

    @property
    def end_time(self) -> float:
        return self.window.end_time

    @property
    def inner_ring_speed(self) -> float:
        return self.window.inner_ring_speed

    @property
    def cage_speed(self) -> float:
        return self.window.cage_speed


class SlipMonitor:
    """Online cage slip and its stability from the two pulse streams (module docstring).

    Args:
        kinematics: the bearing's geometry.
        settings: the monitor's parameters.
    """

    def __init__(self, kinematics: BearingKinematics, settings: MonitorSettings) -> None:
        self.kinematics = kinematics
        self.settings = settings
        self.criterion = settings.criterion
        self._ratio = kinematics.epicyclic_ratio()
        self.thrust = ThrustContact.from_config(settings.bearing_file)
        """The loaded contact angle from the measured load (Harris's thrust equilibrium)."""
        self.loaded = settings.slip_reference == "loaded"
        self.sweep_loaded = settings.sweep_slip_reference == "loaded"
        self.slope = TrailingSlope(
            critical_slope=settings.critical_slope_pct_per_s,
            span=settings.slope_span_s,
            min_points=settings.min_slope_points,
            resolution=settings.slip_resolution_pct,
            change_threshold=settings.change_threshold,
            max_span=max(settings.slope_max_span_s, settings.slope_span_s),
            stable_confidence=settings.stable_confidence,
        )
        self.phase: PhaseSlope | None = None
        """The slope against time from the cage's phase (time criterion, nominal slip); built at
        the first cage pulse, which gives the strip count."""
        self.sweep = LoadSweep(settings.critical_slope_pct_per_n, settings.load_step_n, settings.sweep_settle_s, settings.sweep_average_s)
        self.counter = SlipWindows(settings.window_revolutions, settings.loss_rules(), settings.clock_jump_tolerance_s, settings.min_window_s)
        self._notes: deque[tuple[float | None, str]] = deque(maxlen=5)
        self._loads: deque[tuple[float, float]] = deque(maxlen=LOAD_HISTORY)
        self._loads_unordered = 0
        """Samples in :attr:`_loads` stamped before their predecessor there (0: in time order)."""
        self.reset()

    # -- state ---------------------------------------------------------------------------------
    def reset(self, reason: str = "") -> None:
        """Forget every pulse, window, slope and fault (state unknown); ``reason`` becomes a note."""
        self.counter.reset()
        self.slope.reset()
        self._reset_phase()
        self._latest: MonitorWindow | None = None
        self._invalid: dict[str, tuple[float | None, str]] = {}
        self._warnings: dict[str, tuple[float | None, str]] = {}
        self._steady: bool | None = None
        self._steady_since: float | None = None
        self._previous_inner: float | None = None
        self._last_x: float | None = None
        self.sweep.reset()
        self._sweep_pending: deque[SlipWindow] = deque()
        self._now: float | None = None
        self.windows = 0
        """Windows completed since the last reset (1)."""
        self._notes.clear()
        self._loads.clear()
        self._loads_unordered = 0
        if reason:
            self._notes.append((None, reason))

    @property
    def latest_window(self) -> MonitorWindow | None:
        """The latest completed window (None before the first)."""
        return self._latest

    def last_pulse_time(self) -> float | None:
        """Time of the latest pulse of either shaft, s (None before any)."""
        return self.counter.last_pulse_time()

    # -- input ---------------------------------------------------------------------------------
    def clock_jump(self, previous: float, now: float) -> None:
        """The rig clock went back from ``previous`` to ``now`` (s): reset everything."""
        self.reset(f"reset: the clock jumped back from {previous:.6f} s to {now:.6f} s")

    def add_load(self, time: float, force: float) -> None:
        """A load-cell sample: axial force ``force`` (N) at rig time ``time`` (s); non-finite
        samples are ignored."""
        if math.isfinite(time) and math.isfinite(force):
            loads = self._loads
            if len(loads) == loads.maxlen and loads[1][0] < loads[0][0]:
                self._loads_unordered -= 1  # its successor, out of order after it, no longer is
            if loads and time < loads[-1][0]:
                self._loads_unordered += 1
            loads.append((time, force))
            if self._sweep_pending and time >= self._sweep_pending[0].end_time:
                self._feed_sweep(time)

    def add_pulse(self, shaft: str, pulse: Pulse) -> bool:
        """Take one pulse of ``shaft`` (``"spindle"`` or ``"cage"``); never raises on bad data.

        Returns:
            Whether a slip window was completed (the status may have changed).
        """
        counter = self.counter
        done = counter.add_pulse(shaft, pulse)
        if counter.events:
            self._take_events()
        if counter.phase or self.phase is None or counter.epoch != self._phase_epoch:
            self._take_phase(shaft, pulse)
        t = pulse_stamp(pulse)
        if t is not None and (self._now is None or t > self._now):
            self._now = t
        for window in done:
            self._add_window(window)
        return bool(done)

    def _reset_phase(self, since: float = -math.inf) -> None:
        """Forget the cage's phase; count its pulses from ``since`` (s) on."""
        if self.phase is not None:
            self.phase.reset()
        self._phase_from = since
        self._phase_epoch = self.counter.epoch
        self._phase_look = -math.inf

    def _take_phase(self, shaft: str, pulse: Pulse) -> None:
        """Give the phase slope the cage pulses whose spindle angle is now known."""
        points, self.counter.phase = self.counter.phase, []
        st = self.settings
        if self.criterion != "time" or self.loaded:
            return
        strips = getattr(pulse, "strip_count", None)  # any type: the pulse may be malformed
        if self.phase is None and shaft == "cage" and type(strips) is int and strips >= 1:
            span = st.slope_span_s
            self.phase = PhaseSlope(self._ratio, span, strips, st.slip_resolution_pct, max(st.slope_max_span_s, span))
        if self.phase is None:
            return
        if self.counter.epoch != self._phase_epoch:
            self._reset_phase()
        added = None
        for t, index, strip, angle in points:
            if t > self._phase_from:
                self.phase.add(t, index, strip, angle)
                added = t
        look = PHASE_LOOKS_PER_STATUS * st.status_rate_hz
        if added is not None and self._latest is not None and self.slope.state is SlipState.UNKNOWN and (added - self._phase_look) * look >= 1.0:
            # no verdict yet: a look at every cage pulse, or PHASE_LOOKS_PER_STATUS per status
            # period at high speed, not only at every window (a direct fit of the stretch each)
            self._phase_look = added
            external = self._phase_external(added)
            if external is not None:
                self.slope.refresh(external)

    def _take_events(self) -> None:
        for kind, when, text in self.counter.events:
            if kind == "reset":
                self.slope.reset()
                self._latest, self._steady, self._previous_inner, self._last_x = None, None, None, None
                self.windows = 0
                self._notes.append((when, text))
            elif kind == "invalid":
                self._invalid[text.split(":", 1)[0]] = (when if when is not None else self._now, text)
            elif kind == "gap":
                self._warnings[text.split(":", 1)[0]] = (when, text)
            else:
                self._notes.append((when, text))
        self.counter.events.clear()

    def _restart_series(self, time: float, why: str) -> None:
        if self.slope.n_points or self.slope.state is not SlipState.UNKNOWN:
            self._notes.append((time, f"slip series restarted at {time:.6f} s: {why}"))
        self.slope.reset()
        self._reset_phase(time)
        self._last_x = None

    def _mean_load(self, t0: float, t1: float) -> float:
        loads = self._loads
        if not loads:
            return math.nan
        if loads[-1][0] >= t0 and loads[0][0] <= t1:
            if self._loads_unordered:
                inside = [f for t, f in loads if t0 <= t <= t1]
            else:  # in time order: the same samples, in the same order, found by bisection
                i, j = bisect.bisect_left(loads, t0, key=_stamp), bisect.bisect_right(loads, t1, key=_stamp)
                inside = [loads[k][1] for k in range(i, j)]
            if inside:
                return sum(inside) / len(inside)
        last_time, last_force = loads[-1]
        return last_force if last_time <= t1 and t1 - last_time < t1 - t0 else math.nan

    def _add_window(self, window: SlipWindow) -> None:
        st = self.settings
        inner, t1 = window.inner_ring_speed, window.end_time
        self.windows += 1
        load = self._mean_load(window.start_time, t1)
        if not inner >= st.min_inner_ring_speed_rad_s:
            if self._previous_inner is not None:
                self._restart_series(t1, f"spindle below {st.min_inner_ring_speed_rad_s:g} rad/s")
            self._reset_phase(t1)
            self._previous_inner, self._steady = None, None
            self._latest = MonitorWindow(window, math.nan, load)
            return
        previous = self._previous_inner
        steady = None if previous is None else abs(inner - previous) <= st.restart_speed_change_fraction * previous
        if steady is not None and self._steady is not None and steady != self._steady and st.restart_speed_change_fraction > 0.0:
            change = f"steady at {inner:.6g} rad/s" if steady else f"changing, {previous:.6g} -> {inner:.6g} rad/s"
            self.slope.forget_scatter()
            self._notes.append((t1, f"spindle speed {change}: slip scatter estimated afresh"))
        if not steady:
            self._steady_since = None
        elif self._steady_since is None:  # steady from the previous window on
            self._steady_since = self._latest.start_time if self._latest is not None else window.start_time
        self._steady = steady
        self._previous_inner = inner
        slip = (1.0 - window.cage_speed / (self._ratio * inner)) * 100.0  # Eq. 11, as BearingKinematics.slip_rate
        angle = self.thrust.loaded_contact_angle(load)
        kinematic = math.nan
        if math.isfinite(angle):
            ratio = self.kinematics.at_contact_angle(angle).epicyclic_ratio()
            kinematic = (1.0 - window.cage_speed / (ratio * inner)) * 100.0
        self._latest = MonitorWindow(window, slip, load, angle, kinematic)
        if self.criterion == "axial_load":
            self._sweep_pending.append(window)
            self._feed_sweep(t1)
            return
        judged = kinematic if self.loaded else slip
        if not math.isfinite(judged):  # the loaded slip without a load-cell sample: no point
            return
        if self.criterion == "time":
            self._add_point(t1, t1, judged)

    def _feed_sweep(self, now: float) -> None:
        """Give the load sweep the pending windows whose load-cell samples have come (the latest
        sample at or after their end), or that waited :data:`LOAD_WAIT_S`; ``now`` is the latest
        rig time seen, s."""
        latest = self._loads[-1][0] if self._loads else -math.inf
        while self._sweep_pending and (latest >= self._sweep_pending[0].end_time or now - self._sweep_pending[0].end_time > LOAD_WAIT_S):
            window = self._sweep_pending.popleft()
            inner = window.inner_ring_speed
            load = self._mean_load(window.start_time, window.end_time)
            if self.sweep_loaded:
                slip = loaded_slip_rate(self.kinematics, self.thrust, window.cage_speed, inner, load)
            else:
                slip = (1.0 - window.cage_speed / (self._ratio * inner)) * 100.0
            verdict = self.sweep.add_window(window.start_time, window.end_time, load, slip, inner)
            if verdict is not None:
                self._notes.append((window.end_time, f"load sweep at {verdict.inner_ring_speed * 30.0 / math.pi:.0f} rpm: {verdict.describe()}"))

    def _phase_external(self, t1: float) -> tuple[float, float, int, bool] | None:
        """The phase's slope up to ``t1`` (s) for the slope criterion: (slope, standard error,
        degrees of freedom, whether to check it against the windows' line); None without one."""
        if self.phase is None or self.criterion != "time":
            return None
        change = self.slope.verdict().change_at
        # back to PHASE_MIN_PULSES pulses if the span holds fewer (a slow cage early in a
        # run-up, or one that lost some): older, steeper slip makes the slope only more negative
        estimate = self.phase.estimate(t1, since=change, min_points=PHASE_MIN_PULSES)
        if self._steady_since is not None and self.slope.state is SlipState.UNKNOWN:
            # no verdict yet at a steady speed: the phase since the speed settled (the more
            # data, the surer a first verdict, which no hysteresis protects)
            since = self._steady_since if change is None else max(change, self._steady_since)
            longer = self.phase.estimate(t1, since=since, span=self.settings.slope_max_span_s)
            if longer is not None and (longer.points > (estimate.points if estimate is not None else 0)):
                estimate = longer
        if estimate is None:
            return None
        full = estimate.end - estimate.start >= PHASE_FULL_SPAN * self.settings.slope_span_s
        alone = estimate.white_share >= PHASE_WHITE_SHARE and estimate.points >= PHASE_MIN_PULSES and full
        return estimate.slope, estimate.standard_error, estimate.dof, not alone

    def _add_point(self, t1: float, x: float, slip: float) -> None:
        external = self._phase_external(t1)
        try:
            if self.slope.add(x, slip, external):
                self._notes.append((t1, "a change in the slip: slope window restarted"))
            self._last_x = x
        except AnalysisError as exc:  # cannot happen with ordered points; never crash
            self._restart_series(t1, str(exc))

    # -- time-based checks ---------------------------------------------------------------------
    def check(self, now: float) -> None:
        """Sensor-loss checks and the expiry of held faults and warnings at rig time ``now`` (s)."""
        if not math.isfinite(now):
            return
        self.counter.check(now)
        if self._sweep_pending:
            self._feed_sweep(now)
        hold = self.settings.fault_hold_s
        for held in (self._invalid, self._warnings):
            for key, (when, reason) in list(held.items()):
                if when is None:
                    held[key] = (now, reason)
                elif now - when > hold:
                    del held[key]
        kept = [(now if when is None else when, text) for when, text in self._notes]
        self._notes.clear()
        self._notes.extend((when, text) for when, text in kept if now - when <= hold)
        if self.counter.stopped and (self.slope.n_points or self.slope.state is not SlipState.UNKNOWN):
            self._restart_series(now, "the rig stopped")
            self._previous_inner, self._steady = None, None
        if self.counter.stopped:
            self._latest = None  # no window describes a stopped rig, nor the same rig run up again

    # -- output --------------------------------------------------------------------------------
    def faults(self) -> tuple[str, ...]:
        """Reasons of the active faults (sustained loss first, then malformed pulses)."""
        loss = self.counter.faults()
        return tuple(loss[n] for n in SHAFTS if n in loss) + tuple(r for _, r in self._invalid.values())

    def status(self) -> MonitorStatus:
        """The current status (never raises)."""
        verdict = self.slope.verdict()
        sweep = self.sweep.latest if self.criterion == "axial_load" else None
        faults = self.faults()
        notes = tuple(text for _, text in self._notes)
        warnings = tuple(text for _, text in self._warnings.values())
        latest = self._latest
        if faults:
            state, detail = SlipState.FAULT, "; ".join(faults)
        elif self.counter.stopped:
            state, detail = SlipState.UNKNOWN, self.counter.stopped
        elif self.criterion == "axial_load":
            state, detail = self._sweep_state(latest)
        else:
            state = verdict.state
            detail = verdict.detail if latest is not None else "waiting for whole cage revolutions"
        if warnings:
            detail = f"{detail}; warning: {'; '.join(warnings)}"
        if notes:
            detail = f"{detail}; note: {notes[-1]}"
        at_rest = 0.0 if self.counter.stopped else math.nan
        inner = latest.inner_ring_speed if latest is not None else at_rest
        books = self.counter.books
        if self.criterion == "axial_load":  # the fit's verdict is not a probability: 1 stable, 0 else
            fitted_slope = sweep.slope_at_end if sweep is not None else math.nan
            confidence = 1.0 if state is SlipState.STABLE else 0.0
        else:
            fitted_slope = verdict.slope if verdict.slope is not None else math.nan
            confidence = verdict.confidence if state in (SlipState.STABLE, SlipState.SLIPPING, SlipState.UNKNOWN) else 0.0
        return MonitorStatus(
            state=state,
            time=latest.end_time if latest is not None else None,
            inner_ring_speed=inner,
            cage_speed=latest.cage_speed if latest is not None else at_rest,
            theoretical_cage_speed=self._ratio * inner,
            slip_rate=latest.slip_rate if latest is not None else math.nan,
            fitted_slope=fitted_slope,
            critical_slope=self.settings.critical_slope,
            criterion=self.criterion,
            confidence=confidence,
            window_revolutions=self.settings.window_revolutions,
            detail=detail,
            faults=faults,
            notes=notes,
            windows=self.windows,
            warnings=warnings,
            lost=(books["spindle"].lost, books["cage"].lost),
            windows_skipped=books["cage"].windows_skipped,
            duplicates=(books["spindle"].duplicates, books["cage"].duplicates),
            window_start=latest.start_time if latest is not None else None,
            axial_load=latest.axial_load if latest is not None else math.nan,
            kinematic_slip_rate=latest.kinematic_slip_rate if latest is not None else math.nan,
            loaded_contact_angle=latest.loaded_contact_angle if latest is not None else math.nan,
            sweep_speed=sweep.inner_ring_speed if sweep is not None else math.nan,
            sweep_stable_from=sweep.stable_from if sweep is not None and sweep.stable_from is not None else math.nan,
            sweep_verdict=sweep.describe() if sweep is not None else "",
        )

    def _sweep_state(self, latest: MonitorWindow | None) -> tuple[SlipState, str]:
        """State against load: the latest load-sweep verdict of the spindle's present speed says
        STABLE at a load at or above its "stable from", SLIPPING below it (or when the fitted
        slope never reaches k1), UNKNOWN while the speed has no verdict, or none with a fit."""
        if latest is None:
            return SlipState.UNKNOWN, "waiting for whole cage revolutions"
        sweep = self.sweep.latest
        inner = latest.inner_ring_speed
        if sweep is None or not abs(sweep.inner_ring_speed - inner) <= SWEEP_SPEED_TOLERANCE * sweep.inner_ring_speed:
            return SlipState.UNKNOWN, f"load sweep: {len(self.sweep.points)} settled load point(s) at this speed, a verdict needs 4"
        if sweep.stable_from is not None:
            stable = latest.axial_load >= sweep.stable_from - 0.5 * self.settings.load_step_n
            return (SlipState.STABLE if stable else SlipState.SLIPPING), f"load sweep: {sweep.describe()}"
        return (SlipState.SLIPPING if sweep.fitted else SlipState.UNKNOWN), f"load sweep: {sweep.describe()}"


picklable.by_fields(MonitorStatus, MonitorWindow)
