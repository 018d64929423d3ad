"""Whole-revolution slip windows and lost-pulse accounting from two pulse streams (no ROS).

:class:`SlipWindows` does what the bench's counter does with the fibre-optic pulses of the
spindle and the cage (per pulse: time, strip id, strip count, pulse index), and nothing more:
it turns them into slip windows and keeps the books of what was lost. The monitor judges the
windows; the shadow-mode comparison can reuse the same class.

**Counting by index, not by pulses received.** ``pulse_index`` counts every strip passage,
received or not, so a gap in it tells exactly how many pulses were lost, and the strip of each
index is fixed (``(strip_id - pulse_index) mod strip_count`` is constant for a shaft; a pulse
that breaks it is malformed). A cage window runs from a passage of one strip to the passage of
the same strip ``window_revolutions`` revolutions later (index difference ``window_revolutions
* strip_count``), so the mean cage speed ``2 pi R / (t1 - t0)`` is exact whatever the strips'
spacing. If that closing passage is lost, the window is skipped (counted in
:attr:`LossBooks.windows_skipped`) and the next window starts at the next cage pulse received.

**Time-aligned spindle speed.** The spindle's angle is known at each of its pulses (its index,
corrected for the strip's own spacing error, below) and interpolated at the cage window's two
ends by the parabola through the pulse before the end and the two that bracket it (exact under
a constant acceleration, where a straight line between pulses 4 ms apart errs by some 1e-4
revolution at 60 rad/s^2, 0.01 % of a window's slip); the mean inner-ring speed is the
difference over the same interval, so a changing speed gives no apparent slip from windows
that do not line up. A window waits for the first spindle pulse at or after its end (a gap in
the spindle's pulses widens the interpolation bracket and costs nothing else).

**Strip spacing errors** of the spindle do not bias the interpolated angle: each strip's offset
from its nominal position (a fraction of a revolution) is measured from the pulses themselves,
over three whole revolutions with every pulse received whose strip-0 passages lie on one
parabola of angle against time (a constant speed or a constant acceleration: the parabola
through the first three predicts the fourth within :data:`STEADY_ANGLE_TOLERANCE_REV`), from the
middle revolution's pulse times read on the cubic through the four passages, averaged over
:data:`SPACING_AVERAGE_REVOLUTIONS`, and added to the strip's nominal angle (of every spindle
pulse kept, also those received before). Until then the nominal positions are used. Measured in a
run-up too, not only at a steady speed: on a bench's strips (offsets of 1e-3 revolution) the
nominal positions move a one-revolution window's slip by up to 0.06 %, which hid a run-up's
slope against k2 for seconds.

**Losses** (:class:`LossBooks`, per shaft): pulses lost, isolated gaps, windows skipped. An
isolated loss is a warning. It is a fault only when sustained, by one of two rules stated in
revolutions of the shaft, so they hold at any speed:

* more than ``max_lost_fraction`` of the pulses expected over the last ``loss_horizon_revolutions``
  revolutions were lost (expected pulses are counted by index);
* no pulse for longer than ``loss_silence_revolutions`` revolutions at the shaft's last pulse
  rate (and at least ``loss_min_timeout_s``), found at two consecutive checks, so that a checker
  that was itself held up is not mistaken for the sensor.

**A stop is not a fault.** When both shafts have been silent for :data:`STOP_SILENCE_PERIODS` of
their last pulse periods and each one's last period was longer than the one before by more than
:data:`STOP_PERIOD_GROWTH` (both were slowing down), the rig has stopped. A shaft that falls
silent at a steady or rising speed is lost. Until either shaft has turned
:data:`ESTABLISHED_REVOLUTIONS` revolutions the rig has not started: a silent shaft is then
lost only once the other has turned ``silent_shaft_revolutions`` since its last pulse (a
spindle turned by hand at rest is no fault).

Units: s, rad/s; revolutions and pulses are counts.
"""

