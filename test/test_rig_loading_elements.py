"""Elements of the loading chain on their own: the wire rope's one-sided law and the linear
brake's first-order coil, limits and saturating force."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.rig.loading import LoadingChainConfig
from bearing_rig_sim.rig.loading_elements import ClutchState, LinearBrake, SetpointError, WireRope, WireRopeParams


@pytest.fixture(scope="module")
def shipped() -> LoadingChainConfig:
    return LoadingChainConfig.from_yaml()


def test_wire_rope_law() -> None:
    rope = WireRope(WireRopeParams(stiffness_n_per_m=1e5, damping_n_s_per_m=100.0))
    assert rope.tension(1e-3, 0.0) == pytest.approx(100.0)
    assert rope.tension(1e-3, 0.5) == pytest.approx(150.0)
    assert rope.tension(-1e-3, 0.0) == 0.0  # slack
    assert rope.tension(-1e-3, 5.0) == 0.0  # slack, even while tightening
    assert rope.tension(1e-3, -5.0) == 0.0  # damping slows the unloading but cannot push


def test_brake_current_follows_first_order_law_and_limits(shipped: LoadingChainConfig) -> None:
    params = shipped.brake
    brake = LinearBrake(params)
    tau = params.inductance_h / params.resistance_ohm
    volts = 4.0
    for _ in range(int(round(tau / 1e-4))):
        brake.step(volts, 1e-4)
    assert brake.current == pytest.approx(volts / params.resistance_ohm * (1.0 - math.exp(-1.0)), rel=1e-9)
    for _ in range(2000):
        brake.step(1e6, 1e-3)  # above the rails: clipped
    assert brake.voltage == params.voltage_limit_v
    assert brake.current == pytest.approx(min(params.current_limit_a, params.voltage_limit_v / params.resistance_ohm))
    currents = np.linspace(0.0, 3.0 * params.current_limit_a, 50)
    forces = np.array([brake.force_at(i) for i in currents])
    assert np.all(np.diff(forces) > 0.0) and forces.max() < params.saturation_force_n
    assert brake.force_at(0.01) == pytest.approx(params.force_constant_n_per_a * 0.01, rel=1e-6)
    with pytest.raises(SetpointError, match="finite"):
        brake.step(math.nan, 1e-3)


def test_clutch_state_message_codes() -> None:
    # AxialLoadState.msg: CLUTCH_RELEASED=0, CLUTCH_ENGAGED=1, CLUTCH_SLIPPING=2
    assert [s.message_code for s in (ClutchState.RELEASED, ClutchState.ENGAGED, ClutchState.SLIPPING)] == [0, 1, 2]
