"""Simulated time locked to the wall clock: how many chunks are due, overruns, real-time factor.

In real time the simulated time follows the wall clock::

    target(wall) = sim_start + (wall - wall_start) * rate

and the loop (one timer of period ``loop_period``) runs the chunks whose end is not after the
target. A call normally finds the simulation about one loop period behind; when it finds it
behind by more than ``loop_period + overrun_margin`` wall seconds (late by more than timer
jitter), that call counts one **overrun**; the loop then catches up in batches of at most ``max_batch`` chunks per call, so that
the node still services its subscriptions in between. When it is behind by more than
``resync_lag`` wall seconds, the debt is dropped (the start is re-anchored to now; one
``resync`` is counted): a simulation slower than real time then runs as fast as it can instead of
bursting to catch up ever larger debts.

Without real time (``realtime=False``, the command line's ``--no-realtime``) every call is
given ``max_batch`` chunks: as fast as possible, still in batches.

The achieved real-time factor is simulated seconds per wall second over a sliding window of
``rtf_window`` wall seconds, from the (wall, sim) pairs given to :meth:`RealTimePacer.record`.

The wall clock is injected (``clock``, default :func:`time.monotonic`), so the arithmetic is
tested with a fake clock. The options have no defaults here: the simulator's are in
``config/simulator.yaml`` (:meth:`RealTimePacer.from_settings`).
"""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable
from typing import TYPE_CHECKING

from bearing_rig_sim.errors import RigError

if TYPE_CHECKING:
    from bearing_rig_sim.simulation.settings import SimulatorSettings

CHUNK_EPSILON = 1e-9
"""Tolerance, in chunks, when counting due chunks (float round-off of sums of chunk lengths)."""


class PacerError(RigError):
    """A pacer option out of range, or a call before :meth:`RealTimePacer.start`."""


def _positive(name: str, value: float, *, allow_inf: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value):
        raise PacerError(f"{name}: must be a number > 0, got {value!r}")
    if not value > 0.0 or (math.isinf(value) and not allow_inf):
        raise PacerError(f"{name}: must be > 0{' (inf allowed)' if allow_inf else ' and finite'}, got {value!r}")
    return float(value)


