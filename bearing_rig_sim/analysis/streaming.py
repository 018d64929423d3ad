"""The slope criterion on points arriving one by one: :class:`TrailingSlope`, the monitor's verdict.

x is the time (s) or the axial load (N). The verdict is the slope of a least-squares line through
the slip of a trailing window, decided only when its one-sided bound (Student's t: at
``stable_confidence`` for STABLE, 95 % for SLIPPING) is on one side of k (with hysteresis), with change detection on the slip
itself; microseconds per point (see its docstring; ``bearing-rig bench analysis`` measures it).

The paper's own form, a Gaussian sum fitted to the whole series with the onset of the stable
state (:mod:`bearing_rig_sim.analysis.gaussian`, :func:`~bearing_rig_sim.analysis.stability.stable_onset`),
serves the studies and the reproduction on complete series. It does not serve online: a global
Gaussian does not describe a slip that steps and decays, or a plateau (a 1-term fit to a flat
series runs to its width bound and reports R^2 below zero), and its refits cost milliseconds on
the pulse path.
"""

from __future__ import annotations

import bisect
import functools
import math
import statistics
from collections import deque
from dataclasses import dataclass

import numpy as np
from scipy.special import stdtrit

from bearing_rig_sim.analysis.inputs import AnalysisError, FloatArray, finite_number, positive_int
from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim import picklable


@functools.lru_cache(maxsize=256)
def t_quantile_overturn(dof: int) -> float:
    """One-sided Student's t quantile at 1 - :data:`OVERTURN_AT_ONCE_P` with ``dof`` (>= 1)
    degrees of freedom (``scipy.special.stdtrit``, which ``scipy.stats.t.ppf`` calls, without
    importing ``scipy.stats``'s 23 MB; cached)."""
    return float(stdtrit(dof, 1.0 - OVERTURN_AT_ONCE_P))


@functools.lru_cache(maxsize=1024)
def t_quantile(probability: float, dof: int) -> float:
    """Student's t quantile at ``probability`` (0-1) with ``dof`` (>= 1) degrees of freedom
    (``scipy.special.stdtrit``; cached, as the monitor asks for the same few at every point)."""
    return float(stdtrit(dof, probability))


@functools.lru_cache(maxsize=256)
def t_quantile_95(dof: int) -> float:
    """One-sided 95 % quantile of Student's t with ``dof`` (>= 1) degrees of freedom
    (``scipy.special.stdtrit``; cached, as the monitor asks for the same few at every point)."""
    return float(stdtrit(dof, 0.95))


@dataclass(frozen=True)
class SlopeVerdict:
    """The verdict of :class:`TrailingSlope` after the latest point.

    Attributes:
        state: UNKNOWN (no decision yet in this series), SLIPPING or STABLE.
        slope: slope of the least-squares line over the window that decided (the trailing one,
            or the longer stretch when that decided), %/unit of x; None with fewer than the
            minimum points.
        standard_error: its standard error, same unit; None likewise.
        critical_slope: k, same unit.
        confidence: P(slope >= k) under the line fit's normal approximation (Student's t
            quantiles decide, the normal law gives this number); 0 while the slope is unknown.
        n_points: points of that line.
        span: x covered by those points, unit of x.
        change_at: x of the latest change detected in the series (None if none since reset).
        detail: one readable line.
    """

    state: SlipState
    slope: float | None
    standard_error: float | None
    critical_slope: float
    confidence: float
    n_points: int
    span: float
    change_at: float | None
    detail: str


OVERTURN_CONFIRM = 0.5
"""A held verdict is overturned by the trailing window only once the opposite verdict has been
reached at points spanning this fraction of the span, with no point deciding the held verdict
again in between (1). The slope is re-tested at every slip point (6-19 a second) on overlapping
windows, so a single 5 % test overturned a verdict on a plateau by chance 2-9 times in 30 s once
the points scattered by about 0.06 %; with this rule, not once in the same trials."""

