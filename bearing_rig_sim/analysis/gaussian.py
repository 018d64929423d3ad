"""Sums of Gaussian terms fitted to slip data (paper section 2.2, docs/paper.md section 7).

The model, with ``params`` an (n_terms, 3) array of rows (a, b, c)::

    y(x) = sum_k a_k exp(-((x - b_k) / c_k)^2),      c_k > 0

y is the slip rate in percent and x the axial load (N) or the time (s); a is then in percent, b
and c in the unit of x, and the slope dy/dx in percent per unit of x.

The paper calls its fit "linear fitting" in places; it is a nonlinear least-squares fit, done
here with :func:`scipy.optimize.least_squares` (trust-region reflective, analytic Jacobian,
bounds: c > 0, and at least the median spacing of the x values, see below) from a fixed set of
data-driven starting points, so that it is deterministic.
The quality figures are those of MATLAB's curve-fitting toolbox, which the paper's Tables 4 and
6 report: SSE, R-square = 1 - SSE/SST and RMSE = sqrt(SSE / (n - number of parameters)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, overload
from collections.abc import Sequence

import numpy as np
from scipy.optimize import least_squares

from bearing_rig_sim.analysis.inputs import (
    AnalysisError,
    FloatArray,
    finite_array,
    positive_int,
    same_length,
)

#: A fit with more terms is kept only if its RMSE is lower than that of the best fit with fewer
#: terms by more than this fraction (see :func:`choose_term_count`).
MIN_RMSE_IMPROVEMENT: float = 0.10

# Bounds of the fit, in coordinates normalised so that the data span x in [0, 1] and max|y| = 1.
# Centres may lie 5 spans outside the data (the paper's time fits centre before t = 0), widths range
# from the median spacing of the x values (at least a thousandth of the span) to 10 spans, and
# amplitudes reach 1000 times the data. A term narrower than the spacing of the points fits one
# point, that is the noise; the other bounds keep the optimiser away from the degenerate tails
# (a -> infinity with b -> -infinity).
_B_BOUND = 5.0
_C_MIN, _C_MAX = 1e-3, 10.0
_A_BOUND = 1e3
# Evaluation budgets (per term) of the screening run of every start and of the final run.
_SCREEN_NFEV, _POLISH_NFEV = 25, 200


# -- the model -----------------------------------------------------------------------------------
def gaussian_params(params: Any) -> FloatArray:
    """``params`` checked and returned as an (n_terms, 3) float64 array of rows (a, b, c).

    Raises:
        AnalysisError: wrong shape, non-finite entries or a width c <= 0.
    """
    try:
        p = np.asarray(params, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise AnalysisError(f"params: must be real numbers ({exc})") from None
    if p.ndim == 1 and p.size % 3 == 0:
        p = p.reshape(-1, 3)
    if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 1:
        raise AnalysisError(f"params: must have shape (n_terms, 3) with rows (a, b, c), got shape {p.shape}")
    if not np.all(np.isfinite(p)):
        raise AnalysisError("params: contains a non-finite value")
    if not np.all(p[:, 2] > 0.0):
        raise AnalysisError(f"params: every width c must be > 0, got {p[:, 2].tolist()}")
    return p


def _terms(x: FloatArray, p: FloatArray) -> tuple[FloatArray, FloatArray]:
    """u = (x - b)/c and exp(-u^2), shape (n_terms, len(x))."""
    u = (x[None, :] - p[:, 1:2]) / p[:, 2:3]
    return u, np.exp(-(u * u))


def _value(x: FloatArray, p: FloatArray) -> FloatArray:
    _, e = _terms(x, p)
    return p[:, 0] @ e


def _slope(x: FloatArray, p: FloatArray) -> FloatArray:
    u, e = _terms(x, p)
    return (p[:, 0] / p[:, 2]) @ (-2.0 * u * e)


def _jacobian(x: FloatArray, p: FloatArray) -> FloatArray:
    """d y / d(a_1, b_1, c_1, a_2, ...), shape (len(x), 3 n_terms)."""
    u, e = _terms(x, p)
    a, c = p[:, 0:1], p[:, 2:3]
    jac = np.empty((x.size, p.size))
    jac[:, 0::3] = e.T
    jac[:, 1::3] = (2.0 * a * u * e / c).T
    jac[:, 2::3] = (2.0 * a * u * u * e / c).T
    return jac


def _slope_gradient(x: FloatArray, p: FloatArray) -> FloatArray:
    """d slope / d(a_1, b_1, c_1, ...), shape (len(x), 3 n_terms)."""
    u, e = _terms(x, p)
    a, c = p[:, 0:1], p[:, 2:3]
    grad = np.empty((x.size, p.size))
    grad[:, 0::3] = (-2.0 * u * e / c).T
    grad[:, 1::3] = (2.0 * a * e * (1.0 - 2.0 * u * u) / c**2).T
    grad[:, 2::3] = (4.0 * a * u * e * (1.0 - u * u) / c**2).T
    return grad


@overload
def gaussian_sum(x: float, params: Any) -> float: ...
@overload
def gaussian_sum(x: FloatArray | Sequence[float], params: Any) -> FloatArray: ...
def gaussian_sum(x: float | FloatArray | Sequence[float], params: Any) -> float | FloatArray:
    """y(x) = sum_k a_k exp(-((x - b_k)/c_k)^2), in the unit of a (percent for slip).

    Args:
        x: abscissa (N or s), scalar or 1-D array.
        params: (n_terms, 3) rows (a, b, c), c > 0.

    Raises:
        AnalysisError: non-finite x or bad params.
    """
    p = gaussian_params(params)
    xs = finite_array("x", x)
    y = _value(xs, p)
    return float(y[0]) if np.ndim(x) == 0 else y


@overload
def gaussian_sum_derivative(x: float, params: Any) -> float: ...
@overload
def gaussian_sum_derivative(x: FloatArray | Sequence[float], params: Any) -> FloatArray: ...
def gaussian_sum_derivative(x: float | FloatArray | Sequence[float], params: Any) -> float | FloatArray:
    """dy/dx = sum_k -2 a_k (x - b_k)/c_k^2 exp(-((x - b_k)/c_k)^2), in unit of a per unit of x
    (percent per N or per s for slip).

    Raises:
        AnalysisError: non-finite x or bad params.
    """
    p = gaussian_params(params)
    xs = finite_array("x", x)
    s = _slope(xs, p)
    return float(s[0]) if np.ndim(x) == 0 else s


# -- the fit -------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class GaussianFit:
    """A least-squares sum of Gaussians and its quality, as MATLAB's curve-fitting toolbox reports.

    Attributes:
        params: (n_terms, 3) rows (a, b, c) sorted by centre b; a in the unit of y (percent),
            b and c in the unit of x (N or s).
        n_terms: number of Gaussian terms.
        sse: sum of squared residuals, unit of y squared.
        r_square: 1 - SSE/SST with SST = sum (y - mean y)^2; NaN if SST = 0 (constant data).
        rmse: sqrt(SSE / dof), the residual standard error, unit of y.
        dof: n - 3 n_terms, the residual degrees of freedom (>= 1).
        n_points: number of data points fitted.
        x_range: (smallest, largest) x of the data, unit of x.
        covariance: (3 n_terms, 3 n_terms) estimated covariance of the parameters in the order
            (a_1, b_1, c_1, a_2, ...): rmse^2 (J^T J)^-1 at the optimum, J the Jacobian of the
            model. Entries are inf or nan where J is singular (parameter combinations the data
            do not determine, e.g. a term far from every point).
        residuals: y - fit at each data point, in increasing order of x (ties in the data's
            order), unit of y: their pattern (runs of one sign) says whether the curve follows
            the data or only passes near them.
    """

    params: FloatArray
    n_terms: int
    sse: float
    r_square: float
    rmse: float
    dof: int
    n_points: int
    x_range: tuple[float, float]
    covariance: FloatArray = field(repr=False)
    residuals: FloatArray = field(repr=False)
    _directions: FloatArray = field(repr=False)  # rows rmse v_i / s_i from the SVD of J

    @overload
    def __call__(self, x: float) -> float: ...
    @overload
    def __call__(self, x: FloatArray | Sequence[float]) -> FloatArray: ...
    def __call__(self, x: float | FloatArray | Sequence[float]) -> float | FloatArray:
        """Fitted y at x (percent for slip)."""
        return gaussian_sum(x, self.params)

    @overload
    def slope(self, x: float) -> float: ...
    @overload
    def slope(self, x: FloatArray | Sequence[float]) -> FloatArray: ...
    def slope(self, x: float | FloatArray | Sequence[float]) -> float | FloatArray:
        """dy/dx of the fitted curve at x (percent per N or per s for slip)."""
        return gaussian_sum_derivative(x, self.params)

    @overload
    def slope_standard_error(self, x: float) -> float: ...
    @overload
    def slope_standard_error(self, x: FloatArray | Sequence[float]) -> FloatArray: ...
    def slope_standard_error(self, x: float | FloatArray | Sequence[float]) -> float | FloatArray:
        """Standard error of :meth:`slope` at x from the parameter covariance (delta method),
        same unit as the slope; inf where the slope depends on parameters the data do not
        determine."""
        xs = finite_array("x", x)
        g = _slope_gradient(xs, self.params)
        with np.errstate(invalid="ignore", over="ignore"):
            proj = g @ self._directions.T
        proj[np.isnan(proj)] = np.inf  # inf times a zero component of g
        se = np.sqrt(np.sum(proj * proj, axis=1))
        return float(se[0]) if np.ndim(x) == 0 else se


def fit_gaussians(
    x: FloatArray | Sequence[float],
    y: FloatArray | Sequence[float],
    n_terms: int,
    *,
    starts: Sequence[Any] = (),
    multistart: bool = True,
) -> GaussianFit:
    """Fit a sum of ``n_terms`` Gaussians to (x, y) by nonlinear least squares.

    The data are normalised (x to [0, 1], y to max|y| = 1) and the fit is run from each of a fixed
    set of starting points; the one with the lowest SSE wins. The starting points are: the
    caller's ``starts``; "peeling" (a term on the largest residual, its width from the half-height
    run around it, subtracted, repeated); and, with ``multistart``, terms spread evenly over the
    data, terms centred at the larger end of the data with narrow and wide widths, a term centred
    half a span outside it (a decay whose peak lies before the data, as in the paper's Table 7),
    and for n_terms >= 2 the best (n_terms - 1)-term fit plus one new term (on the largest
    residual, and with zero amplitude: so that adding a term never raises the SSE).

    Args:
        x: abscissa, N or s; at least 3 n_terms + 1 distinct finite values.
        y: slip, percent (any unit), same length as x.
        n_terms: number of Gaussian terms, >= 1.
        starts: extra starting points, each (n_terms, 3) rows (a, b, c) in the data's units (e.g.
            the previous fit when refitting a growing series).
        multistart: False, with ``starts`` given, is a warm refit of a growing series: one run
            per start, of at most 25 evaluations per term, and no polishing run (the result may
            be short of convergence; the next warm refit continues from it). Without ``starts``
            it tries the peeling start (and the (n_terms - 1)-term based ones when
            :func:`select_gaussian_fit` has that fit).

    Raises:
        AnalysisError: non-finite, mismatched or too few data, x all equal, bad n_terms/starts.
    """
    return _fit(*_fit_data(x, y, positive_int("n_terms", n_terms)), n_terms, starts, multistart, None)


def _fit_data(x: Any, y: Any, n_terms: int) -> tuple[FloatArray, FloatArray]:
    xs = finite_array("x", x)
    ys = finite_array("y", y)
    same_length(x=xs, y=ys)
    need = 3 * n_terms + 1
    if xs.size < need:
        raise AnalysisError(f"x, y: a {n_terms}-term Gaussian fit needs at least {need} points, got {xs.size}")
    if not np.ptp(xs) > 0.0:
        raise AnalysisError(f"x: all {xs.size} values are equal ({xs[0]!r}); nothing to fit against")
    return xs, ys


def _fit(
    x: FloatArray,
    y: FloatArray,
    n_terms: int,
    starts: Sequence[Any],
    multistart: bool,
    fewer: GaussianFit | None,
) -> GaussianFit:
    x0, sx = float(x.min()), float(np.ptp(x))
    sy = float(np.max(np.abs(y))) or 1.0
    z, w = (x - x0) / sx, y / sy

    def to_norm(p: FloatArray) -> FloatArray:
        return np.column_stack([p[:, 0] / sy, (p[:, 1] - x0) / sx, p[:, 2] / sx])

    candidates = [to_norm(gaussian_params(s)) for s in starts]
    for s in candidates:
        if s.shape[0] != n_terms:
            raise AnalysisError(f"starts: each start must have {n_terms} rows, got {s.shape[0]}")
    warm = bool(candidates) and not multistart
    if not warm:
        candidates.append(_peel(z, w, np.zeros((0, 3)), n_terms))
    if multistart:
        candidates += _spread_starts(z, w, n_terms)
        if n_terms >= 2 and fewer is None:
            fewer = _fit(x, y, n_terms - 1, (), True, None)
    if fewer is not None and not warm:
        base = to_norm(fewer.params)
        candidates.append(_peel(z, w, base, 1))
        candidates.append(np.vstack([base, [0.0, 0.5, 0.5]]))

    c_min = max(_C_MIN, float(np.median(np.diff(np.sort(z)))))
    lower = np.tile([-_A_BOUND, -_B_BOUND, c_min], n_terms)
    upper = np.tile([_A_BOUND, 1.0 + _B_BOUND, _C_MAX], n_terms)

    def solve(p0: FloatArray, max_nfev: int) -> Any:
        return least_squares(
            lambda q: _value(z, q.reshape(-1, 3)) - w,
            np.clip(p0, lower + 1e-9, upper - 1e-9),
            jac=lambda q: _jacobian(z, q.reshape(-1, 3)),
            bounds=(lower, upper),
            method="trf",
            x_scale="jac",
            max_nfev=max_nfev,
        )

    # Every start gets a short run; the best continues to convergence (a start crawling along a
    # degenerate valley towards a bound would otherwise cost hundreds of evaluations).
    # A warm refit gets the short run only: if it has not converged, the next refit of the growing
    # series continues from where it stopped, which bounds the cost of each refit.
    screened = [solve(start.ravel(), _SCREEN_NFEV * n_terms) for start in candidates]
    best = min(screened, key=lambda r: r.cost)
    if best.status == 0 and not warm:  # evaluation budget exhausted, not converged
        best = solve(best.x, _POLISH_NFEV * n_terms)
    pn = best.x.reshape(-1, 3)
    params = np.column_stack([pn[:, 0] * sy, x0 + pn[:, 1] * sx, pn[:, 2] * sx])
    params = params[np.argsort(params[:, 1], kind="stable")]
    return _summary(x, y, params)


def _summary(x: FloatArray, y: FloatArray, params: FloatArray) -> GaussianFit:
    resid = y - _value(x, params)
    in_order = resid[np.argsort(x, kind="stable")]
    sse = float(resid @ resid)
    sst = float(np.sum((y - y.mean()) ** 2))
    dof = x.size - params.size
    rmse = math.sqrt(sse / dof)
    jac = _jacobian(x, params)
    _, sv, vt = np.linalg.svd(jac, full_matrices=False)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        directions = rmse * vt / sv[:, None]
        cov = directions.T @ directions
    directions[np.isnan(directions)] = np.inf  # a zero singular value with rmse = 0
    for arr in (params, cov, directions, in_order):
        arr.setflags(write=False)
    return GaussianFit(
        params=params,
        n_terms=params.shape[0],
        sse=sse,
        r_square=1.0 - sse / sst if sst > 0.0 else math.nan,
        rmse=rmse,
        dof=dof,
        n_points=x.size,
        x_range=(float(x.min()), float(x.max())),
        covariance=cov,
        residuals=in_order,
        _directions=directions,
    )


def _half_width(z: FloatArray, r: FloatArray, i: int) -> float:
    """Width c of a Gaussian matching the run of |r| >= |r[i]|/2 around index i (z sorted)."""
    half = abs(r[i]) / 2.0
    lo, hi = i, i
    while lo > 0 and abs(r[lo - 1]) >= half:
        lo -= 1
    while hi < z.size - 1 and abs(r[hi + 1]) >= half:
        hi += 1
    run = max(z[hi] - z[i], z[i] - z[lo])  # one-sided when the peak is at an end of the data
    return max(run / math.sqrt(math.log(2.0)), 2.0 / z.size, _C_MIN * 10)


def _peel(z: FloatArray, w: FloatArray, base: FloatArray, n_new: int) -> FloatArray:
    """``base`` plus ``n_new`` terms, each put on the largest residual and subtracted."""
    order = np.argsort(z, kind="stable")
    zs, resid = z[order], w[order] - (_value(z, base)[order] if base.size else 0.0)
    rows = [row for row in base]
    for _ in range(n_new):
        i = int(np.argmax(np.abs(resid)))
        a, b, c = float(resid[i]), float(zs[i]), _half_width(zs, resid, i)
        rows.append(np.array([a, b, c]))
        resid = resid - a * np.exp(-(((zs - b) / c) ** 2))
    return np.array(rows)


def _spread_starts(z: FloatArray, w: FloatArray, n_terms: int) -> list[FloatArray]:
    """Fixed, data-driven starting points (normalised coordinates)."""
    order = np.argsort(z, kind="stable")
    zs, ws = z[order], w[order]

    def at(b: float) -> float:
        return float(np.interp(b, zs, ws))

    centres = (np.arange(n_terms) + 0.5) / n_terms
    spread = np.array([[at(b), b, 1.0 / n_terms] for b in centres])
    peak_end = 0.0 if abs(ws[0]) >= abs(ws[-1]) else 1.0
    outside = -0.5 if peak_end == 0.0 else 1.5
    starts = [spread]
    for b, c in ((peak_end, 0.3), (peak_end, 1.0), (outside, 1.0)):
        first = np.array([[at(peak_end) / math.exp(-(((peak_end - b) / c) ** 2)), b, c]])
        rest = spread[: n_terms - 1].copy()
        rest[:, 0] *= 0.5
        starts.append(np.vstack([first, rest]) if n_terms > 1 else first)
    return starts


# -- choosing the number of terms ----------------------------------------------------------------
def choose_term_count(rmse: Sequence[float], min_improvement: float = MIN_RMSE_IMPROVEMENT) -> int:
    """Number of terms to keep given the RMSE of the 1-, 2-, ... term fits (paper Tables 4, 6).

    Rule: the paper's, lowest RMSE, with a margin. Start from 1 term; a fit with more terms
    replaces the kept one only if its RMSE is lower by more than the fraction ``min_improvement``
    (default 10 %); ties go to fewer terms. With the paper's own figures this gives its choices:
    Table 4 (RMSE 0.045 -> 0.040, 11 % lower) keeps 2 terms, Table 6 (0.0048 -> 0.0098) keeps 1.

    RMSE divides the SSE by the degrees of freedom, so it charges each term its three parameters,
    but not the search over where to put the extra term: on noisy 1-term data the 2-term fit finds
    the best-placed cluster of noise. Measured on the Table 7 curve with 0.01 % noise, 40-100 seeds
    per size, the 2-term RMSE was more than 10 % lower in about 45 % of the cases with 14 points,
    20 % with 30, 2.5 % with 60 and never with 100 or 150 (more than 5 % lower: 60 %, 60 %, 33 %,
    5 %, 2 %). With few points a second term is therefore weak evidence; a stricter margin costs
    agreement with the paper's Table 4.

    Args:
        rmse: RMSE of the fits with 1, 2, ... terms, in order, finite and >= 0.
        min_improvement: required relative reduction, in [0, 1).

    Returns:
        The number of terms, 1-based.

    Raises:
        AnalysisError: empty or non-finite rmse, or min_improvement out of range.
    """
    values = finite_array("rmse", rmse)
    if np.any(values < 0.0):
        raise AnalysisError(f"rmse: must be >= 0, got {values.tolist()}")
    if not 0.0 <= min_improvement < 1.0:
        raise AnalysisError(f"min_improvement: must be in [0, 1), got {min_improvement!r}")
    best = 0
    for i in range(1, values.size):
        if values[i] < values[best] * (1.0 - min_improvement):
            best = i
    return best + 1


def select_gaussian_fit(
    x: FloatArray | Sequence[float],
    y: FloatArray | Sequence[float],
    max_terms: int = 2,
    *,
    min_improvement: float = MIN_RMSE_IMPROVEMENT,
    starts: dict[int, Any] | None = None,
    multistart: bool = True,
) -> tuple[GaussianFit, list[GaussianFit]]:
    """Fit 1..max_terms Gaussian terms and keep one by :func:`choose_term_count`.

    Each fit with k >= 2 terms starts, among others, from the kept (k - 1)-term fit (see
    :func:`fit_gaussians`).

    Args:
        x: abscissa, N or s; at least 3 max_terms + 1 points.
        y: slip, percent.
        max_terms: the most terms tried, >= 1.
        min_improvement: see :func:`choose_term_count`.
        starts: optional extra starting points per term count, {k: (k, 3) array}.
        multistart: see :func:`fit_gaussians`.

    Returns:
        (the chosen fit, all fits in order of term count).

    Raises:
        AnalysisError: as :func:`fit_gaussians`.
    """
    max_terms = positive_int("max_terms", max_terms)
    xs, ys = _fit_data(x, y, max_terms)
    starts = starts or {}
    fits: list[GaussianFit] = []
    for k in range(1, max_terms + 1):
        extra = [starts[k]] if k in starts else []
        fits.append(_fit(xs, ys, k, extra, multistart, fits[-1] if fits else None))
    chosen = choose_term_count([f.rmse for f in fits], min_improvement)
    return fits[chosen - 1], fits
