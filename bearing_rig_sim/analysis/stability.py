"""The slope criterion: when has the slip reached its stable state? (paper Eq. 14; docs/paper.md section 7).

The paper fits a curve to the slip (percent) against axial load (N) or time (s) and computes the
slope between successive points of the fitted curve, k_n = (s_n - s_(n-1)) / (x_n - x_(n-1)).
Where the slope is **at or above** a critical value (less steep a fall than k) the bearing is
*stable*; where it is **below** (a steeper fall) it is *slipping*. The slope of the fitted curve
is used here at a point (the limit of Eq. 14 for close points), analytically for a
:class:`~bearing_rig_sim.analysis.gaussian.GaussianFit`, by a central difference otherwise.

**Onset of the stable state** over a range [x_start, x_end], two readings
(:data:`ONSET_READINGS`):

* ``first`` (:attr:`StabilityResult.first_onset`; the load sweep's, shipped): where the slope
  first reaches k after the fall, i.e. the end of the first stretch where it is below k; x_start
  if it never is; ``None`` if that stretch lasts to x_end. A stretch at or above k before the
  fall (the top of a curve that first rises) is not the onset.
* ``last`` (:attr:`StabilityResult.onset`): the smallest x* such that the slope is >= k at every
  x in [x*, x_end], the start of the stable stretch that lasts to the end of the range; ``None``
  ("not reached") if the slope at x_end is below k; x_start with ``stable_from_start`` if it is
  >= k on the whole range (the true onset may lie before the range).

They differ only for a slope that is not monotonic. A fitted sum of Gaussians has one beyond the
data's turn: every term falls to zero past its centre, so the curve falls again at the end of a
range whatever the data do there (the paper's own Table 5 curve at 1000 rpm, docs/method.md),
and "last" then judges a term's flank rather than the bearing. Run-ups (k2) keep ``last``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum
from typing import Any
from collections.abc import Callable, Sequence

import numpy as np
import numpy.typing as npt
from scipy.optimize import brentq

from bearing_rig_sim.analysis.gaussian import GaussianFit, select_gaussian_fit
from bearing_rig_sim.analysis.inputs import (
    AnalysisError,
    FloatArray,
    finite_array,
    finite_number,
    same_length,
    strictly_increasing,
)

K1_PAPER: float = -5e-6
"""The paper's k1 as printed, for slip against axial load, without a unit (docs/paper.md
section 7)."""

K1_AXIAL_LOAD: float = K1_PAPER * 100.0
"""Critical slope of slip against axial load, shipped: **-5e-4 percent per newton**, the paper's
-5e-6 read as slip *fraction* per newton.

The paper gives no unit. Its own 1000 rpm curve (Table 5, a 2-term Gaussian with x in N, y in %)
falls to 2.04 % at 416 N, rises to 2.06 % at 500 N and falls again to 1.80 % at 700 N (its second
term, centred at 530 N, must fall to zero beyond its centre whatever the data did). Of the four
readings (unit x meaning, :data:`K1_READINGS`, :data:`ONSET_READINGS`) only the two "first
reach" ones give the verdict the paper's text claims there (slip falls with load and levels off,
at 394 N by this unit and 416 N by percent per newton); "stays to the last load" gives no stable
state in either unit (docs/method.md, test_analysis_stability.py). Between the two units the
curve does not decide; the rig does: -5e-6 %/N is a fall of 0.0005 pp per 100 N, ten times below
what a settled load point resolves, so that reading finds a stable state only where a fit
happens to turn (its minimum), while -5e-4 %/N, 0.05 pp per 100 N, is the slope at which the
bench twin's loaded-angle slip levels off (docs/method.md). Slope in percent per newton.
"""

K1_READINGS: dict[str, float] = {"fraction per N": K1_AXIAL_LOAD, "percent per N": K1_PAPER}
"""The two units the paper's k1 can be read in, as the critical slope in %/N each gives."""

ONSET_READINGS: tuple[str, ...] = ("first", "last")
"""What "stable from N" means (:class:`StabilityResult`): ``first``, the load where the fitted
slope first reaches k after the fall (:attr:`StabilityResult.first_onset`; shipped), or
``last``, the load from which it stays at or above k to the last load
(:attr:`StabilityResult.onset`)."""


