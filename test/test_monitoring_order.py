"""The monitor's statuses depend on the pulses' stamps, not on the order they were received in
(monitoring/schedule.py ``StampOrder``).

The same pulses of a bench-like run-up (the acceleration program's 20 rad/s^2 with the slip of
the paper's Table 7 curve) are received in stamp order, and in the orders a recorder gets after a
hold-up: the spindle's pulses 0.7 s behind the cage's (seen on a loaded host), the cage's 0.3 s
behind, and each pulse delayed at random by up to 0.5 s (each shaft's own order kept). Put back in
order by their stamps, every interleaving gives the statuses of the stamp order exactly, offline
(``StampOrder``, ``analyze``'s) and live (``PulseMerger``, the node's): the live summary, the
replay of its bag and the recorded statuses agree on every verdict.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring.monitor import SlipMonitor
from bearing_rig_sim.monitoring.schedule import MERGE_MAX_WAIT_S, ORDER_MAX_LEAD_S, PulseMerger, StampOrder, StatusSchedule
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.rig.fibre_optic import Pulse
from bearing_rig_sim.synthetic.bench import bench_pulses, table7_run_up, write_bench_bag

SETTINGS = MonitorSettings.from_yaml()
RATIO = SETTINGS.kinematics().epicyclic_ratio()
SCENARIO = table7_run_up(20.0, epicyclic_ratio=RATIO, seed=0)
PULSES = bench_pulses(SCENARIO)


def released(arrivals: list[tuple[float, str, Pulse]], order: StampOrder | PulseMerger | None) -> list[tuple[str, Pulse]]:
    """The pulses received at the given times (s), in the order ``order`` lets them go on (as
    received without one); a PulseMerger's held pulses go on when both shafts have been silent
    for its ``max_wait_s`` after the last, a StampOrder's at the end of the recording."""
    out: list[tuple[str, Pulse]] = []
    for at, shaft, pulse in arrivals:
        if isinstance(order, PulseMerger):
            out += order.push(shaft, pulse, at)
        elif order is not None:
            out += order.push(shaft, pulse)
        else:
            out.append((shaft, pulse))
    if isinstance(order, PulseMerger):
        out += order.expire(arrivals[-1][0] + 2.0 * order.max_wait_s)
    elif order is not None:
        out += order.flush()
    return out


def statuses(received: list[tuple[str, Pulse]] | list[tuple[float, str, Pulse]], order: StampOrder | PulseMerger | None) -> list[tuple[float, str, int, float]]:
    """(time, reason, state, confidence) of every status the schedule gives on the pulses in the
    order received (with or without their reception times), put in stamp order first by
    ``order`` if given."""
    schedule = StatusSchedule(SlipMonitor(SETTINGS.kinematics(), SETTINGS))
    arrivals = [a if len(a) == 3 else (0.0, *a) for a in received]
    out = []
    for ordered in released(arrivals, order):
        out += schedule.on_pulse(*ordered)
    final = schedule.finish()
    assert final is not None
    return [(r.time, r.reason, int(r.status.state), r.status.confidence) for r in [*out, final]]


def arrivals(lag: dict[str, float], spread_s: float = 0.0, seed: int = 0) -> list[tuple[float, str, Pulse]]:
    """The pulses with their reception times, in that order: stamp + the shaft's lag + a random
    delay up to ``spread_s`` (each shaft's reception times kept increasing, as one topic's queue
    does)."""
    rng = np.random.default_rng(seed)
    out, latest = [], {"spindle": -np.inf, "cage": -np.inf}
    for shaft, pulse in PULSES:
        at = max(pulse.time + lag.get(shaft, 0.0) + rng.uniform(0.0, spread_s), latest[shaft])
        latest[shaft] = at
        out.append((at, shaft, pulse))
    out.sort(key=lambda a: a[0])
    return out


def received(lag: dict[str, float], spread_s: float = 0.0, seed: int = 0) -> list[tuple[str, Pulse]]:
    """The pulses in the order of their reception (:func:`arrivals`)."""
    return [(shaft, pulse) for _, shaft, pulse in arrivals(lag, spread_s, seed)]


EXPECTED = statuses(PULSES, None)


def test_the_run_up_in_stamp_order_is_judged_without_fault() -> None:
    states = {state for _, _, state, _ in EXPECTED}
    assert SlipState.STABLE in states and SlipState.FAULT not in states


