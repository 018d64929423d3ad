"""The monitor on bench-like recordings made from a known slip history (synthetic/bench.py):
4 strips per shaft with spacing errors, microseconds of timing jitter, lost pulses isolated and
in bursts, a stopped sensor, a bench system clock (epoch offset).

The true verdict is the paper's criterion on the true slip curve (stable where dS/dt >= k2),
computed from the scenario's formula, not by the monitor. Every status the schedule emits is
compared with it, except within the settling allowance: the first SETTLE_S seconds, and SETTLE_S
after each change of the true verdict and each start or end of a speed change (a verdict needs
a second of slip points, :data:`slope_span_s`, after anything changes; at 900 rpm one cage
revolution lasts 0.16 s).

Criteria (issue 12): agreement >= 95 % of the statuses outside the allowance; no state change
on a plateau (constant speed and a true slope clearly above k); first verdict within 1.5 s at
900 rpm; FAULT only in the scenario with a real sensor fault, and there within the loss rule's
time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.analysis.slip import ThrustContact
from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring import MonitorSettings, PulseMerger, SlipMonitor, StatusSchedule, shipped_parameters
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.synthetic.bench import BenchScenario, Burst, bench_pulses, load_samples, table7_onset, table7_run_up, true_verdict, write_bench_bag

SETTINGS = MonitorSettings.from_yaml()
RATIO = SETTINGS.kinematics().epicyclic_ratio()
K2 = SETTINGS.critical_slope_pct_per_s
SETTLE_S = 1.5
W900 = 900.0 * math.pi / 30.0  # rad/s
W1800 = 1800.0 * math.pi / 30.0


def constant(value: float):
    return lambda t: np.full_like(t, value)


def step_decay(t: np.ndarray, at: float = 5.0, base: float = 2.0, jump: float = 3.0, tau: float = 2.0) -> np.ndarray:
    """2 % jumping to 5 % at 5 s and decaying back with a 2 s time constant (a load step)."""
    return np.where(t < at, base, base + jump * np.exp(-(t - at) / tau))


def ramp(t: np.ndarray) -> np.ndarray:
    """900 rpm, a 3 s linear ramp to 1800 rpm from 6 s, 1800 rpm from 9 s."""
    return np.interp(t, [0.0, 6.0, 9.0, 1e9], [W900, W900, W1800, W1800])


def from_rest(t: np.ndarray) -> np.ndarray:
    """20 rad/s^2 from rest to 900 rpm (4.71 s), then held."""
    return np.minimum(20.0 * t, W900)


def run_up_slip(t: np.ndarray) -> np.ndarray:
    """Slip falling from 8 % to a 1.5 % plateau during the run-up (a Gaussian fall, as the
    paper's Table 7 fits), steep at first, flat after about 4 s."""
    return 1.5 + 6.5 * np.exp(-((t / 1.8) ** 2))


@dataclass
class Outcome:
    times: np.ndarray  # s from the scenario's start
    states: np.ndarray
    truth: np.ndarray
    settled: np.ndarray  # outside the settling allowance
    statuses: list


def run(scenario: BenchScenario, speed_changes: tuple[float, ...] = (), settle_until: float = SETTLE_S) -> Outcome:
    monitor = SlipMonitor(SETTINGS.kinematics(), SETTINGS)
    schedule = StatusSchedule(monitor)
    rows = []
    for shaft, pulse in bench_pulses(scenario):
        rows += schedule.on_pulse(shaft, pulse)
    final = schedule.finish()
    assert final is not None
    rows.append(final)
    times = np.array([r.time for r in rows]) - scenario.epoch_s
    states = np.array([int(r.status.state) for r in rows])
    truth = true_verdict(scenario, times, K2)
    grid = np.arange(0.0, scenario.duration_s, 1e-3)
    verdicts = true_verdict(scenario, grid, K2)
    changes = [*grid[1:][verdicts[1:] != verdicts[:-1]], *speed_changes]
    settled = times >= max(SETTLE_S, settle_until)
    for at in changes:
        settled &= ~((times >= at) & (times < at + SETTLE_S))
    return Outcome(times, states, truth, settled, [r.status for r in rows])


def agreement(out: Outcome) -> float:
    return float(np.mean(out.states[out.settled] == out.truth[out.settled]))


def state_changes(out: Outcome, start: float, end: float) -> int:
    inside = (out.times >= start) & (out.times < end)
    s = out.states[inside]
    return int(np.count_nonzero(s[1:] != s[:-1]))


def first_verdict(out: Outcome) -> float:
    decided = out.times[np.isin(out.states, (SlipState.STABLE, SlipState.SLIPPING))]
    return float(decided[0]) if decided.size else math.inf


def test_constant_slip_is_stable_soon_and_stays_so() -> None:
    out = run(BenchScenario(30.0, constant(W900), constant(2.0), epicyclic_ratio=RATIO))
    assert first_verdict(out) <= 1.5
    assert agreement(out) >= 0.95
    assert state_changes(out, SETTLE_S, 30.0) == 0
    assert SlipState.FAULT not in out.states
    windows = [s.slip_rate for s in out.statuses if math.isfinite(s.slip_rate)]
    assert np.mean(windows) == pytest.approx(2.0, abs=0.002)  # spacing errors and jitter do not bias


PLATEAU_AFTER_DECAY = 5.0 + 2.0 * math.log(1.5 / (0.1 * -K2))
"""After the step at 5 s, the decay's slope 1.5 exp(-(t - 5) / 2) %/s is within a tenth of k2 of
zero from here on (17.4 s): a plateau."""


RETURN_S = 2.5
"""Allowance for a held verdict to be overturned after the true change (s): the slope is that
of the line through the last second of windows (about 0.6 s behind its last point on a decay),
clear of k by the 95 % bound, and a held verdict is overturned only once the opposite one has
been reached over half a second, or the longer stretch reaches it too
(analysis.streaming.OVERTURN_CONFIRM)."""


def test_slip_step_and_exponential_decay_at_constant_speed() -> None:
    """True verdict: stable to 5 s, slipping until the decay's slope is back above k2
    (5 + 2 ln(1.5 / 0.03) = 12.82 s), stable after."""
    scenario = BenchScenario(30.0, constant(W900), step_decay, epicyclic_ratio=RATIO)
    out = run(scenario)
    assert agreement(out) >= 0.95
    # the verdict follows the slip: slipping soon after the step, stable again after the decay
    slipping = out.times[out.states == SlipState.SLIPPING]
    assert slipping.size and 5.0 <= slipping[0] <= 5.0 + SETTLE_S
    assert 12.82 <= slipping[-1] <= 12.82 + RETURN_S
    assert state_changes(out, PLATEAU_AFTER_DECAY, 30.0) == 0 and state_changes(out, SETTLE_S, 5.0) == 0


def scattered(base, sigma_pct: float, seed: int, rate_hz: float = 20.0):
    """``base`` plus white scatter: a new normal value of ``sigma_pct`` every 1 / rate_hz s
    (a one-revolution window at 900 rpm, 0.16 s, averages about three of them)."""
    values = np.random.default_rng(seed).normal(0.0, sigma_pct, 200_000)
    return lambda t: base(t) + values[np.floor(np.asarray(t) * rate_hz).astype(int)]


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5])
def test_a_scattered_plateau_gets_one_verdict_that_never_flaps(seed: int) -> None:
    """Constant 2 % slip at 900 rpm with white scatter of 0.1 % every 50 ms (per window about
    0.06 %, above the 0.005-0.045 % RMS the paper's fits leave): the true verdict is stable
    throughout (the underlying slip is flat). Exactly one state change (UNKNOWN to STABLE), the
    first verdict within 3.5 s (the scatter needs more points than clean data's 1.5 s), no FAULT.
    With one 95 % test at every point and no confirmation, such trials flapped 3-6 times in 30 s."""
    out = run(BenchScenario(30.0, constant(W900), scattered(constant(2.0), 0.1, seed), epicyclic_ratio=RATIO))
    assert first_verdict(out) <= 3.5
    assert state_changes(out, 0.0, 30.0) == 1
    assert out.states[-1] == SlipState.STABLE and SlipState.FAULT not in out.states


