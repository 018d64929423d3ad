"""Online slope criterion: verdicts on slip series fed point by point.

The reference onsets are the crossings of the critical slope by the generating curve, found by a
bisection of its slope formula written here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.analysis import AnalysisError
from bearing_rig_sim.analysis.stability import K1_AXIAL_LOAD, K2_TIME, SlipState
from bearing_rig_sim.analysis.streaming import RMSE_JUMP, StreamingStability, Verdict, t_quantile_95

LAM, K, D = 3.5, -1.52, 1.29  # paper Table 7, 20 rad/s^2
LOAD_TERMS = [(3.0, 0.0, 150.0), (1.5, 700.0, 2000.0)]  # slip falling with load to a plateau


def table7(t: np.ndarray) -> np.ndarray:
    return LAM * np.exp(-(((t - K) / D) ** 2))


def table7_slope(t: float) -> float:
    u = (t - K) / D
    return -2.0 * LAM * u / D * math.exp(-u * u)


def load_curve(x: np.ndarray) -> np.ndarray:
    return sum(a * np.exp(-(((x - b) / c) ** 2)) for a, b, c in LOAD_TERMS)  # type: ignore[return-value]


def load_slope(x: float) -> float:
    return sum(-2.0 * a * (x - b) / c**2 * math.exp(-(((x - b) / c) ** 2)) for a, b, c in LOAD_TERMS)


def bisect(f, lo: float, hi: float) -> float:  # type: ignore[no-untyped-def]
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if (f(mid) > 0) == (f(lo) > 0):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


TIME_ONSET = bisect(lambda t: table7_slope(t) - K2_TIME, K + D / math.sqrt(2.0), 3.0)  # about 1.667 s


def feed(monitor: StreamingStability, x: np.ndarray, y: np.ndarray) -> list[tuple[float, Verdict]]:
    """Add every point, asking for the verdict after each; return the verdicts where the state changed."""
    changes: list[tuple[float, Verdict]] = []
    for xi, yi in zip(x, y):
        monitor.add(float(xi), float(yi))
        v = monitor.verdict()
        if not changes or changes[-1][1].state != v.state:
            changes.append((float(xi), v))
    return changes


def noisy_run(seed: int, dt: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(dt, 3.0 + 1e-9, dt)
    return t, table7(t) + np.random.default_rng(seed).normal(0.0, 0.005, t.size)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_time_verdict_goes_unknown_slipping_stable_at_the_onset(seed: int) -> None:
    monitor = StreamingStability("time")
    t, y = noisy_run(seed)
    changes = feed(monitor, t, y)
    assert [v.state for _, v in changes] == [SlipState.UNKNOWN, SlipState.SLIPPING, SlipState.STABLE]
    assert changes[1][0] == pytest.approx(t[monitor.min_points - 1])  # first verdict with the first fit
    stable_at, first_stable = changes[2]
    # declared stable within a refit interval (10 points, 0.2 s) after the true onset
    assert TIME_ONSET - 0.04 <= stable_at <= TIME_ONSET + 0.2
    final = monitor.verdict()
    assert final.onset == pytest.approx(TIME_ONSET, abs=0.03)
    assert final.slope == pytest.approx(table7_slope(3.0), abs=2e-3)
    assert final.critical_slope == K2_TIME
    assert final.fit_rmse == pytest.approx(0.005, rel=0.3)
    assert final.n_points == t.size and final.x == pytest.approx(3.0)
    assert 0.8 < final.confidence <= 1.0
    assert "1-term" in final.detail and "stable since" in final.detail


def test_unknown_until_enough_points() -> None:
    monitor = StreamingStability("time", min_points=12)
    t, y = noisy_run(0)
    for i in range(11):
        monitor.add(float(t[i]), float(y[i]))
        v = monitor.verdict()
        assert v.state == SlipState.UNKNOWN and v.slope is None and v.fit_rmse is None and v.confidence == 0.0
        assert v.n_points == i + 1 and "collecting points" in v.detail
    monitor.add(float(t[11]), float(y[11]))
    assert monitor.verdict().state == SlipState.SLIPPING
    assert StreamingStability("time").verdict().x is None


def test_refit_policy_by_point_count() -> None:
    monitor = StreamingStability("time", refit_interval=10, min_points=12)
    t, y = noisy_run(0)
    fits = []
    for i in range(60):
        monitor.add(float(t[i]), float(y[i]))
        fits.append(monitor.fit)
    # fits after points 12, 22, 32, 42, 52: the fit object changes only then
    assert monitor.refits == 5
    changed = [i + 1 for i in range(1, 60) if fits[i] is not fits[i - 1]]
    assert changed == [12, 22, 32, 42, 52]
    assert monitor.fit is not None and monitor.fit.n_points == 52


def test_refit_policy_by_age() -> None:
    monitor = StreamingStability("time", refit_interval=1000, min_points=12, max_fit_age=0.11)
    t, y = noisy_run(0)
    for i in range(40):
        monitor.add(float(t[i]), float(y[i]))
    # points every 0.02 s: a refit once x has advanced by more than 0.11 s, i.e. every 6 points
    assert monitor.refits == 1 + (40 - 12) // 6
    assert monitor.fit is not None and monitor.fit.n_points == 12 + 6 * ((40 - 12) // 6)


def test_full_and_warm_refits_agree() -> None:
    t, y = noisy_run(4)
    warm, full = StreamingStability("time"), StreamingStability("time", full_refit_every=1)
    for xi, yi in zip(t, y):
        warm.add(float(xi), float(yi))
        full.add(float(xi), float(yi))
    assert warm.fit is not None and full.fit is not None
    np.testing.assert_allclose(warm.fit.params, full.fit.params, rtol=1e-4)


def test_warm_refit_that_loses_track_is_redone_in_full() -> None:
    monitor = StreamingStability("time", refit_interval=10, min_points=12, full_refit_every=100)
    t, y = noisy_run(0)
    for xi, yi in zip(t[:42], y[:42]):
        monitor.add(float(xi), float(yi))
    assert monitor.refits == 4 and 1 <= monitor.full_refits < 4  # the first fit is full
    full_before, rmse = monitor.full_refits, monitor.fit.rmse  # type: ignore[union-attr]
    for xi, yi in zip(t[42:52], y[42:52] + 1.0):  # the slip jumps by 1 %: no Gaussian follows that
        monitor.add(float(xi), float(yi))
    assert monitor.refits == 5 and monitor.full_refits == full_before + 1
    assert monitor.fit is not None and monitor.fit.rmse > RMSE_JUMP * rmse


def test_axial_load_criterion_with_two_terms() -> None:
    onset = bisect(lambda x: load_slope(x) - K1_AXIAL_LOAD, 150.0 / math.sqrt(2.0), 700.0)
    monitor = StreamingStability("axial_load")
    assert monitor.critical_slope == K1_AXIAL_LOAD and monitor.max_terms == 2 and monitor.min_points == 14
    x = np.arange(50.0, 700.0 + 1e-9, 5.0)
    changes = feed(monitor, x, load_curve(x))
    assert [v.state for _, v in changes] == [SlipState.UNKNOWN, SlipState.SLIPPING, SlipState.STABLE]
    assert onset <= changes[2][0] <= onset + 10 * 5.0
    final = monitor.verdict()
    assert final.onset == pytest.approx(onset, abs=1.0)
    assert monitor.fit is not None and monitor.fit.n_terms == 2
    assert "%/N" in final.detail


def test_confidence_is_low_where_the_slope_meets_k() -> None:
    # refitting at every point: the confidence is high far from the crossing of k and falls
    # where the fitted slope is within a standard error or so of k
    t, y = noisy_run(1)
    monitor = StreamingStability("time", refit_interval=1)
    confidences = {}
    for xi, yi in zip(t, y):
        monitor.add(float(xi), float(yi))
        if monitor.fit is not None:
            confidences[round(float(xi), 2)] = monitor.verdict().confidence
    assert all(0.0 <= c <= 1.0 for c in confidences.values())
    near = confidences[round(round(TIME_ONSET / 0.02) * 0.02, 2)]
    assert near < 0.5
    assert confidences[1.0] > 0.9 and confidences[3.0] > 0.9


@pytest.mark.parametrize(
    ("x", "slip", "message"),
    [(math.nan, 1.0, "x: must be finite"), (0.5, math.inf, "slip_pct: must be finite"), ("now", 1.0, "x: must be a real number")],
)
def test_non_finite_input_is_refused_and_state_kept(x: object, slip: object, message: str) -> None:
    monitor = StreamingStability("time")
    monitor.add(0.1, 3.0)
    with pytest.raises(AnalysisError, match=message):
        monitor.add(x, slip)  # type: ignore[arg-type]
    assert monitor.n_points == 1


def test_clock_jump_is_an_error_and_reset_recovers() -> None:
    monitor = StreamingStability("time")
    t, y = noisy_run(0)
    for xi, yi in zip(t[:40], y[:40]):
        monitor.add(float(xi), float(yi))
    before = monitor.verdict()
    with pytest.raises(AnalysisError, match=r"x: must increase, got 0.5 s after 0.8 s .*reset\(\)"):
        monitor.add(0.5, 2.0)
    with pytest.raises(AnalysisError, match="must increase"):
        monitor.add(float(t[39]), 2.0)  # a repeated time stamp is no increase either
    assert monitor.verdict() == before
    monitor.reset()
    assert monitor.n_points == 0 and monitor.fit is None and monitor.refits == 0
    assert monitor.verdict().state == SlipState.UNKNOWN
    monitor.add(0.01, 3.0)  # an earlier time is fine after a reset
    assert monitor.n_points == 1


def test_window_bounds_the_points_held() -> None:
    monitor = StreamingStability("time", window=50)
    t, y = noisy_run(2, dt=0.01)
    feed(monitor, t, y)
    assert monitor.n_points == 50
    xs, _ = monitor.points()
    np.testing.assert_allclose(xs, t[-50:])
    final = monitor.verdict()
    # the last 0.5 s are all stable: the onset can only be bounded by the first point held
    assert final.state == SlipState.STABLE and final.onset == pytest.approx(t[-50])
    assert "at or before" in final.detail


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"criterion": "speed"}, "criterion: must be one of time, axial_load"),
        ({"criterion": "time", "min_points": 3}, "min_points: a 1-term fit needs at least 4"),
        ({"criterion": "axial_load", "min_points": 6}, "min_points: a 2-term fit needs at least 7"),
        ({"criterion": "time", "window": 5}, "window: must be >= min_points = 12"),
        ({"criterion": "time", "refit_interval": 0}, "refit_interval: must be an integer >= 1"),
        ({"criterion": "time", "critical_slope": math.nan}, "critical_slope: must be finite"),
        ({"criterion": "time", "max_fit_age": -1.0}, "max_fit_age: must be > 0 s"),
    ],
)
def test_bad_options(kwargs: dict, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        StreamingStability(**kwargs)


def test_deferred_refits_run_only_when_asked() -> None:
    """With defer_refit, add() only stores (cheap on a latency-sensitive path); refit_if_due()
    then fits exactly when the policy is due, and the verdict uses that fit."""
    t = np.linspace(0.0, 3.0, 61)
    y = 3.0 * np.exp(-(((t + 1.0) / 1.5) ** 2))
    eager = StreamingStability("time", refit_interval=5)
    lazy = StreamingStability("time", refit_interval=5, defer_refit=True)
    for x, v in zip(t, y):
        eager.add(float(x), float(v))
        lazy.add(float(x), float(v))
    assert eager.refits > 0 and lazy.refits == 0 and lazy.fit is None
    assert lazy.refit_if_due() is True and lazy.refits == 1
    assert lazy.refit_if_due() is False  # nothing new since the fit
    assert lazy.verdict().state == eager.verdict().state


# -- the Student's t quantile of the monitor's slope test --------------------------------------
@pytest.mark.parametrize(
    ("dof", "table"),
    [(1, 6.314), (2, 2.920), (5, 2.015), (10, 1.812), (20, 1.725), (21, 1.721), (30, 1.697), (40, 1.684), (60, 1.671), (120, 1.658)],
)
def test_t_quantile_matches_the_one_sided_5_percent_column_of_a_t_table(dof: int, table: float) -> None:
    """t(0.95; dof) as any statistics table prints it to three decimals (e.g. the NIST/SEMATECH
    e-Handbook, table 1.3.6.7.2, column 0.05); above 20 degrees of freedom it stays above the
    normal 1.645, which would make the test anti-conservative."""
    assert t_quantile_95(dof) == pytest.approx(table, abs=5e-4)
    if dof > 20:
        assert t_quantile_95(dof) > 1.645 + 0.01