@pytest.mark.parametrize(("lag", "spread_s"), [({"spindle": 0.7}, 0.0), ({"cage": 0.3}, 0.0), ({}, 0.5)])
def test_every_interleaving_put_in_stamp_order_gives_the_same_statuses(lag: dict[str, float], spread_s: float) -> None:
    order = received(lag, spread_s)
    assert order != PULSES
    assert statuses(order, StampOrder()) == EXPECTED


def test_replayed_in_reception_order_the_run_up_was_judged_a_fault() -> None:
    """Why the order matters: fed as received with the spindle 0.7 s behind, the schedule's
    checks find the spindle silent (FAULT), which the live monitor never reported."""
    assert SlipState.FAULT in {state for _, _, state, _ in statuses(received({"spindle": 0.7}), None)}


def test_analyze_of_a_bag_recorded_out_of_order_gives_the_stamp_orders_statuses(tmp_path: Path) -> None:
    """A bench bag whose spindle messages were logged 0.7 s after their stamps: ``analyze`` gives
    the states of the stamp order (it gave FAULT)."""
    rows: list = []
    analyse_bag(write_bench_bag(tmp_path / "late", SCENARIO, log_lag_s={"spindle": 0.7}), on_row=rows.append)
    assert [r.state for r in rows] == [state for _, _, state, _ in EXPECTED]


STAMP_ORDER = sorted(PULSES, key=lambda p: (p[1].time, p[0]))
"""The pulses merged by stamp, equal stamps cage first: the order both mergers must give."""


@pytest.mark.parametrize("seed", range(12))
def test_the_live_merger_gives_the_replays_order_on_random_interleavings(seed: int) -> None:
    """Each shaft's pulses received with its own lag (0-0.6 s) plus a random delay up to 0.3 s, in
    its own order, each shaft heard of more often than every MERGE_MAX_WAIT_S from the first
    pulse on (reception times are steady-clock times here): the live merger (PulseMerger) lets them go on in exactly the
    order of the replay (StampOrder), the stamp order. (The merger before it let some go up to two
    of the other shaft's pulse intervals early.)"""
    rng = np.random.default_rng(1000 + seed)
    lag = {"spindle": float(rng.uniform(0.0, 0.6)), "cage": float(rng.uniform(0.0, 0.6))}
    got = arrivals(lag, spread_s=0.3, seed=seed)
    assert abs(lag["spindle"] - lag["cage"]) + 0.3 < ORDER_MAX_LEAD_S
    for shaft in ("spindle", "cage"):
        heard = [at for at, s, _ in got if s == shaft]
        assert max(np.diff(heard)) < MERGE_MAX_WAIT_S and abs(heard[0] - got[0][0]) < MERGE_MAX_WAIT_S
    live, replay = released(got, PulseMerger()), released(got, StampOrder())
    assert live == replay == STAMP_ORDER


@pytest.mark.parametrize(("lag", "spread_s"), [({"spindle": 0.7}, 0.0), ({"cage": 0.3}, 0.0), ({}, 0.5)])
def test_the_live_merger_gives_the_statuses_of_the_stamp_order(lag: dict[str, float], spread_s: float) -> None:
    """The interleavings above through the live merger: the statuses of the stamp order exactly."""
    assert statuses(arrivals(lag, spread_s), PulseMerger()) == EXPECTED


def test_the_live_merger_holds_no_pulse_for_a_shaft_not_heard_of() -> None:
    """The cage falls silent after one pulse (a dead sensor), the spindle's later pulses come 10 ms
    apart on the steady clock: they wait for the cage's next pulse until the cage has not been
    heard of for MERGE_MAX_WAIT_S, then go on as they come, in order, so the schedule's checks
    see the silence."""
    merger = PulseMerger()
    cage = next(pulse for shaft, pulse in PULSES if shaft == "cage")
    spindle = [pulse for shaft, pulse in PULSES if shaft == "spindle" and pulse.time > cage.time][:200]
    out = [p for _, p in merger.push("cage", cage, 0.0)]
    for k, pulse in enumerate(spindle, start=1):
        out += [p for _, p in merger.push("spindle", pulse, 0.01 * k)]
        held = k + 1 - len(out)
        assert held == (k if 0.01 * k <= MERGE_MAX_WAIT_S else 0)
    assert out == [cage, *spindle]
