"""Bench-like fibre-optic pulse recordings from a known slip history, for testing the monitor.

What a physical bench records, and nothing more: the pulses of the spindle's and the cage's
fibre-optic sensors (``FibreOpticPulse``: stamp, strip id, strip count, pulse index) and the
load cell's force, stamped on the bench computer's system clock (an epoch offset of about
1.7e9 s). The truth is known exactly, because the pulses are made from it:

* the spindle speed ``omega_i(t)`` (rad/s) and the slip ``S(t)`` (percent) are given as
  functions; the cage turns at ``omega_c = r omega_i (1 - S / 100)``, ``r`` the bearing's
  epicyclic ratio (Eq. 11-12 of the paper, docs/paper.md), so the slip of the pulses is ``S``;
* both angles are integrated on a fine grid (trapezoidal rule, 50 us steps); a strip passes the
  sensor when the shaft's angle reaches the strip's position, ``k + j / n + e_j`` revolutions for
  strip ``j`` of ``n`` in revolution ``k``, ``e_j`` the strip's spacing error;
* each pulse time gets Gaussian timing jitter; pulses are then lost at random (isolated), in
  bursts, or for good after a sensor stops; ``pulse_index`` keeps counting the lost ones, as the
  bench's counter does.

:func:`true_verdict` applies the paper's criterion to the true slip curve: stable where its slope
is at or above k.

Units: s, rad/s, N; slip in percent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Callable
from typing import Any

import numpy as np

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.interfaces import AXIAL_LOAD_FORCE, PULSE_TOPICS, SPINDLE_PULSES
from bearing_rig_sim.instruments.fibre_optic import Pulse

BENCH_EPOCH_S = 1_732_300_000.0
"""A bench computer's system clock at the start of a recording, s since 1970."""

GRID_STEP_S = 5e-5
"""Integration step of the shafts' angles, s (angle error below 1e-9 revolutions at 100 rad/s^2)."""

Profile = Callable[[np.ndarray], np.ndarray]
"""A function of time (s, array) giving a speed (rad/s) or a slip (percent)."""


@dataclass(frozen=True)
class Burst:
    """``count`` consecutive pulses of ``shaft`` lost, from the first one after ``time`` (s)."""

    shaft: str
    time: float
    count: int


@dataclass(frozen=True)
class BenchScenario:
    """A bench recording to generate.

    Attributes:
        duration_s: length, s.
        spindle_speed: omega_i(t), rad/s (>= 0).
        slip_pct: S(t), percent.
        epicyclic_ratio: r = cage speed / spindle speed without slip (1).
        strips: strips per shaft (the bench has 4).
        spacing_error_rev: per shaft, each strip's offset from its nominal position, revolutions.
        jitter_s: standard deviation of the timing jitter, s.
        lost_fraction: probability that any one pulse is lost on its own (1).
        bursts: bursts of consecutive lost pulses.
        sensor_stops: (shaft, time): that sensor gives no pulse after ``time`` (s).
        load_n: measured axial force F(t), N, published at ``load_rate_hz``.
        load_rate_hz: load-cell rate, Hz.
        epoch_s: the bench clock at t = 0, s.
        seed: of the jitter and losses.
        unstamped: the pulses' header stamps are left at zero (a counter that does not stamp);
            :func:`write_bench_bag` then carries the pulse times only as log times.
    """

    duration_s: float
    spindle_speed: Profile
    slip_pct: Profile
    epicyclic_ratio: float = 0.4283
    strips: int = 4
    spacing_error_rev: dict[str, tuple[float, ...]] = field(
        default_factory=lambda: {"spindle": (0.0, 0.0014, -0.0009, 0.0006), "cage": (0.0, -0.0011, 0.0007, 0.0012)}
    )
    jitter_s: float = 3e-6
    lost_fraction: float = 0.0
    bursts: tuple[Burst, ...] = ()
    sensor_stops: tuple[tuple[str, float], ...] = ()
    load_n: Profile | None = None
    load_rate_hz: float = 100.0
    epoch_s: float = BENCH_EPOCH_S
    seed: int = 0
    unstamped: bool = False