class RealTimePacer:
    """Locks simulated time to the wall clock (see the module docstring).

    Args:
        chunk: simulated length of one chunk, s (> 0).
        loop_period: wall period of the loop's timer, s (> 0; None: one chunk at ``rate``).
        realtime: lock to the wall clock (True) or run as fast as possible (False).
        rate: simulated seconds per wall second in real time (1 = real time; > 0).
        overrun_margin: lateness beyond one loop period, wall s, that counts as an overrun (> 0).
        rtf_window: length of the sliding window of the real-time factor, wall s (> 0).
        max_batch: most chunks given to one call (>= 1).
        resync_lag: lag, in wall seconds, beyond which the debt is dropped (> 0; inf: never).
        clock: the wall clock, s (monotonic).

    Raises:
        PacerError: an option out of range.
    """

    def __init__(
        self,
        chunk: float,
        *,
        loop_period: float | None,
        realtime: bool,
        rate: float,
        overrun_margin: float,
        rtf_window: float,
        max_batch: int,
        resync_lag: float,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.chunk = _positive("chunk", chunk)
        self.rate = _positive("rate", rate)
        self.loop_period = self.chunk / self.rate if loop_period is None else _positive("loop_period", loop_period)
        self.overrun_margin = _positive("overrun_margin", overrun_margin)
        self.rtf_window = _positive("rtf_window", rtf_window)
        self.resync_lag = _positive("resync_lag", resync_lag, allow_inf=True)
        if isinstance(max_batch, bool) or not isinstance(max_batch, int) or max_batch < 1:
            raise PacerError(f"max_batch: must be an integer >= 1, got {max_batch!r}")
        if not isinstance(realtime, bool):
            raise PacerError(f"realtime: must be true or false, got {realtime!r}")
        self.realtime = realtime
        self.max_batch = max_batch
        self._clock = clock
        self._wall_start: float | None = None
        self._sim_start = 0.0
        self._samples: deque[tuple[float, float]] = deque()
        self.overruns = 0
        """Calls that found the simulation behind by more than ``overrun_margin`` (1)."""
        self.resyncs = 0
        """Times the debt was dropped because the lag exceeded ``resync_lag`` (1)."""
        self.behind = False
        """Whether the latest call found the simulation late by more than the margin."""

    @classmethod
    def from_settings(cls, settings: SimulatorSettings, clock: Callable[[], float] = time.monotonic) -> RealTimePacer:
        """The simulator's pacer, every option from its settings (``config/simulator.yaml``)."""
        return cls(
            settings.chunk_s,
            loop_period=settings.loop_period_s,
            realtime=settings.realtime,
            rate=settings.rate,
            overrun_margin=settings.overrun_margin_s,
            rtf_window=settings.rtf_window_s,
            max_batch=settings.max_batch_chunks,
            resync_lag=settings.resync_lag_s,
            clock=clock,
        )

    @property
    def started(self) -> bool:
        """Whether :meth:`start` has been called."""
        return self._wall_start is not None

    def start(self, sim_time: float) -> None:
        """Anchor the simulated time ``sim_time`` (s) to the wall clock now; clears the counters."""
        now = self._clock()
        self._wall_start = now
        self._sim_start = float(sim_time)
        self._samples = deque([(now, float(sim_time))])
        self.overruns = 0
        self.resyncs = 0
        self.behind = False

    def target(self) -> float:
        """The simulated time the wall clock asks for now, s (real time only)."""
        if self._wall_start is None:
            raise PacerError("call start() first")
        return self._sim_start + (self._clock() - self._wall_start) * self.rate

    def lag(self, sim_time: float) -> float:
        """How far the simulation at ``sim_time`` is behind the wall clock, wall s (< 0: ahead);
        0 without real time."""
        if not self.realtime:
            return 0.0
        return (self.target() - sim_time) / self.rate

    def due_chunks(self, sim_time: float) -> int:
        """Chunks to run now, from the simulated time ``sim_time`` (s) reached so far.

        Counts an overrun when behind by more than one loop period plus the margin, re-anchors
        when behind by more than ``resync_lag``; at most ``max_batch``.
        """
        if self._wall_start is None:
            raise PacerError("call start() first")
        if not self.realtime:
            return self.max_batch
        lag = self.lag(sim_time)
        self.behind = lag > self.loop_period + self.overrun_margin
        if self.behind:
            self.overruns += 1
        if lag > self.resync_lag:
            self.resyncs += 1
            self._wall_start = self._clock()
            self._sim_start = float(sim_time)
            return 1
        due = math.floor(lag * self.rate / self.chunk + CHUNK_EPSILON)
        return max(0, min(due, self.max_batch))

    def next_due_in(self, sim_time: float) -> float:
        """Wall seconds until the next chunk is due (0 if it is already; 0 without real time)."""
        if not self.realtime:
            return 0.0
        return max(0.0, (self.chunk - self.lag(sim_time) * self.rate) / self.rate)

    # -- real-time factor ----------------------------------------------------------------------
    def record(self, sim_time: float) -> None:
        """Note the simulated time (s) reached now, for the real-time factor."""
        now = self._clock()
        self._samples.append((now, float(sim_time)))
        while len(self._samples) > 2 and now - self._samples[1][0] >= self.rtf_window:
            self._samples.popleft()

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall second over the last ``rtf_window`` wall seconds (or since
        the start, if shorter); NaN before any time has passed."""
        if len(self._samples) < 2:
            return math.nan
        (w0, s0), (w1, s1) = self._samples[0], self._samples[-1]
        if not w1 > w0:
            return math.nan
        return (s1 - s0) / (w1 - w0)


class StreamLead:
    """Without real time: how far the simulation may run ahead of a stream that follows its clock.

    A stream *follows the clock* when its stamps advance and each lies within ``follow_s`` of the
    simulated time when it is taken. While one does, :meth:`room` allows the chunks that keep the
    simulated time at most ``lead_s`` past its latest stamp: the bound is enforced by the loop
    running no chunk beyond it. Pacing stops (:meth:`room` is None, with :attr:`off` saying why)
    before the stream follows, when :meth:`stop` is called (its publisher left the active state
    or exited) and after ``silent_s`` of wall time without a new stamp (a publisher gone without
    a word); it resumes when the stream advances again.

    Args:
        name: what the stream is, for :attr:`off` (e.g. the topic).
        lead_s: most simulated time past the stream's latest stamp, s (> 0).
        follow_s: stamps this close to the simulated time follow the clock, s (> 0).
        silent_s: wall time without a new stamp after which pacing stops, s (> 0).

    Raises:
        PacerError: an option out of range.
    """

    def __init__(self, name: str, lead_s: float, *, follow_s: float = 1.0, silent_s: float = 10.0) -> None:
        self.name = name
        self.lead_s = _positive("lead_s", lead_s)
        self.follow_s = _positive("follow_s", follow_s)
        self.silent_s = _positive("silent_s", silent_s)
        self.pace: float | None = None
        """The latest stamp of the stream while it follows the clock, s; None otherwise."""
        self.stamp = -math.inf
        """The latest stamp taken, s."""
        self.seen = -math.inf
        """Wall time (monotonic) the latest stamp was taken, s."""
        self.off = f"no {name} following the clock yet"
        """Why the stream does not pace the loop (empty while it does)."""
        self.paused = False
        """Its publisher left the active state: no pacing until it is active again."""

    def observe(self, stamp: float, sim_time: float, wall: float) -> None:
        """A message stamped ``stamp`` (s) taken at the simulated time ``sim_time`` (s), wall
        time ``wall`` (s). The same stamp again (a status with no newer rig time behind it)
        changes nothing: the pacing stays where the last advance put it, and the silence guard
        counts from that advance. A stamp that does not follow the clock (off by more than
        ``follow_s``, or earlier than the last) stops the pacing, and :attr:`off` says which it
        was, unless the publisher is paused (its reason stands)."""
        if stamp == self.stamp:
            return
        near = abs(stamp - sim_time) <= self.follow_s
        advancing = stamp > self.stamp and near
        self.pace = stamp if advancing and self.stamp > -math.inf else None
        if not advancing and not self.paused:
            if near:
                self.off = f"{self.name} went back to {stamp:.3f} s from {self.stamp:.3f} s"
            else:
                self.off = f"{self.name} stamped {stamp:.3f} s, more than {self.follow_s:g} s from the simulated time {sim_time:.3f} s"
        self.stamp = stamp
        self.seen = wall

    def stop(self, reason: str, *, paused: bool = False) -> None:
        """Stop pacing on the stream until it advances again (``paused``: and :attr:`paused` is
        cleared); ``reason`` goes to :attr:`off`."""
        self.pace, self.stamp, self.off = None, -math.inf, reason
        self.paused = paused

    def room(self, sim_time: float, chunk: float, wall: float, *, idle: str = "") -> int | None:
        """Chunks of ``chunk`` s the simulation at ``sim_time`` (s) may still run, wall time
        ``wall`` (s); None while the stream does not pace (see the class docstring), or while
        ``idle`` says why its source has nothing to send now (a rig at rest; :attr:`off` then
        says so, and pacing resumes with the next call without it)."""
        if idle:
            self.off = idle
            return None
        if self.pace is None or self.paused:
            self.off = self.off or f"no {self.name} following the clock"
            return None
        if wall - self.seen > self.silent_s:
            self.stop(f"no {self.name} for {self.silent_s:g} s of wall time")
            return None
        self.off = ""
        return max(0, int((self.pace + self.lead_s - sim_time) / chunk + CHUNK_EPSILON))
