"""Load cell and force controller on their own: noise and filter variance laws, anti-windup,
set-point rate limiting."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from bearing_rig_sim.rig.force_control import ForceController, LoadCell
from bearing_rig_sim.rig.loading import LoadingChainConfig

DT = 1e-3  # the load controller's period, s


@pytest.fixture(scope="module")
def shipped() -> LoadingChainConfig:
    return LoadingChainConfig.from_yaml()


def test_load_cell_noise_and_filter_variance(shipped: LoadingChainConfig) -> None:
    # white noise through y += a (x - y): variance a sigma^2 / (2 - a), a = 1 - exp(-2 pi fc dt)
    sigma = 3.0
    raw = LoadCell(dataclasses.replace(shipped.load_cell, noise_std_n=sigma, cutoff_hz=0.0))
    filtered = LoadCell(dataclasses.replace(shipped.load_cell, noise_std_n=sigma, cutoff_hz=50.0))
    raw_values = np.array([raw.measure(100.0, DT) for _ in range(40000)])
    filtered_values = np.array([filtered.measure(100.0, DT) for _ in range(40000)])[100:]
    a = 1.0 - math.exp(-2.0 * math.pi * 50.0 * DT)
    assert raw_values.mean() == pytest.approx(100.0, abs=0.1)
    assert raw_values.std() == pytest.approx(sigma, rel=0.03)
    assert filtered_values.std() == pytest.approx(sigma * math.sqrt(a / (2.0 - a)), rel=0.08)


def test_controller_anti_windup_and_setpoint_rate(shipped: LoadingChainConfig) -> None:
    params = shipped.controller
    controller = ForceController(params)
    previous = controller.ramped_setpoint
    for _ in range(5000):  # 5 s far below a set-point: output saturated
        command = controller.update(1000.0, 0.0, DT)
        assert controller.ramped_setpoint - previous <= params.setpoint_rate_n_per_s * DT + 1e-9
        previous = controller.ramped_setpoint
    assert command == params.output_max_v
    assert controller.integral <= params.output_max_v  # no wind-up beyond the output range
    # the measurement overshoots: the command must leave saturation at once, not after unwinding
    assert controller.update(1000.0, 1100.0, DT) < params.output_max_v


# -- closed loop ------------------------------------------------------------------------------