from __future__ import annotations

import bisect
import math
from collections import deque
from dataclasses import dataclass, field
from typing import Any

from bearing_rig_sim.instruments.fibre_optic import TWO_PI, Pulse
from bearing_rig_sim import picklable

SHAFTS = ("spindle", "cage")
OTHER = {"spindle": "cage", "cage": "spindle"}
"""Each shaft's counterpart."""

MAX_PENDING_WINDOWS = 1000
"""Most cage windows kept waiting for spindle pulses; older ones are dropped (1)."""

STOP_PERIOD_GROWTH = 0.01
"""A pulse period longer than the shaft's previous one by more than this fraction means the
shaft was slowing down (1). A microsecond of timing jitter changes a 5.5 ms pulse period (2700 rpm,
4 strips) by less than 0.1 %."""

STOP_SILENCE_PERIODS = 4.0
"""Both shafts slowing down and silent for this many of their last pulse periods (and at least
``loss_min_timeout_s``): the rig has stopped (1). No fault hangs on it, so it may be decided
sooner than a sensor loss."""

STEADY_ANGLE_TOLERANCE_REV = 4e-3
"""Three spindle revolutions measure the strips' spacing when the parabola of angle against time
through their first three strip-0 passages predicts the fourth's angle within this, revolutions:
a constant speed or acceleration passes (3 us of jitter moves the prediction by 2e-4 revolution at
900 rpm), the corner where a run-up reaches its speed (about 8e-3 revolution at 60 rad/s^2) does
not."""

ESTABLISHED_REVOLUTIONS = 2
"""Pulses of this many revolutions since a shaft's restart make it a running shaft (1). Until
either shaft runs, the rig has not started, and a silent shaft is judged as one silent since the
start: lost only once the other shaft has turned ``silent_shaft_revolutions`` since its last
pulse, so a spindle turned by hand at rest, or a stray edge of a strip standing at the sensor,
is no fault. Once one shaft runs, each is judged by its own silence."""

SPINDLE_PRUNE_PULSES = 64
"""Spindle pulses kept beyond those still needed before the old ones are dropped (1): a pruning
at every pulse cost more than the rest of the pulse's handling."""

SPACING_AVERAGE_REVOLUTIONS = 32
"""Revolutions over which each strip's spacing error is averaged: the plain mean of the first 32
samples, then an exponential weight of 1/32."""


@dataclass(frozen=True)
class LossRules:
    """When lost pulses make a fault (see the module docstring); every count in revolutions. The
    values come from ``config/monitor.yaml`` (:meth:`MonitorSettings.loss_rules`).

    Attributes:
        loss_horizon_revolutions: revolutions over which the lost fraction is taken (> 0).
        max_lost_fraction: more than this fraction of the expected pulses lost is a fault (0-1).
        loss_silence_revolutions: no pulse for this many revolutions at the last pulse rate is
            a fault (> 0).
        loss_min_timeout_s: ... but never sooner than this, s (> 0).
        silent_shaft_revolutions: a shaft silent since the start is lost once the other has
            turned this many revolutions.
    """

    loss_horizon_revolutions: float
    max_lost_fraction: float
    loss_silence_revolutions: float
    loss_min_timeout_s: float
    silent_shaft_revolutions: float


@dataclass(frozen=True)
class SlipWindow:
    """One completed window of whole cage revolutions.

    Attributes:
        start_time, end_time: its two cage pulses (same strip), s.
        cage_speed: mean cage speed, rad/s.
        inner_ring_speed: mean spindle speed over the same interval, rad/s.
    """

    start_time: float
    end_time: float
    cage_speed: float
    inner_ring_speed: float
    revolutions: int = 1
    """Whole cage revolutions in the window."""