OVERTURN_AT_ONCE_P = 1e-4
"""... unless the opposite verdict is beyond doubt: its one-sided bound at 1 - this (Student's t,
about 4 standard errors at 60 degrees of freedom, 6.4 at 8) is on the other side of k, which
chance does not give on a plateau (1). A run-up's slope crosses k2 and runs on to zero within
half a second (Table 7: from -0.03 to -0.005 %/s in 0.3 s at 60 rad/s^2): its clean windows
reach this bound at once, where waiting out half the span added 0.5 s to each time to stable."""

SCATTER_POINTS = 64
"""Second differences kept for the scatter of the slip points (1)."""

MIN_SCATTER_POINTS = 8
"""Second differences needed before their scatter is used (1)."""


class TrailingSlope:
    """The slope criterion on a trailing window of (x, slip %) points, one point at a time.

    **Slope.** A least-squares line through the points of the last ``span`` (unit of x; at least
    the latest ``min_points`` whatever their span): the paper's Eq. 14 slope of a smoothed slip
    curve, taken where the verdict is wanted, at the end. Its standard error is ``sigma /
    sqrt(Sxx)``, with ``sigma`` the scatter of the slip points about the curve, estimated from the
    second differences of the last :data:`SCATTER_POINTS` points of the series (``y_i - 2 y_(i-1)
    + y_(i-2)`` has variance ``6 sigma^2`` plus a curvature term negligible between neighbouring
    windows; the median of their magnitudes, divided by ``0.6745 sqrt 6``, ignores the few that
    straddle a change), and never below ``resolution`` (percent): until enough points are in,
    the larger of that and the line's own residual scatter.

    **Decision with hysteresis.** With ``q_c`` and ``q`` the one-sided Student's t quantiles at
    ``stable_confidence`` and 95 %: the state becomes STABLE when ``slope - q_c se >= k``,
    SLIPPING when ``slope + q se < k`` and the slope clearly falls (:meth:`falling`), and otherwise
    stays what it was (UNKNOWN at the start of a series). Since the test is repeated at every
    point, a held verdict is overturned only once the opposite one has been reached over
    :data:`OVERTURN_CONFIRM` of the span, or at once when beyond doubt
    (:data:`OVERTURN_AT_ONCE_P`) (not after a detected change in the slip:
    the held verdict's points are gone, and the new ones decide afresh), or at once when the
    longer stretch (below) reaches the same opposite verdict. A verdict thus changes only when the data puts the
    slope clearly on the other side of k, so noise on a plateau cannot flap it.

    **Changes in the slip itself** (a load step, a lubrication event, anything): each new point
    is compared with the line's prediction; a point outside ``change_threshold`` prediction
    standard errors, followed by one more on the same side, marks a change at the first of them.
    The points before it are dropped, so the slope answers for the slip after the change. The
    state is kept until the new points decide (hysteresis again). One outlier is not a change.

    **Longer evidence when the trailing window cannot decide** (``max_span``): with slip points
    that scatter more than a second's worth of them can resolve against k (a bench's slip
    scatters by some hundredths of a point per revolution: the paper's fits leave an RMS of
    0.005-0.045 %), the slope of the last ``span`` straddles k for ever. Then the line through
    the longer stretch of the same series is tried, back to at most ``max_span``, and it decides
    if it is clear by the same rule. It never reaches back before the data that made the current
    decision (the first point of the window that last decided), before a change, or before the
    last :meth:`forget_scatter` (a speed change), so it can only confirm the held state from
    newer points or overturn it with points taken after it, and it gives a new verdict only on the
    side of k the trailing slope itself is on, so a plateau cannot flap.

    Args:
        critical_slope: k, %/unit of x.
        span: trailing window, unit of x (> 0).
        min_points: points needed for a slope (>= 3).
        resolution: least residual standard deviation believed, percent (> 0).
        change_threshold: prediction standard errors beyond which a point is a candidate change.
        max_span: longest stretch of the series the slope may rest on when the trailing window
            cannot decide, unit of x (None: the trailing window only; >= span).
        stable_confidence: one-sided confidence of the STABLE test (0.5-1): a false STABLE at a
            true slope of k with P = 1 - this per test (docs/method.md); no default: the monitor's
            ``stable_confidence`` parameter is the one source.
    """

    def __init__(
        self,
        critical_slope: float,
        span: float,
        min_points: int,
        resolution: float,
        change_threshold: float,
        max_span: float | None = None,
        *,
        stable_confidence: float,
    ) -> None:
        self.stable_confidence = finite_number("stable_confidence", stable_confidence)
        if not 0.5 <= self.stable_confidence < 1.0:
            raise AnalysisError(f"stable_confidence: must be in [0.5, 1), got {stable_confidence!r}")
        self.critical_slope = finite_number("critical_slope", critical_slope)
        self.span = finite_number("span", span)
        if not self.span > 0.0:
            raise AnalysisError(f"span: must be > 0, got {span!r}")
        self.min_points = positive_int("min_points", min_points)
        if self.min_points < 3:
            raise AnalysisError(f"min_points: must be >= 3, got {min_points!r}")
        self.resolution = finite_number("resolution", resolution)
        if not self.resolution > 0.0:
            raise AnalysisError(f"resolution: must be > 0, got {resolution!r}")
        self.change_threshold = finite_number("change_threshold", change_threshold)
        self.max_span = None if max_span is None else finite_number("max_span", max_span)
        if self.max_span is not None and not self.max_span >= self.span:
            raise AnalysisError(f"max_span: must be >= span ({self.span!r}), got {max_span!r}")
        self.reset()

    def reset(self) -> None:
        """Forget every point and the decision (a new series: state UNKNOWN)."""
        self._x: list[float] = []
        self._y: list[float] = []
        self._origin: float | None = None
        self._state = SlipState.UNKNOWN
        self._candidate: tuple[int, float] | None = None  # (sign, x) of an outlying point
        self._change_at: float | None = None
        self._sigma = self.resolution
        self._dof = 1
        self._d2: deque[float] = deque(maxlen=SCATTER_POINTS)
        self._last2: list[tuple[float, float]] = []
        self._line: tuple[float, float, float, float, float, int] | None = None  # slope, se, xbar, ybar, sxx, n
        self._hx: list[float] = []  # the series since the last change or speed change, pruned to max_span
        self._hy: list[float] = []
        self._anchor: float | None = None  # first x of the window that made the current decision
        self._overturn: tuple[SlipState, float] | None = None  # (opposite state, x since it held)
        self._used: tuple[tuple[float, float, float, float, float, int], float] | None = None  # line, span
        self._verdict = self._make_verdict()

    @property
    def n_points(self) -> int:
        """Points in the trailing window."""
        return len(self._x)

    def forget_scatter(self) -> None:
        """Start the scatter estimate afresh (a new operating point: the points' scatter about
        the curve may differ, and the second differences of a steep, curved stretch such as a
        run-up measure its curvature, not the scatter); points and decision are kept."""
        self._d2.clear()
        self._last2 = []
        self._hx, self._hy = [], []

    def points(self) -> tuple[FloatArray, FloatArray]:
        """Copies of the points in the trailing window: x (unit of x) and slip (percent)."""
        origin = self._origin or 0.0
        return np.asarray(self._x) + origin, np.asarray(self._y, dtype=np.float64)

    @property
    def state(self) -> SlipState:
        """The current decision."""
        return self._state

    def add(self, x: float, slip_pct: float, external: tuple[float, float, int] | tuple[float, float, int, bool] | None = None) -> bool:
        """Add one point (x increasing); returns whether a change in the slip was detected.

        ``external``: (slope, standard error, degrees of freedom) of the slip over the trailing
        window estimated from finer data than the points (the cage's phase,
        :class:`~bearing_rig_sim.analysis.phase.PhaseSlope`), which then decides in place of the
        points' line (with fewer than ``min_points`` points too); the points still serve the
        change detection and the longer stretch. A fourth element True: that standard error is
        not to be trusted below the points' own line's (its data wander: the larger of the two
        is used, and the smaller degrees of freedom; none with fewer than 3 points).

        Raises:
            AnalysisError: a non-finite value or an x not after the previous one (the point is
                not added).
        """
        xv = finite_number("x", x)
        yv = finite_number("slip_pct", slip_pct)
        if self._origin is None:
            self._origin = xv
        u = xv - self._origin
        if self._x and not u > self._x[-1]:
            raise AnalysisError(f"x: must increase, got {xv!r} after {self._x[-1] + self._origin!r}; call reset()")
        changed = self._test_change(u, yv)
        if changed:
            self._last2 = []
        self._second_difference(u, yv)
        self._x.append(u)
        self._y.append(yv)
        while len(self._x) > self.min_points and u - self._x[0] > self.span:
            del self._x[0], self._y[0]
        if self.max_span is not None:
            self._hx.append(u)
            self._hy.append(yv)
            while u - self._hx[0] > self.max_span:
                del self._hx[0], self._hy[0]
        self._fit(external)
        self._decide()
        self._verdict = self._make_verdict()
        return changed

    def refresh(self, external: tuple[float, float, int] | tuple[float, float, int, bool]) -> None:
        """A newer finer estimate (``external`` of :meth:`add`) between two points: decides
        afresh on it while no verdict is held (a first verdict need not wait for the next slip
        point); nothing before the first point, or once a verdict is held (its overturn rules
        count points)."""
        if not self._x or self._state is not SlipState.UNKNOWN:
            return
        self._fit(external)
        self._decide()
        self._verdict = self._make_verdict()

    def _test_change(self, u: float, y: float) -> bool:
        line = self._line
        if line is None:
            return False
        slope, _se, xbar, ybar, sxx, n = line
        if not sxx > 0.0:
            return False
        sigma = self._sigma
        predicted = ybar + slope * (u - xbar)
        spread = sigma * math.sqrt(1.0 + 1.0 / n + (u - xbar) ** 2 / sxx)
        z = (y - predicted) / spread
        if abs(z) <= self.change_threshold:
            self._candidate = None
            return False
        sign = 1 if z > 0 else -1
        if self._candidate is None or self._candidate[0] != sign:
            self._candidate = (sign, u)
            return False
        start = self._candidate[1]
        self._candidate = None
        keep = [i for i, xi in enumerate(self._x) if xi >= start]
        self._x = [self._x[i] for i in keep]
        self._y = [self._y[i] for i in keep]
        keep = [i for i, xi in enumerate(self._hx) if xi >= start]
        self._hx = [self._hx[i] for i in keep]
        self._hy = [self._hy[i] for i in keep]
        self._anchor = None
        self._change_at = start + (self._origin or 0.0)
        self._line = None
        return True

    def _second_difference(self, u: float, y: float) -> None:
        """Record the second difference ending at (u, y), scaled to equal spacing."""
        last = self._last2
        if len(last) == 2:
            (x0, y0), (x1, y1) = last
            h0, h1 = x1 - x0, u - x1
            if h0 > 0.0 and h1 > 0.0:
                # divided second difference times the mean spacing squared / 2: 'y_i - 2 y_(i-1) + y_(i-2)'
                # for equal spacing; its noise variance is 6 sigma^2 at equal spacing
                d2 = 2.0 * ((y - y1) / h1 - (y1 - y0) / h0) / (h0 + h1) * (0.5 * (h0 + h1)) ** 2
                self._d2.append(abs(d2))
        last.append((u, y))
        if len(last) > 2:
            del last[0]

    def _scatter(self, residual_scatter: float) -> tuple[float, int]:
        """sigma (percent) and its degrees of freedom."""
        if len(self._d2) >= MIN_SCATTER_POINTS:
            pooled = statistics.median(self._d2) / (0.6745 * math.sqrt(6.0))
            return max(pooled, self.resolution), len(self._d2)
        return max(residual_scatter, self.resolution), max(len(self._x) - 2, 1)

    @staticmethod
    def _least_squares(xs: list[float], ys: list[float]) -> tuple[float, float, float, float, float] | None:
        """(slope, xbar, ybar, sxx, residual scatter) of the line through the points, or None."""
        n = len(xs)
        # plain sums: a few dozen points, where numpy's call overhead would dominate
        xbar, ybar = sum(xs) / n, sum(ys) / n
        dx = [x - xbar for x in xs]
        sxx = sum(d * d for d in dx)
        if not sxx > 0.0:
            return None
        slope = sum(d * (y - ybar) for d, y in zip(dx, ys)) / sxx
        sse = sum((y - ybar - slope * d) ** 2 for d, y in zip(dx, ys))
        return slope, xbar, ybar, sxx, math.sqrt(sse / (n - 2)) if n > 2 else 0.0

    def _fit(self, external: tuple[float, float, int] | tuple[float, float, int, bool] | None = None) -> None:
        n = len(self._x)
        fit = self._least_squares(self._x, self._y) if n >= (3 if external is not None else self.min_points) else None
        if external is not None and all(math.isfinite(v) for v in external[:3]) and external[1] > 0.0:
            slope, se, dof, checked = external[0], external[1], max(1, int(external[2])), len(external) > 3 and bool(external[3])
            if fit is not None:
                self._sigma, points_dof = self._scatter(fit[4])
                if checked:  # no better than the points' own line
                    se, dof = max(se, self._sigma / math.sqrt(fit[3])), min(dof, points_dof)
            if fit is not None or not checked:
                xbar, ybar, sxx = (fit[1], fit[2], fit[3]) if fit is not None else (self._x[-1], self._y[-1], 0.0)
                self._dof = dof
                self._line = (slope, se, xbar, ybar, sxx, n)
                return
        if fit is None or n < self.min_points:
            self._line = None
            return
        slope, xbar, ybar, sxx, scatter = fit
        self._sigma, self._dof = self._scatter(scatter)
        self._line = (slope, self._sigma / math.sqrt(sxx), xbar, ybar, sxx, n)

    def falling(self, slope: float, standard_error: float) -> bool:
        """Whether a slope may raise the alarm (SLIPPING) besides being clearly below k: it is
        also below zero by twice the one-sided 95 % bound, so that a flat slip (a hold, the
        stable state the alarm must not be raised in) gives a false alarm with P(T < -2 t_0.95)
        per test at any resolution: 0.13 % at 20 degrees of freedom, 0.07 % at 60
        (docs/method.md). The bare 95 % test gave up to 5 % at each of the first, least resolved
        tests of a hold, where |k| is within the noise. A slope steeper than k by several
        standard errors, the slipping the alarm is for, passes both at once."""
        return slope + 2.0 * t_quantile_95(self._dof) * standard_error < 0.0

    def _clear(self, line: tuple[float, float, float, float, float, int], strict: bool = False) -> SlipState:
        """The state a line decides by its one-sided bounds, at ``stable_confidence`` for STABLE and
        95 % for SLIPPING (UNKNOWN: neither side); with ``strict``, both at 1 -
        :data:`OVERTURN_AT_ONCE_P`. SLIPPING only on a slope
        also clearly falling (:meth:`falling`)."""
        slope, se, *_rest = line
        q = t_quantile_overturn(self._dof) if strict else t_quantile_95(self._dof)
        q_stable = q if strict else t_quantile(self.stable_confidence, self._dof)
        k = self.critical_slope
        if slope - q_stable * se >= k:
            return SlipState.STABLE
        if slope + q * se < k and self.falling(slope, se):
            return SlipState.SLIPPING
        return SlipState.UNKNOWN

    def _longer_line(self) -> tuple[tuple[float, float, float, float, float, int], float] | None:
        """The line through the series back to the anchor, the last change or speed change and
        at most ``max_span``, with its span; None when that adds no point before the trailing window."""
        if self.max_span is None or not self._hx or not self._x:
            return None
        start = self._hx[0] if self._anchor is None else max(self._hx[0], self._anchor)
        if not start < self._x[0]:
            return None
        i = bisect.bisect_left(self._hx, start)
        xs, ys = self._hx[i:], self._hy[i:]
        fit = self._least_squares(xs, ys) if len(xs) > len(self._x) else None
        if fit is None:
            return None
        slope, xbar, ybar, sxx, _scatter = fit
        return (slope, self._sigma / math.sqrt(sxx), xbar, ybar, sxx, len(xs)), xs[-1] - xs[0]

    def _decide(self) -> None:
        if self._line is None:
            self._used = None
            return
        self._used = (self._line, self._x[-1] - self._x[0])
        decided, held = self._clear(self._line), self._state
        if decided is not SlipState.UNKNOWN:
            if decided is held or held is SlipState.UNKNOWN or self._anchor is None:
                self._state, self._anchor, self._overturn = decided, self._x[0], None
                return
            # an overturn of the held verdict: reached over OVERTURN_CONFIRM of the span first
            since = self._overturn[1] if self._overturn is not None and self._overturn[0] is decided else self._x[-1]
            self._overturn = (decided, since)
            if self._x[-1] - since >= OVERTURN_CONFIRM * self.span or self._clear(self._line, strict=True) is decided:
                self._state, self._anchor, self._overturn = decided, self._x[0], None
                return
        # the trailing window cannot decide, or its overturn is not confirmed yet: the longer
        # stretch decides, or (far less scattered) confirms that overturn at once
        longer = self._longer_line()
        if longer is None:
            return
        line, _span = longer
        by_longer = self._clear(line)
        if by_longer is SlipState.UNKNOWN or (decided is not SlipState.UNKNOWN and by_longer is not decided):
            return
        if by_longer is not held and self._line is not None:
            # a new verdict only where the trailing slope itself points (the older points may be
            # from before a steep stretch ended, which the trailing window has left behind)
            if (self._line[0] >= self.critical_slope) != (by_longer is SlipState.STABLE):
                return
            # and a held STABLE is overturned to the alarm only while the trailing slope itself
            # falls clearly (:meth:`falling`): the windows' longer line of a 900 rpm hold with
            # 50 us of jitter once said -0.107 +- 0.023 %/s where the phase said -0.032 +- 0.033
            if by_longer is SlipState.SLIPPING and held is SlipState.STABLE and not self.falling(self._line[0], self._line[1]):
                return
        if by_longer is not held or self._anchor is None:
            self._anchor = self._hx[-line[5]]  # the first of its points
            self._overturn = None
        self._state, self._used = by_longer, longer

    def _make_verdict(self) -> SlopeVerdict:
        k = self.critical_slope
        n = len(self._x)
        span = self._x[-1] - self._x[0] if n else 0.0
        if self._line is None or self._used is None:
            detail = f"collecting slip points: {n} of the {self.min_points} needed for a slope"
            if self._state is not SlipState.UNKNOWN:
                since = f" since a change at x = {self._change_at:.6g}" if self._change_at is not None else ""
                detail += f" (holding {self._state.label}{since})"
            return SlopeVerdict(self._state, None, None, k, 0.0, n, span, self._change_at, detail)
        line, span = self._used
        slope, se, n = line[0], line[1], line[5]
        confidence = 0.5 * (1.0 + math.erf((slope - k) / (se * math.sqrt(2.0))))
        relation = {SlipState.STABLE: "clearly >=", SlipState.SLIPPING: "clearly <"}.get(self._state, "not clearly either side of")
        detail = f"slope {slope:.3g} +- {se:.2g} over {n} points ({span:.3g}) {relation} k = {k:g}; P(slope >= k) {confidence:.3f}"
        return SlopeVerdict(self._state, slope, se, k, confidence, n, span, self._change_at, detail)

    def verdict(self) -> SlopeVerdict:
        """The verdict after the latest point (cached; microseconds)."""
        return self._verdict


picklable.by_fields(SlopeVerdict)
