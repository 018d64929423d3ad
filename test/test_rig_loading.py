"""Axial loading chain: statics of the lever and rope, one-sided elements, the clutch limit, the
closed-loop settle time against a bound derived from the chain's parameters, noise robustness,
interlocks and their recovery, refused set-points and configuration errors.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.rig.loading import ClutchState, LoadChainState, LoadingChain, LoadingChainConfig, SetpointError

DT = 1e-3  # the load controller's period, s


@pytest.fixture(scope="module")
def shipped() -> LoadingChainConfig:
    return LoadingChainConfig.from_yaml()


@pytest.fixture(scope="module")
def quiet(shipped: LoadingChainConfig) -> LoadingChainConfig:
    """The shipped chain with a noise-free load cell (for exact statics)."""
    return dataclasses.replace(shipped, load_cell=dataclasses.replace(shipped.load_cell, noise_std_n=0.0))


def with_part(config: LoadingChainConfig, part: str, **changes: float) -> LoadingChainConfig:
    return dataclasses.replace(config, **{part: dataclasses.replace(getattr(config, part), **changes)})


def run(chain: LoadingChain, seconds: float) -> list[LoadChainState]:
    return [chain.step(DT) for _ in range(int(round(seconds / DT)))]


def step_response(config: LoadingChainConfig, setpoint: float, seconds: float) -> tuple[LoadingChain, list[LoadChainState]]:
    """A fresh chain, clutch engaged, stepped to ``setpoint`` for ``seconds``."""
    chain = LoadingChain(config)
    chain.engage()
    chain.set_setpoint(setpoint)
    return chain, run(chain, seconds)


def loaded_chain(config: LoadingChainConfig, setpoint: float, seconds: float = 1.0) -> LoadingChain:
    return step_response(config, setpoint, seconds)[0]


# -- statics and one-sided elements -------------------------------------------------------------
@pytest.mark.parametrize("setpoint", [50.0, 400.0, 1000.0])
def test_statics_bearing_force_is_lever_ratio_times_rope_tension(quiet: LoadingChainConfig, setpoint: float) -> None:
    chain = loaded_chain(quiet, setpoint)
    state = chain.state()
    ratio = quiet.lever.force_ratio
    assert state.bearing_force == pytest.approx(ratio * state.rope_tension, rel=1e-6)
    assert state.brake_force == pytest.approx(state.rope_tension, rel=1e-6)  # plunger at rest
    assert state.bearing_force == pytest.approx(setpoint, rel=1e-3)  # integral action: no offset
    assert state.bearing_force < quiet.clutch.holding_force_n
    assert state.clutch_state == "engaged" and not state.fault


def test_clutch_never_transmits_more_than_its_holding_force(quiet: LoadingChainConfig) -> None:
    _, states = step_response(with_part(quiet, "clutch", holding_force_n=600.0), 900.0, 1.0)
    assert max(s.bearing_force for s in states) <= 600.0
    slipping = [s for s in states if s.clutch_state is ClutchState.SLIPPING]
    assert slipping and all(s.bearing_force == pytest.approx(600.0) for s in slipping)


def test_rope_never_pushes_when_the_brake_drives_backwards(quiet: LoadingChainConfig) -> None:
    chain = loaded_chain(quiet, 500.0)
    chain.release()
    chain.set_manual_voltage(-quiet.brake.voltage_limit_v)
    lever_positions, tensions = [], []
    for _ in range(500):
        state = chain.step(DT)
        tensions.append(state.rope_tension)
        lever_positions.append(chain.lever_position)
        assert state.bearing_force == 0.0  # released: nothing reaches the housing
    assert min(tensions) >= 0.0
    assert state.brake_force < 0.0 and chain.plunger_position == quiet.brake.stroke_min_m
    assert tensions[-1] == 0.0
    assert np.all(np.diff(lever_positions) >= -1e-15)  # the slack rope never pushes the lever back


def closed_loop_time_constant(config: LoadingChainConfig, force: float) -> float:
    """tau_cl = (L/R) / (Kp K), K = d(bearing force)/d(voltage) at ``force``: the PI with
    Ti = L/R cancels the coil pole, leaving a first-order loop (mechanics much faster)."""
    b, c = config.brake, config.controller
    brake_force = force / config.lever.force_ratio
    slope = b.force_constant_n_per_a * (1.0 - (brake_force / b.saturation_force_n) ** 2)  # d tanh
    gain = slope * config.lever.force_ratio / b.resistance_ohm
    return (b.inductance_h / b.resistance_ohm) / (c.proportional_gain_v_per_n * gain)


def settle_bound(config: LoadingChainConfig, start: float, target: float) -> float:
    """Ramp at the set-point rate, then the ramp-following lag rate x tau decays to 2 % of the
    target: |dF|/rate + tau ln(rate tau / (0.02 target)), plus 2 tau for the lags neglected
    (coil lag vs cancellation off the working point, load-cell filter, one-period delay)."""
    rate = config.controller.setpoint_rate_n_per_s
    tau = max(closed_loop_time_constant(config, f) for f in (start, target))
    return abs(target - start) / rate + tau * max(0.0, math.log(rate * tau / (0.02 * target))) + 2.0 * tau


@pytest.mark.parametrize("start, target", [(0.0, 500.0), (0.0, 1000.0), (500.0, 1000.0), (1000.0, 100.0)])
def test_load_step_settles_within_2_percent_in_the_stated_time(shipped: LoadingChainConfig, start: float, target: float) -> None:
    chain = loaded_chain(shipped, start) if start > 0 else LoadingChain(shipped)
    chain.engage()
    chain.set_setpoint(target)
    states = run(chain, 1.5)
    forces = np.array([s.bearing_force for s in states])
    times = np.arange(1, len(states) + 1) * DT
    outside = np.nonzero(np.abs(forces - target) > 0.02 * target)[0]
    settle = times[outside[-1]] if len(outside) else 0.0
    bound = settle_bound(shipped, start, target)
    assert bound < 0.5  # the chain's stated settle time: well under the 1-2 s required
    assert settle <= bound
    overshoot = (forces.max() - target) if target > start else (target - forces.min())
    assert overshoot < 0.02 * target
    assert not any(s.fault for s in states)


@pytest.mark.parametrize("noise", [5.0, 20.0])
def test_load_cell_noise_does_not_destabilise(shipped: LoadingChainConfig, noise: float) -> None:
    noisy = with_part(shipped, "load_cell", noise_std_n=noise)
    chain = loaded_chain(noisy, 500.0, seconds=0.5)
    forces = np.array([s.bearing_force for s in run(chain, 3.0)])
    first, last = forces[:1500], forces[1500:]
    assert abs(forces.mean() - 500.0) < 0.005 * 500.0
    assert np.max(np.abs(forces - 500.0)) < 0.05 * 500.0
    assert last.std() < 1.3 * first.std() + 1e-9  # no growth over time
    assert not chain.fault


# -- interlocks -------------------------------------------------------------------------------
def assert_safe_then_recovers(chain: LoadingChain, config: LoadingChainConfig) -> None:
    """After a trip: brake command 0 V, force decays; after reset, a set-point is reached."""
    states = run(chain, 0.3)
    assert all(s.fault for s in states)
    assert chain.brake.voltage == 0.0
    assert abs(states[-1].brake_current) < 0.01 * config.brake.current_limit_a
    assert states[-1].bearing_force < 0.01 * config.max_setpoint_n
    chain.reset_fault()
    chain.set_setpoint(300.0)
    state = run(chain, 1.0)[-1]
    assert not state.fault and state.fault_reason == ""
    assert state.bearing_force == pytest.approx(300.0, rel=0.02)


def test_load_limit_trips_and_recovers(shipped: LoadingChainConfig) -> None:
    chain = LoadingChain(shipped)
    chain.engage()
    volts = 0.0
    for _ in range(10000):  # slow open-loop ramp: only the load limit can trip
        volts = min(volts + 0.01, shipped.brake.voltage_limit_v)
        chain.set_manual_voltage(volts)
        state = chain.step(DT)
        if state.fault:
            break
    assert state.fault and state.fault_reason.startswith("load limit")
    assert state.load_cell_force > shipped.interlocks.max_force_n
    assert_safe_then_recovers(chain, shipped)


def test_rate_limit_trips_and_recovers(shipped: LoadingChainConfig) -> None:
    chain = LoadingChain(shipped)
    chain.engage()
    chain.set_manual_voltage(shipped.brake.voltage_limit_v)  # full voltage at once: a runaway
    states = run(chain, 0.05)
    tripped = [s for s in states if s.fault]
    assert tripped and tripped[0].fault_reason.startswith("rate limit")
    assert tripped[0].load_cell_force < shipped.interlocks.max_force_n
    assert_safe_then_recovers(chain, shipped)


def test_clutch_slip_trips_and_recovers(shipped: LoadingChainConfig) -> None:
    weak = with_part(shipped, "clutch", holding_force_n=600.0)
    chain, states = step_response(weak, 900.0, 1.0)
    tripped = [s for s in states if s.fault]
    assert tripped and tripped[0].fault_reason.startswith("clutch slip")
    assert tripped[0].clutch_state == "slipping"
    assert_safe_then_recovers(chain, weak)
    assert chain.state().clutch_state == "engaged"


def test_normal_operation_trips_nothing(shipped: LoadingChainConfig) -> None:
    chain = LoadingChain(shipped)
    chain.engage()
    for setpoint in (1000.0, 0.0, 1000.0, 50.0):
        chain.set_setpoint(setpoint)
        assert not any(s.fault for s in run(chain, 0.6))


# -- commands and configuration ---------------------------------------------------------------
def test_repeated_commands_do_not_disturb_a_settled_loop(quiet: LoadingChainConfig) -> None:
    chain = loaded_chain(quiet, 600.0)
    reference = loaded_chain(quiet, 600.0)
    chain.engage()  # already engaged
    chain.reset_fault()  # no fault
    chain.set_manual_voltage(None)  # already closed loop
    for _ in range(200):
        assert chain.step(DT).bearing_force == pytest.approx(reference.step(DT).bearing_force, rel=1e-12)


@pytest.mark.parametrize("bad, word", [(math.nan, "finite"), (math.inf, "finite"), (-1.0, ">= 0"), (1000.5, "<= 1000"), ("500", "number"), (True, "number")])
def test_bad_setpoints_are_refused_and_the_previous_one_kept(shipped: LoadingChainConfig, bad: object, word: str) -> None:
    chain = LoadingChain(shipped)
    chain.set_setpoint(250.0)
    with pytest.raises(SetpointError, match=word) as info:
        chain.set_setpoint(bad)  # type: ignore[arg-type]
    assert "keeping 250 N" in str(info.value)
    assert chain.setpoint == 250.0
    assert chain.step(DT).setpoint == 250.0


@pytest.mark.parametrize("bad", [math.nan, 30.0, -30.0])
def test_bad_manual_voltage_is_refused(shipped: LoadingChainConfig, bad: float) -> None:
    with pytest.raises(SetpointError, match="manual brake voltage"):
        LoadingChain(shipped).set_manual_voltage(bad)


@pytest.mark.parametrize("dt", [0.0, -1e-3, math.nan])
def test_bad_time_step_is_refused(shipped: LoadingChainConfig, dt: float) -> None:
    with pytest.raises(Exception, match="time step"):
        LoadingChain(shipped).step(dt)


def test_long_step_is_subdivided_to_the_same_result(quiet: LoadingChainConfig) -> None:
    fine, coarse = LoadingChain(quiet), LoadingChain(quiet)
    for chain in (fine, coarse):
        chain.engage()
        chain.set_setpoint(400.0)
    run(fine, 0.5)
    for _ in range(5):
        coarse.step(0.1)
    assert coarse.time == pytest.approx(fine.time)
    assert coarse.state().bearing_force == pytest.approx(fine.state().bearing_force, rel=1e-9)


def test_shipped_rig_file_and_config_errors(tmp_path: Path) -> None:
    text = config_path("rig.yaml").read_text()
    path = tmp_path / "rig.yaml"
    path.write_text("simulator:\n  not_ours: 1\n" + text)
    LoadingChainConfig.from_yaml(path)  # sections owned by others are ignored
    cases = [
        (text.replace("resistance_ohm: 2.0", "resistance_ohm: -2.0"), "loading_chain.brake.resistance_ohm", "> 0"),
        (text.replace("force_ratio: 3.0", "force_ratio: .nan"), "loading_chain.lever.force_ratio", "finite"),
        (text.replace("    inductance_h: 0.020\n", ""), "loading_chain.brake.inductance_h", "missing"),
        (text.replace("seed: 7", "seed: 7\n    sead: 8"), "loading_chain.load_cell.sead", "unknown"),
        (text.replace("max_force_n: 1100.0", "max_force_n: 900.0"), "loading_chain.interlocks.max_force_n", "max_setpoint_n"),
    ]
    for bad, key, problem in cases:
        path.write_text(bad)
        with pytest.raises(ConfigError) as info:
            LoadingChainConfig.from_yaml(path)
        assert info.value.source == str(path)
        assert info.value.key == key
        assert problem in info.value.problem
