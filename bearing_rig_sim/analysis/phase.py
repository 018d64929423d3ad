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
import operator
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
import numpy.typing as npt

from bearing_rig_sim.analysis.inputs import FloatArray

MIN_PHASE_REVOLUTIONS = 2.0
"""A stretch covers at least this many cage revolutions (reaching back beyond the span if need
be), so that the strips' offsets are told apart from the curvature (1)."""

BULK_SUM_POINTS = 16
"""Fresh sums over at least this many points are taken as arrays, fewer one by one (1)."""

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


_Strip = TypeVar("_Strip", int, npt.NDArray[np.intp])
"""A strip number, or an array of them (the indices are then taken elementwise)."""


class _SumLayout:
    """Where each running sum sits in :class:`PhaseSlope`'s flat sums, for ``strips`` cage strips.

    The fit's rows are z = (u, v = u^2, one indicator per strip, y), so z z' and dz dz' (dz: z
    minus the previous pulse's z) hold few distinct numbers: the sums of uu, uv, vv, uy, vy, yy;
    per strip its pulses and the sums of u, v and y over them; of the differences du, dv, dy the
    same six products; per strip the sums of du, dv and dy times its indicator's difference c
    (+1 for the pulse's strip, -1 for the previous pulse's, when they differ), and per pair of
    strips the sum of their c's product. These are kept, not the dense matrices: a pulse costs a
    few scalar additions, and the normal equations are assembled from them (:meth:`PhaseSlope.estimate`).
    """

    UU, UV, VV, UY, VY, YY = range(6)

    def __init__(self, strips: int) -> None:
        self.strips = strips
        self.pairs = 6 + 4 * strips  # first of the sums over the differences
        self.pair_strips = self.pairs + 6
        self.pair_cross = self.pair_strips + 3 * strips
        self.size = self.pair_cross + strips * strips

    def count(self, strip: _Strip) -> _Strip:
        """Pulses of ``strip``; then the sums of u, v and y over them."""
        return 6 + 4 * strip

    def pair_strip(self, strip: _Strip) -> _Strip:
        """Sum of du c(strip); then of dv c(strip) and of dy c(strip)."""
        return self.pair_strips + 3 * strip

    def cross(self, strip: _Strip, other: _Strip) -> _Strip:
        """Sum of c(strip) c(other)."""
        return self.pair_cross + strip * self.strips + other


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
        self._layout = _SumLayout(strips)
        self.reset()

    def reset(self) -> None:
        """Forget every pulse."""
        self._t: list[float] = []
        self._index: list[int] = []
        self._strip: list[int] = []
        self._inner: list[float] = []
        self._head = 0  # first kept point of the lists
        self._ref: tuple[float, int] = (0.0, 0)  # spindle angle and cage index of the reference
        self._trend: FloatArray = np.zeros(self._dim - 1)  # taken out of y: coefficients of (u, u^2, strips)
        self._ref_time, self._rebuilt_at = -math.inf, 0
        self._restart_sums()

    def _restart_sums(self) -> None:
        """Running sums from the lists' first point on, none taken yet."""
        self._summed = 0  # points (from the lists' start) taken into the sums
        self._last_row: tuple[float, float, int, float] | None = None  # (u, u^2, strip, y) of the last point summed
        # the sums (_SumLayout) over the lists' first k points: row k of _bulk for k up to
        # _bulk_count (the points summed at once, as arrays, after a rebuild), then entry
        # k - _bulk_count - 1 of _prefix (the points summed one by one since)
        self._bulk: FloatArray = np.zeros((1, self._layout.size))
        self._bulk_count = 0
        self._prefix: list[tuple[float, ...]] = []
        self._running = [0.0] * self._layout.size

    def _sums_through(self, k: int) -> list[float] | tuple[float, ...]:
        """The running sums over the lists' first ``k`` points (``k`` up to the points summed)."""
        return self._bulk[k].tolist() if k <= self._bulk_count else self._prefix[k - self._bulk_count - 1]

    @property
    def points(self) -> int:
        """Cage pulses kept (1)."""
        return len(self._t) - self._head

    def add(self, time: float, cage_index: int, strip: int, spindle_angle: float) -> None:
        """One cage pulse: its time (s, increasing), pulse index (increasing) and strip, and the
        spindle's angle then (rad, spacing-corrected). Kept as given: the sums take it in at
        the next :meth:`estimate` (with the others since, a few scalar additions each), and now and
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
        """Take the pulses added since into the running sums (:class:`_SumLayout`), a few scalar
        additions each."""
        lo, hi = self._summed, len(self._t)
        if hi <= lo:
            return
        if lo == 0 and hi >= BULK_SUM_POINTS:
            self._sum_at_once(hi)
            return
        layout = self._layout
        inner_ref, index_ref = self._ref
        trend = self._trend.tolist()
        trend_u, trend_v = trend[0], trend[1]
        step, ratio = 2.0 * math.pi / self.strips, self.ratio
        # the batch's own sums, each added to the sums before it (as a cumulative sum of the batch
        # would be): one rounding at the prefix's magnitude per point, not one per term
        base, run, prefix = self._running, [0.0] * layout.size, self._prefix
        UU, UV, VV, UY, VY, YY = _SumLayout.UU, _SumLayout.UV, _SumLayout.VV, _SumLayout.UY, _SumLayout.VY, _SumLayout.YY
        pairs = layout.pairs
        last = self._last_row
        for inner, index, strip in zip(self._inner[lo:hi], self._index[lo:hi], self._strip[lo:hi]):
            u = inner - inner_ref
            v = u * u
            y = step * (index - index_ref) - ratio * u
            y = y - (trend_u * u + trend_v * v + trend[2 + strip])
            run[UU] += u * u
            run[UV] += u * v
            run[VV] += v * v
            run[UY] += u * y
            run[VY] += v * y
            run[YY] += y * y
            k = layout.count(strip)
            run[k] += 1.0
            run[k + 1] += u
            run[k + 2] += v
            run[k + 3] += y
            if last is not None:
                du, dv, dy = u - last[0], v - last[1], y - last[3]
                run[pairs + UU] += du * du
                run[pairs + UV] += du * dv
                run[pairs + VV] += dv * dv
                run[pairs + UY] += du * dy
                run[pairs + VY] += dv * dy
                run[pairs + YY] += dy * dy
                before = last[2]
                if before != strip:
                    k, j = layout.pair_strip(strip), layout.pair_strip(before)
                    run[k] += du
                    run[k + 1] += dv
                    run[k + 2] += dy
                    run[j] -= du
                    run[j + 1] -= dv
                    run[j + 2] -= dy
                    run[layout.cross(strip, strip)] += 1.0
                    run[layout.cross(before, before)] += 1.0
                    run[layout.cross(strip, before)] -= 1.0
                    run[layout.cross(before, strip)] -= 1.0
            last = (u, v, strip, y)
            prefix.append(tuple(map(operator.add, base, run)))
        self._running = list(prefix[-1])
        self._summed, self._last_row = hi, last

    def _sum_at_once(self, hi: int) -> None:
        """The lists' first ``hi`` points into fresh running sums, as arrays (after a rebuild,
        when every kept point is summed again on the new reference): the same products and the
        same additions in the same order as :meth:`_sync` one by one, so the same sums."""
        layout = self._layout
        inner_ref, index_ref = self._ref
        trend = self._trend
        strip = np.asarray(self._strip[:hi], dtype=np.intp)
        u = np.asarray(self._inner[:hi]) - inner_ref
        v = u * u
        y = 2.0 * math.pi / self.strips * (np.asarray(self._index[:hi], dtype=np.int64) - index_ref) - self.ratio * u
        y = y - (trend[0] * u + trend[1] * v + trend[2 + strip])
        inc = np.zeros((hi + 1, layout.size))  # row 0: nothing summed
        UU, UV, VV, UY, VY, YY = _SumLayout.UU, _SumLayout.UV, _SumLayout.VV, _SumLayout.UY, _SumLayout.VY, _SumLayout.YY
        now = inc[1:]
        now[:, UU], now[:, UV], now[:, VV], now[:, UY], now[:, VY], now[:, YY] = u * u, u * v, v * v, u * y, v * y, y * y
        rows = np.arange(hi)
        k = layout.count(strip)
        now[rows, k], now[rows, k + 1], now[rows, k + 2], now[rows, k + 3] = 1.0, u, v, y
        du, dv, dy = np.diff(u), np.diff(v), np.diff(y)
        later = inc[2:]  # the differences, from the second point on
        q = layout.pairs
        later[:, q + UU], later[:, q + UV], later[:, q + VV] = du * du, du * dv, dv * dv
        later[:, q + UY], later[:, q + VY], later[:, q + YY] = du * dy, dv * dy, dy * dy
        changed = np.flatnonzero(strip[1:] != strip[:-1])
        if changed.size:
            now_strip, before = strip[1:][changed], strip[:-1][changed]
            at = changed + 2
            ks, js = layout.pair_strip(now_strip), layout.pair_strip(before)  # the layout's indices, elementwise
            inc[at, ks], inc[at, ks + 1], inc[at, ks + 2] = du[changed], dv[changed], dy[changed]
            inc[at, js], inc[at, js + 1], inc[at, js + 2] = -du[changed], -dv[changed], -dy[changed]
            inc[at, layout.cross(now_strip, now_strip)] = 1.0
            inc[at, layout.cross(before, before)] = 1.0
            inc[at, layout.cross(now_strip, before)] = -1.0
            inc[at, layout.cross(before, now_strip)] = -1.0
        np.cumsum(inc, axis=0, out=inc)
        self._bulk, self._bulk_count, self._prefix = inc, hi, []
        self._running = inc[-1].tolist()
        self._summed, self._last_row = hi, (float(u[-1]), float(v[-1]), int(strip[-1]), float(y[-1]))

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
        self._restart_sums()

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
        n = last - first + 1
        solved = _normal_equations(self._layout, self._sums_through(first), self._sums_through(first + 1), self._sums_through(last + 1), n)
        if solved is None:
            return None
        c2, c2_variance_factor, sse, near, p = solved
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
        var_c2 = max(s2, self.angle_floor**2) * c2_variance_factor
        return PhaseEstimate(
            slope=factor * (c2 + float(self._trend[1])),  # the trend's curvature taken out of y
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


def _normal_equations(
    layout: _SumLayout, before: list[float] | tuple[float, ...], second: list[float] | tuple[float, ...], through: list[float] | tuple[float, ...], n: int
) -> tuple[float, float, float, float, int] | None:
    """The least-squares fit of a stretch of ``n`` pulses from its running sums (:class:`_SumLayout`):
    ``before`` the sums up to the pulse before its first, ``second`` up to its first (the
    differences start at its second pulse) and ``through`` up to its last.

    The strips' offsets enter the normal equations as a diagonal block (each pulse has one
    strip), so they are eliminated exactly: u and u^2 are taken relative to their means on each
    strip (the Schur complement of that block), which leaves two equations for c1 and c2, and
    each strip's offset follows as its mean residual. A few dozen operations on plain floats,
    cheaper than any call into numpy at this size. The two equations are refused as singular
    when their determinant is not above 1e-12 of the product of their diagonal.

    Returns:
        (c2, the factor of the residual variance that gives Var(c2), the residuals' sum of
        squares, the sum of their successive differences squared, the columns' count p: u,
        u^2 and the strips present), or None (u or u^2 constant on every strip, too few pulses
        for the columns with :data:`MIN_DOF` to spare, or a singular system).
    """
    UU, UV, VV, UY, VY, YY = _SumLayout.UU, _SumLayout.UV, _SumLayout.VV, _SumLayout.UY, _SumLayout.VY, _SumLayout.YY
    q = layout.pairs
    # the strips present, each as (strip, pulses, sum u, sum v, sum y)
    strips = []
    for s in range(layout.strips):
        k = layout.count(s)
        count = through[k] - before[k]
        if count > 0.0:
            strips.append((s, count, through[k + 1] - before[k + 1], through[k + 2] - before[k + 2], through[k + 3] - before[k + 3]))
    p = 2 + len(strips)
    if n < p + MIN_DOF:
        return None
    a11, a12, a22 = through[UU] - before[UU], through[UV] - before[UV], through[VV] - before[VV]
    uy, vy, yy = through[UY] - before[UY], through[VY] - before[VY], through[YY] - before[YY]
    b1, b2 = uy, vy
    for _s, count, su, sv, sy in strips:  # the Schur complement of the strips' diagonal block
        a11 -= su * su / count
        a12 -= su * sv / count
        a22 -= sv * sv / count
        b1 -= su * sy / count
        b2 -= sv * sy / count
    det = a11 * a22 - a12 * a12
    if not (a11 > 0.0 and a22 > 0.0 and det > 1e-12 * a11 * a22):
        return None
    c1, c2 = (a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det
    offsets = [(s, (sy - su * c1 - sv * c2) / count) for s, count, su, sv, sy in strips]
    # residuals' sum of squares: y'y - c'X'y
    sse = yy - c1 * uy - c2 * vy - sum(e * sy for (_s, e), (_, _count, _su, _sv, sy) in zip(offsets, strips))

    def pair(k: int) -> float:
        return through[k] - second[k]

    # their successive differences' sum of squares: dy'dy - 2 c'dX'dy + c'dX'dX c
    dc = c1 * c1 * pair(q + UU) + 2.0 * c1 * c2 * pair(q + UV) + c2 * c2 * pair(q + VV)
    dcy = c1 * pair(q + UY) + c2 * pair(q + VY)
    for s, e in offsets:
        j = layout.pair_strip(s)
        dc += 2.0 * e * (c1 * pair(j) + c2 * pair(j + 1))
        dcy += e * pair(j + 2)
        dc += e * sum(f * pair(layout.cross(s, r)) for r, f in offsets)
    near = pair(q + YY) - 2.0 * dcy + dc
    return c2, a11 / det, max(sse, 0.0), max(near, 0.0), p
