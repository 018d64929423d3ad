"""The slope of slip against time from the cage's phase: :class:`PhaseSlope`.

Differencing whole-revolution windows and fitting a line to their slips wastes the data: each
window's slip rests on its two end pulses only, neighbouring windows share an end, and a slope
needs several windows (at 20 rad/s^2 from rest the cage turns 2 revolutions in the first 1.7 s).
Here every cage pulse counts. The cage's angle ``theta_c`` (its pulse index, radians) is fitted
against the spindle's angle ``theta_i`` at the same instant (interpolated from the spindle's
pulses, :mod:`~bearing_rig_sim.monitoring.windows`) over a trailing stretch of time:

    theta_c - r theta_i = c0 + c1 u + c2 u^2 + e(strip),    u = theta_i - theta_m

with ``theta_m`` the middle of the stretch's spindle angles (c2 does not depend on it), ``r`` the
epicyclic ratio and ``e(strip)`` the cage strips' own spacing offsets (free
parameters, so no prior measurement of them is needed). Since ``d theta_c / d theta_i = r (1 -
S / 100)`` (Eq. 11-12 of the paper, docs/paper.md), the slip is ``S = -100 / r d(...)/du`` and
its slope against the spindle's angle ``dS/d theta_i = -200 c2 / r``; against time it is that
times the stretch's mean spindle speed. A changing spindle speed costs nothing: the abscissa is
the spindle's own angle. The line fit of window slips over the same second averages the slope the
same way (a parabola's curvature is the mean slope of its derivative), so the verdicts mean the
same, with a standard error several times smaller (every pulse, no differencing).

**Standard error** of ``c2`` under two noises told apart by the residuals' variogram at a lag of
one pulse and of an eighth of the stretch: white on each pulse's angle (timing jitter; never
below the angle a window slip of ``resolution`` percent means) and a random walk of the phase (a
slip that scatters from moment to moment makes the phase wander; the plain formula would believe
the wandering line too much). :attr:`PhaseEstimate.white_share` says which dominates; the
degrees of freedom are the fit's for the white part and about one per cage revolution for the
walk.

Units: s, rad; slip in percent, slopes in percent per second.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np

from bearing_rig_sim.analysis.inputs import FloatArray
from bearing_rig_sim import picklable

MIN_PHASE_REVOLUTIONS = 2.0
"""A stretch covers at least this many cage revolutions (reaching back beyond the span if need
be), so that the strips' offsets are told apart from the curvature (1)."""

MIN_DOF = 3
"""... and at least this many pulses more than the fit's parameters (strips + 2), reaching back
beyond the span if lost pulses leave fewer (1)."""

WHITE_CHECK = 0.75
"""Below this ratio of the residuals' lag-one variogram to twice their variance (the
Durbin-Watson statistic over 2: 1 for white residuals, its standard deviation about
``1 / sqrt(n)`` over n pulses) the residuals are taken to wander, and the standard error is the
two-noise one of the stretch's pulses (O(pulses)); white residuals fall below it with a
probability of about ``Phi(-0.25 sqrt(n))``: 10 % at 26 pulses, 0.1 % at 150 (1)."""


@dataclass(frozen=True)
class PhaseEstimate:
    """A slope of slip against time from the cage's phase.

    Attributes:
        slope: dS/dt, percent per second.
        standard_error: its standard error, percent per second.
        dof: degrees of freedom of the standard error (1).
        points: cage pulses fitted (1).
        start, end: time of the first and the last of them, s.
        inner_ring_speed: the stretch's mean spindle speed, rad/s.
        white_share: the share of the slope's variance due to the white noise on each pulse
            (1: timing jitter alone; near 0: a wandering slip, which the slips of whole
            windows resolve as well and whose scatter they estimate over more data).
    """

    slope: float
    standard_error: float
    dof: int
    points: int
    start: float
    end: float
    inner_ring_speed: float
    white_share: float = 1.0