def test_a_plateau_whose_scatter_one_second_cannot_resolve_is_decided_on_a_longer_stretch() -> None:
    """Constant 2 % slip with a 0.05 % ripple at 3.1 Hz (half the window rate at 900 rpm, so
    neighbouring windows differ most): the slope of one second of windows has a standard error
    of about 0.044 %/s, above |k2| = 0.03 %/s, so it never decides (the monitor said UNKNOWN for
    all 20 s). The line through up to slope_max_span_s = 8 s of the steady series has about
    8^1.5 = 23 times less and decides: stable by 8 s, and never changed after."""
    assert SETTINGS.slope_span_s == 1.0 and SETTINGS.slope_max_span_s == 8.0
    ripple = lambda t: 2.0 + 0.05 * np.sin(2.0 * np.pi * 3.1 * t)
    out = run(BenchScenario(20.0, constant(W900), ripple, epicyclic_ratio=RATIO))
    assert first_verdict(out) <= 8.0
    assert state_changes(out, 0.0, 20.0) == 1 and out.states[-1] == SlipState.STABLE


def test_speed_ramp_with_constant_slip_gives_no_apparent_slip() -> None:
    """Time-aligned speeds: a 900 -> 1800 rpm ramp (31 rad/s^2) with constant true slip is stable
    throughout, and every window's slip stays at the true 2 %."""
    scenario = BenchScenario(20.0, ramp, constant(2.0), epicyclic_ratio=RATIO)
    out = run(scenario, speed_changes=(6.0, 9.0))
    assert agreement(out) >= 0.95
    assert SlipState.SLIPPING not in out.states
    slips = np.array([s.slip_rate for s in out.statuses if math.isfinite(s.slip_rate)])
    assert np.max(np.abs(slips - 2.0)) < 0.05
    assert state_changes(out, 9.0 + SETTLE_S, 20.0) == 0