K2_TIME: float = -3e-2
"""Critical slope of slip against time under acceleration, read as **percent per second** (%/s).

The paper gives k2 = -3e-2 without a unit (docs/paper.md section 7). Read as %/s, with slip in percent
and time in seconds as in its Table 7 fits y = lambda exp(-((t - k)/d)^2), it reproduces the
stable-onset times the paper's data imply: 1.67, 1.41, 1.23 and 0.97 s for 20, 40, 60 and
80 rad/s^2 (docs/paper.md section 11). Read as a fraction per second (3 %/s) it would put every onset
before 0.6 s.
"""


class SlipState(IntEnum):
    """State of the bearing by the slope criterion, and of the monitor: the one state enum of the
    project. The values are SlipStatus.msg's ``STATE_*`` constants; :attr:`label` is the name
    shown to people ("stable")."""

    UNKNOWN = 0
    SLIPPING = 1
    STABLE = 2
    FAULT = 3
    """Sensor loss or invalid data (the monitor's; the slope criterion never gives it)."""

    @property
    def label(self) -> str:
        """Lower-case name: "unknown", "slipping", "stable" or "fault"."""
        return self.name.lower()

    def __str__(self) -> str:
        return self.label


SlipCurve = Callable[[Any], Any]
"""A fitted slip curve: a :class:`GaussianFit` (analytic slope) or any callable y(x)."""


def successive_slopes(x: FloatArray | Sequence[float], y: FloatArray | Sequence[float]) -> FloatArray:
    """Paper Eq. 14: k_n = (y_n - y_(n-1)) / (x_n - x_(n-1)) for n = 1 .. len(x) - 1.

    Args:
        x: abscissa, N or s, strictly increasing, at least 2 values.
        y: slip, percent, same length.

    Returns:
        len(x) - 1 slopes, percent per unit of x (%/N or %/s).

    Raises:
        AnalysisError: non-finite or mismatched data, fewer than 2 points, x not increasing.
    """
    xs = finite_array("x", x, min_len=2)
    ys = finite_array("y", y, min_len=2)
    same_length(x=xs, y=ys)
    strictly_increasing("x", xs)
    return np.diff(ys) / np.diff(xs)


def slope_function(curve: SlipCurve, step: float) -> Callable[[FloatArray], FloatArray]:
    """The slope of ``curve`` as a vectorised function of x (percent per unit of x).

    A curve with a ``slope`` method (a :class:`GaussianFit`) gives its analytic derivative;
    any other callable the central difference (y(x + step/2) - y(x - step/2)) / step, which is
    Eq. 14 between two points ``step`` apart.
    """
    analytic = getattr(curve, "slope", None)
    if callable(analytic):
        return lambda x: np.asarray(analytic(np.asarray(x, dtype=np.float64)), dtype=np.float64)
    if not callable(curve):
        raise AnalysisError(f"curve: must be a fitted curve or a callable y(x), got {type(curve).__name__}")
    h = float(step)

    def central(x: FloatArray) -> FloatArray:
        xa = np.asarray(x, dtype=np.float64)
        hi = np.asarray(curve(xa + 0.5 * h), dtype=np.float64)
        lo = np.asarray(curve(xa - 0.5 * h), dtype=np.float64)
        return (hi - lo) / h

    return central


def classify(x: FloatArray | Sequence[float], curve: SlipCurve, critical_slope: float, *, step: float | None = None) -> npt.NDArray[np.str_]:
    """State of each sample point by the slope of the fitted curve there.

    Args:
        x: sample points, N or s.
        curve: the fitted slip curve (percent against x).
        critical_slope: k, percent per unit of x (e.g. :data:`K2_TIME` for time).
        step: difference step for a plain callable (unit of x); default 1e-6 of the span of x
            (or 1e-6 if x has a single point).

    Returns:
        Array of "stable" (slope >= k) or "slipping" (slope < k), one per point.

    Raises:
        AnalysisError: non-finite x or critical slope, or a curve giving a non-finite slope.
    """
    xs = finite_array("x", x)
    k = finite_number("critical_slope", critical_slope)
    h = step if step is not None else (1e-6 * float(np.ptp(xs)) or 1e-6)
    slopes = slope_function(curve, h)(xs)
    if not np.all(np.isfinite(slopes)):
        raise AnalysisError("curve: gives a non-finite slope")
    return np.where(slopes >= k, SlipState.STABLE.label, SlipState.SLIPPING.label)