@dataclass
class LossBooks:
    """Lost-pulse accounting of one shaft since the last reset (counts).

    Attributes:
        received: pulses taken.
        lost: pulses missing from ``pulse_index``.
        gaps: gaps in ``pulse_index`` (one gap may lose several pulses).
        windows_skipped: cage windows whose closing pulse was lost (cage only).
        duplicates: exact repeats of the shaft's previous pulse (same index and stamp, as a
            merged or re-sent recording gives), dropped without restarting the shaft.
        last_gap: (rig time, pulses lost) of the latest gap; None before any.
    """

    received: int = 0
    lost: int = 0
    gaps: int = 0
    windows_skipped: int = 0
    duplicates: int = 0
    last_gap: tuple[float, int] | None = None


@dataclass
class _Shaft:
    """What is kept of one shaft's pulses since its last restart."""

    name: str
    strip_count: int | None = None
    offset: int | None = None
    last_time: float | None = None
    last_index: int | None = None
    last_period: float | None = None
    previous_period: float | None = None
    pulses: int = 0
    times: list[float] = field(default_factory=list)
    indices: list[int] = field(default_factory=list)  # pulse_index of each of times
    window_start: tuple[int, float] | None = None
    window_grown: bool = False  # the open window reached a revolution too short to close
    recent_gaps: deque[tuple[int, int]] = field(default_factory=deque)  # (index, lost)
    recent: deque[tuple[int, float]] = field(default_factory=deque)  # last pulses (index, time)
    other_pulses_at_last: int = 0  # the other shaft's pulses received when this one last pulsed
    prune_at: int = 0  # kept spindle pulses at which the next pruning is due

    def established(self) -> bool:
        """Whether the shaft has turned :data:`ESTABLISHED_REVOLUTIONS` since its restart, so that
        its pulse period is a running speed (a shaft turned by hand a fraction of a revolution
        at rest has no speed to fall silent from)."""
        return bool(self.strip_count) and self.pulses >= ESTABLISHED_REVOLUTIONS * (self.strip_count or 0)

    def revolutions_since(self, pulses: int) -> float:
        """Revolutions counted since the shaft had received ``pulses`` since its restart (pulses
        received since then / strips; 0 with no strip count yet)."""
        return (self.pulses - pulses) / self.strip_count if self.strip_count else 0.0

    def slowing(self) -> bool:
        """Whether the last pulse period was longer than the one before (STOP_PERIOD_GROWTH)."""
        if self.last_period is None or self.previous_period is None:
            return False
        return self.last_period > self.previous_period * (1.0 + STOP_PERIOD_GROWTH)


