"""Fibre-optic sensor and pulse counter: crossing times against closed-form shaft motions, the
counter's speed against the true speed and its jitter statistics, lost pulses, bad input.

References are computed here from the shaft's motion law (angle = w t, or w0 t + a t^2 / 2),
never taken from the model's own output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.instruments.fibre_optic import (
    JITTER_CLIP,
    FibreOpticSensor,
    Pulse,
    PulseCounter,
    SensorError,
)

TWO_PI = 2.0 * math.pi


def run_shaft(sensor: FibreOpticSensor, angle, t_end: float, h: float) -> list[Pulse]:
    """Drive ``sensor`` with the angle law ``angle(t)`` in steps of ``h`` from 0 to ``t_end``."""
    pulses: list[Pulse] = []
    steps = int(round(t_end / h))
    for k in range(steps):
        t0, t1 = k * h, (k + 1) * h
        pulses.extend(sensor.update(t0, angle(t0), t1, angle(t1)))
    return pulses


def test_constant_speed_pulses_at_analytic_times_several_per_step() -> None:
    omega, strips, phase, theta0, h = 2000.0, 8, 0.3, 0.1, 1e-3  # 2 rad per step: 2-3 strips per step
    sensor = FibreOpticSensor("spindle", strips, phase=phase)
    pulses = run_shaft(sensor, lambda t: theta0 + omega * t, 0.5, h)
    spacing = TWO_PI / strips
    first = math.floor((theta0 - phase) / spacing) + 1
    expected = [(phase + j * spacing - theta0) / omega for j in range(first, first + len(pulses))]
    assert len(pulses) == math.floor((theta0 + omega * 0.5 - phase) / spacing) - first + 1
    np.testing.assert_allclose([p.time for p in pulses], expected, rtol=0, atol=1e-12)
    assert [p.pulse_index for p in pulses] == list(range(len(pulses)))
    assert [p.strip_id for p in pulses] == [j % strips for j in range(first, first + len(pulses))]
    assert [p.revolution for p in pulses] == [i // strips for i in range(len(pulses))]
    assert all(p.strip_count == strips and p.sensor_id == "spindle" for p in pulses)
    per_step = np.bincount([int(p.time // h) for p in pulses])
    assert per_step.max() >= 3  # several strips within one step, all emitted in order


@pytest.mark.parametrize("window", [1, 3])
def test_counter_returns_true_constant_speed(window: int) -> None:
    omega, strips = 157.0, 4
    sensor = FibreOpticSensor("cage", strips, phase=1.0)
    counter = PulseCounter(strips, revolutions_per_window=window)
    estimates = [counter.add(p) for p in run_shaft(sensor, lambda t: omega * t, 1.0, 1e-3)]
    assert estimates[: strips * window] == [None] * (strips * window)  # needs a whole window first
    speeds = [e for e in estimates if e is not None]
    assert len(speeds) == len(estimates) - strips * window
    np.testing.assert_allclose(speeds, omega, rtol=1e-9)
    assert counter.speed == pytest.approx(omega, rel=1e-9)


def test_counter_jitter_error_follows_window_statistics() -> None:
    # speed = 2 pi R / (t_b - t_a): the window's error is the difference of two independent
    # jitters, so the relative speed error has std sqrt(2) sigma / T_R with T_R = 2 pi R / w.
    omega, strips, sigma = 100.0, 4, 1e-5
    rms = {}
    for window in (1, 4):
        sensor = FibreOpticSensor("spindle", strips, jitter_std=sigma, seed=3)
        counter = PulseCounter(strips, window)
        speeds = [s for s in (counter.add(p) for p in run_shaft(sensor, lambda t: omega * t, 40.0, 1e-3)) if s]
        relative = np.asarray(speeds) / omega - 1.0
        predicted = math.sqrt(2.0) * sigma / (TWO_PI * window / omega)
        rms[window] = float(np.sqrt(np.mean(relative**2)))
        assert len(speeds) > 2000
        assert 0.85 * predicted < rms[window] < 1.15 * predicted
    assert rms[4] < rms[1] / 3.0


def test_jittered_pulses_increase_strictly_and_stay_near_true_crossing() -> None:
    omega, strips, sigma = 300.0, 16, 2e-6
    sensor = FibreOpticSensor("cage", strips, jitter_std=sigma, seed=5)
    pulses = run_shaft(sensor, lambda t: omega * t, 2.0, 1e-3)
    times = np.array([p.time for p in pulses])
    true = np.array([(p.pulse_index + 1) * TWO_PI / strips / omega for p in pulses])
    assert np.all(np.diff(times) > 0.0)
    assert np.max(np.abs(times - true)) <= JITTER_CLIP * sigma + 1e-12
    assert np.std(times - true) == pytest.approx(sigma, rel=0.1)


def test_constant_acceleration_crossing_error_is_the_chord_error() -> None:
    # Linear interpolation of a convex angle curve: for a crossing u seconds into a step of h,
    # the chord lies a u (h - u) / 2 above the curve, so the pulse is early by exactly
    # a u (h - u) / (2 w_mean), at most a h^2 / (8 w_mean).
    omega0, alpha, strips, h = 5.0, 80.0, 4, 2e-3
    theta = lambda t: omega0 * t + 0.5 * alpha * t * t
    sensor = FibreOpticSensor("spindle", strips)
    pulses = run_shaft(sensor, theta, 2.0, h)
    spacing = TWO_PI / strips
    ratios = []
    for p in pulses:
        target = (p.pulse_index + 1) * spacing
        t_true = (-omega0 + math.sqrt(omega0**2 + 2.0 * alpha * target)) / alpha
        k = math.floor(t_true / h)
        u = t_true - k * h
        w_mean = (theta((k + 1) * h) - theta(k * h)) / h
        early = t_true - p.time
        assert early == pytest.approx(alpha * u * (h - u) / (2.0 * w_mean), abs=1e-12)
        bound = alpha * h * h / (8.0 * w_mean)
        assert -1e-12 <= early <= bound + 1e-12
        ratios.append(early / bound)
    assert len(pulses) > 50 and max(ratios) > 0.5  # the bound is reached, not vacuous


def test_zero_and_backward_motion_give_no_spurious_pulses() -> None:
    sensor = FibreOpticSensor("cage", 1)
    assert sensor.update(0.0, 0.5, 0.1, 0.5) == []  # at rest
    assert len(sensor.update(0.1, 0.5, 0.2, 7.0)) == 1  # passes 2 pi
    assert sensor.update(0.2, 7.0, 0.3, 6.0) == []  # rocks back across 2 pi
    assert sensor.update(0.3, 6.0, 0.4, 6.5) == []  # forward again, still behind its furthest angle
    again = sensor.update(0.4, 6.5, 0.5, 12.8)  # passes 4 pi
    assert [p.pulse_index for p in again] == [1]


def test_dropped_pulses_are_flagged_and_estimates_stay_exact() -> None:
    omega, strips = 120.0, 4
    sensor = FibreOpticSensor("cage", strips, seed=9, drop_probability=0.2)
    counter = PulseCounter(strips)
    pulses = run_shaft(sensor, lambda t: omega * t, 3.0, 1e-3)
    speeds = [s for s in (counter.add(p) for p in pulses) if s is not None]
    span = pulses[-1].pulse_index - pulses[0].pulse_index + 1
    assert sensor.pulses_dropped > 0
    assert counter.gap_detected
    assert counter.lost_pulses == span - len(pulses) > 0
    assert speeds and np.allclose(speeds, omega, rtol=1e-9)  # estimates only from received pairs

    healthy = PulseCounter(strips)
    for p in run_shaft(FibreOpticSensor("cage", strips), lambda t: omega * t, 1.0, 1e-3):
        healthy.add(p)
    assert not healthy.gap_detected and healthy.lost_pulses == 0


def test_stale_detection_and_reset() -> None:
    counter = PulseCounter(2)
    assert counter.is_stale(0.0, 0.1)  # nothing received yet
    for p in run_shaft(FibreOpticSensor("spindle", 2), lambda t: 50.0 * t, 0.5, 1e-3):
        counter.add(p)
    last = counter.last_pulse_time
    assert last is not None
    assert not counter.is_stale(last + 0.05, 0.1)
    assert counter.is_stale(last + 0.15, 0.1)
    counter.reset()
    assert counter.speed is None and counter.last_pulse_time is None and counter.is_stale(last, 0.1)

    sensor = FibreOpticSensor("spindle", 2)
    sensor.update(0.0, 0.0, 1.0, 10.0)
    with pytest.raises(SensorError, match="previous step"):
        sensor.update(0.5, 10.0, 1.5, 20.0)  # clock went back
    sensor.reset()
    restarted = sensor.update(0.5, 10.0, 1.5, 20.0)
    assert restarted[0].pulse_index == 0


@pytest.mark.parametrize(
    "args",
    [
        (math.nan, 0.0, 0.1, 1.0),
        (0.0, math.inf, 0.1, 1.0),
        (0.0, 0.0, 0.1, math.nan),
        (0.0, 0.0, 0.0, 1.0),  # zero-length step
        (0.2, 0.0, 0.1, 1.0),  # time going backwards
    ],
)
def test_sensor_refuses_bad_steps(args: tuple[float, float, float, float]) -> None:
    with pytest.raises(SensorError, match="sensor 'cage'"):
        FibreOpticSensor("cage", 4).update(*args)


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"strip_count": 0}, "strip_count"),
        ({"strip_count": 2.0}, "strip_count"),
        ({"jitter_std": -1e-6}, "jitter_std"),
        ({"phase": math.nan}, "phase"),
        ({"drop_probability": 1.0}, "drop_probability"),
    ],
)
def test_sensor_refuses_bad_parameters(kwargs: dict, word: str) -> None:
    args = {"sensor_id": "spindle", "strip_count": 4} | kwargs
    with pytest.raises(SensorError, match=word):
        FibreOpticSensor(**args)


def test_counter_refuses_inconsistent_pulses() -> None:
    counter = PulseCounter(4)
    counter.add(Pulse(time=1.0, strip_id=0, strip_count=4, revolution=0, pulse_index=0))
    with pytest.raises(SensorError, match="pulse_index"):
        counter.add(Pulse(time=2.0, strip_id=0, strip_count=4, revolution=0, pulse_index=0))
    with pytest.raises(SensorError, match="not after"):
        counter.add(Pulse(time=0.5, strip_id=1, strip_count=4, revolution=0, pulse_index=1))
    with pytest.raises(SensorError, match="strip_count"):
        counter.add(Pulse(time=2.0, strip_id=1, strip_count=8, revolution=0, pulse_index=1))
    with pytest.raises(SensorError, match="finite"):
        counter.add(Pulse(time=math.nan, strip_id=1, strip_count=4, revolution=0, pulse_index=1))
    for i in range(1, 4):
        counter.add(Pulse(time=1.0 + i, strip_id=i, strip_count=4, revolution=0, pulse_index=i))
    with pytest.raises(SensorError, match="strip"):  # same index distance, different strip
        counter.add(Pulse(time=6.0, strip_id=3, strip_count=4, revolution=1, pulse_index=4))
    with pytest.raises(SensorError, match="max_period"):
        counter.is_stale(1.0, 0.0)
    with pytest.raises(SensorError):
        PulseCounter(4, revolutions_per_window=0)