@dataclass(frozen=True)
class StabilityResult:
    """Where the slope criterion finds the stable state on [x_start, x_end].

    Attributes:
        onset: start of the final stable stretch (N or s), or None if not reached: the "last"
            reading (module docstring).
        first_onset: end of the first stretch where the slope is below k (N or s), x_start if
            there is none, None if it lasts to x_end: the "first" reading.
        critical_slope: k used, percent per unit of x.
        x_start: start of the range examined (N or s).
        x_end: end of the range examined (N or s).
        slope_at_end: slope of the curve at x_end, percent per unit of x.
        stable_from_start: True if the slope is >= k on the whole range (onset = x_start, and the
            true onset may lie before the range).
        stable_intervals: every stretch (from, to) of the range where slope >= k, in order; more
            than one means the slope is non-monotonic (only the last one can give the onset).
    """

    onset: float | None
    first_onset: float | None
    critical_slope: float
    x_start: float
    x_end: float
    slope_at_end: float
    stable_from_start: bool
    stable_intervals: tuple[tuple[float, float], ...]

    @property
    def reached(self) -> bool:
        """Whether the stable state holds at the end of the range."""
        return self.onset is not None

    def onset_by(self, reading: str) -> float | None:
        """The onset by one of :data:`ONSET_READINGS`: "first" or "last" (N or s)."""
        if reading not in ONSET_READINGS:
            raise AnalysisError(f"reading: must be one of {', '.join(ONSET_READINGS)}, got {reading!r}")
        return self.first_onset if reading == "first" else self.onset


def stable_onset(
    curve: SlipCurve,
    x_start: float,
    x_end: float,
    critical_slope: float,
    resolution: float | None = None,
) -> StabilityResult:
    """Find the onset of the stable state of a fitted slip curve (see the module docstring).

    The slope is sampled on a uniform grid of spacing ``resolution``; each change of state between
    grid points is refined by Brent's method to 1e-9 of the range. A stretch narrower than the
    grid spacing can be missed.

    Args:
        curve: the fitted slip curve (percent against x), e.g. a :class:`GaussianFit`.
        x_start: start of the range, N or s.
        x_end: end of the range, N or s, > x_start.
        critical_slope: k, percent per unit of x (:data:`K1_AXIAL_LOAD`, :data:`K2_TIME`).
        resolution: grid spacing in the unit of x; default (x_end - x_start) / 2000.

    Raises:
        AnalysisError: non-finite or empty range, bad resolution, non-finite slope.
    """
    x0 = finite_number("x_start", x_start)
    x1 = finite_number("x_end", x_end)
    k = finite_number("critical_slope", critical_slope)
    if not x1 > x0:
        raise AnalysisError(f"x_end: must be > x_start = {x0!r}, got {x1!r}")
    span = x1 - x0
    step = span / 2000.0 if resolution is None else finite_number("resolution", resolution)
    if not 0.0 < step <= span:
        raise AnalysisError(f"resolution: must be in (0, {span!r}], got {step!r}")
    slope = slope_function(curve, min(step, span * 1e-6))
    grid = np.linspace(x0, x1, int(math.ceil(span / step)) + 1)
    margin = slope(grid) - k
    if not np.all(np.isfinite(margin)):
        raise AnalysisError("curve: gives a non-finite slope on the range")
    stable = margin >= 0.0

    def crossing(i: int) -> float:
        """x where the slope crosses k between grid[i] and grid[i + 1]."""
        return float(brentq(lambda v: float(slope(np.array([v]))[0]) - k, grid[i], grid[i + 1], xtol=span * 1e-9))

    intervals: list[tuple[float, float]] = []
    begin = x0 if stable[0] else None
    for i in np.flatnonzero(stable[1:] != stable[:-1]):
        at = crossing(int(i))
        if stable[i + 1]:
            begin = at
        else:
            intervals.append((float(begin), at))  # type: ignore[arg-type]  # begin is set before at in this branch
            begin = None
    if begin is not None:
        intervals.append((float(begin), x1))
    onset = intervals[-1][0] if stable[-1] else None
    after_fall = [begin for begin, _ in intervals if begin > x0 or not stable[0]]
    first_onset = x0 if bool(np.all(stable)) else (after_fall[0] if after_fall else None)
    return StabilityResult(
        onset=onset,
        first_onset=first_onset,
        critical_slope=k,
        x_start=x0,
        x_end=x1,
        slope_at_end=float(margin[-1] + k),
        stable_from_start=bool(np.all(stable)),
        stable_intervals=tuple(intervals),
    )