class SlipWindows:
    """Whole-revolution windows and loss accounting (see the module docstring).

    Args:
        window_revolutions: whole cage revolutions per window (>= 1).
        rules: when losses are a fault.
        min_window_s: a window lasts at least this long, s: at ``window_revolutions`` it closes
            only if it has, else at the first whole revolution after which it has (at high speed
            a window of more revolutions, whose ends' timing jitter weighs less); 0: always
            ``window_revolutions``.
        clock_jump_tolerance_s: a pulse further back than this before its shaft's previous one
            is a clock jump (everything restarts); less far back, an out-of-order pulse (that
            shaft restarts), s.
    """

    def __init__(self, window_revolutions: int, rules: LossRules, clock_jump_tolerance_s: float, min_window_s: float) -> None:
        self.window_revolutions = window_revolutions
        self.min_window_s = min_window_s
        self.rules = rules
        self.clock_jump_tolerance_s = clock_jump_tolerance_s
        self.books = {name: LossBooks() for name in SHAFTS}
        self.events: list[tuple[str, float | None, str]] = []
        """(kind, rig time, text) since the caller last cleared it; kind is "invalid" (a
        malformed pulse, discarded), "gap" (lost pulses), "note" (an out-of-order pulse or a
        restart) or "reset" (a clock jump: the caller resets what it derived)."""
        self._spacing: dict[int, float] = {}
        self._spacing_samples: dict[int, int] = {}  # samples of each strip's spacing error taken
        self.phase: list[tuple[float, int, int, float]] = []
        """Cage pulses with the spindle's angle at their time, since the caller last cleared
        it: (time s, cage pulse_index, cage strip, spindle angle rad); the series restarts
        (:attr:`epoch` changes) when either shaft's counting does."""
        self.epoch = 0
        """Count of restarts of either shaft's counting (1)."""
        self.reset()

    def reset(self) -> None:
        """Forget every pulse and window (the books and the strips' spacing are kept)."""
        self._shafts = {name: _Shaft(name) for name in SHAFTS}
        self._pending: deque[tuple[float, float, int]] = deque()  # start, end, revolutions
        self._phase_pending: deque[tuple[float, int, int]] = deque()  # cage pulses: time, index, strip
        self.epoch = getattr(self, "epoch", 0) + 1
        self._suspect: set[str] = set()
        self.silent: dict[str, str] = {}
        """Shafts found silent at two consecutive checks, with the reason."""
        self.stopped = ""
        """Why the rig is taken to have stopped ("" while it is not)."""

    # -- queries -------------------------------------------------------------------------------
    def last_pulse_time(self) -> float | None:
        """Time of the latest pulse of either shaft, s (None before any)."""
        times = [s.last_time for s in self._shafts.values() if s.last_time is not None]
        return max(times) if times else None

    def lost_fraction(self, shaft: str) -> float:
        """Lost pulses over the last ``loss_horizon_revolutions`` of ``shaft`` as a fraction of
        the pulses expected there (by index); 0 before any pulse."""
        s = self._shafts[shaft]
        if s.strip_count is None or s.last_index is None:
            return 0.0
        horizon = self.rules.loss_horizon_revolutions * s.strip_count
        while s.recent_gaps and s.recent_gaps[0][0] <= s.last_index - horizon:
            s.recent_gaps.popleft()
        return sum(lost for _, lost in s.recent_gaps) / horizon

    def faults(self) -> dict[str, str]:
        """Active sustained-loss faults by shaft (silence, or too large a lost fraction)."""
        out = dict(self.silent)
        for name in SHAFTS:
            if name in out:
                continue
            fraction = self.lost_fraction(name)
            if fraction > self.rules.max_lost_fraction:
                out[name] = (
                    f"{name}: {100.0 * fraction:.3g} % of the pulses of the last "
                    f"{self.rules.loss_horizon_revolutions:g} revolutions lost (limit "
                    f"{100.0 * self.rules.max_lost_fraction:g} %): sustained loss"
                )
        return out

    def spacing(self) -> dict[int, float]:
        """The spindle strips' measured spacing errors, fractions of a revolution by strip."""
        return dict(self._spacing)

    # -- input ---------------------------------------------------------------------------------
    def add_pulse(self, shaft: str, pulse: Pulse) -> list[SlipWindow]:
        """Take one pulse of ``shaft`` (``"spindle"`` or ``"cage"``); the windows it completes.

        Never raises on bad data: what happened goes to :attr:`events`.
        """
        pulse_fields: Any = pulse  # fields of any type until _malformed has checked them (compiled,
        # a field read as the type Pulse declares raises on another)
        s = self._shafts.get(shaft)
        if s is None:
            self.events.append(("note", None, f"pulse of unknown shaft {shaft!r} ignored"))
            return []
        problem = _malformed(pulse_fields)
        if problem:
            self.events.append(("invalid", None, f"{shaft}: invalid pulse discarded ({problem})"))
            return []
        t, index = float(pulse_fields.time), int(pulse_fields.pulse_index)
        last_time, last_index = s.last_time, s.last_index
        if last_time is not None and last_index is not None:
            if t < last_time - self.clock_jump_tolerance_s:
                self.reset()
                self.events.append(("reset", t, f"reset: {shaft} pulse at {t:.6f} s after one at {last_time:.6f} s (clock jumped back)"))
                s = self._shafts[shaft]
            elif index == last_index and t == last_time:
                self.books[shaft].duplicates += 1
                return []
            elif t <= last_time or index <= last_index:
                self.events.append(
                    (
                        "note",
                        t,
                        f"{shaft}: out-of-order pulse (index {index} at {t:.6f} s after index {s.last_index} at "
                        f"{s.last_time:.6f} s) discarded; {shaft} counting restarted",
                    )
                )
                self._restart_shaft(shaft)
                return []
            elif pulse_fields.strip_count != s.strip_count:
                self.events.append(("note", t, f"{shaft}: strip_count changed from {s.strip_count} to {pulse_fields.strip_count}; counting restarted"))
                self._restart_shaft(shaft)
                s = self._shafts[shaft]
            elif (pulse_fields.strip_id - index) % pulse_fields.strip_count != s.offset:
                self.events.append(
                    (
                        "invalid",
                        t,
                        f"{shaft}: strip {pulse_fields.strip_id} at pulse_index {index} does not match the earlier strips "
                        "(strip ids inconsistent with the indices); counting restarted",
                    )
                )
                self._restart_shaft(shaft)
                s = self._shafts[shaft]
        books = self.books[shaft]
        books.received += 1
        if s.last_index is not None and s.last_time is not None:
            step = index - s.last_index
            if step > 1:
                books.lost += step - 1
                books.gaps += 1
                books.last_gap = (t, step - 1)
                s.recent_gaps.append((index, step - 1))
                self.events.append(("gap", t, f"{shaft}: {step - 1} pulse(s) lost before pulse_index {index}"))
            s.previous_period = s.last_period
            s.last_period = (t - s.last_time) / step
        else:
            s.strip_count = pulse_fields.strip_count
            s.offset = (pulse_fields.strip_id - index) % pulse_fields.strip_count
        s.last_time, s.last_index = t, index
        s.pulses += 1
        s.other_pulses_at_last = self._shafts[OTHER[shaft]].pulses
        if self.silent:
            self.silent.pop(shaft, None)
        if self._suspect:
            self._suspect.discard(shaft)
        self.stopped = ""
        if shaft == "spindle":
            self._add_spindle_pulse(s, t, index)
            return self._process_pending()
        return self._add_cage_pulse(s, t, index)

    def _restart_shaft(self, shaft: str) -> None:
        self._shafts[shaft] = _Shaft(shaft)
        self._phase_pending.clear()
        self.epoch += 1
        self.silent.pop(shaft, None)
        self._suspect.discard(shaft)

    def _add_spindle_pulse(self, s: _Shaft, t: float, index: int) -> None:
        assert s.strip_count is not None and s.offset is not None
        n = s.strip_count
        strip = (index + s.offset) % n
        s.recent.append((index, t))
        if len(s.recent) > 3 * n + 1:
            s.recent.popleft()
        if strip == 0 and n > 1:
            self._measure_spacing(s, n)
        s.times.append(t)
        s.indices.append(index)

    def _measure_spacing(self, s: _Shaft, n: int) -> None:
        """Update the strips' spacing errors from the three revolutions that end at this strip-0
        pulse (module docstring).

        The strip-0 passages at times T0..T3 are at angles 0..3 revolutions (strip 0's own error
        is a common offset); on a constant speed or acceleration the angle is a parabola in
        time, so the cubic through the four gives the angle of the middle revolution's pulses,
        and pulse m's angle minus its nominal one is e(strip m) - e(0). With the errors' mean
        taken as zero (only differences matter), each strip's error follows.
        """
        recent = list(s.recent)
        if len(recent) != 3 * n + 1 or recent[-1][0] - recent[0][0] != 3 * n:
            return
        first_index = recent[0][0]
        t0, t1, t2, t3 = recent[0][1], recent[n][1], recent[2 * n][1], recent[3 * n][1]
        if not t0 < t1 < t2 < t3:
            return
        # the parabola through the first three passages, at the fourth: 3 revolutions if the
        # acceleration is constant
        predicted = _parabola(t0, t1, t2, 0.0, 1.0, 2.0, t3)
        if not abs(predicted - 3.0) <= STEADY_ANGLE_TOLERANCE_REV:
            return
        middle = recent[n + 1 : 2 * n + 1]
        d = [value - (index - first_index) / n for (index, _), value in zip(middle, _cubic_at(t0, t1, t2, t3, [time for _, time in middle]))]
        mean = sum(d) / n
        assert s.offset is not None
        for (index, _), dm in zip(middle, d):
            strip = (index + s.offset) % n
            sample = dm - mean
            # the mean of the samples so far, then an exponential average over the last
            # SPACING_AVERAGE_REVOLUTIONS (the first sample alone is as scattered as the jitter,
            # and an exponential weight of 1/32 kept 60 % of it for 15 revolutions)
            count = self._spacing_samples.get(strip, 0) + 1
            self._spacing_samples[strip] = count
            old = self._spacing.get(strip, 0.0)
            self._spacing[strip] = old + (sample - old) / min(count, SPACING_AVERAGE_REVOLUTIONS)

    def _add_cage_pulse(self, cage: _Shaft, t: float, index: int) -> list[SlipWindow]:
        assert cage.strip_count is not None and cage.offset is not None
        n = cage.strip_count
        self._phase_pending.append((t, index, (index + cage.offset) % n))
        if len(self._phase_pending) > MAX_PENDING_WINDOWS:
            self._phase_pending.popleft()
        span = self.window_revolutions * n
        if cage.window_start is None:
            cage.window_start, cage.window_grown = (index, t), False
            return []
        start_index, start_time = cage.window_start
        turned = index - start_index
        if turned < span:
            return []
        if turned % n == 0 and (turned == span or cage.window_grown):
            if t - start_time < self.min_window_s:  # too short yet: grow by whole revolutions
                cage.window_grown = True
                return []
            self._pending.append((start_time, t, turned // n))
            if len(self._pending) > MAX_PENDING_WINDOWS:
                self._pending.popleft()
        elif cage.window_grown:
            return []  # between two revolutions of a growing window (a lost boundary: the next one)
        else:  # the passage closing the window was lost: skip it, start afresh here
            self.books["cage"].windows_skipped += 1
        cage.window_start, cage.window_grown = (index, t), False
        return self._process_pending()

    # -- windows -------------------------------------------------------------------------------
    def _spindle_angle(self, spindle: _Shaft, t: float) -> float:
        """Spindle revolutions at ``t`` (index units / strips, spacing-corrected), on the parabola
        through the pulse before the bracket of ``t`` and the bracket's two (a line with only two
        pulses; the last pulse's angle at or after it)."""
        times = spindle.times
        k = bisect.bisect_right(times, t) - 1
        if k >= len(times) - 1:
            return self._angle(spindle, len(times) - 1)
        first = max(0, min(k - 1, len(times) - 3))
        if first + 3 > len(times):
            picks = range(first, len(times))
            return _lagrange(tuple(times[j] for j in picks), tuple(self._angle(spindle, j) for j in picks), t)
        return _parabola(
            times[first], times[first + 1], times[first + 2], self._angle(spindle, first), self._angle(spindle, first + 1), self._angle(spindle, first + 2), t
        )

    def _angle(self, spindle: _Shaft, j: int) -> float:
        """Angle of the spindle's kept pulse ``j``, revolutions, with its strip's spacing error."""
        assert spindle.strip_count is not None and spindle.offset is not None
        index = spindle.indices[j]
        return index / spindle.strip_count + self._spacing.get((index + spindle.offset) % spindle.strip_count, 0.0)

    def _process_pending(self) -> list[SlipWindow]:
        spindle = self._shafts["spindle"]
        done: list[SlipWindow] = []
        while self._pending and spindle.times and spindle.times[-1] >= self._pending[0][1]:
            t0, t1, revolutions = self._pending.popleft()
            if spindle.times[0] > t0:
                continue  # the spindle's pulses start after the window: cannot be measured
            duration = t1 - t0
            inner = TWO_PI * (self._spindle_angle(spindle, t1) - self._spindle_angle(spindle, t0)) / duration
            cage = TWO_PI * revolutions / duration
            done.append(SlipWindow(t0, t1, cage, inner, revolutions))
        while self._phase_pending and spindle.times and spindle.times[-1] >= self._phase_pending[0][0]:
            t, index, strip = self._phase_pending.popleft()
            if spindle.times[0] <= t:
                self.phase.append((t, index, strip, TWO_PI * self._spindle_angle(spindle, t)))
        self._prune_spindle()
        return done

    def _prune_spindle(self) -> None:
        """Drop the spindle pulses no window or cage pulse waiting can need, once
        :data:`SPINDLE_PRUNE_PULSES` have come since the last time (keeping older ones changes
        no interpolation: the pulse before the bracket is kept either way)."""
        spindle, cage = self._shafts["spindle"], self._shafts["cage"]
        if len(spindle.times) < spindle.prune_at:
            return
        starts = [t0 for t0, _, _ in self._pending]
        if self._phase_pending:
            starts.append(self._phase_pending[0][0])
        if cage.window_start is not None:
            starts.append(cage.window_start[1])
        keep_from = min(starts) if starts else math.inf
        k = bisect.bisect_right(spindle.times, keep_from) - 2  # one more before: the parabola's
        k = min(k, len(spindle.times) - 1)
        if k > 0:
            del spindle.times[:k]
            del spindle.indices[:k]
        spindle.prune_at = len(spindle.times) + SPINDLE_PRUNE_PULSES

    # -- time-based checks ---------------------------------------------------------------------
    def check(self, now: float) -> None:
        """Silence checks at rig time ``now`` (s): updates :attr:`silent` and :attr:`stopped`.

        A shaft is silent when found so at this check and at the previous one. ``now`` may run
        ahead of the pulses (extrapolated by a wall clock when the source has stopped).
        """
        if not math.isfinite(now):
            return
        rules = self.rules
        quiet: dict[str, str] = {}
        started = any(x.established() for x in self._shafts.values())
        for name in SHAFTS:
            s = self._shafts[name]
            other = self._shafts[OTHER[name]]
            if s.last_time is None or not started:
                turned = other.revolutions_since(0 if s.last_time is None else s.other_pulses_at_last)
                if turned >= rules.silent_shaft_revolutions:
                    when = "since the start" if s.last_time is None else f"for {now - s.last_time:.3g} s"
                    quiet[name] = f"{name}: no pulse {when} while the {other.name} turned {turned:.3g} revolutions"
                continue
            limit = rules.loss_min_timeout_s
            if s.last_period is not None and s.strip_count:
                limit = max(limit, rules.loss_silence_revolutions * s.strip_count * s.last_period)
            silence = now - s.last_time
            if silence > limit:
                quiet[name] = f"{name}: no pulse for {silence:.3g} s (limit {limit:.3g} s, {rules.loss_silence_revolutions:g} revolutions)"
        confirmed = {name: reason for name, reason in quiet.items() if name in self._suspect}
        self._suspect = set(quiet)
        spindle, cage = self._shafts["spindle"], self._shafts["cage"]
        if all(
            s.slowing()
            and s.last_time is not None
            and s.last_period is not None
            and now - s.last_time > max(rules.loss_min_timeout_s, STOP_SILENCE_PERIODS * s.last_period)
            for s in (spindle, cage)
        ):
            self.stopped = "spindle and cage stopped (their pulse periods grew before the pulses ceased)"
            self.silent = {}
        else:
            self.stopped = ""
            self.silent = {name: f"{reason}: sensor loss" for name, reason in confirmed.items()}


UNSTAMPED_AFTER_S = 1.0
"""A pulse stamped exactly 0 that arrives later than this on the receiver's clock (s) was not
stamped (a counter that leaves the header empty); at the start of a clock from zero, a stamp
of 0 is genuine."""


def unstamped(stamp: float, received: float) -> bool:
    """Whether a pulse stamped ``stamp`` (s) and received at ``received`` (s, the receiver's
    clock or the bag's log time) was not stamped, so that its reception time must stand in."""
    return stamp == 0.0 and received > UNSTAMPED_AFTER_S


def _lagrange(xs: tuple[float, ...], ys: tuple[float, ...], x: float) -> float:
    """The polynomial through the points (xs, ys) (distinct xs, 1 to 4 of them) at ``x``."""
    total = 0.0
    for i, (xi, yi) in enumerate(zip(xs, ys)):
        weight = 1.0
        for j, xj in enumerate(xs):
            if j != i:
                weight *= (x - xj) / (xi - xj)
        total += weight * yi
    return total


def _parabola(x0: float, x1: float, x2: float, y0: float, y1: float, y2: float, x: float) -> float:
    """:func:`_lagrange` through three points, with the same operations in the same order (so
    the same value to the bit), without its loops."""
    return (
        0.0
        + (x - x1) / (x0 - x1) * ((x - x2) / (x0 - x2)) * y0
        + (x - x0) / (x1 - x0) * ((x - x2) / (x1 - x2)) * y1
        + (x - x0) / (x2 - x0) * ((x - x1) / (x2 - x1)) * y2
    )


def _cubic_at(x0: float, x1: float, x2: float, x3: float, xs: list[float]) -> list[float]:
    """:func:`_lagrange` through (x0, 0), (x1, 1), (x2, 2), (x3, 3) at each of ``xs``, with the
    same operations in the same order (so the same values to the bit), without its loops and with
    the nodes' differences taken once."""
    d01, d02, d03, d12, d13, d23 = x0 - x1, x0 - x2, x0 - x3, x1 - x2, x1 - x3, x2 - x3
    d10, d20, d30, d21, d31, d32 = x1 - x0, x2 - x0, x3 - x0, x2 - x1, x3 - x1, x3 - x2
    values = []
    for x in xs:
        a0, a1, a2, a3 = x - x0, x - x1, x - x2, x - x3
        w0 = a1 / d01 * (a2 / d02) * (a3 / d03)
        w1 = a0 / d10 * (a2 / d12) * (a3 / d13)
        w2 = a0 / d20 * (a1 / d21) * (a3 / d23)
        w3 = a0 / d30 * (a1 / d31) * (a2 / d32)
        values.append(0.0 + w0 * 0.0 + w1 * 1.0 + w2 * 2.0 + w3 * 3.0)
    return values


def pulse_stamp(pulse: Any) -> float | None:
    """A pulse's stamp as a float, s; None unless it is a finite number (a bool is none here).
    ``pulse``: a :class:`Pulse` whose fields may hold anything (taken as Any: where this module
    runs compiled, a field read as the type Pulse declares would raise on another)."""
    t = pulse.time
    if type(t) is float:  # the common case first
        return t if math.isfinite(t) else None
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not math.isfinite(t):
        return None
    return float(t)


def _malformed(pulse: Any) -> str:
    """Why a pulse, its fields of any type (:func:`pulse_stamp`), cannot be used ("" if it can)."""
    t = pulse.time
    strip_id, strip_count, pulse_index = pulse.strip_id, pulse.strip_count, pulse.pulse_index
    # the common case first, on exact types (a bool is no int here); anything else is checked below
    if type(t) is float and type(strip_id) is int and type(strip_count) is int and type(pulse_index) is int:
        if math.isfinite(t) and 0 <= strip_id < strip_count and pulse_index >= 0:
            return ""
    if pulse_stamp(pulse) is None:
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


picklable.by_fields(LossRules, SlipWindow, LossBooks)