def test_constant_acceleration_from_rest() -> None:
    """Slow revolutions at first: the allowance runs until the spindle is above the monitor's
    minimum speed and min_slope_points + 1 whole cage revolutions have passed (a slope needs that
    many windows), computed from the profile: about 3 s."""
    scenario = BenchScenario(20.0, from_rest, run_up_slip, epicyclic_ratio=RATIO)
    t = np.arange(0.0, 10.0, 1e-4)
    cage = RATIO * from_rest(t) * (1.0 - run_up_slip(t) / 100.0)
    start = SETTINGS.min_inner_ring_speed_rad_s / 20.0
    turned = np.cumsum(np.where(t >= start, cage, 0.0)) * 1e-4 / (2.0 * math.pi)
    first_slope = float(t[np.searchsorted(turned, SETTINGS.min_slope_points + 1)])
    assert 2.5 < first_slope < 3.5
    out = run(scenario, speed_changes=(W900 / 20.0,), settle_until=first_slope)
    assert agreement(out) >= 0.95
    assert SlipState.SLIPPING in out.states and out.states[-1] == SlipState.STABLE
    assert SlipState.FAULT not in out.states


@pytest.mark.parametrize(
    ("name", "changes"),
    [
        ("0.5 % of pulses lost, isolated", {"lost_fraction": 0.005, "seed": 7}),
        ("a burst of 20 lost pulses on each shaft", {"bursts": (Burst("cage", 8.0, 20), Burst("spindle", 14.0, 20))}),
        ("10 us of timing jitter", {"jitter_s": 10e-6, "seed": 3}),
        ("a bench clock at 1.73e9 s", {"epoch_s": 1.73e9}),
    ],
)
def test_sensor_imperfections_are_no_fault_and_change_no_verdict(name: str, changes: dict) -> None:
    base = BenchScenario(30.0, constant(W900), step_decay, epicyclic_ratio=RATIO)
    scenario = BenchScenario(**{**base.__dict__, **changes})
    out = run(scenario)
    assert SlipState.FAULT not in out.states, name
    assert agreement(out) >= 0.95, name
    assert first_verdict(out) <= 1.5, name
    assert state_changes(out, PLATEAU_AFTER_DECAY, 30.0) == 0 and state_changes(out, SETTLE_S, 5.0) == 0, name
    if "lost_fraction" in changes or "bursts" in changes:
        last = out.statuses[-1]
        assert sum(last.lost) > 0  # counted, for /diagnostics


