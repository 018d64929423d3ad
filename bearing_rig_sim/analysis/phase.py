"""The slope of slip against time from the cage's phase: :class:`PhaseSlope`.

Differencing whole-revolution windows and fitting a line to their slips wastes the data: each
window's slip rests on its two end pulses only, neighbouring windows share an end, and a slope
needs several windows (at 20 rad/s^2 from rest the cage turns 2 revolutions in the first 1.7 s).
Here every cage pulse counts. The cage's angle ``theta_c`` (its pulse index, radians) is fitted
against the spindle's angle ``theta_i`` at the same instant (interpolated from the spindle's
pulses, :mod:`~bearing_rig_sim.monitoring.windows`) over a trailing stretch of time:

    theta_c - r theta_i = c0 + c1 u + c2 u^2 + e(strip),    u = theta_i - mean(theta_i)

with ``r`` the epicyclic ratio and ``e(strip)`` the cage strips' own spacing offsets (free
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
    docstring), kept as running sums so that an estimate costs O(strips^2), whatever the pulses.

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
        self._dim = strips + 3  # z = (u, u^2, one indicator per strip, y)
        self.reset()

    def reset(self) -> None:
        """Forget every pulse."""
        self._t: list[float] = []
        self._index: list[int] = []
        self._strip: list[int] = []
        self._inner: list[float] = []
        self._head = 0  # first kept point of the lists
        self._summed = 0  # points (from the lists' start) taken into the sums
        self._z_last: FloatArray | None = None
        # row j + 1: sums over points head..j of z z' and of dz dz' (dz: z minus the previous
        # point's z), flattened; row 0 zero
        self._sums = np.zeros((64, 2 * self._dim * self._dim))
        self._ref: tuple[float, int] = (0.0, 0)  # spindle angle and cage index of the reference
        self._trend: FloatArray = np.zeros(self._dim - 1)  # taken out of y: coefficients of (u, u^2, strips)
        self._ref_time, self._rebuilt_at = -math.inf, 0

    @property
    def points(self) -> int:
        """Cage pulses kept (1)."""
        return len(self._t) - self._head

    def add(self, time: float, cage_index: int, strip: int, spindle_angle: float) -> None:
        """One cage pulse: its time (s, increasing), pulse index (increasing) and strip, and the
        spindle's angle then (rad, spacing-corrected). Kept as given: the sums take it in at
        the next :meth:`estimate` (with the others since, in one vectorised step), and now and
        then (once a ``span``) they are rebuilt on a new reference, O(pulses kept)."""
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
        self._head = head
        if time - self._ref_time > self.span or count - head >= 2 * self._rebuilt_at or 2 * head > count:
            self._rebuild()

    def _rows(self, lo: int, hi: int) -> FloatArray:
        """The rows z = (u, u^2, strip indicators, y) of points ``lo`` to ``hi - 1`` on the
        present reference, the trend taken out of y."""
        inner_ref, index_ref = self._ref
        n = hi - lo
        u = np.asarray(self._inner[lo:hi]) - inner_ref
        z = np.zeros((n, self._dim))
        z[:, 0], z[:, 1] = u, u * u
        z[np.arange(n), 2 + np.asarray(self._strip[lo:hi], dtype=np.intp)] = 1.0
        y = 2.0 * math.pi / self.strips * (np.asarray(self._index[lo:hi], dtype=np.float64) - index_ref) - self.ratio * u
        z[:, -1] = y - z[:, :-1] @ self._trend
        return z

    def _sync(self) -> None:
        """Take the pulses added since into the sums (vectorised)."""
        lo, hi = self._summed, len(self._t)
        if hi <= lo:
            return
        z = self._rows(lo, hi)
        dz = np.diff(z, axis=0, prepend=(z[:1] if self._z_last is None else self._z_last[None, :]))
        if hi + 1 > self._sums.shape[0]:
            grown = np.zeros((max(64, 1 << (hi + 1).bit_length()), self._sums.shape[1]))
            grown[: lo + 1] = self._sums[: lo + 1]
            self._sums = grown
        n, dim = hi - lo, self._dim
        outer = np.empty((n, 2, dim, dim))  # each point's z z' and dz dz', then their running sums
        np.multiply(z[:, :, None], z[:, None, :], out=outer[:, 0])
        np.multiply(dz[:, :, None], dz[:, None, :], out=outer[:, 1])
        flat = outer.reshape(n, 2 * dim * dim)
        np.add.accumulate(flat, axis=0, out=flat)  # np.cumsum without its dispatch
        np.add(self._sums[lo], flat, out=self._sums[lo + 1 : hi + 1])
        self._summed, self._z_last = hi, z[-1]

    def _rebuild(self) -> None:
        """Drop the pulses left behind, put the reference at the latest pulse (the estimates end
        near it: the sums stay well conditioned) and take out of y the fit of the latest
        ``span`` (parabola and strip offsets), so that the residuals' sum of squares is not the
        small difference of large sums; the sums start afresh."""
        head = self._head
        for kept in (self._t, self._index, self._strip, self._inner):
            del kept[:head]
        self._head = 0
        n = len(self._t)
        self._ref = (self._inner[-1], self._index[-1])
        self._trend = np.zeros(self._dim - 1)
        first = bisect.bisect_left(self._t, self._t[-1] - self.span)
        if n - first > self._dim:
            recent = self._rows(first, n)
            fit, _res, rank, _sv = np.linalg.lstsq(recent[:, :-1], recent[:, -1], rcond=None)
            if rank == self._dim - 1:
                self._trend = np.asarray(fit, dtype=np.float64)
        self._ref_time, self._rebuilt_at = self._t[-1], n
        self._sums = np.zeros((max(64, 1 << (n + 1).bit_length()), 2 * self._dim * self._dim))
        self._summed, self._z_last = 0, None

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

        From the running sums (the normal equations); when the residuals' lag-one variogram
        says they are not white (:data:`WHITE_CHECK`), the two-noise standard error of the
        stretch's pulses (module docstring) instead."""
        found = self._stretch(end, since, span, min_points)
        self._sync()
        if found is None:
            return None
        first, last = found
        dim, d2 = self._dim, self._dim * self._dim
        sums = self._sums
        gram = (sums[last + 1, :d2] - sums[first, :d2]).reshape(dim, dim)
        pairs = (sums[last + 1, d2:] - sums[first + 1, d2:]).reshape(dim, dim)
        columns = np.flatnonzero(gram.diagonal()[:-1] > 0.0)  # u, u^2 and the strips present
        n, p = last - first + 1, len(columns)
        if n < p + MIN_DOF:
            return None
        if p == dim - 1:  # every strip present: no columns to pick (b contiguous, as the dot products below expect)
            a, b = gram[:-1, :-1], gram[:-1, -1].copy()
        else:
            a, b = gram[columns][:, columns], gram[columns, -1]
        root = 1.0 / np.sqrt(a.diagonal())
        scale = root[:, None] * root
        eigenvalues, vectors = np.linalg.eigh(a * scale)  # equilibrated: eigenvalues of order 1
        if not eigenvalues[0] > 1e-12 * eigenvalues[-1]:
            return None
        inverse = (vectors / eigenvalues) @ vectors.T * scale
        coef = inverse @ b
        sse = max(float(gram[-1, -1] - b @ coef), 0.0)
        da, db = pairs[columns][:, columns], pairs[columns, -1]
        near = max(float(pairs[-1, -1] - 2.0 * db @ coef + coef @ da @ coef), 0.0)
        s2 = sse / (n - p)
        # residuals' lag-one variogram against their variance: 1 for white residuals (the
        # Durbin-Watson statistic over 2), near 0 for a wandering phase
        white_share = min(near / (2.0 * (n - 1)) / s2, 1.0) if s2 > 0.0 else 1.0
        t0, t1 = self._t[first], self._t[last]
        duration = t1 - t0
        speed = (self._inner[last] - self._inner[first]) / duration if duration > 0.0 else math.nan
        if not (math.isfinite(speed) and speed > 0.0):
            return None
        factor = -200.0 / self.ratio * speed  # dS/dt per unit of c2
        if white_share < WHITE_CHECK:
            return self._two_noise(first, last, factor, speed)
        var_c2 = max(s2, self.angle_floor**2) * float(inverse[1, 1])
        return PhaseEstimate(
            slope=factor * (float(coef[1]) + float(self._trend[1])),  # the trend's curvature taken out of y
            standard_error=abs(factor) * math.sqrt(max(var_c2, 0.0)),
            dof=n - p,
            points=n,
            start=t0,
            end=t1,
            inner_ring_speed=speed,
            white_share=white_share,
        )

    def _two_noise(self, first: int, last: int, factor: float, speed: float) -> PhaseEstimate | None:
        """The estimate of points ``first`` to ``last`` with the two-noise standard error
        (module docstring), by a least-squares fit of their rows, O(pulses)."""
        sl = slice(first, last + 1)
        t = np.asarray(self._t[sl])
        inner = np.asarray(self._inner[sl])
        cage = 2.0 * math.pi / self.strips * (np.asarray(self._index[sl], dtype=np.float64) - self._index[first])
        strip_of = np.asarray(self._strip[sl])
        u = inner - inner.mean()
        scale = max(float(np.max(np.abs(u))), 1e-12)
        columns = [np.ones_like(u), u / scale, (u / scale) ** 2]
        columns += [(strip_of == s).astype(np.float64) for s in sorted(set(self._strip[sl]))[1:]]
        x = np.column_stack(columns)
        y = cage - self.ratio * (inner - inner[0])
        y = y - y.mean()
        n, p = x.shape
        coef, _res, rank, _sv = np.linalg.lstsq(x, y, rcond=None)
        if rank < p:
            return None
        residual = y - x @ coef
        # two noises: white on each pulse's angle (timing jitter, w2 rad^2) and a wandering
        # phase (a slip that scatters from moment to moment: a random walk of q rad^2/s); the
        # residuals' variogram tells them apart: E (r_(k+L) - r_k)^2 = 2 w2 + q (t_(k+L) - t_k),
        # at lags 1 and L (an eighth of the pulses: short-range correlation, such as two cage
        # pulses read on the same spindle pulses, does not pass for a random walk)
        lag = max(2, n // 8)
        near, far = residual[1:] - residual[:-1], residual[lag:] - residual[:-lag]
        near_dt, far_dt = float(np.mean(np.diff(t))), float(np.mean(t[lag:] - t[:-lag]))
        gamma_near, gamma_far = float(np.mean(near * near)), float(np.mean(far * far))
        q = max((gamma_far - gamma_near) / (far_dt - near_dt), 0.0)
        w2 = max(0.5 * (gamma_far - q * far_dt), self.angle_floor**2)
        normal = np.linalg.inv(x.T @ x)
        row = (normal @ x.T)[2]  # c2 = row . y
        # Var(c2) = w2 |row|^2 + q sum_k (e_k - e_(k-1)) (sum_(j >= k) row_j)^2, the random walk's
        # increments since the first pulse (e: time since the first pulse)
        tails = np.cumsum(row[::-1])[::-1]
        walk = float(np.sum(np.diff(t) * tails[1:] ** 2))
        white = w2 * float(row @ row)
        var_c2_unscaled = white + q * walk
        white_share = white / var_c2_unscaled if var_c2_unscaled > 0.0 else 1.0
        revolutions = (self._index[last] - self._index[first]) / self.strips
        dof = n - p
        effective = max(2, int(round(dof * white_share + max(revolutions - 2.0, 1.0) * (1.0 - white_share))))
        c2, var_c2 = float(coef[2]) / scale**2, var_c2_unscaled / scale**4
        return PhaseEstimate(
            slope=factor * c2,
            standard_error=abs(factor) * math.sqrt(max(var_c2, 0.0)),
            dof=effective,
            points=n,
            start=float(t[0]),
            end=float(t[-1]),
            inner_ring_speed=speed,
            white_share=white_share,
        )