def _angles(scenario: BenchScenario) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The grid and each shaft's angle on it, revolutions."""
    t = np.arange(0.0, scenario.duration_s + GRID_STEP_S, GRID_STEP_S)
    inner = np.asarray(scenario.spindle_speed(t), dtype=np.float64)
    cage = scenario.epicyclic_ratio * inner * (1.0 - np.asarray(scenario.slip_pct(t), dtype=np.float64) / 100.0)
    out = {}
    for name, speed in (("spindle", inner), ("cage", cage)):
        increments = 0.5 * (speed[1:] + speed[:-1]) * GRID_STEP_S / (2.0 * math.pi)
        out[name] = np.concatenate(([0.0], np.cumsum(increments)))
    return t, out


def bench_pulses(scenario: BenchScenario) -> list[tuple[str, Pulse]]:
    """Every pulse the bench would record, in time order: (shaft, pulse) with bench-clock stamps."""
    rng = np.random.default_rng(scenario.seed)
    t, angles = _angles(scenario)
    n = scenario.strips
    events: list[tuple[float, str, Pulse]] = []
    for shaft, angle in angles.items():
        errors = np.asarray(scenario.spacing_error_rev.get(shaft, (0.0,) * n), dtype=np.float64)[:n]
        turns = int(math.floor(angle[-1]))
        k = np.arange(turns + 1)
        targets = (k[:, None] + np.arange(n)[None, :] / n + errors[None, :]).ravel()
        valid = np.flatnonzero((targets > 0.0) & (targets < angle[-1]))
        if not valid.size:
            continue
        strip_of = valid % n
        targets = targets[valid]
        # a strip passage: the first grid interval where the angle reaches the target
        hi = np.searchsorted(angle, targets, side="left")
        lo = np.clip(hi - 1, 0, angle.size - 1)
        hi = np.clip(hi, 0, angle.size - 1)
        span = angle[hi] - angle[lo]
        with np.errstate(invalid="ignore", divide="ignore"):
            frac = np.where(span > 0.0, (targets - angle[lo]) / span, 0.0)
        times = t[lo] + frac * (t[hi] - t[lo])
        times = times + rng.normal(0.0, scenario.jitter_s, times.size) if scenario.jitter_s > 0.0 else times
        keep = rng.random(times.size) >= scenario.lost_fraction
        for burst in scenario.bursts:
            if burst.shaft == shaft:
                first = int(np.searchsorted(times, burst.time))
                keep[first : first + burst.count] = False
        for stopped, when in scenario.sensor_stops:
            if stopped == shaft:
                keep &= times <= when
        for index in np.flatnonzero(keep):
            i = int(index)
            pulse = Pulse(
                time=scenario.epoch_s + float(times[i]),
                strip_id=int(strip_of[i]),
                strip_count=n,
                revolution=i // n,
                pulse_index=i,
                sensor_id=shaft,
            )
            events.append((pulse.time, shaft, pulse))
    events.sort(key=lambda e: e[0])
    return [(shaft, pulse) for _, shaft, pulse in events]


def load_samples(scenario: BenchScenario) -> list[tuple[float, float]]:
    """The load cell's samples (bench-clock s, N); [] without a load profile."""
    if scenario.load_n is None:
        return []
    t = np.arange(0.0, scenario.duration_s, 1.0 / scenario.load_rate_hz)
    force = np.asarray(scenario.load_n(t), dtype=np.float64)
    return [(scenario.epoch_s + float(a), float(b)) for a, b in zip(t, force)]


def true_verdict(scenario: BenchScenario, times: np.ndarray, critical_slope: float, step: float = 1e-3) -> np.ndarray:
    """The paper's criterion on the true slip curve at ``times`` (s from the start): STABLE where
    dS/dt >= k (%/s), SLIPPING elsewhere (central difference over ``step`` s); int states."""
    times = np.asarray(times, dtype=np.float64)
    slope = (np.asarray(scenario.slip_pct(times + 0.5 * step)) - np.asarray(scenario.slip_pct(times - 0.5 * step))) / step
    return np.where(slope >= critical_slope, int(SlipState.STABLE), int(SlipState.SLIPPING))