def test_a_stopped_sensor_is_a_fault_within_the_loss_rule() -> None:
    """The cage sensor stops at 10 s while the spindle turns on: FAULT from 8 cage revolutions
    (plus one check) later, never before."""
    scenario = BenchScenario(20.0, constant(W900), constant(2.0), epicyclic_ratio=RATIO, sensor_stops=(("cage", 10.0),))
    out = run(scenario)
    cage_revolution = 2.0 * math.pi / (RATIO * 0.98 * W900)
    limit = 10.0 + SETTINGS.loss_silence_revolutions * cage_revolution
    faults = out.times[out.states == SlipState.FAULT]
    assert faults.size and limit <= faults[0] <= limit + 2.0 / SETTINGS.status_rate_hz + 1e-6
    assert np.all(out.states[out.times > faults[0]] == SlipState.FAULT)
    assert "cage" in out.statuses[-1].detail and "sensor loss" in out.statuses[-1].detail
    before = out.times < 10.0
    assert np.mean(out.states[before & out.settled] == out.truth[before & out.settled]) >= 0.95


def test_a_bench_bag_analysed_offline_gives_the_schedules_statuses(tmp_path: Path) -> None:
    """One policy: `analyze` on a bench bag (pulse topics and load cell only, bench clock) gives
    the states the schedule gives on the same pulses."""
    scenario = BenchScenario(12.0, constant(W900), step_decay, epicyclic_ratio=RATIO, lost_fraction=0.002, seed=5, load_n=constant(300.0))
    bag = write_bench_bag(tmp_path / "bench", scenario)
    rows: list = []
    result = analyse_bag(bag, on_row=rows.append)
    direct = run(scenario)
    assert [r.state for r in rows] == [int(s) for s in direct.states]
    assert result.first_time == pytest.approx(scenario.epoch_s, abs=0.1)


def test_a_bench_bag_of_unstamped_pulses_is_analysed_on_its_log_times(tmp_path: Path) -> None:
    """A counter that leaves the header stamps at zero: `analyze` says so and uses the log
    (reception) times, which here are the pulse times, so it gives the same states as the
    stamped bag; without the fallback every pulse would be out of order (all at 0 s)."""
    scenario = BenchScenario(12.0, constant(W900), step_decay, epicyclic_ratio=RATIO, seed=5)
    stamped = analyse_bag(write_bench_bag(tmp_path / "stamped", scenario))
    rows: list = []
    with pytest.warns(UserWarning, match="zero header stamp"):
        unstamped = analyse_bag(write_bench_bag(tmp_path / "unstamped", BenchScenario(**{**scenario.__dict__, "unstamped": True})), on_row=rows.append)
    assert unstamped.windows == stamped.windows > 60
    assert [r.state for r in rows] == [int(s) for s in run(scenario).states]


def sweep_statuses(settings: MonitorSettings, scenario: BenchScenario) -> list:
    monitor = SlipMonitor(settings.kinematics(), settings)
    schedule = StatusSchedule(monitor)
    loads = load_samples(scenario)
    statuses = []
    k = 0
    for shaft, pulse in bench_pulses(scenario):
        while k < len(loads) and loads[k][0] <= pulse.time:
            monitor.add_load(*loads[k])
            k += 1
        statuses += [(r.time - scenario.epoch_s, r.status) for r in schedule.on_pulse(shaft, pulse)]
    return statuses


SWEEP_LOADS = (50.0, 100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0)


