"""The slope of slip against time from the cage's phase (analysis/phase.py), against closed forms.

The cage pulses are made here from a slip law: the cage's angle theta_c(t) = r int omega_i (1 - S /
100) dt (Eq. 11-12 of the paper, docs/paper.md), a pulse where it reaches each quarter revolution
(plus the strip's own offset), and the spindle's angle omega_i t at the same instant.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.analysis.phase import PhaseSlope

RATIO = 0.4283
STRIPS = 4
OFFSETS = (0.0, -0.0011, 0.0007, 0.0012)  # revolutions, a bench's cage strips


def pulses(slip, duration: float, omega: float = 94.25, alpha: float = 0.0, jitter_s: float = 0.0, seed: int = 0, offsets=OFFSETS):
    """(time, cage index, strip, spindle angle rad) of every cage pulse of the slip law ``slip(t)``
    (percent) at spindle speed omega + alpha t."""
    t = np.linspace(0.0, duration, 400_001)
    inner_speed = omega + alpha * t
    cage_speed = RATIO * inner_speed * (1.0 - slip(t) / 100.0)
    cage = np.concatenate(([0.0], np.cumsum(0.5 * (cage_speed[1:] + cage_speed[:-1]) * np.diff(t)))) / (2.0 * math.pi)
    inner = omega * t + 0.5 * alpha * t**2
    rng = np.random.default_rng(seed)
    out = []
    k = 1
    while True:
        strip = k % STRIPS
        target = k / STRIPS + offsets[strip]
        if target >= cage[-1]:
            break
        when = float(np.interp(target, cage, t)) + (rng.normal(0.0, jitter_s) if jitter_s else 0.0)
        out.append((when, k, strip, float(np.interp(when, t, inner))))  # the spindle read at the stamp
        k += 1
    return out


def fitted(points, end: float, span: float = 1.0):
    phase = PhaseSlope(RATIO, span, STRIPS, resolution=1e-4)
    for when, index, strip, angle in points:
        phase.add(when, index, strip, angle)
    estimate = phase.estimate(end)
    assert estimate is not None
    return estimate


@pytest.mark.parametrize("b", [-0.2, -0.03, 0.0, 0.05])
def test_a_slip_linear_in_time_at_constant_speed_gives_its_slope(b: float) -> None:
    """S = 2 + b t at 900 rpm: S is linear in the spindle's angle, so the parabola is exact and
    the slope is b whatever the strips' offsets."""
    estimate = fitted(pulses(lambda t: 2.0 + b * t, 3.0), end=3.0)
    assert estimate.slope == pytest.approx(b, abs=2e-4)
    assert estimate.inner_ring_speed == pytest.approx(94.25, rel=1e-6)


def test_a_changing_speed_makes_no_apparent_slope() -> None:
    """Constant 1.5 % slip while the spindle accelerates at 60 rad/s^2: slope 0 (the abscissa is
    the spindle's own angle)."""
    estimate = fitted(pulses(lambda t: np.full_like(t, 1.5), 2.5, omega=30.0, alpha=60.0), end=2.5)
    assert estimate.slope == pytest.approx(0.0, abs=2e-4)


def test_under_acceleration_the_slope_is_the_mean_slope_of_the_stretch() -> None:
    """S = 1 - 0.1 t while the spindle accelerates at 40 rad/s^2 from 50 rad/s: S is not quite
    linear in the spindle's angle, and the fit returns the mean slope over its stretch, -0.1 %/s,
    to within the stretch's speed change (a few percent)."""
    estimate = fitted(pulses(lambda t: 1.0 - 0.1 * t, 3.0, omega=50.0, alpha=40.0), end=3.0)
    assert estimate.slope == pytest.approx(-0.1, rel=0.05)


def test_the_standard_error_under_jitter_is_the_scatter_of_the_slope() -> None:
    """50 us of white timing jitter on the cage pulses at 3000 rpm, constant slip: over 60 records
    the slopes scatter about 0 by their reported standard error (within 35 %, the scatter of a
    60-sample standard deviation and of the noise estimate), the reported share of white noise is
    high, and |slope| exceeds 1.645 standard errors in about 10 % of records (below 20 %)."""
    slopes, errors, shares = [], [], []
    for seed in range(60):
        estimate = fitted(pulses(lambda t: np.full_like(t, 2.0), 1.2, omega=314.16, jitter_s=50e-6, seed=seed), end=1.2)
        slopes.append(estimate.slope)
        errors.append(estimate.standard_error)
        shares.append(estimate.white_share)
    assert abs(np.mean(slopes)) < 3.0 * np.std(slopes) / math.sqrt(60)
    assert np.std(slopes) == pytest.approx(np.median(errors), rel=0.35)
    assert np.median(shares) > 0.5
    assert np.mean(np.abs(np.array(slopes)) > 1.645 * np.array(errors)) < 0.2


def test_a_wandering_slip_is_not_taken_for_jitter() -> None:
    """A slip that scatters by 0.1 % every 50 ms (a random walk of the phase): the standard error
    grows to the scatter of the slope over many records (within a factor 2), and the share of
    white noise falls below a half."""
    slopes, errors, shares = [], [], []
    for seed in range(40):
        values = np.random.default_rng(100 + seed).normal(0.0, 0.1, 100)
        estimate = fitted(pulses(lambda t, v=values: 2.0 + v[np.floor(t * 20.0).astype(int)], 2.0), end=2.0)
        slopes.append(estimate.slope)
        errors.append(estimate.standard_error)
        shares.append(estimate.white_share)
    assert 0.5 < np.median(errors) / np.std(slopes) < 2.0
    assert np.median(shares) < 0.5


def test_too_few_pulses_give_no_slope() -> None:
    """Under two cage revolutions in the stretch (the strips' offsets could not be told from the
    curvature): no estimate."""
    phase = PhaseSlope(RATIO, 1.0, STRIPS, resolution=1e-4)
    for when, index, strip, angle in pulses(lambda t: np.full_like(t, 2.0), 0.2):
        phase.add(when, index, strip, angle)
    assert phase.estimate(0.2) is None
