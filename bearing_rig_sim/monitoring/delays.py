"""How soon the monitor says stable on bench-like recordings: ``python -m bearing_rig_sim.monitoring.delays``.

Prints, for the paper's run-ups from rest (Table 7 curves, synthetic/bench.py) at 20-80 rad/s^2,
the first STABLE status after the true onset (the curve's slope rising through k2), and for 10 s
holds at constant 2 % slip with 50 us of timing jitter the first STABLE status after the start,
and for the 20 rad/s^2 run-up with a burst of 8 lost cage pulses just after its onset, each over
several seeds of the jitter, with the share within 1.5 s, whether a verdict before it was false
and whether the stable one was kept. The shipped monitor parameters (config/monitor.yaml) are used.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Iterable, Sequence

import numpy as np

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring.monitor import SlipMonitor
from bearing_rig_sim.monitoring.schedule import StatusSchedule
from bearing_rig_sim.monitoring.settings import MonitorSettings, shipped_parameters
from bearing_rig_sim.synthetic.bench import TABLE7, BenchScenario, Burst, Profile, bench_pulses, table7_onset, table7_run_up


BURST_AFTER_ONSET_S = 0.1
"""The burst case: 8 cage pulses (2 revolutions) lost from this long after the onset of the
20 rad/s^2 run-up, where the cage gives some 9 pulses a second (s)."""


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


def first_stable_after(settings: MonitorSettings, scenarios: Iterable[BenchScenario], onset: float, *, slipping_expected: bool) -> tuple[list[float], set[str]]:
    """For each recording, the first STABLE status's delay after ``onset`` (s from the
    recording's start; inf if none), and what went wrong in any of them: a STABLE before the
    onset, a SLIPPING where none is expected (a constant slip), a STABLE not kept, a FAULT."""
    delays: list[float] = []
    notes: set[str] = set()
    for scenario in scenarios:
        times, states = statuses(settings, scenario)
        at, kept = first_stable(times, states)
        delays.append(at - onset)
        if np.any(states[times < onset] == SlipState.STABLE):
            notes.add("STABLE before the onset")
        if not slipping_expected and SlipState.SLIPPING in states:
            notes.add("a false SLIPPING")
        if not kept:
            notes.add("not kept")
        if SlipState.FAULT in states:
            notes.add("FAULT")
    return delays, notes


DELAY_BOUND_S = 1.5
"""Issue 25's bound on the first STABLE after the true onset, s: each case prints the share of
seeds within it."""


def _line(label: str, delays: list[float], notes: set[str]) -> str:
    """One printed case: range, median and share within :data:`DELAY_BOUND_S` of the delays (s)."""
    within = sum(d <= DELAY_BOUND_S for d in delays)
    return (
        f"  {label}: {min(delays):.2f} to {max(delays):.2f} (median {float(np.median(delays)):.2f}; "
        f"{within}/{len(delays)} within {DELAY_BOUND_S:g} s) {'; '.join(sorted(notes))}"
    ).rstrip()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=5, help="seeds of the jitter per case (default 5)")
    parser.add_argument("--first-seed", type=int, default=0, help="first seed (default 0; held-out checks use others)")
    parser.add_argument("--stable-confidence", type=float, default=None, help="override the monitor's stable_confidence (default: config/monitor.yaml's)")
    args = parser.parse_args(argv)
    settings = MonitorSettings.from_yaml()
    if args.stable_confidence is not None:
        settings = MonitorSettings.from_values({**shipped_parameters(), "stable_confidence": args.stable_confidence})
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    ratio = settings.kinematics().epicyclic_ratio()
    k2 = settings.critical_slope_pct_per_s
    print(f"stable_confidence {settings.stable_confidence:g}, seeds {seeds.start}-{seeds.stop - 1}")
    print("run-ups from rest, Table 7 slip, 3 us jitter: first STABLE after the true onset, s")
    run_ups: list[tuple[str, float, tuple[Burst, ...]]] = [(f"{a:4.0f} rad/s^2", a, ()) for a in TABLE7]
    burst_onset = table7_onset(20.0, k2)
    run_ups.append(
        (f"  20 rad/s^2, 8 cage pulses lost {BURST_AFTER_ONSET_S:g} s after the onset", 20.0, (Burst("cage", burst_onset + BURST_AFTER_ONSET_S, 8),))
    )
    for label, acceleration, bursts in run_ups:
        onset = table7_onset(acceleration, k2)
        run_up = (table7_run_up(acceleration, epicyclic_ratio=ratio, seed=seed, bursts=bursts) for seed in seeds)
        print(_line(f"{label} (onset {onset:.2f} s)", *first_stable_after(settings, run_up, onset, slipping_expected=True)))
    print("10 s holds at 2 % slip, 50 us jitter: first STABLE after the start, s")
    for rpm in (900.0, 1500.0, 3000.0, 9000.0):
        w = rpm * math.pi / 30.0
        holds = (BenchScenario(10.0, constant(w), constant(2.0), epicyclic_ratio=ratio, jitter_s=50e-6, seed=seed) for seed in seeds)
        print(_line(f"{rpm:5.0f} rpm", *first_stable_after(settings, holds, 0.0, slipping_expected=False)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
