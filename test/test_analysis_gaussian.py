"""Gaussian-sum model and its least-squares fit.

The reference model, its Jacobian (by central differences) and the parameter standard errors
expected from the noise level, sigma sqrt(diag((J^T J)^-1)) at the true parameters, are computed
here independently of the module. Data are synthetic with fixed seeds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.analysis import AnalysisError
from bearing_rig_sim.analysis.gaussian import (
    GaussianFit,
    choose_term_count,
    fit_gaussians,
    gaussian_params,
    gaussian_sum,
    gaussian_sum_derivative,
    select_gaussian_fit,
)

# paper Table 7, 20 rad/s^2: slip (%) against time (s), one term
TABLE7_20 = np.array([[3.5, -1.52, 1.29]])
# paper Table 5, 1000 rpm (the one readable row, docs/paper.md section 10): slip (%) against load (N)
TABLE5_1000 = np.array([[5.18, -4.14, 214.0], [2.05, 530.0, 469.0]])
# two separated peaks
TWO_PEAKS = np.array([[2.0, 3.0, 1.0], [1.2, 7.0, 1.5]])


def model(x: np.ndarray, p: np.ndarray) -> np.ndarray:
    y = np.zeros_like(x, dtype=float)
    for a, b, c in np.reshape(p, (-1, 3)):
        y += a * np.exp(-(((x - b) / c) ** 2))
    return y


def numeric_jacobian(x: np.ndarray, p: np.ndarray) -> np.ndarray:
    flat = np.ravel(p).astype(float)
    cols = []
    for j in range(flat.size):
        h = 1e-6 * max(1.0, abs(flat[j]))
        up, down = flat.copy(), flat.copy()
        up[j] += h
        down[j] -= h
        cols.append((model(x, up) - model(x, down)) / (2.0 * h))
    return np.column_stack(cols)


def expected_standard_errors(x: np.ndarray, p: np.ndarray, sigma: float) -> np.ndarray:
    jac = numeric_jacobian(x, p)
    return sigma * np.sqrt(np.diag(np.linalg.inv(jac.T @ jac))).reshape(-1, 3)


# -- the model -------------------------------------------------------------------------------------
def test_gaussian_sum_values() -> None:
    p = np.array([[2.0, 1.0, 0.5]])
    assert gaussian_sum(1.0, p) == pytest.approx(2.0, rel=1e-15)
    np.testing.assert_allclose(gaussian_sum(np.array([0.5, 1.5]), p), 2.0 / math.e, rtol=1e-15)
    x = np.linspace(-3.0, 12.0, 41)
    np.testing.assert_allclose(gaussian_sum(x, TWO_PEAKS), model(x, TWO_PEAKS), rtol=1e-14)
    # flat (a, b, c, a, b, c) is accepted as well
    np.testing.assert_allclose(gaussian_sum(x, TWO_PEAKS.ravel()), model(x, TWO_PEAKS), rtol=1e-14)


def test_gaussian_sum_derivative_matches_differences() -> None:
    x = np.linspace(0.0, 700.0, 57)
    h = 1e-3
    numeric = (model(x + h, TABLE5_1000) - model(x - h, TABLE5_1000)) / (2 * h)
    np.testing.assert_allclose(gaussian_sum_derivative(x, TABLE5_1000), numeric, rtol=1e-6, atol=1e-12)
    # zero slope at the centre of a single term, odd about it
    p = np.array([[1.0, 2.0, 0.7]])
    assert gaussian_sum_derivative(2.0, p) == 0.0
    assert gaussian_sum_derivative(2.3, p) == pytest.approx(-gaussian_sum_derivative(1.7, p), rel=1e-12)


@pytest.mark.parametrize(
    ("params", "message"),
    [
        (np.zeros((2, 2)), r"shape \(n_terms, 3\)"),
        (np.zeros((0, 3)), r"shape \(n_terms, 3\)"),
        ([[1.0, 0.0, 0.0]], r"every width c must be > 0"),
        ([[1.0, 0.0, -1.0]], r"every width c must be > 0"),
        ([[np.nan, 0.0, 1.0]], "non-finite"),
    ],
)
def test_bad_params(params: object, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        gaussian_params(params)
    with pytest.raises(AnalysisError):
        gaussian_sum(1.0, params)


# -- recovering known parameters -----------------------------------------------------------------
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(
    ("true", "x", "sigma"),
    [(TABLE7_20, np.linspace(0.0, 3.0, 200), 0.01), (TWO_PEAKS, np.linspace(0.0, 10.0, 150), 0.02)],
    ids=["1-term Table 7", "2-term peaks"],
)
def test_fit_recovers_known_parameters(true: np.ndarray, x: np.ndarray, sigma: float, seed: int) -> None:
    y = model(x, true) + np.random.default_rng(seed).normal(0.0, sigma, x.size)
    fit = fit_gaussians(x, y, true.shape[0])
    se = expected_standard_errors(x, true, sigma)
    assert np.all(np.abs(fit.params - true) < 4.0 * se), (fit.params, se)
    assert fit.rmse == pytest.approx(sigma, rel=0.2)
    assert fit.r_square > 1.0 - 1.3 * x.size * sigma**2 / np.sum((y - y.mean()) ** 2)
    # the reported covariance agrees with the noise-level standard errors
    reported = np.sqrt(np.diag(fit.covariance)).reshape(-1, 3)
    np.testing.assert_allclose(reported, se, rtol=0.25)


def test_noise_free_fits_are_exact() -> None:
    t = np.linspace(0.0, 3.0, 60)
    np.testing.assert_allclose(fit_gaussians(t, model(t, TABLE7_20), 1).params, TABLE7_20, rtol=1e-6)
    x = np.linspace(0.0, 10.0, 80)
    np.testing.assert_allclose(fit_gaussians(x, model(x, TWO_PEAKS), 2).params, TWO_PEAKS, rtol=1e-6)
    load = np.linspace(50.0, 700.0, 40)
    exact = fit_gaussians(load, model(load, TABLE5_1000), 2)
    assert exact.rmse < 1e-6  # the curve is reproduced, even where its parameters trade off


def test_quality_figures_follow_their_definitions() -> None:
    x = np.linspace(50.0, 700.0, 14)
    y = model(x, TABLE5_1000) + np.random.default_rng(7).normal(0.0, 0.03, x.size)
    for n_terms in (1, 2):
        fit = fit_gaussians(x, y, n_terms)
        resid = y - model(x, fit.params)
        sse = float(resid @ resid)
        assert fit.sse == pytest.approx(sse, rel=1e-12)
        assert fit.dof == 14 - 3 * n_terms and fit.n_points == 14
        assert fit.rmse == pytest.approx(math.sqrt(sse / (14 - 3 * n_terms)), rel=1e-12)
        assert fit.r_square == pytest.approx(1.0 - sse / float(np.sum((y - y.mean()) ** 2)), rel=1e-12)
        assert fit.x_range == (50.0, 700.0)
        np.testing.assert_allclose(fit(x), model(x, fit.params), rtol=1e-13)


def test_more_terms_never_raise_the_sse() -> None:
    x = np.linspace(50.0, 700.0, 30)
    for seed in range(3):
        y = model(x, TABLE5_1000) + np.random.default_rng(seed).normal(0.0, 0.05, x.size)
        _, fits = select_gaussian_fit(x, y, 3)
        assert fits[1].sse <= fits[0].sse * (1 + 1e-9)
        assert fits[2].sse <= fits[1].sse * (1 + 1e-9)


def test_fit_slope_and_its_standard_error() -> None:
    t = np.linspace(0.0, 3.0, 120)
    y = model(t, TABLE7_20) + np.random.default_rng(3).normal(0.0, 0.01, t.size)
    fit = fit_gaussians(t, y, 1)
    h = 1e-6
    np.testing.assert_allclose(fit.slope(t), (fit(t + h) - fit(t - h)) / (2 * h), rtol=1e-5, atol=1e-9)
    # delta method, with the slope's parameter gradient by differences here
    at = 1.7

    def slope_of(p: np.ndarray) -> float:
        return float((model(np.array([at + h]), p) - model(np.array([at - h]), p))[0] / (2 * h))

    grad = np.array([(slope_of(fit.params.ravel() + e * 1e-5) - slope_of(fit.params.ravel() - e * 1e-5)) / 2e-5 for e in np.eye(3)])
    expected = math.sqrt(grad @ fit.covariance @ grad)
    assert fit.slope_standard_error(at) == pytest.approx(expected, rel=1e-3)


def test_fit_is_deterministic_and_accepts_a_warm_start() -> None:
    t = np.linspace(0.0, 3.0, 100)
    y = model(t, TABLE7_20) + np.random.default_rng(4).normal(0.0, 0.01, t.size)
    a, b = fit_gaussians(t, y, 1), fit_gaussians(t, y, 1)
    np.testing.assert_array_equal(a.params, b.params)
    warm = fit_gaussians(t, y, 1, starts=[a.params], multistart=False)
    assert warm.sse == pytest.approx(a.sse, rel=1e-9)


@pytest.mark.parametrize(
    ("x", "y", "n_terms", "message"),
    [
        (np.arange(6.0), np.ones(6), 2, r"a 2-term Gaussian fit needs at least 7 points, got 6"),
        (np.arange(8.0), np.ones(7), 1, r"lengths differ: x has 8, y has 7"),
        (np.arange(8.0), np.r_[np.ones(7), np.nan], 1, r"y: non-finite value nan at index 7"),
        (np.ones(8), np.arange(8.0), 1, r"x: all 8 values are equal"),
        (np.arange(8.0), np.ones(8), 0, r"n_terms: must be an integer >= 1"),
        (np.array([]), np.array([]), 1, r"x: needs at least 1 value\(s\), got empty"),
    ],
)
def test_fit_bad_input(x: np.ndarray, y: np.ndarray, n_terms: int, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        fit_gaussians(x, y, n_terms)


def test_fit_rejects_a_start_of_the_wrong_size() -> None:
    x = np.arange(10.0)
    with pytest.raises(AnalysisError, match="starts: each start must have 2 rows, got 1"):
        fit_gaussians(x, np.exp(-x), 2, starts=[[[1.0, 0.0, 1.0]]])


# -- choosing the number of terms ------------------------------------------------------------------
def test_term_count_rule_gives_the_papers_choices() -> None:
    assert choose_term_count([0.045, 0.040]) == 2  # Table 4: slip against load, 2 terms kept
    assert choose_term_count([0.0048, 0.0098]) == 1  # Table 6: slip against time, 1 term kept


def test_term_count_rule_margin_and_ties() -> None:
    assert choose_term_count([1.0, 1.0]) == 1
    assert choose_term_count([1.0, 0.91]) == 1  # within the 10 % margin
    assert choose_term_count([1.0, 0.89]) == 2
    assert choose_term_count([1.0, 0.8, 0.75]) == 2  # the third is not 10 % below the second
    assert choose_term_count([1.0, 0.8, 0.7]) == 3
    assert choose_term_count([1.0, 0.96], min_improvement=0.0) == 2
    with pytest.raises(AnalysisError, match="min_improvement"):
        choose_term_count([1.0], min_improvement=1.0)
    with pytest.raises(AnalysisError, match="rmse: must be >= 0"):
        choose_term_count([1.0, -0.1])


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_selection_keeps_one_term_on_one_term_data(seed: int) -> None:
    # 3 s sampled every 0.03 s, like an acceleration run (the rule is weak on short series; see
    # choose_term_count)
    t = np.linspace(0.0, 3.0, 100)
    y = model(t, TABLE7_20) + np.random.default_rng(seed).normal(0.0, 0.01, t.size)
    chosen, fits = select_gaussian_fit(t, y, 2)
    assert [f.n_terms for f in fits] == [1, 2]
    assert chosen.n_terms == 1


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_selection_keeps_two_terms_on_two_term_data(seed: int) -> None:
    load = np.linspace(50.0, 700.0, 14)  # the paper's load grid
    y = model(load, TABLE5_1000) + np.random.default_rng(seed).normal(0.0, 0.03, load.size)
    chosen, fits = select_gaussian_fit(load, y, 2)
    assert chosen.n_terms == 2
    assert fits[1].rmse < 0.5 * fits[0].rmse


def test_gaussian_fit_is_frozen() -> None:
    fit = fit_gaussians(np.linspace(0, 3, 20), model(np.linspace(0, 3, 20), TABLE7_20), 1)
    assert isinstance(fit, GaussianFit)
    with pytest.raises(AttributeError):
        fit.rmse = 0.0  # type: ignore[misc]
    with pytest.raises(ValueError):
        fit.params[0, 0] = 1.0