def write_bench_bag(path: str | Path, scenario: BenchScenario, log_lag_s: dict[str, float] | None = None) -> Path:
    """Write the scenario's pulses (and load cell, if any) as a bag like the bench's: the pulse
    topics and ``/rig/axial_load/force`` only, log times on the bench clock, each shaft's pulses
    logged ``log_lag_s[shaft]`` (s) after their stamps (a recorder held up). Returns the path."""
    from bearing_rig_sim.bags import BagWriter, rig_typestore  # bag I/O only for this function

    store = rig_typestore()
    types = store.types
    pulse_type = SPINDLE_PULSES.msgtype
    wrench_type = AXIAL_LOAD_FORCE.msgtype

    def header(time_s: float) -> Any:
        ns = int(round(time_s * 1e9))
        return types["std_msgs/msg/Header"](stamp=types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9), frame_id="bench")

    messages: list[tuple[float, str, Any]] = []
    for shaft, p in bench_pulses(scenario):
        message = types[pulse_type](
            header=header(0.0 if scenario.unstamped else p.time),
            sensor_id=shaft,
            strip_id=p.strip_id,
            strip_count=p.strip_count,
            revolution=p.revolution,
            pulse_index=p.pulse_index,
        )
        messages.append((p.time + (log_lag_s or {}).get(shaft, 0.0), PULSE_TOPICS[shaft].name, message))
    vector = types["geometry_msgs/msg/Vector3"]
    for when, force in load_samples(scenario):
        wrench = types["geometry_msgs/msg/Wrench"](force=vector(x=0.0, y=0.0, z=force), torque=vector(x=0.0, y=0.0, z=0.0))
        messages.append((when, AXIAL_LOAD_FORCE.name, types[wrench_type](header=header(when), wrench=wrench)))
    messages.sort(key=lambda m: m[0])
    with BagWriter(path, typestore=store) as bag:
        for topic in (*PULSE_TOPICS.values(), *((AXIAL_LOAD_FORCE,) if scenario.load_n is not None else ())):
            bag.add_topic(topic.name, topic.msgtype, topic.qos)
        for when, topic, message in messages:
            bag.write_message(topic, int(round(when * 1e9)), message)
    return Path(path)


TABLE7: dict[float, tuple[float, float, float]] = {20.0: (3.5, -1.52, 1.29), 40.0: (1.64, -0.73, 0.9), 60.0: (1.33, -0.49, 0.72), 80.0: (0.76, -0.09, 0.45)}
"""The paper's Table 7 (docs/paper.md section 11): rad/s^2 -> (lambda %, k s, d s) of the slip of a
run-up from rest, S(t) = lambda exp(-((t - k)/d)^2)."""


def table7_run_up(acceleration: float, final_speed: float = 157.08, duration_s: float = 8.0, **options: Any) -> BenchScenario:
    """A run-up from rest at ``acceleration`` (rad/s^2, one of :data:`TABLE7`) to ``final_speed``
    (rad/s, then held) whose slip follows the paper's Table 7 curve; ``options`` go to
    :class:`BenchScenario` (jitter, seed, epicyclic ratio...)."""
    lam, k, d = TABLE7[acceleration]
    return BenchScenario(
        duration_s,
        lambda t: np.minimum(acceleration * np.asarray(t), final_speed),
        lambda t: lam * np.exp(-(((np.asarray(t) - k) / d) ** 2)),
        **options,
    )


def table7_onset(acceleration: float, critical_slope: float) -> float:
    """Where the slope of the Table 7 curve last rises through ``critical_slope`` (%/s): the true
    onset of the stable state, s from the run-up's start (closed form: the slope -2 lambda (t - k)/d^2
    exp(-((t - k)/d)^2) solved by Brent's method past its steepest point, t = k + d / sqrt(2))."""
    from scipy.optimize import brentq

    lam, k, d = TABLE7[acceleration]

    def margin(t: float) -> float:
        return -2.0 * lam * (t - k) / d**2 * math.exp(-(((t - k) / d) ** 2)) - critical_slope

    return float(brentq(margin, k + d / math.sqrt(2.0), k + 10.0 * d, xtol=1e-9))
