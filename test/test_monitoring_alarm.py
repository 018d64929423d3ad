"""The alarm rule of the slope criterion (analysis/streaming.py ``TrailingSlope.falling``): its
false-alarm probability at a flat slip, against the closed form of the rule.

A flat slip (slope 0, a hold) estimated with standard error ``se`` on ``dof`` degrees of freedom
gives an estimate ``se T`` with T Student's t. The rule calls SLIPPING when the estimate is below
k by its one-sided 95 % bound *and* below zero by twice that bound, so a false alarm needs
``T < -max(t95 + |k| / se, 2 t95)`` (t95 = scipy.stats.t.ppf(0.95, dof)).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import t as student_t

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.analysis.streaming import TrailingSlope

K2 = -0.03  # %/s, the shipped critical slope (config/monitor.yaml)
DOF = 20


def first_state(slope: float, se: float, dof: int = DOF) -> SlipState:
    """The state after one slip point whose slope (phase estimate) is ``slope`` +- ``se``."""
    trailing = TrailingSlope(K2, span=1.0, min_points=5, resolution=0.002, change_threshold=4.0, max_span=8.0, stable_confidence=0.95)
    trailing.add(0.0, 2.0, (slope, se, dof))
    return trailing.state


@pytest.mark.parametrize("se", [0.005, 0.015, 0.05, 0.2])
def test_false_alarms_at_a_flat_slip_match_the_closed_form(se: float) -> None:
    """20 000 estimates of a flat slip at each standard error: the SLIPPING fraction is the
    closed form's within 4 binomial standard deviations, never above P(T < -2 t95) = 0.13 %."""
    q = float(student_t.ppf(0.95, DOF))
    expected = float(student_t.cdf(-max(q - K2 / se, 2.0 * q), DOF))
    assert expected <= float(student_t.cdf(-2.0 * q, DOF)) < 0.0013
    draws = np.random.default_rng(11).standard_t(DOF, 20_000) * se
    alarms = sum(first_state(float(s), se) is SlipState.SLIPPING for s in draws)
    sd = np.sqrt(20_000 * max(expected, 1e-6) * (1.0 - expected))
    assert abs(alarms - 20_000 * expected) <= 4.0 * sd + 1.0


def test_a_steep_fall_raises_the_alarm_at_once_and_an_unresolved_one_does_not() -> None:
    """-1.5 %/s +- 0.1 (a load step's decay, 50 times k): clear of k and of zero, SLIPPING.
    -0.2 +- 0.07 (a hold's first second at 900 rpm and 50 us of jitter, 3 standard errors from
    its true 0): below k by the 95 % bound (-0.2 + 1.72 * 0.07 = -0.08) but not below zero by
    twice it (-0.2 + 2 * 1.72 * 0.07 = +0.04), no verdict; and STABLE keeps the bare 95 % test."""
    assert first_state(-1.5, 0.1) is SlipState.SLIPPING
    assert first_state(-0.2, 0.07) is SlipState.UNKNOWN
    assert first_state(0.05, 0.04) is SlipState.STABLE  # 0.05 - 1.72 * 0.04 = -0.019 >= k


def test_a_first_verdict_may_come_between_slip_points_and_is_then_held() -> None:
    """``refresh`` with a newer phase estimate between two windows decides a first verdict
    (0.01 - 1.72 * 0.01 >= k: STABLE) and, once one is held, leaves it to the next point's
    overturn rules (a refresh at -1.0 +- 0.01 changes nothing)."""
    trailing = TrailingSlope(K2, span=1.0, min_points=5, resolution=0.002, change_threshold=4.0, max_span=8.0, stable_confidence=0.95)
    trailing.refresh((0.0, 0.01, DOF))  # before any point: nothing
    assert trailing.state is SlipState.UNKNOWN
    trailing.add(0.0, 2.0, (0.0, 0.05, DOF))  # 0 - 1.72 * 0.05 < k: undecided
    assert trailing.state is SlipState.UNKNOWN
    trailing.refresh((0.01, 0.01, DOF))
    assert trailing.state is SlipState.STABLE
    trailing.refresh((-1.0, 0.01, DOF))
    assert trailing.state is SlipState.STABLE


def held_then_falling_windows(trailing: tuple[float, float, int]) -> list[SlipState]:
    """States of a series held STABLE on 3 s of flat slip points (scattering +-0.01 %, 0.159 s
    apart, the phase's trailing slope 0 +- 0.005), whose points then fall at -0.1 %/s for 2 s
    while the phase's trailing slope is ``trailing``."""
    series = TrailingSlope(K2, span=1.0, min_points=5, resolution=0.002, change_threshold=4.0, max_span=8.0, stable_confidence=0.95)
    states = []
    for i in range(32):
        x = 0.159 * i
        noise = 0.01 if i % 2 else -0.01
        falling = x >= 3.0
        series.add(x, 2.0 - 0.1 * max(x - 3.0, 0.0) + noise, trailing if falling else (0.0, 0.005, DOF))
        states.append(series.state)
    return states


def test_the_windows_longer_line_raises_the_alarm_only_with_the_trailing_slope_falling() -> None:
    """The windows' line from the held verdict's data on (up to 2.2 s of points falling at -0.1
    %/s for their last second and more) comes out clearly below k2; the held STABLE is overturned
    to SLIPPING only while the finer trailing slope itself falls clearly (-0.1 +- 0.02: -0.1 + 2 *
    1.72 * 0.02 < 0), not while it is undecided (-0.032 +- 0.033, a 900 rpm hold's phase at one
    second: 2 t95 se = 0.11 above it), which a 50 us-jitter hold once turned into a false alarm."""
    undecided = held_then_falling_windows((-0.032, 0.033, DOF))
    assert undecided[18] is SlipState.STABLE and set(undecided[18:]) == {SlipState.STABLE}
    falling = held_then_falling_windows((-0.1, 0.02, DOF))
    assert falling[18] is SlipState.STABLE and falling[-1] is SlipState.SLIPPING
