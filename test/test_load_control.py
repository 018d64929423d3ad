"""The load controller's operation of the loading chain, without ROS: stepping by elapsed sim time
(batched ticks give the same chain as single ticks; a clock that goes back or jumps), the state
and diagnostics schedule, set-point refusals and the health they leave, the fault latch and its
reset policy, the stated settle-time bound, the radial loader's set-point against the rig
file's limits, and load set-points stamped ahead (in force from their stamp, not a sample before).
"""

from __future__ import annotations

import dataclasses
import math

import pytest

from bearing_rig_sim.errors import RigError
from bearing_rig_sim.load_control import AxialLoadOperation, HealthLevel, RadialLoad, SetpointSource, settle_time_bound
from bearing_rig_sim.rig.loading import LoadingChain, LoadingChainConfig
from bearing_rig_sim.rig.program import RigLimits


@pytest.fixture(scope="module")
def config() -> LoadingChainConfig:
    return LoadingChainConfig.from_yaml()


def weak_clutch(config: LoadingChainConfig, holding: float = 300.0) -> LoadingChainConfig:
    return dataclasses.replace(config, clutch=dataclasses.replace(config.clutch, holding_force_n=holding))


def drive(op: AxialLoadOperation, start: float, stop: float, tick: float) -> list:
    """Clock readings every ``tick`` s from ``start`` (exclusive) to ``stop``; the results."""
    n = int(round((stop - start) / tick))
    return [op.advance_to(start + (k + 1) * tick) for k in range(n)]


def test_first_reading_starts_the_count_and_later_ones_step_the_elapsed_time(config: LoadingChainConfig) -> None:
    op = AxialLoadOperation.from_config(config)
    first = op.advance_to(5.0)
    assert first.stepped == 0.0 and op.chain.time == 0.0
    later = op.advance_to(5.004)
    assert later.stepped == pytest.approx(0.004) and op.chain.time == pytest.approx(0.004)


def test_batched_ticks_step_the_same_chain_as_single_ticks(config: LoadingChainConfig) -> None:
    """A simulator faster than real time delivers ticks in bursts; the node takes the latest:
    the chain must end where 1 ms ticks take it (sub-steps of max_substep_s)."""
    single, batched = AxialLoadOperation.from_config(config), AxialLoadOperation.from_config(config)
    for op in (single, batched):
        op.advance_to(0.0)
        assert op.request_setpoint(400.0, SetpointSource.TOPIC).accepted
    drive(single, 0.0, 0.3, 0.001)
    drive(batched, 0.0, 0.3, 0.010)
    a, b = single.chain.state(), batched.chain.state()
    assert a.bearing_force == pytest.approx(b.bearing_force, rel=1e-9)
    assert a.load_cell_force == pytest.approx(b.load_cell_force, rel=1e-9)
    assert a.time == pytest.approx(0.3) and b.time == pytest.approx(0.3)


def test_follow_steps_one_force_sample_per_millisecond_however_the_clock_is_read(config: LoadingChainConfig) -> None:
    """The node wakes every 10 ms of wall time and reads whatever /clock came last: follow gives a
    result (a force message) for each multiple of the 1 ms sample period passed, stepped from the
    previous one, so the forces are those of a clock read every millisecond."""
    chunked, every_ms = AxialLoadOperation.from_config(config, sample_period_s=0.001), AxialLoadOperation.from_config(config)
    assert [r.time for r in chunked.follow(0.0)] == [0.0]  # the first reading starts the count
    every_ms.advance_to(0.0)
    for op in (chunked, every_ms):
        assert op.request_setpoint(400.0, SetpointSource.TOPIC).accepted
    samples = chunked.follow(0.0105)
    assert [round(r.time, 9) for r in samples] == [round(0.001 * k, 9) for k in range(1, 11)]
    assert all(r.stepped == pytest.approx(0.001) for r in samples)
    assert chunked.follow(0.0105) == [] and chunked.follow(0.0109) == []  # the next sample not reached
    samples += chunked.follow(0.0371)
    assert [round(r.time, 9) for r in samples] == [round(0.001 * k, 9) for k in range(1, 38)]
    reference = drive(every_ms, 0.0, 0.037, 0.001)
    assert [r.state.bearing_force for r in samples] == pytest.approx([r.state.bearing_force for r in reference], rel=1e-12)
    assert [round(r.time, 9) for r in samples if r.state_due] == [0.01, 0.02, 0.03]  # 100 Hz of sim time
    back = chunked.follow(0.002)
    assert len(back) == 1 and back[0].stepped == 0.0 and "went back" in back[0].clock_note