def test_axial_load_criterion_is_the_paper_load_sweep() -> None:
    """The paper's sweep at 900 rpm: 8 loads held 3 s each, slip following the first term of the
    paper's 1000 rpm curve (Table 5: 5.18 exp(-((F + 4.14)/214)^2) %) plus 1.8 %, judged with k1
    read as a fraction per newton (-5e-4 %/N; docs/method.md: read as -5e-6 %/N the criterion asks
    for the slope to 1e-6 %/N, below what 3 us of jitter leaves, 0.0006 % per point). The true
    slope -2 a (F - b)/c^2 exp(-((F - b)/c)^2) crosses k1 near 490 N (computed below on a grid
    from the formula, not by the monitor); the Gaussian fitted to the 8 settled points crosses it
    within a load step of there, so the sweep is stable from between 400 and 600 N."""
    settings = MonitorSettings.from_values({**shipped_parameters(), "criterion": "axial_load", "sweep_slip_reference": "nominal"})
    assert settings.critical_slope_pct_per_n == -5e-4  # shipped

    def load(t: np.ndarray) -> np.ndarray:
        return np.asarray(SWEEP_LOADS)[np.minimum(np.floor(np.asarray(t) / 3.0).astype(int), 7)]

    def curve(f: np.ndarray) -> np.ndarray:
        return 1.8 + 5.18 * np.exp(-(((f + 4.14) / 214.0) ** 2))

    scenario = BenchScenario(24.0, constant(W900), lambda t: curve(load(t)), epicyclic_ratio=RATIO, load_n=load)
    statuses = sweep_statuses(settings, scenario)
    assert SlipState.FAULT not in {s.state for _, s in statuses}
    final = statuses[-1][1]
    # the true onset of the curve's slope >= k1, and the first load point at or above it
    f = np.linspace(50.0, 700.0, 650_001)
    slope = -2.0 * 5.18 * (f + 4.14) / 214.0**2 * np.exp(-(((f + 4.14) / 214.0) ** 2))
    onset = float(f[np.flatnonzero(slope < settings.critical_slope_pct_per_n)[-1] + 1])
    assert 480.0 < onset < 500.0
    expected = final.sweep_stable_from
    assert onset - 100.0 < expected < onset + 100.0, final.sweep_verdict
    assert final.sweep_speed == pytest.approx(W900, rel=1e-3)
    assert final.sweep_verdict.startswith(f"stable from {expected:.0f} N")
    # a load below the stable load is slipping by the fit, one at or above it stable
    assert final.state == SlipState.STABLE
    judged = [(t, s) for t, s in statuses if s.sweep_verdict]
    assert judged and judged[0][0] < 4 * 3.0 + 0.1  # the first verdict once 4 loads have settled
    assert all(s.state == SlipState.SLIPPING for t, s in judged if s.axial_load < expected - 5.0 and "stable from" in s.sweep_verdict)


def test_load_sweep_without_enough_points_says_why() -> None:
    """Three loads only: no fit, and the status says how many points there are."""
    settings = MonitorSettings.from_values({**shipped_parameters(), "criterion": "axial_load"})
    load = lambda t: np.where(np.asarray(t) < 3.0, 100.0, np.where(np.asarray(t) < 6.0, 200.0, 300.0))
    scenario = BenchScenario(9.0, constant(W900), constant(2.0), epicyclic_ratio=RATIO, load_n=load)
    statuses = sweep_statuses(settings, scenario)
    final = statuses[-1][1]
    assert final.state == SlipState.UNKNOWN and final.sweep_verdict == ""
    assert "3 settled load point(s) at this speed, a verdict needs 4" in final.detail


def test_sustained_loss_is_a_fault_by_the_stated_rule() -> None:
    """30 % of the cage pulses lost at random: more than max_lost_fraction (20 %) of those
    expected over the last 50 revolutions, a FAULT naming the cage; 0.5 % stays a warning."""
    scenario = BenchScenario(20.0, constant(W900), constant(2.0), epicyclic_ratio=RATIO, lost_fraction=0.3, seed=11)
    out = run(scenario)
    faults = [s for s in out.statuses if s.state == SlipState.FAULT]
    assert faults and all("sustained loss" in s.detail for s in faults)
    assert any("cage" in s.detail for s in faults) and any("spindle" in s.detail for s in faults)


def test_strip_spacing_is_measured_from_the_pulses() -> None:
    """The spindle's strip spacing errors of the generator (mean removed: only differences are
    observable) are found from the pulses to within a few 1e-5 revolution."""
    scenario = BenchScenario(20.0, constant(W900), constant(2.0), epicyclic_ratio=RATIO)
    monitor = SlipMonitor(SETTINGS.kinematics(), SETTINGS)
    for shaft, pulse in bench_pulses(scenario):
        monitor.add_pulse(shaft, pulse)
    errors = np.array(scenario.spacing_error_rev["spindle"])  # by strip id
    measured = monitor.counter.spacing()
    expected = {strip: float(e) for strip, e in enumerate(errors - errors.mean())}
    assert set(measured) == set(expected)
    for strip, value in expected.items():
        assert measured[strip] == pytest.approx(value, abs=3e-5)