# -- the load sweep by the paper's method ----------------------------------------------------------
SWEEP_MIN_R_SQUARE: float = 0.95
"""A slip-against-load fit is accepted when its R^2 is at least this (the paper's Table 4 fits
give 0.9993-0.9996) ..."""
SWEEP_MAX_RMSE_PCT: float = 0.1
"""... and its RMSE at most this, percentage points (the paper's Table 4: 0.040-0.045; a fit that
misses the points by more cannot resolve the flat end of the curve, where k1 is judged) ..."""
SWEEP_FLAT_RMSE_PCT: float = 0.02
"""... or, for a sweep whose slip hardly changes (R^2 is then dominated by the scatter and says
nothing), when its RMSE is at most this, percentage points; ..."""
SWEEP_MIN_RUNS_P: float = 0.05
"""... and in either case its residuals are not ordered in too few runs of one sign: the exact
one-sided runs test (:func:`residual_runs`) gives P(so few runs) >= this (1). A curve that misses
the data systematically (above them at both ends, below in the middle) leaves long runs. The sizes
of a Gaussian sum's parameters are no gate: its terms are not physical, and a steep fall is
followed by the flank of a term of thousands of percent centred below zero load whose curve
nonetheless meets every point."""
SKID_SLIP_PCT: float = 20.0
"""Slip (%) above which a load point is gross skidding rather than rolling with creep: the
Gaussian-slope method presumes a smooth slip curve, so such points are left out of the fit (and
said so)."""
SWEEP_MIN_POINTS: int = 4
"""Load points needed for a verdict: a 1-term Gaussian has 3 parameters (gaussian.py)."""
TWO_TERM_POINTS: int = 7
"""Load points from which the 2-term Gaussian is tried too (6 parameters)."""
SWEEP_ONSET_READING: str = "first"
"""What "stable from N" means for the load sweep (:data:`ONSET_READINGS`, :data:`K1_AXIAL_LOAD`)."""


def residual_runs(residuals: FloatArray | Sequence[float]) -> tuple[int, float]:
    """Runs of one sign in ``residuals`` (in order of x; zeros left out) and the exact one-sided
    probability of so few runs or fewer for that many positive and negative values in random order
    (Wald and Wolfowitz 1940; the distribution as in Swed and Eisenhart 1943, Table 1).

    Returns:
        (number of runs, P(runs <= that)); (runs, 1.0) when one sign is missing.
    """
    r = np.asarray(residuals, dtype=np.float64)
    signs = np.sign(r[r != 0.0])
    if signs.size == 0:
        return 0, 1.0
    runs = 1 + int(np.count_nonzero(signs[1:] != signs[:-1]))
    n1, n2 = int(np.count_nonzero(signs > 0)), int(np.count_nonzero(signs < 0))
    if n1 == 0 or n2 == 0:
        return runs, 1.0
    ways = 0
    for total in range(2, runs + 1):
        k = total // 2
        if total % 2 == 0:
            ways += 2 * math.comb(n1 - 1, k - 1) * math.comb(n2 - 1, k - 1)
        else:
            ways += math.comb(n1 - 1, k - 1) * math.comb(n2 - 1, k) + math.comb(n1 - 1, k) * math.comb(n2 - 1, k - 1)
    return runs, ways / math.comb(n1 + n2, n1)


