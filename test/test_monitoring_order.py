"""The monitor's statuses depend on the pulses' stamps, not on the order they were received in
(monitoring/schedule.py ``StampOrder``).

The same pulses of a bench-like run-up (the acceleration program's 20 rad/s^2 with the slip of
the paper's Table 7 curve) are received in stamp order, and in the orders a recorder gets after a
hold-up: the spindle's pulses 0.7 s behind the cage's (seen on a loaded host), the cage's 0.3 s
behind, and each pulse delayed at random by up to 0.5 s (each shaft's own order kept). Put back in
order by their stamps, every interleaving gives the statuses of the stamp order exactly.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring.monitor import SlipMonitor
from bearing_rig_sim.monitoring.schedule import StampOrder, StatusSchedule
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.synthetic.bench import bench_pulses, table7_run_up, write_bench_bag

SETTINGS = MonitorSettings.from_yaml()
RATIO = SETTINGS.kinematics().epicyclic_ratio()
SCENARIO = table7_run_up(20.0, epicyclic_ratio=RATIO, seed=0)
PULSES = bench_pulses(SCENARIO)


def statuses(received: list[tuple[str, Pulse]], order: StampOrder | None) -> list[tuple[float, str, int, float]]:
    """(time, reason, state, confidence) of every status the schedule gives on the pulses in the
    order received, put in stamp order first by ``order`` if given."""
    schedule = StatusSchedule(SlipMonitor(SETTINGS.kinematics(), SETTINGS))
    out = []
    for shaft, pulse in received:
        for ordered in order.push(shaft, pulse) if order is not None else [(shaft, pulse)]:
            out += schedule.on_pulse(*ordered)
    for ordered in order.flush() if order is not None else []:
        out += schedule.on_pulse(*ordered)
    final = schedule.finish()
    assert final is not None
    return [(r.time, r.reason, int(r.status.state), r.status.confidence) for r in [*out, final]]


def received(lag: dict[str, float], spread_s: float = 0.0, seed: int = 0) -> list[tuple[str, Pulse]]:
    """The pulses in the order of their reception: stamp + the shaft's lag + a random delay up
    to ``spread_s`` (each shaft's reception times kept increasing, as one topic's queue does)."""
    rng = np.random.default_rng(seed)
    arrivals, latest = [], {"spindle": -np.inf, "cage": -np.inf}
    for shaft, pulse in PULSES:
        at = max(pulse.time + lag.get(shaft, 0.0) + rng.uniform(0.0, spread_s), latest[shaft])
        latest[shaft] = at
        arrivals.append((at, shaft, pulse))
    arrivals.sort(key=lambda a: a[0])
    return [(shaft, pulse) for _, shaft, pulse in arrivals]


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


def test_equal_stamps_go_on_cage_first_and_each_shaft_in_its_own_order() -> None:
    """The release rule at ties: a pulse goes on once the other shaft has one at or after it, the
    cage's before the spindle's at the same stamp; the end of the recording flushes the rest in
    stamp order."""
    order = StampOrder(max_lead_s=5.0)
    spindle = [Pulse(t, 0, 1, 0, k) for k, t in enumerate((1.0, 2.0, 2.0, 3.0))]
    cage = [Pulse(t, 0, 1, 0, k) for k, t in enumerate((2.0, 2.5))]
    released = [p for s in spindle for p in order.push("spindle", s)]
    assert released == []  # no cage pulse yet, and the spindle has not run max_lead_s ahead
    released = order.push("cage", cage[0])
    assert released == [("spindle", spindle[0]), ("cage", cage[0]), ("spindle", spindle[1]), ("spindle", spindle[2])]
    assert order.push("cage", cage[1]) == [("cage", cage[1])]  # the spindle is at 3.0 already
    assert order.flush() == [("spindle", spindle[3])]  # the cage never reached 3.0