@pytest.mark.parametrize("acceleration", [20.0, 80.0])
def test_strip_spacing_is_measured_during_a_run_up(acceleration: float) -> None:
    """A run-up from rest at constant acceleration (no steady revolution before 2 s): the
    spindle's strip spacing errors of the generator (mean removed) are found from the pulses of
    its first 2 s to within a few 1e-5 revolution, so the run-up's windows do not carry them
    (uncorrected, 1e-3 revolution moves a one-revolution window's slip by up to 0.06 %)."""
    scenario = BenchScenario(2.0, lambda t: acceleration * np.asarray(t), constant(1.0), epicyclic_ratio=RATIO)
    monitor = SlipMonitor(SETTINGS.kinematics(), SETTINGS)
    for shaft, pulse in bench_pulses(scenario):
        monitor.add_pulse(shaft, pulse)
    errors = np.array(scenario.spacing_error_rev["spindle"])
    measured = monitor.counter.spacing()
    assert set(measured) == set(range(4))
    for strip, value in enumerate(errors - errors.mean()):
        assert measured[strip] == pytest.approx(float(value), abs=3e-5)


def _backlogged(pulses: list, start: float, end: float) -> list:
    """The arrival order after a subscriber held up from ``start`` to ``end`` (s from the epoch
    offset): the backlog of each topic comes one message per topic in turn, as an executor
    serves two ready subscriptions."""
    t0 = pulses[0][1].time
    before = [p for p in pulses if p[1].time - t0 < start]
    during = [p for p in pulses if start <= p[1].time - t0 < end]
    after = [p for p in pulses if p[1].time - t0 >= end]
    queues = {s: [p for p in during if p[0] == s] for s in ("spindle", "cage")}
    turns = []
    while queues["spindle"] or queues["cage"]:
        for s in ("cage", "spindle"):
            if queues[s]:
                turns.append(queues[s].pop(0))
    return before + turns + after


def test_a_backlog_of_the_two_topics_is_put_back_in_time_order() -> None:
    """After a 2 s hold-up at 2100 rpm the cage backlog runs ahead of the spindle's in time; fed
    as received, the checks find the spindle silent (FAULT); through PulseMerger, the pulses go
    on in time order (within two pulse intervals) and no FAULT comes."""
    w = 2100.0 * math.pi / 30.0
    scenario = BenchScenario(10.0, constant(w), constant(2.0), epicyclic_ratio=RATIO)
    arrivals = _backlogged(bench_pulses(scenario), 4.0, 6.0)

    def states(merge: bool) -> tuple[list[int], list[float]]:
        monitor = SlipMonitor(SETTINGS.kinematics(), SETTINGS)
        schedule, merger = StatusSchedule(monitor), PulseMerger()
        out, order = [], []
        for k, (shaft, pulse) in enumerate(arrivals):
            released = merger.push(shaft, pulse, wall_now=k * 1e-4) if merge else [(shaft, pulse)]
            for s, p in released:
                order.append(p.time)
                out += [int(r.status.state) for r in schedule.on_pulse(s, p)]
        return out, order

    unmerged, _ = states(False)
    assert SlipState.FAULT in unmerged  # the problem is real
    merged, order = states(True)
    assert SlipState.FAULT not in merged
    # in time order up to the merger's tolerance: two pulse intervals of the other shaft
    latest = np.maximum.accumulate(np.array(order))
    spindle_interval = 2.0 * math.pi / (4 * w)
    assert np.max(latest - np.array(order)) <= 2.0 * spindle_interval * 1.01