@dataclass(frozen=True)
class LoadSweepVerdict:
    """The paper's verdict on one speed's load sweep (section 4.1; docs/method.md).

    Attributes:
        inner_ring_speed: mean spindle speed of the sweep's points, rad/s.
        loads: the fitted load points' measured axial loads, N, increasing.
        slips: the settled slip of each of them, percent.
        critical_slope: k1, percent per newton.
        stable_from: the load where the fitted slope reaches k1 by :data:`SWEEP_ONSET_READING`, N
            (None: no stable state).
        onset: the same load by the other reading ("last": from where the slope stays at or
            above k1), N (None without).
        n_terms / r_square / rmse / sse: the kept Gaussian fit's (0 / NaN without a fit).
        runs / runs_p: runs of one sign in its residuals and P(so few) (0 / NaN without a fit).
        slope_at_end: fitted slope at the last load, %/N (NaN without a fit).
        reason: why there is no "stable from" (empty when there is one).
        left_out: the points left out of the fit and why (empty when none).
    """

    inner_ring_speed: float
    loads: tuple[float, ...]
    slips: tuple[float, ...]
    critical_slope: float
    stable_from: float | None
    onset: float | None
    n_terms: int
    r_square: float
    rmse: float
    sse: float
    slope_at_end: float
    reason: str
    left_out: str = ""
    runs: int = 0
    runs_p: float = math.nan

    @property
    def fitted(self) -> bool:
        """Whether a Gaussian fit passed the quality gates."""
        return self.n_terms > 0

    def describe(self) -> str:
        """One line: "stable from 308 N (2-term Gaussian, R^2 0.9999, RMSE 0.023 %, 5 runs, 7
        loads)" or "no stable state: <reason>"."""
        quality = ""
        if self.fitted:
            quality = f"{self.n_terms}-term Gaussian, R^2 {self.r_square:.4f}, RMSE {self.rmse:.3g} %, {self.runs} residual runs, {len(self.loads)} loads"
            if self.left_out:
                quality += f"; {self.left_out}"
        if self.stable_from is not None:
            return f"stable from {self.stable_from:.0f} N ({quality})"
        return f"no stable state: {self.reason}" + (f" ({quality})" if quality else "")


def fit_accepted(fit: GaussianFit) -> bool:
    """The gates of a slip-against-load fit, its quality where the data are: R^2 >=
    :data:`SWEEP_MIN_R_SQUARE` with RMSE <= :data:`SWEEP_MAX_RMSE_PCT`, or RMSE <=
    :data:`SWEEP_FLAT_RMSE_PCT` (a flat sweep); and residual runs not improbably few
    (:data:`SWEEP_MIN_RUNS_P`)."""
    return not fit_problem(fit)


def fit_problem(fit: GaussianFit) -> str:
    """Why a slip-against-load fit fails the gates of :func:`fit_accepted` ("" if it passes)."""
    runs, p = residual_runs(fit.residuals)
    if p < SWEEP_MIN_RUNS_P:
        return f"{runs} runs of one sign in {fit.n_points} residuals (P {p:.3f} < {SWEEP_MIN_RUNS_P}): the curve misses the points systematically"
    if fit.rmse <= SWEEP_FLAT_RMSE_PCT:
        return ""
    if math.isfinite(fit.r_square) and fit.r_square >= SWEEP_MIN_R_SQUARE and fit.rmse <= SWEEP_MAX_RMSE_PCT:
        return ""
    return (
        f"R^2 {fit.r_square:.4f}, RMSE {fit.rmse:.3g} %: needs R^2 >= {SWEEP_MIN_R_SQUARE} with RMSE <= {SWEEP_MAX_RMSE_PCT} % "
        f"or RMSE <= {SWEEP_FLAT_RMSE_PCT} %"
    )