def test_clock_going_back_restarts_the_count_and_a_jump_is_capped(config: LoadingChainConfig) -> None:
    op = AxialLoadOperation.from_config(config, max_clock_gap_s=0.5)
    drive(op, 0.0, 1.0, 0.01)
    back = op.advance_to(0.2)
    assert back.stepped == 0.0 and "went back" in back.clock_note
    assert op.chain.time == pytest.approx(1.0 - 0.01)  # first reading of drive() did not step
    jump = op.advance_to(100.0)
    assert jump.stepped == pytest.approx(0.5) and "max_clock_gap_s" in jump.clock_note
    assert op.advance_to(100.001).clock_note == ""


@pytest.mark.parametrize("tick", [0.001, 0.003, 0.010])
def test_state_is_due_at_its_rate_of_sim_time_whatever_the_tick(config: LoadingChainConfig, tick: float) -> None:
    op = AxialLoadOperation.from_config(config, state_period_s=0.01, diagnostics_period_s=0.25)
    op.advance_to(0.0)
    results = drive(op, 0.0, 1.0, tick)
    assert sum(r.state_due for r in results) == pytest.approx(100, abs=1)
    periodic = [r.time for r in results if r.diagnostics_due]
    assert len(periodic) == pytest.approx(4, abs=1)  # health unchanged: only the period


def test_refused_setpoints_keep_the_previous_one_and_warn_until_the_next_accepted(config: LoadingChainConfig) -> None:
    op = AxialLoadOperation.from_config(config)
    assert op.request_setpoint(150.0, "service").accepted
    for bad, word in ((math.nan, "finite"), (-1.0, ">= 0"), (1e4, "<= 1000"), ("ten", "number"), (True, "number")):
        reply = op.request_setpoint(bad, SetpointSource.PARAMETER)
        assert not reply.accepted and word in reply.message and "by parameter" in reply.message
        assert op.setpoint == 150.0
        health = op.health()
        assert health.level is HealthLevel.WARN and word in health.message
    assert op.request_setpoint(0, SetpointSource.TOPIC).accepted
    assert op.health().level is HealthLevel.OK


def test_health_change_makes_diagnostics_due_at_once(config: LoadingChainConfig) -> None:
    op = AxialLoadOperation.from_config(config, diagnostics_period_s=10.0)
    assert op.advance_to(0.0).diagnostics_due  # the first reading reports
    assert not op.advance_to(0.001).diagnostics_due
    op.request_setpoint(-3.0, SetpointSource.TOPIC)
    assert op.health_changed() and op.advance_to(0.002).diagnostics_due


def test_fault_latches_and_resets_only_once_its_cause_is_gone(config: LoadingChainConfig) -> None:
    op = AxialLoadOperation.from_config(weak_clutch(config))
    op.advance_to(0.0)
    op.request_setpoint(500.0, SetpointSource.SERVICE)
    results = drive(op, 0.0, 0.3, 0.001)
    tripped = [r for r in results if r.tripped]
    assert len(tripped) == 1 and tripped[0].tripped.startswith("clutch slip")
    assert op.health().level is HealthLevel.ERROR
    refused = op.reset_fault()
    assert not refused.accepted and "holding force 300 N" in refused.message
    stored = op.request_setpoint(200.0, SetpointSource.TOPIC)
    assert stored.accepted and "after reset_fault" in stored.message
    drive(op, 0.3, 0.6, 0.001)
    assert op.chain.fault and op.chain.state().bearing_force < 5.0  # a set-point does not clear it
    assert op.reset_fault().accepted
    drive(op, 0.6, 1.2, 0.001)
    state = op.chain.state()
    assert not state.fault and state.bearing_force == pytest.approx(200.0, rel=0.02)
    assert op.health().level is HealthLevel.OK