def test_kinematic_slip_removes_the_contact_angle_and_either_slip_can_be_judged() -> None:
    """A sweep at 900 rpm whose cage runs at the kinematic slip S_k(F) = 5.18 exp(-((F + 4.14)/214)^2) %
    (Table 5's first term) against the pure-rolling speed at the loaded contact angle a(F). The
    paper's nominal-angle slip is then 100 (1 - r(a(F)) / r(a0) (1 - S_k/100)), which keeps falling
    as the load raises the angle (by hand: r = (1 - Dw cos a / dm)/2, a from 18.65 to 18.95 deg
    between 600 and 700 N, a fall of about 2.9e-4 %/N) and goes negative at high load. With k1 =
    -1e-4 %/N: judging the nominal slip, no stable state (its slope at 700 N is below k1);
    judging the kinematic slip, stable from the true onset of S_k's slope >= k1 (between 500 and
    600 N, from the formula), as the fit to the 8 points finds it within a load step. The load
    sweep's own parameter, ``sweep_slip_reference``, says which it judges. Both slips are on every
    status."""
    base = {**shipped_parameters(), "criterion": "axial_load", "critical_slope_pct_per_n": -1e-4}
    thrust = ThrustContact.from_config(SETTINGS.bearing_file)
    kin = SETTINGS.kinematics()

    def load(t: np.ndarray) -> np.ndarray:
        return np.asarray(SWEEP_LOADS)[np.minimum(np.floor(np.asarray(t) / 3.0).astype(int), 7)]

    def kinematic(f: np.ndarray) -> np.ndarray:
        return 5.18 * np.exp(-(((f + 4.14) / 214.0) ** 2))

    def ratio(f: float) -> float:
        return kin.at_contact_angle(thrust.loaded_contact_angle(f)).epicyclic_ratio()

    ratios = np.array([ratio(x) for x in SWEEP_LOADS])

    def nominal(t: np.ndarray) -> np.ndarray:
        f = load(t)
        r = ratios[np.searchsorted(SWEEP_LOADS, f)]
        return 100.0 * (1.0 - r / RATIO * (1.0 - kinematic(f) / 100.0))

    scenario = BenchScenario(24.0, constant(W900), nominal, epicyclic_ratio=RATIO, load_n=load)
    assert nominal(np.array([22.0]))[0] < -0.2  # 700 N: the nominal slip is negative
    f = np.linspace(50.0, 700.0, 650_001)
    slope = -2.0 * 5.18 * (f + 4.14) / 214.0**2 * np.exp(-(((f + 4.14) / 214.0) ** 2))
    onset = float(f[np.flatnonzero(slope < -1e-4)[-1] + 1])
    assert 500.0 < onset < 600.0
    by_nominal = sweep_statuses(MonitorSettings.from_values({**base, "sweep_slip_reference": "nominal"}), scenario)[-1][1]
    by_loaded = sweep_statuses(MonitorSettings.from_values({**base, "sweep_slip_reference": "loaded"}), scenario)[-1][1]
    assert math.isnan(by_nominal.sweep_stable_from) and "below k1" in by_nominal.sweep_verdict
    assert onset - 100.0 < by_loaded.sweep_stable_from < onset + 100.0, by_loaded.sweep_verdict
    for status in (by_nominal, by_loaded):
        assert status.kinematic_slip_rate == pytest.approx(float(kinematic(np.array([700.0]))[0]), abs=0.005)
        assert status.slip_rate == pytest.approx(float(nominal(np.array([23.0]))[0]), abs=0.005)
        assert math.degrees(status.loaded_contact_angle) == pytest.approx(18.95, abs=0.01)


ONSET_DELAY_S = 1.5
"""Issue 25: a stable verdict within 1.5 s after the true onset (the Table 7 curve's slope rising
through k2, from the formula: 1.67, 1.41, 1.23, 0.97 s at 20-80 rad/s^2)."""


@pytest.mark.parametrize("seed", [0, 4, 5])
@pytest.mark.parametrize("acceleration", [20.0, 40.0, 60.0, 80.0])
def test_run_ups_of_the_paper_are_judged_stable_and_stay_so(acceleration: float, seed: int) -> None:
    """Run-ups from rest at the paper's accelerations with the slip of its Table 7 curves (3 us of
    jitter): no FAULT; no stable verdict before the true onset, one within ONSET_DELAY_S after it,
    kept to the end. (Measured 0.5-1.4 s; before the cage's phase decided the slope and the
    spindle's strips were measured in the run-up, 2.0-2.7 s: the bound here was 3 s.)"""
    scenario = table7_run_up(acceleration, epicyclic_ratio=RATIO, seed=seed)
    onset = table7_onset(acceleration, K2)
    out = run(scenario)
    assert SlipState.FAULT not in out.states
    stable = out.times[out.states == SlipState.STABLE]
    assert stable.size and onset <= stable[0] <= onset + ONSET_DELAY_S
    assert np.all(out.states[out.times >= stable[0]] == SlipState.STABLE)