def load_sweep_verdict(
    loads: FloatArray | Sequence[float],
    slips: FloatArray | Sequence[float],
    critical_slope: float,
    inner_ring_speed: float = math.nan,
    skid_slip_pct: float = SKID_SLIP_PCT,
    reading: str = SWEEP_ONSET_READING,
) -> LoadSweepVerdict:
    """The paper's method on one speed's load points (docs/paper.md section 7): fit the Gaussian
    sum to slip against load (1 term, and 2 terms from :data:`TWO_TERM_POINTS` points, the better
    kept by :func:`~bearing_rig_sim.analysis.gaussian.select_gaussian_fit`), accept it only
    through the quality gates (:func:`fit_accepted`), and report the load where its slope reaches
    k1 (``reading`` "first", shipped) or from which it stays there ("last"),
    :func:`stable_onset`. Never raises on data: a sweep that cannot be judged gets a ``reason``.

    Args:
        loads: measured axial load of each point, N (sorted here).
        slips: settled slip of each point, percent.
        critical_slope: k1, %/N (:data:`K1_AXIAL_LOAD` shipped).
        inner_ring_speed: the sweep's spindle speed, rad/s (carried along).
        skid_slip_pct: points slipping more are left out (:data:`SKID_SLIP_PCT`), percent.
        reading: one of :data:`ONSET_READINGS`.

    Raises:
        AnalysisError: an unknown ``reading`` (a programming error, not data).
    """
    if reading not in ONSET_READINGS:
        raise AnalysisError(f"reading: must be one of {', '.join(ONSET_READINGS)}, got {reading!r}")
    other = "last" if reading == "first" else "first"
    x = np.asarray(loads, dtype=np.float64)
    y = np.asarray(slips, dtype=np.float64)
    keep = np.isfinite(x) & np.isfinite(y)
    order = np.argsort(x[keep], kind="stable")
    x, y = x[keep][order], y[keep][order]
    skid = int(np.count_nonzero(y > skid_slip_pct))
    x, y = x[y <= skid_slip_pct], y[y <= skid_slip_pct]
    left_out = f"; {skid} load point(s) above {skid_slip_pct:g} % slip (skidding) left out" if skid else ""

    def verdict(reason: str, fit: GaussianFit | None = None, result: StabilityResult | None = None) -> LoadSweepVerdict:
        accepted = result is not None
        runs, runs_p = residual_runs(fit.residuals) if fit is not None else (0, math.nan)
        return LoadSweepVerdict(
            inner_ring_speed=inner_ring_speed,
            loads=tuple(x.tolist()),
            slips=tuple(y.tolist()),
            critical_slope=critical_slope,
            stable_from=result.onset_by(reading) if result is not None else None,
            onset=result.onset_by(other) if result is not None else None,
            n_terms=fit.n_terms if fit is not None and accepted else 0,
            r_square=fit.r_square if fit is not None else math.nan,
            rmse=fit.rmse if fit is not None else math.nan,
            sse=fit.sse if fit is not None else math.nan,
            slope_at_end=float(fit.slope(float(x[-1]))) if fit is not None and accepted else math.nan,
            reason=reason + (left_out if fit is None else "") if reason else "",
            left_out=left_out.removeprefix("; "),
            runs=runs,
            runs_p=runs_p,
        )

    distinct = np.unique(x).size
    if distinct < SWEEP_MIN_POINTS:
        return verdict(f"{distinct} distinct load point(s), a Gaussian fit needs {SWEEP_MIN_POINTS}")
    try:
        fit, _ = select_gaussian_fit(x, y, max_terms=2 if x.size >= TWO_TERM_POINTS else 1)
    except AnalysisError as exc:
        return verdict(f"no Gaussian fit: {exc}")
    problem = fit_problem(fit)
    if problem:
        return verdict(f"the Gaussian fit fails the gates ({problem})", fit)
    result = stable_onset(fit, float(x[0]), float(x[-1]), critical_slope)
    if result.onset_by(reading) is None:
        if reading == "first":
            highest = float(np.max(slope_function(fit, 1.0)(np.linspace(x[0], x[-1], 2001))))
            why = f"the fitted slope stays below k1 = {critical_slope:.3g} %/N (at most {highest:.3g} %/N)"
        else:
            why = f"the fitted slope at {x[-1]:.0f} N is {result.slope_at_end:.3g} %/N, below k1 = {critical_slope:.3g} %/N"
        return verdict(why, fit, result)
    return verdict("", fit, result)