def test_reset_is_refused_while_the_load_cell_is_over_the_limit(config: LoadingChainConfig) -> None:
    op = AxialLoadOperation.from_config(config)
    op.advance_to(0.0)
    op.chain.set_manual_voltage(config.brake.voltage_limit_v)  # a runaway: the rate limit trips
    results = drive(op, 0.0, 0.05, 0.001)
    assert any(r.tripped.startswith("rate limit") for r in results)
    assert op.reset_fault().accepted  # the brake is off and the force falls: nothing persists
    assert op.reset_fault().message == "no interlock fault latched"


def test_a_long_wait_at_zero_load_does_not_trip_the_next_set_point(config: LoadingChainConfig) -> None:
    """Regulating around 0 N lets the plunger drift to the slack stop (a rope cannot push), and the
    next set-point then slams the rope taut: the brake is de-energised at 0 N instead."""
    op = AxialLoadOperation.from_config(config)
    op.advance_to(0.0)
    drive(op, 0.0, 3.0, 0.001)
    assert "de-energised" in op.health().message
    assert abs(op.chain.plunger_position) < 0.2e-3  # m: no drift to the slack stop (-5 mm)
    op.request_setpoint(100.0, SetpointSource.TOPIC)
    results = drive(op, 3.0, 4.0, 0.001)
    assert not any(r.tripped for r in results)
    assert op.chain.state().bearing_force == pytest.approx(100.0, rel=0.02)
    op.request_setpoint(0.0, SetpointSource.TOPIC)  # and back to zero: unloads, brake off
    drive(op, 4.0, 4.5, 0.001)
    assert op.chain.state().bearing_force < 1.0 and op.chain.brake.voltage == 0.0


def test_clutch_release_and_engage(config: LoadingChainConfig) -> None:
    op = AxialLoadOperation.from_config(config, engage=False)
    assert op.chain.state().clutch_state == "released"
    op.request_setpoint(300.0, SetpointSource.TOPIC)
    op.advance_to(0.0)
    drive(op, 0.0, 0.3, 0.001)
    assert op.chain.state().bearing_force == 0.0 and "clutch released" in op.health().message
    assert op.set_clutch(True).accepted
    drive(op, 0.3, 0.9, 0.001)
    assert op.chain.state().bearing_force == pytest.approx(300.0, rel=0.02)


def test_settle_time_bound_grows_with_the_step_and_states_the_chain_under_a_quarter_second(
    config: LoadingChainConfig,
) -> None:
    small, large = settle_time_bound(config, 0.0, 100.0), settle_time_bound(config, 0.0, 1000.0)
    assert small < large
    assert settle_time_bound(config, 0.0, 500.0) < 0.25
    with pytest.raises(RigError):
        settle_time_bound(config, 0.0, 0.0)


@pytest.mark.parametrize("option", ["state_period_s", "diagnostics_period_s", "max_clock_gap_s"])
@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, math.inf])
def test_bad_options_and_clock_times_are_refused(config: LoadingChainConfig, option: str, bad: float) -> None:
    with pytest.raises(RigError, match=option):
        AxialLoadOperation.from_config(config, **{option: bad})
    op = AxialLoadOperation.from_config(config)
    with pytest.raises(RigError, match="clock time"):
        op.advance_to(bad if bad != 0.0 else -0.5)