class PhaseSlope:
    """Trailing slope of slip against time from cage pulses and the spindle angle (module
    docstring). The pulses of the last ``max_span`` are kept; an estimate fits the stretch it
    names directly, O(pulses) in a few dozen array operations.

    Args:
        epicyclic_ratio: r = cage speed / spindle speed without slip (1).
        span: trailing stretch, s (> 0).
        strips: strips on the cage (>= 1).
        resolution: least scatter of a one-revolution window's slip believed, percent (> 0).
        max_span: longest stretch kept, s (>= span).
    """

    def __init__(self, epicyclic_ratio: float, span: float, strips: int, resolution: float, max_span: float | None = None) -> None:
        if not (epicyclic_ratio > 0.0 and span > 0.0 and strips >= 1 and resolution > 0.0):
            raise ValueError(f"PhaseSlope: need a ratio, span, strips and resolution > 0, got {epicyclic_ratio!r}, {span!r}, {strips!r}, {resolution!r}")
        self.ratio = epicyclic_ratio
        self.span = span
        self.strips = strips
        self.max_span = max(span, max_span or span)
        # one window's slip of `resolution` % is an angle error of the cage over one revolution,
        # shared by its two ends
        self.angle_floor = resolution / 100.0 * 2.0 * math.pi / math.sqrt(2.0)
        self.reset()

    def reset(self) -> None:
        """Forget every pulse."""
        self._t: list[float] = []
        self._index: list[int] = []
        self._strip: list[int] = []
        self._inner: list[float] = []
        self._head = 0  # first kept point of the lists

    @property
    def points(self) -> int:
        """Cage pulses kept (1)."""
        return len(self._t) - self._head

    def add(self, time: float, cage_index: int, strip: int, spindle_angle: float) -> None:
        """One cage pulse: its time (s, increasing), pulse index (increasing) and strip, and the
        spindle's angle then (rad, spacing-corrected). A pulse not later than the last, in time
        or index, starts a new series. Pulses older than ``max_span`` (and than two cage
        revolutions) leave."""
        times, indices = self._t, self._index
        if len(times) > self._head and not (time > times[-1] and cage_index > indices[-1]):
            self.reset()
            times, indices = self._t, self._index
        times.append(time)
        indices.append(cage_index)
        self._strip.append(strip % self.strips)
        self._inner.append(spindle_angle)
        keep = max(self.max_span, MIN_PHASE_REVOLUTIONS * 2.0 * math.pi / max(self._cage_speed(), 1e-9))
        head, count = self._head, len(times)
        while count - head > 2 and time - times[head] > keep:
            head += 1
        if 2 * head > count:  # the lists hold twice the pulses kept at most
            for kept in (times, indices, self._strip, self._inner):
                del kept[:head]
            head = 0
        self._head = head

    def _cage_speed(self) -> float:
        if self.points < 2 or self._t[-1] <= self._t[self._head]:
            return 0.0
        return 2.0 * math.pi * (self._index[-1] - self._index[self._head]) / self.strips / (self._t[-1] - self._t[self._head])

    def _stretch(self, end: float, since: float | None, span: float | None, min_points: int = 0) -> tuple[int, int] | None:
        """First and last kept point (list positions) of the stretch :meth:`estimate` fits."""
        start = -math.inf if since is None else since
        stretch = self.span if span is None else min(span, self.max_span)
        t, index = self._t, self._index
        lo = bisect.bisect_left(t, start, self._head)
        hi = bisect.bisect_right(t, end, self._head) - 1
        if hi - lo + 1 < 2:
            return None
        need = MIN_PHASE_REVOLUTIONS * self.strips
        by_time = min(bisect.bisect_left(t, end - stretch, lo, hi + 1), hi)
        by_index = bisect.bisect_right(index, index[hi] - need, lo, hi + 1) - 1
        by_count = hi + 1 - max(self.strips + 2 + MIN_DOF, min_points)  # pulses received: lost ones count for nothing
        first = max(lo, min(by_time, by_index, by_count))
        if index[hi] - index[first] < need:
            return None
        return first, hi

    def estimate(self, end: float, since: float | None = None, span: float | None = None, min_points: int = 0) -> PhaseEstimate | None:
        """The slope over the pulses of the last ``span`` (s; default the one given at
        construction, at most ``max_span``) up to ``end`` (s), or back to
        :data:`MIN_PHASE_REVOLUTIONS` cage revolutions and to ``min_points`` pulses (at least
        :data:`MIN_DOF` more than the fit's parameters) if the span holds fewer, none before
        ``since`` (s: a change in the slip); None with too few pulses for the fit.

        The strips' offsets enter the normal equations as a diagonal block (each pulse has one
        strip), so they are eliminated exactly: u, u^2 and y are taken about their means on
        each strip (the Schur complement of that block), which leaves two equations for c1 and
        c2, refused as singular when their determinant is not above 1e-12 of the product of
        their diagonal. u is taken about the middle of the stretch's spindle angles, so that u
        and u^2 are nearly orthogonal. When the residuals' lag-one variogram says they are not
        white (:data:`WHITE_CHECK`), the two-noise standard error (module docstring)."""
        found = self._stretch(end, since, span, min_points)
        if found is None:
            return None
        first, last = found
        n = last - first + 1
        stop = last + 1
        strips = self.strips
        strip = np.array(self._strip[first:stop], dtype=np.intp)
        inner = np.array(self._inner[first:stop], dtype=np.float64)
        counts = np.bincount(strip, minlength=strips).astype(np.float64)
        p = 2 + int(np.count_nonzero(counts))  # c1, c2 and the strips present
        if n < p + MIN_DOF:
            return None
        u = inner - 0.5 * (inner[0] + inner[-1])
        v = u * u
        cage = 2.0 * math.pi / strips * np.array(self._index[first:stop], dtype=np.float64)
        y = cage - cage[0] - self.ratio * (inner - inner[0])
        counts[counts == 0.0] = 1.0  # strips absent: no pulse takes their means
        uc = u - (np.bincount(strip, u, strips) / counts)[strip]
        vc = v - (np.bincount(strip, v, strips) / counts)[strip]
        yc = y - (np.bincount(strip, y, strips) / counts)[strip]
        a11, a12, a22 = float(uc @ uc), float(uc @ vc), float(vc @ vc)
        b1, b2 = float(uc @ yc), float(vc @ yc)
        det = a11 * a22 - a12 * a12
        if not (a11 > 0.0 and a22 > 0.0 and det > 1e-12 * a11 * a22):
            return None
        c1, c2 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
        residual = yc - c1 * uc - c2 * vc
        near = residual[1:] - residual[:-1]
        sse, near_sse = float(residual @ residual), float(near @ near)
        s2 = sse / (n - p)
        # residuals' lag-one variogram against their variance: 1 for white residuals (the
        # Durbin-Watson statistic over 2), near 0 for a wandering phase
        white_share = min(near_sse / (2.0 * (n - 1)) / s2, 1.0) if s2 > 0.0 else 1.0
        t0, t1 = self._t[first], self._t[last]
        duration = t1 - t0
        speed = (self._inner[last] - self._inner[first]) / duration if duration > 0.0 else math.nan
        if not (math.isfinite(speed) and speed > 0.0):
            return None
        factor = -200.0 / self.ratio * speed  # dS/dt per unit of c2
        dof = n - p
        if white_share < WHITE_CHECK:
            # c2 = row . y: the two-noise variance of that sum
            row = (a11 / det) * vc - (a12 / det) * uc
            var_c2, white_share = self._two_noise(first, stop, residual, near, row)
            revolutions = (self._index[last] - self._index[first]) / strips
            dof = max(2, int(round(dof * white_share + max(revolutions - 2.0, 1.0) * (1.0 - white_share))))
        else:
            var_c2 = max(s2, self.angle_floor**2) * a11 / det
        return PhaseEstimate(
            slope=factor * c2,
            standard_error=abs(factor) * math.sqrt(max(var_c2, 0.0)),
            dof=dof,
            points=n,
            start=t0,
            end=t1,
            inner_ring_speed=speed,
            white_share=white_share,
        )

    def _two_noise(self, first: int, stop: int, residual: FloatArray, near: FloatArray, row: FloatArray) -> tuple[float, float]:
        """The variance of c2 = ``row`` . y under two noises (module docstring), from the fit's
        ``residual`` of points ``first`` to ``stop - 1`` and their successive differences
        ``near``; and the white noise's share of it."""
        # two noises: white on each pulse's angle (timing jitter, w2 rad^2) and a wandering
        # phase (a slip that scatters from moment to moment: a random walk of q rad^2/s); the
        # residuals' variogram tells them apart: E (r_(k+L) - r_k)^2 = 2 w2 + q (t_(k+L) - t_k),
        # at lags 1 and L (an eighth of the pulses: short-range correlation, such as two cage
        # pulses read on the same spindle pulses, does not pass for a random walk)
        t = np.array(self._t[first:stop], dtype=np.float64)
        n = t.size
        lag = max(2, n // 8)
        far = residual[lag:] - residual[:-lag]
        steps = np.diff(t)
        near_dt, far_dt = float(np.mean(steps)), float(np.mean(t[lag:] - t[:-lag]))
        gamma_near, gamma_far = float(near @ near) / near.size, float(far @ far) / far.size
        q = max((gamma_far - gamma_near) / (far_dt - near_dt), 0.0)
        w2 = max(0.5 * (gamma_far - q * far_dt), self.angle_floor**2)
        # Var(c2) = w2 |row|^2 + q sum_k (e_k - e_(k-1)) (sum_(j >= k) row_j)^2, the random walk's
        # increments since the first pulse (e: time since the first pulse)
        tails = np.cumsum(row[::-1])[::-1]
        walk = float(steps @ (tails[1:] * tails[1:]))
        white = w2 * float(row @ row)
        variance = white + q * walk
        return variance, (white / variance if variance > 0.0 else 1.0)


picklable.by_fields(PhaseEstimate)
