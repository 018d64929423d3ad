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

import math
from collections import deque
from dataclasses import dataclass

import numpy as np

MIN_PHASE_REVOLUTIONS = 2.0
"""A stretch covers at least this many cage revolutions (reaching back beyond the span if need
be), so that the strips' offsets are told apart from the curvature (1)."""


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
    docstring).

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
        self._points: deque[tuple[float, int, int, float]] = deque()

    def reset(self) -> None:
        """Forget every pulse."""
        self._points.clear()

    def add(self, time: float, cage_index: int, strip: int, spindle_angle: float) -> None:
        """One cage pulse: its time (s, increasing), pulse index and strip, and the spindle's
        angle then (rad, spacing-corrected)."""
        points = self._points
        if points and not time > points[-1][0]:
            self.reset()
        points.append((time, cage_index, strip, spindle_angle))
        keep = max(self.max_span, MIN_PHASE_REVOLUTIONS * 2.0 * math.pi / max(self._cage_speed(), 1e-9))
        while len(points) > 2 and time - points[0][0] > keep:
            points.popleft()

    def _cage_speed(self) -> float:
        p = self._points
        if len(p) < 2 or p[-1][0] <= p[0][0]:
            return 0.0
        return 2.0 * math.pi * (p[-1][1] - p[0][1]) / self.strips / (p[-1][0] - p[0][0])

    def estimate(self, end: float, since: float | None = None, span: float | None = None) -> PhaseEstimate | None:
        """The slope over the pulses of the last ``span`` (s; default the one given at
        construction, at most ``max_span``) up to ``end`` (s), or back to
        :data:`MIN_PHASE_REVOLUTIONS` cage revolutions if the span holds fewer, none before
        ``since`` (s: a change in the slip); None with too few pulses for the fit (three more
        than its parameters)."""
        start = -math.inf if since is None else since
        stretch = self.span if span is None else min(span, self.max_span)
        rows = [p for p in self._points if start <= p[0] <= end]
        if len(rows) < 2:
            return None
        last_index = rows[-1][1]
        first = len(rows) - 1
        need = MIN_PHASE_REVOLUTIONS * self.strips
        while first > 0 and (end - rows[first - 1][0] <= stretch or last_index - rows[first][1] < need):
            first -= 1
        rows = rows[first:]
        if last_index - rows[0][1] < need:
            return None
        t = np.array([r[0] for r in rows])
        cage = 2.0 * math.pi / self.strips * np.array([r[1] for r in rows], dtype=np.float64)
        inner = np.array([r[3] for r in rows])
        strips = sorted({r[2] for r in rows})
        u = inner - inner.mean()
        scale = max(float(np.max(np.abs(u))), 1e-12)
        columns = [np.ones_like(u), u / scale, (u / scale) ** 2]
        strip_of = np.array([r[2] for r in rows])
        columns += [(strip_of == s).astype(np.float64) for s in strips[1:]]
        x = np.column_stack(columns)
        y = cage - self.ratio * inner
        y = y - y.mean()
        n, p = x.shape
        if n < p + 3:
            return None
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
        revolutions = (rows[-1][1] - rows[0][1]) / self.strips
        dof = n - p
        effective = max(2, int(round(dof * white_share + max(revolutions - 2.0, 1.0) * (1.0 - white_share))))
        c2, var_c2 = float(coef[2]) / scale**2, var_c2_unscaled / scale**4
        duration = float(t[-1] - t[0])
        speed = float(inner[-1] - inner[0]) / duration if duration > 0.0 else math.nan
        if not (math.isfinite(speed) and speed > 0.0):
            return None
        factor = -200.0 / self.ratio * speed  # dS/dt per unit of c2
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