def test_release_engage_then_200_n_reaches_200_n_within_the_settle_bound(config: LoadingChainConfig) -> None:
    """The audit's case: loaded at 200 N, clutch released (the brake's decaying current pulls the
    lever down until the plunger meets its stop), engaged again: the bearing must see 200 N again
    within the chain's stated settle bound, not stay at 0 N with the health OK."""
    op = AxialLoadOperation.from_config(config)
    op.advance_to(0.0)
    op.request_setpoint(200.0, SetpointSource.TOPIC)
    drive(op, 0.0, 0.5, 0.001)
    assert op.set_clutch(False).accepted
    drive(op, 0.5, 1.0, 0.001)
    assert op.chain.state().bearing_force == 0.0
    assert op.chain.lever_position > 4e-3  # m: the free lever ran down to where the rope runs out
    assert op.set_clutch(True).accepted
    bound = settle_time_bound(config, 0.0, 200.0)
    steps = math.ceil(bound / 0.001)
    results = drive(op, 1.0, 1.0 + steps * 0.001, 0.001)
    assert results[-1].state.bearing_force == pytest.approx(200.0, rel=0.02)
    assert all(r.state.bearing_force <= config.interlocks.max_force_n for r in results)
    assert op.health().level is HealthLevel.OK
    # and once more: a second cycle does not use up the lever's travel
    op.set_clutch(False)
    drive(op, 1.0 + steps * 0.001, 2.0, 0.001)
    op.set_clutch(True)
    drive(op, 2.0, 2.0 + steps * 0.001, 0.001)
    assert op.chain.state().bearing_force == pytest.approx(200.0, rel=0.02)


def test_a_set_point_the_chain_cannot_reach_is_an_error_after_the_settle_bound(config: LoadingChainConfig) -> None:
    """A brake driver limited to 1 A (50 N/A: 50 N at the brake, 150 N at the bearing through the
    lever ratio 3) is asked for 600 N. The health says so once the stated bound has passed, not
    before, and clears once a reachable set-point is reached (the PI integrator, wound up
    against the current limit, takes some 0.6 s to come back)."""
    weak = dataclasses.replace(config, brake=dataclasses.replace(config.brake, current_limit_a=1.0))
    # 1 A: about 50 N at the brake, 150 N through the lever ratio 3: 600 N is out of reach
    op = AxialLoadOperation.from_config(weak)
    op.advance_to(0.0)
    op.request_setpoint(600.0, SetpointSource.TOPIC)
    bound = settle_time_bound(weak, 0.0, 600.0)
    drive(op, 0.0, 0.5 * bound, 0.0005)
    assert op.health().level is HealthLevel.OK  # still within the bound
    drive(op, 0.5 * bound, bound + 0.01, 0.0005)
    health = op.health()
    assert health.level is HealthLevel.ERROR and "set-point 600 N not reached" in health.message
    assert op.chain.state().bearing_force < 200.0
    op.request_setpoint(100.0, SetpointSource.TOPIC)  # reachable: the error clears once in the band
    drive(op, bound + 0.01, bound + 1.5, 0.0005)
    assert op.chain.state().bearing_force == pytest.approx(100.0, abs=5.0)
    assert op.health().level is HealthLevel.OK


def test_a_checked_set_point_is_not_applied_and_a_refused_one_warns(config: LoadingChainConfig) -> None:
    """The node's parameter validation asks check_setpoint first and applies only once the
    parameter is set: checking must change nothing but the refusal's WARN."""
    op = AxialLoadOperation.from_config(config)
    assert op.request_setpoint(100.0, SetpointSource.SERVICE).accepted
    assert op.check_setpoint(250.0, SetpointSource.PARAMETER).accepted
    assert op.setpoint == 100.0  # checked, not applied
    assert op.health().level == HealthLevel.OK
    refused = op.check_setpoint(config.max_setpoint_n + 1.0, SetpointSource.PARAMETER)
    assert not refused.accepted and "max_setpoint_n" in refused.message and "by parameter" in refused.message
    assert op.setpoint == 100.0 and op.health().level == HealthLevel.WARN
    assert op.request_setpoint(250.0, SetpointSource.PARAMETER).accepted  # the accepted one clears the WARN
    assert op.setpoint == 250.0 and op.health().level == HealthLevel.OK