@pytest.mark.parametrize(
    ("acceleration", "changes"),
    [
        (20.0, {"lost_fraction": 0.005, "seed": 1}),
        (60.0, {"bursts": (Burst("cage", 1.8, 8),)}),
        (20.0, {"bursts": (Burst("cage", 1.77, 8),)}),  # 0.1 s after the onset (1.67 s)
        (40.0, {"jitter_s": 10e-6, "seed": 2}),
    ],
)
def test_run_ups_with_sensor_imperfections_are_judged_stable_after_the_onset(acceleration: float, changes: dict) -> None:
    """The same run-ups with 0.5 % of the pulses lost, a burst of 8 lost cage pulses (2 revolutions)
    just after the onset, or 10 us of jitter: no FAULT, never stable before the onset, stable
    within ONSET_DELAY_S after it and kept. (Seeds 100-119 of each case at 20-80 rad/s^2:
    0.53-1.43 s at a stable_confidence of 0.95; a burst of 2 cage revolutions 0.1 s after the
    onset at 20 rad/s^2, where the cage gives some 9 pulses a second, took 1.83 s then and 1.43 s
    at the shipped 0.6, tested below. Before the phase's stretch reached back to
    PHASE_MIN_PULSES pulses, 10 us of jitter took up to 1.8 s.)"""
    scenario = table7_run_up(acceleration, epicyclic_ratio=RATIO, **changes)
    onset = table7_onset(acceleration, K2)
    out = run(scenario)
    assert SlipState.FAULT not in out.states
    stable = out.times[out.states == SlipState.STABLE]
    assert stable.size and onset <= stable[0] <= onset + ONSET_DELAY_S
    assert np.all(out.states[out.times >= stable[0]] == SlipState.STABLE)


@pytest.mark.parametrize(("rpm", "first_stable_s"), [(900.0, 1.5), (1500.0, 1.5), (3000.0, 1.5), (9000.0, 1.5)])
def test_a_hold_with_50_us_of_jitter_is_stable_and_its_median_slip_true(rpm: float, first_stable_s: float) -> None:
    """A 10 s hold at constant 2 % slip with 50 us of timing jitter on every pulse: no FAULT, a
    stable verdict that is kept, and the median slip of the statuses within 0.02 pp of the truth
    (windows of at least min_window_s = 0.1 s: at 9000 rpm a one-revolution window's slip
    scatters by about 0.45 % under this jitter, a 0.1 s one by 0.07 %). The verdict comes within
    1.5 s (issue 25). At 900 rpm the data hardly allow it: the cage's phase over T seconds (26
    pulses a second, each 50 us = 2e-3 rad off, the spindle's angle as much again) leaves the
    slope a standard error of about 0.034 T^-2.5 %/s, and a 95 % bound cleared k2 = -0.03 %/s
    from a true slope of 0 within 1.5 s for 75 % of seeds; the shipped stable_confidence of 0.6
    does for all 40 held-out seeds (docs/method.md). (Before the phase fit: 3-4 s.)"""
    w = rpm * math.pi / 30.0
    scenario = BenchScenario(10.0, constant(w), constant(2.0), epicyclic_ratio=RATIO, jitter_s=50e-6, seed=3)
    out = run(scenario)
    assert SlipState.FAULT not in out.states
    stable = out.times[out.states == SlipState.STABLE]
    assert stable.size and stable[0] <= first_stable_s
    assert np.all(out.states[out.times >= stable[0]] == SlipState.STABLE)
    slips = [s.slip_rate for s in out.statuses if math.isfinite(s.slip_rate)]
    assert abs(float(np.median(slips)) - 2.0) <= 0.02
