"""The slope criterion (paper Eq. 14) and the onset of the stable state.

For a single Gaussian y = lam exp(-((x - b)/c)^2) the slope is -2 lam (x - b)/c^2 exp(-((x - b)/c)^2);
the crossings of the critical slope are found here by a bisection of that formula, independently
of the module. The paper's own check: with Table 7's parameters and k2 = -3e-2 %/s the stable
state starts near 1.67, 1.41, 1.23 and 0.97 s (docs/paper.md section 11).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.analysis import AnalysisError
from bearing_rig_sim.analysis.gaussian import fit_gaussians
from bearing_rig_sim.analysis.stability import (
    load_sweep_verdict,
    residual_runs,
    K1_AXIAL_LOAD,
    K1_READINGS,
    K2_TIME,
    SlipState,
    classify,
    stable_onset,
    successive_slopes,
)

# paper Table 7: (acceleration rad/s^2, lambda %, k s, d s, stable onset s read from the paper's data)
TABLE7 = [
    (20, 3.5, -1.52, 1.29, 1.67),
    (40, 1.64, -0.73, 0.9, 1.41),
    (60, 1.33, -0.49, 0.72, 1.23),
    (80, 0.76, -0.09, 0.45, 0.97),
]


class OneGaussian:
    """y = lam exp(-((x - b)/c)^2) with its analytic slope, written independently of the module."""

    def __init__(self, lam: float, b: float, c: float) -> None:
        self.lam, self.b, self.c = lam, b, c

    def __call__(self, x):  # type: ignore[no-untyped-def]
        return self.lam * np.exp(-(((np.asarray(x) - self.b) / self.c) ** 2))

    def slope(self, x):  # type: ignore[no-untyped-def]
        u = (np.asarray(x) - self.b) / self.c
        return -2.0 * self.lam * u / self.c * np.exp(-u * u)


def bisect(f, lo: float, hi: float) -> float:  # type: ignore[no-untyped-def]
    flo = f(lo)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (f(mid) > 0) == (flo > 0):
            lo, flo = mid, f(mid)
        else:
            hi = mid
    return 0.5 * (lo + hi)


def test_critical_slopes() -> None:
    assert K1_AXIAL_LOAD == pytest.approx(-5e-4)  # the paper's -5e-6 per newton, slip as a fraction
    assert K2_TIME == -3e-2
    # the values are SlipStatus.msg's STATE_* constants; the labels are what people read
    assert (SlipState.UNKNOWN, SlipState.SLIPPING, SlipState.STABLE, SlipState.FAULT) == (0, 1, 2, 3)
    assert [s.label for s in SlipState] == ["unknown", "slipping", "stable", "fault"]


# -- Eq. 14 ----------------------------------------------------------------------------------------
def test_successive_slopes_of_a_line_are_its_slope() -> None:
    x = np.array([50.0, 100.0, 175.0, 180.0, 400.0, 700.0])
    np.testing.assert_allclose(successive_slopes(x, 4.0 - 2.5e-3 * x), -2.5e-3, rtol=1e-12)


def test_successive_slopes_are_secants() -> None:
    x = np.array([0.0, 1.0, 3.0, 4.0])
    # y = x^2: the secant slope between x_(n-1) and x_n is x_(n-1) + x_n
    np.testing.assert_allclose(successive_slopes(x, x**2), [1.0, 4.0, 7.0], rtol=1e-15)


@pytest.mark.parametrize(
    ("x", "y", "message"),
    [
        ([0.0, 1.0, 1.0], [1.0, 2.0, 3.0], r"x: must increase strictly, but x\[2\] = 1.0 <= x\[1\] = 1.0"),
        ([0.0, 1.0], [1.0, 2.0, 3.0], "lengths differ"),
        ([0.0], [1.0], r"x: needs at least 2"),
        ([0.0, 1.0], [1.0, np.nan], r"y: non-finite value nan at index 1"),
    ],
)
def test_successive_slopes_bad_input(x: list, y: list, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        successive_slopes(x, y)


# -- the paper's own numbers -----------------------------------------------------------------------
@pytest.mark.parametrize(("acceleration", "lam", "k", "d", "paper_onset"), TABLE7)
def test_table7_onsets(acceleration: int, lam: float, k: float, d: float, paper_onset: float) -> None:
    curve = OneGaussian(lam, k, d)
    result = stable_onset(curve, 0.0, 3.0, K2_TIME)
    assert result.reached and not result.stable_from_start
    assert result.onset == pytest.approx(paper_onset, abs=0.02)
    # the same from a plain callable (slope by differences, Eq. 14 with a small step)
    plain = stable_onset(lambda t: curve(t), 0.0, 3.0, K2_TIME)
    assert plain.onset == pytest.approx(result.onset, abs=1e-6)
    # and exactly where the slope formula crosses k2 (bisection here, beyond the steepest point)
    exact = bisect(lambda t: float(curve.slope(t)) - K2_TIME, k + d / math.sqrt(2.0), 3.0)
    assert result.onset == pytest.approx(exact, abs=1e-6)


def test_table7_onset_from_a_fit_of_noisy_data() -> None:
    # the method end to end: noisy slip samples -> 1-term fit -> slope criterion
    t = np.linspace(0.02, 3.0, 150)
    _, lam, k, d, paper_onset = TABLE7[0]
    y = OneGaussian(lam, k, d)(t) + np.random.default_rng(11).normal(0.0, 0.005, t.size)
    result = stable_onset(fit_gaussians(t, y, 1), float(t[0]), float(t[-1]), K2_TIME)
    assert result.onset == pytest.approx(paper_onset, abs=0.03)


def test_higher_acceleration_stabilises_sooner_by_table7() -> None:
    # docs/paper.md section 11: Table 7 with k2 gives shorter times for higher accelerations
    onsets = [stable_onset(OneGaussian(lam, k, d), 0.0, 3.0, K2_TIME).onset for _, lam, k, d, _ in TABLE7]
    assert all(a is not None for a in onsets)
    assert np.all(np.diff(np.array(onsets, dtype=float)) < 0.0)


# -- classification and the onset definition -------------------------------------------------------
def test_classification_flips_where_the_slope_crosses_k() -> None:
    # decay from the peak at x = 0: slope 0 at the peak (stable by the criterion), steepest at
    # x = c/sqrt(2), then back towards 0
    curve, k = OneGaussian(2.0, 0.0, 1.0), -0.1
    first = bisect(lambda x: float(curve.slope(x)) - k, 0.0, 1.0 / math.sqrt(2.0))
    second = bisect(lambda x: float(curve.slope(x)) - k, 1.0 / math.sqrt(2.0), 4.0)
    x = np.linspace(0.0, 4.0, 401)
    states = classify(x, curve, k)
    expected = np.where((x > first) & (x < second), "slipping", "stable")
    np.testing.assert_array_equal(states, expected)
    # a plain callable gives the same away from the crossings
    far = (np.abs(x - first) > 1e-4) & (np.abs(x - second) > 1e-4)
    np.testing.assert_array_equal(classify(x[far], lambda v: curve(v), k), expected[far])

    result = stable_onset(curve, 0.0, 4.0, k)
    # the early stretch at the peak is not the onset: only the stretch lasting to the end is
    assert result.onset == pytest.approx(second, abs=1e-7)
    assert len(result.stable_intervals) == 2
    assert result.stable_intervals[0][0] == 0.0 and result.stable_intervals[0][1] == pytest.approx(first, abs=1e-7)
    assert result.stable_intervals[1] == (pytest.approx(second, abs=1e-7), 4.0)
    assert not result.stable_from_start


def test_not_reached_and_stable_from_start() -> None:
    curve, k = OneGaussian(2.0, 0.0, 1.0), -0.1
    second = bisect(lambda x: float(curve.slope(x)) - k, 1.0 / math.sqrt(2.0), 4.0)
    early = stable_onset(curve, 0.5, second - 0.01, k)
    assert early.onset is None and not early.reached
    assert early.slope_at_end == pytest.approx(float(curve.slope(second - 0.01)), rel=1e-12)
    assert early.slope_at_end < k
    late = stable_onset(curve, second + 0.01, 5.0, k)
    assert late.reached and late.stable_from_start and late.onset == second + 0.01


def test_coarse_resolution_still_locates_the_crossing() -> None:
    _, lam, k, d, _ = TABLE7[1]
    curve = OneGaussian(lam, k, d)
    fine = stable_onset(curve, 0.0, 3.0, K2_TIME)
    coarse = stable_onset(curve, 0.0, 3.0, K2_TIME, resolution=0.25)
    assert coarse.onset == pytest.approx(fine.onset, abs=1e-7)


def test_axial_load_criterion_on_a_plateau() -> None:
    # slip falling with load to a plateau: 2-term form as the paper's Table 5, x in N
    def curve(x):  # type: ignore[no-untyped-def]
        x = np.asarray(x)
        return 3.0 * np.exp(-((x / 150.0) ** 2)) + 1.5

    # slope -6 x/150^2 exp(-(x/150)^2) %/N crosses k1 = -5e-6 %/N far out on the tail
    def slope(x: float) -> float:
        return -6.0 * x / 150.0**2 * math.exp(-((x / 150.0) ** 2))

    exact = bisect(lambda x: slope(x) - K1_AXIAL_LOAD, 150.0 / math.sqrt(2.0), 2000.0)
    result = stable_onset(curve, 50.0, 700.0, K1_AXIAL_LOAD)
    assert result.onset == pytest.approx(exact, rel=1e-5)
    assert result.first_onset == result.onset  # a monotonic slope: both readings agree
    assert 300.0 < exact < 400.0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((1.0, 1.0, K2_TIME), "x_end: must be > x_start"),
        ((0.0, math.nan, K2_TIME), "x_end: must be finite"),
        ((0.0, 3.0, math.inf), "critical_slope: must be finite"),
    ],
)
def test_stable_onset_bad_range(args: tuple, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        stable_onset(OneGaussian(1.0, 0.0, 1.0), *args)


def test_stable_onset_bad_resolution_and_curve() -> None:
    with pytest.raises(AnalysisError, match=r"resolution: must be in \(0, 3.0\]"):
        stable_onset(OneGaussian(1.0, 0.0, 1.0), 0.0, 3.0, K2_TIME, resolution=0.0)
    with pytest.raises(AnalysisError, match="curve: must be a fitted curve or a callable"):
        stable_onset(3.0, 0.0, 3.0, K2_TIME)  # type: ignore[arg-type]
    with pytest.raises(AnalysisError, match="non-finite slope"):
        stable_onset(lambda x: np.full(np.shape(x), np.nan), 0.0, 3.0, K2_TIME)
    with pytest.raises(AnalysisError, match="non-finite slope"):
        classify([0.0, 1.0], lambda x: np.full(np.shape(x), np.nan), K2_TIME)


# -- the load sweep by the paper's method -------------------------------------------------------
SWEEP_LOADS_N = [50.0, 100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0]
TABLE5_1000RPM = [(5.18, -4.14, 214.0), (2.05, 530.0, 469.0)]  # docs/paper.md section 10


def _table5(f: float) -> float:
    return sum(a * math.exp(-(((f - b) / c) ** 2)) for a, b, c in TABLE5_1000RPM)


def _table5_slope(f: float) -> float:
    return sum(-2.0 * a * (f - b) / c**2 * math.exp(-(((f - b) / c) ** 2)) for a, b, c in TABLE5_1000RPM)


def test_the_readings_of_k1_on_the_paper_curve_by_hand() -> None:
    """The paper's own 1000 rpm curve (Table 5; docs/paper.md section 10), an independent source.
    By hand from the formula: the slope is -5.8e-3 %/N at 300 N, -3.6e-4 at 400 N, crosses zero
    near 416 N (slip 2.04 %), and falls again to -2.8e-3 at 700 N (the second term's centre is
    at 530 N). The four readings, each crossing found by bisection on the closed-form slope:
    "first reach" gives 394 N (k1 -5e-4 %/N, the shipped reading) and 416 N (-5e-6 %/N), where
    the text says slip has levelled off at about 2 %; "stays to 700 N" gives no stable state in
    either unit. docs/method.md tabulates the same."""
    assert _table5_slope(300.0) == pytest.approx(-5.8e-3, rel=0.05)
    assert _table5_slope(400.0) == pytest.approx(-3.6e-4, rel=0.1)
    assert _table5_slope(700.0) == pytest.approx(-2.8e-3, rel=0.05)
    assert K1_READINGS == {"fraction per N": K1_AXIAL_LOAD, "percent per N": -5e-6}
    for unit, k in K1_READINGS.items():
        exact = bisect(lambda f: _table5_slope(f) - k, 300.0, 420.0)  # noqa: B023 - called at once
        result = stable_onset(np.vectorize(_table5), 50.0, 700.0, k)
        assert result.onset_by("first") == pytest.approx(exact, abs=0.01), unit
        assert result.onset_by("last") is None, unit  # the curve falls again past 530 N
        assert 1.95 < _table5(exact) < 2.15, unit  # "levels off at about 2 %"
    assert bisect(lambda f: _table5_slope(f) - K1_AXIAL_LOAD, 300.0, 420.0) == pytest.approx(394.0, abs=1.0)


def test_load_sweep_of_the_paper_curve_gives_the_papers_verdict() -> None:
    """The shipped method on the Table 5 curve sampled at the sweep's loads: the fit recovers the
    curve, and "stable from" is where its slope first reaches k1, 394 N by the closed form above
    (the Gaussian's own parameters, 5.18 and 2.05 %, play no part in the gates)."""
    slips = [_table5(f) for f in SWEEP_LOADS_N]
    exact = bisect(lambda f: _table5_slope(f) - K1_AXIAL_LOAD, 300.0, 420.0)
    verdict = load_sweep_verdict(SWEEP_LOADS_N, slips, K1_AXIAL_LOAD)
    assert verdict.fitted and verdict.n_terms == 2 and verdict.r_square > 0.9999
    assert verdict.stable_from == pytest.approx(exact, abs=2.0)
    assert verdict.onset is None  # the other reading, "stays to the last load"
    assert verdict.describe().startswith("stable from 394 N (2-term Gaussian, R^2 1.0000")
    last = load_sweep_verdict(SWEEP_LOADS_N, slips, K1_AXIAL_LOAD, reading="last")
    assert last.stable_from is None and "below k1" in last.reason and last.slope_at_end == pytest.approx(_table5_slope(700.0), rel=0.01)


def test_a_steep_fall_is_judged_by_its_fit_not_by_its_terms_sizes() -> None:
    """A cliff like the bench twin's (slip e-folding every 25 N down to a plateau of 0.1 %): the
    fit's terms reach hundreds of percent, yet it meets the points, and the verdict is where the
    curve's slope reaches k1. By hand: slope -(S0/25) exp(-(F - 100)/25) = -5e-4 %/N at
    F = 100 + 25 ln(S0 / (25 x 5e-4)) = 100 + 25 ln(240) = 237 N for S0 = 3 %."""
    loads = np.array([100.0, 150.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0])
    slips = 0.1 + 3.0 * np.exp(-(loads - 100.0) / 25.0)
    verdict = load_sweep_verdict(loads, slips, K1_AXIAL_LOAD)
    assert verdict.fitted, verdict.reason
    assert 200.0 < (verdict.stable_from or 0.0) < 300.0  # within a load step of the closed form's 237 N


def test_residual_runs_by_hand() -> None:
    """Swed and Eisenhart's exact distribution: 4 positives and 4 negatives in 2 runs happen in 2
    of C(8, 4) = 70 orders; in 3 runs in 6 more (P <= 3 runs = 8/70)."""
    assert residual_runs([1, 1, 1, 1, -1, -1, -1, -1]) == (2, pytest.approx(2 / 70))
    assert residual_runs([1, 1, 1, -1, -1, -1, -1, 1]) == (3, pytest.approx(8 / 70))
    assert residual_runs([1, -1, 1, -1]) == (4, pytest.approx(1.0))
    assert residual_runs([1.0, 2.0, 0.0]) == (1, 1.0)


def test_load_sweep_states_why_there_is_no_verdict() -> None:
    few = load_sweep_verdict([100.0, 200.0, 300.0], [3.0, 2.0, 1.5], K1_AXIAL_LOAD)
    assert few.stable_from is None and not few.fitted and "3 distinct load point(s)" in few.reason
    rng = np.random.default_rng(3)
    noise = load_sweep_verdict(SWEEP_LOADS_N, list(2.0 + rng.normal(0.0, 0.5, 8)), K1_AXIAL_LOAD)
    assert not noise.fitted and "fails the gates" in noise.reason and noise.describe().startswith("no stable state: ")
    skid = load_sweep_verdict(SWEEP_LOADS_N, [28.7] + [_table5(f) for f in SWEEP_LOADS_N[1:]], -5e-3)
    assert skid.loads[0] == 100.0 and "1 load point(s) above 20 % slip (skidding) left out" in skid.describe()