# -- the radial loader's set-point --------------------------------------------------------------
def radial_limits(radial_n: float, moment_n_m: float) -> RigLimits:
    """A rig whose ``combined_loading`` section states these limits (the rest as shipped)."""
    return dataclasses.replace(RigLimits.from_rig_file(), source="radial.yaml", max_radial_load_n=radial_n, max_moment_n_m=moment_n_m)


def radial_operation(config: LoadingChainConfig) -> AxialLoadOperation:
    """An engaged operation with a 1 ms sample period on a rig file stating a radial loader of
    800 N and 5 N m."""
    return AxialLoadOperation(
        LoadingChain(config),
        state_period_s=0.01,
        diagnostics_period_s=1.0,
        max_clock_gap_s=0.5,
        sample_period_s=0.001,
        engage=True,
        radial_limits=radial_limits(800.0, 5.0),
    )


def test_shipped_rig_refuses_any_radial_setpoint_naming_the_limit(config: LoadingChainConfig) -> None:
    """config/rig.yaml states 0 N and 0 N m: the paper's bench loads only axially."""
    op = AxialLoadOperation.from_config(config)
    reply = op.request_radial(RadialLoad(force_x=500.0), SetpointSource.TOPIC)
    assert not reply.accepted
    assert "radial force 500 N is above the rig's limit of 0 N (combined_loading.max_radial_setpoint_n in rig.yaml)" in reply.message
    assert op.radial == RadialLoad()
    assert op.health().level is HealthLevel.WARN and reply.message in op.health().message
    assert op.request_radial(RadialLoad(), SetpointSource.TOPIC).accepted  # zero is what the shipped rig gives
    assert op.health().level is HealthLevel.OK


def test_radial_setpoint_within_the_limits_is_applied_as_given_and_refusals_keep_it(config: LoadingChainConfig) -> None:
    op = radial_operation(config)
    # (300, 400) N is 500 N (3-4-5); (0.6, 0.8) N m is 1 N m
    accepted = op.request_radial(RadialLoad(300.0, 400.0, 0.6, 0.8), SetpointSource.TOPIC)
    assert accepted.accepted and "500 N, moment 1 N m" in accepted.message
    in_force = RadialLoad(300.0, 400.0, 0.6, 0.8)
    assert op.radial == in_force
    # applied without the axial chain's dynamics, and the axial chain untouched by it
    op.advance_to(0.0)
    op.advance_to(0.001)
    assert op.radial == in_force and op.setpoint == 0.0
    # (600, 600) N is 848.5 N > 800 N; (3, 4) N m is 5 N m: at the limit, accepted
    refused = op.request_radial(RadialLoad(600.0, 600.0), SetpointSource.TOPIC)
    assert not refused.accepted
    assert "radial force 848.528 N is above the rig's limit of 800 N (combined_loading.max_radial_setpoint_n in radial.yaml)" in refused.message
    assert op.radial == in_force and op.health().level is HealthLevel.WARN
    moment = op.request_radial(RadialLoad(0.0, 0.0, 3.0, -6.0), SetpointSource.TOPIC)  # 6.708 N m
    assert not moment.accepted and "moment 6.7082 N m is above the rig's limit of 5 N m (combined_loading.max_moment_setpoint_n_m" in moment.message
    nan = op.request_radial(RadialLoad(math.nan), SetpointSource.TOPIC)
    assert not nan.accepted and "force.x must be a finite number" in nan.message
    assert op.radial == in_force
    assert op.request_radial(RadialLoad(0.0, 0.0, 3.0, 4.0), SetpointSource.TOPIC).accepted
    assert op.health().level is HealthLevel.OK


