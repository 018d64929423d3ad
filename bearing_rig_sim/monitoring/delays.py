"""How soon the monitor says stable on bench-like recordings: ``python -m bearing_rig_sim.monitoring.delays``.

Prints, for the paper's run-ups from rest (Table 7 curves, synthetic/bench.py) at 20-80 rad/s^2,
the first STABLE status after the true onset (the curve's slope rising through k2), and for 10 s
holds at constant 2 % slip with 50 us of timing jitter the first STABLE status after the start,
each over several seeds of the jitter, with whether a verdict before it was false and whether the
stable one was kept. The shipped monitor parameters (config/monitor.yaml) are used.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence

import numpy as np

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring.monitor import SlipMonitor
from bearing_rig_sim.monitoring.schedule import StatusSchedule
from bearing_rig_sim.monitoring.settings import MonitorSettings
from bearing_rig_sim.synthetic.bench import TABLE7, BenchScenario, Profile, bench_pulses, table7_onset, table7_run_up


def constant(value: float) -> Profile:
    """A profile of constant ``value`` (rad/s or percent)."""

    def profile(t: np.ndarray) -> np.ndarray:
        return np.full_like(t, value)

    return profile


def statuses(settings: MonitorSettings, scenario: BenchScenario) -> tuple[np.ndarray, np.ndarray]:
    """Times (s from the recording's start) and states of every status the schedule gives."""
    schedule = StatusSchedule(SlipMonitor(settings.kinematics(), settings))
    rows = []
    for shaft, pulse in bench_pulses(scenario):
        rows += schedule.on_pulse(shaft, pulse)
    final = schedule.finish()
    if final is not None:
        rows.append(final)
    return np.array([r.time for r in rows]) - scenario.epoch_s, np.array([int(r.status.state) for r in rows])


def first_stable(times: np.ndarray, states: np.ndarray) -> tuple[float, bool]:
    """Time of the first STABLE status (inf if none) and whether every later status is STABLE."""
    stable = times[states == SlipState.STABLE]
    if not stable.size:
        return math.inf, False
    return float(stable[0]), bool(np.all(states[times >= stable[0]] == SlipState.STABLE))


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5, help="seeds of the jitter per case (default 5)")
    args = parser.parse_args(argv)
    settings = MonitorSettings.from_yaml()
    ratio = settings.kinematics().epicyclic_ratio()
    k2 = settings.critical_slope_pct_per_s
    print("run-ups from rest, Table 7 slip, 3 us jitter: first STABLE after the true onset, s")
    for acceleration in TABLE7:
        onset = table7_onset(acceleration, k2)
        delays, notes = [], set()
        for seed in range(args.seeds):
            times, states = statuses(settings, table7_run_up(acceleration, epicyclic_ratio=ratio, seed=seed))
            at, kept = first_stable(times, states)
            delays.append(at - onset)
            if np.any(states[times < onset] == SlipState.STABLE):
                notes.add("STABLE before the onset")
            if not kept:
                notes.add("not kept")
            if SlipState.FAULT in states:
                notes.add("FAULT")
        print(f"  {acceleration:4.0f} rad/s^2 (onset {onset:.2f} s): {min(delays):.2f} to {max(delays):.2f} {'; '.join(sorted(notes))}")
    print("10 s holds at 2 % slip, 50 us jitter: first STABLE after the start, s")
    for rpm in (900.0, 1500.0, 3000.0, 9000.0):
        w = rpm * math.pi / 30.0
        firsts, notes = [], set()
        for seed in range(args.seeds):
            scenario = BenchScenario(10.0, constant(w), constant(2.0), epicyclic_ratio=ratio, jitter_s=50e-6, seed=seed)
            times, states = statuses(settings, scenario)
            at, kept = first_stable(times, states)
            firsts.append(at)
            if SlipState.SLIPPING in states:
                notes.add("a false SLIPPING")
            if not kept:
                notes.add("not kept")
            if SlipState.FAULT in states:
                notes.add("FAULT")
        print(f"  {rpm:5.0f} rpm: {min(firsts):.2f} to {max(firsts):.2f} (median {float(np.median(firsts)):.2f}) {'; '.join(sorted(notes))}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