def test_a_stamped_set_point_takes_effect_at_its_stamp_not_a_sample_before(config: LoadingChainConfig) -> None:
    """``request_load`` with a stamp ahead: queued; the samples before the stamp keep the old
    set-point, the one at the stamp shows the new one (force samples of 1 ms)."""
    op = AxialLoadOperation.from_config(config)
    op.follow(1.0)
    assert op.request_setpoint(100.0, SetpointSource.TOPIC).accepted
    queued = op.request_load(300.0, RadialLoad(), 1.005, SetpointSource.TOPIC)
    assert queued.accepted and "from t = 1.005 s" in queued.message
    assert op.setpoint == 100.0 and op.pending == 1
    results = op.follow(1.010)
    assert [round(r.time, 6) for r in results] == [1.001, 1.002, 1.003, 1.004, 1.005, 1.006, 1.007, 1.008, 1.009, 1.010]
    assert [r.state.setpoint for r in results] == [100.0] * 4 + [300.0] * 6
    assert [bool(r.applied) for r in results] == [False] * 4 + [True] + [False] * 5
    assert results[4].applied[0].accepted and "300 N" in results[4].applied[0].message
    assert op.pending == 0


def test_a_stamp_between_samples_splits_the_step_there(config: LoadingChainConfig) -> None:
    """A set-point stamped 0.4 ms into a 1 ms sample is in force for its last 0.6 ms: the chain
    ends where one stepped 0.4 ms, given the set-point, then stepped 0.6 ms ends."""
    op = AxialLoadOperation.from_config(config)
    op.follow(0.0)
    assert op.request_load(400.0, RadialLoad(), 0.0024, SetpointSource.TOPIC).accepted
    op.follow(0.003)
    by_hand = LoadingChain(config)
    by_hand.engage()
    by_hand.set_manual_voltage(0.0)  # the 0 N set-point: brake de-energised
    by_hand.step(0.002)
    by_hand.step(0.0004)
    by_hand.set_setpoint(400.0)
    by_hand.set_manual_voltage(None)
    by_hand.step(0.0006)
    state, hand = op.chain.state(), by_hand.state()
    for name in ("ramped_setpoint", "bearing_force", "load_cell_force", "rope_tension", "brake_current"):
        assert getattr(state, name) == pytest.approx(getattr(hand, name), rel=1e-9, abs=1e-9), name
    # the set-point ramps at its rate from the stamp on: 0.6 ms of it (the ramp's own closed form)
    assert state.ramped_setpoint == pytest.approx(config.controller.setpoint_rate_n_per_s * 0.0006, rel=0.02)


def test_a_stamp_reached_already_or_none_applies_at_once_and_refusals_are_whole(config: LoadingChainConfig) -> None:
    op = radial_operation(config)
    op.follow(2.0)
    assert op.request_load(200.0, RadialLoad(0.0, 500.0), None, SetpointSource.TOPIC).accepted
    assert op.setpoint == 200.0 and op.radial == RadialLoad(0.0, 500.0) and op.pending == 0
    assert op.request_load(250.0, RadialLoad(), 1.5, SetpointSource.TOPIC).accepted  # a stamp in the past
    assert op.setpoint == 250.0 and op.radial == RadialLoad() and op.pending == 0
    # 900 N radial is above the rig's 800 N: the axial part refused with it, nothing queued
    refused = op.request_load(300.0, RadialLoad(900.0), 3.0, SetpointSource.TOPIC)
    assert not refused.accepted and "radial force 900 N is above the rig's limit of 800 N" in refused.message
    assert op.pending == 0 and op.health().level is HealthLevel.WARN
    negative = op.request_load(-1.0, RadialLoad(), 3.0, SetpointSource.TOPIC)
    assert not negative.accepted and negative.message.startswith("set-point by topic refused")
    op.follow(3.5)
    assert op.setpoint == 250.0
