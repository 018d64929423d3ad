"""The engine inside the rig's envelope: cases that diverged before the secant-implicit step
(docs/model.md, Integration) must run to their end within physical bounds.

Bounds checked after every 1 ms chunk (beside the engine's own divergence check): no ball or
cage segment turns backwards or faster than the inner ring has turned (the inner ring is the
only driven body); the cage is no faster than pure rolling of the balls at any contact angle,
omega_i (1 - Dw cos a / d_m) / 2 <= omega_i / 2, plus the engine's speed tolerance (0.2 rad/s).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters
from bearing_rig_sim.dynamics import kernels as kn

RPM = math.pi / 30.0
CHUNK = 1e-3
TOLERANCE = 0.2
"""rad/s: the engine's absolute speed tolerance (engine.SPEED_TOLERANCE)."""
ROLLING_BOUND = 0.5
"""Cage over inner-ring speed of pure rolling at a 90 deg contact angle, the largest (module doc)."""
ROLLING_RATIO = 0.5 * (1.0 - 0.0063 * math.cos(math.radians(15.0)) / 0.04245)
"""Cage over inner-ring speed of pure rolling at the unloaded 15 deg (Dw = 6.3 mm,
d_m = 42.45 mm, a0 = 15 deg: config/bearings/h7006c.yaml, paper Table 2)."""


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.calibrated()


def assert_physical(engine: BearingDynamics, peak: float) -> None:
    """Every speed within the bounds of the module docstring (``peak``: the inner ring's
    fastest so far, rad/s)."""
    cage = engine.cage[:, kn.C_OMEGA]
    orbit = engine.ball[:, kn.B_OMEGA]
    assert np.all(np.isfinite(engine.ball)) and np.all(np.isfinite(engine.cage))
    assert cage.min() >= -TOLERANCE and orbit.min() >= -TOLERANCE, (engine.time, cage.min(), orbit.min())
    assert cage.max() <= peak + TOLERANCE and orbit.max() <= peak + TOLERANCE, (engine.time, cage.max(), peak)
    assert engine.cage_speed <= ROLLING_BOUND * peak + TOLERANCE, (engine.time, engine.cage_speed, peak)


def run_up(engine: BearingDynamics, target: float, acceleration: float, load: float, radial: float = 0.0) -> float:
    """Accelerate in 1 ms chunks to ``target`` (rad/s) under ``load`` N axial and ``radial`` N
    radial (the engine's moment and load azimuth as set), checking the bounds; returns the peak."""
    peak = engine.inner_ring_speed
    while engine.inner_ring_speed < target - 1e-9:
        step = min(CHUNK, (target - engine.inner_ring_speed) / acceleration)
        engine.advance(step if step >= engine.time_step else engine.time_step, axial_load=load, inner_ring_acceleration=acceleration, radial_load=radial)
        peak = max(peak, engine.inner_ring_speed)
        assert_physical(engine, peak)
    return peak


def stop(engine: BearingDynamics, deceleration: float, load: float, peak: float) -> None:
    """Decelerate to rest in 1 ms chunks as the twin does (the engine stops integrating where the
    ring would reverse; the rest of the chunk is spent at rest), checking the bounds."""
    while engine.inner_ring_speed > 0.0:
        t_end = engine.time + CHUNK
        engine.advance(CHUNK, axial_load=load, inner_ring_acceleration=-deceleration)
        if t_end - engine.time > 0.5 * engine.time_step:
            engine.set_inner_ring_speed(0.0)
            engine.advance(t_end - engine.time, axial_load=load)
        assert_physical(engine, peak)


def test_load_change_at_rest_then_run_up(params: BearingParameters) -> None:
    """The issue's case: initialised at rest under 100 N, the load raised at rest to 200 N over
    0.2 s and held to 1 s, then 20 rad/s^2 in 1 ms chunks (diverged at 1.001 s, the cage at
    0.49 rad/s with the ring at 0.02 rad/s). Now: 1 s of run-up within the bounds, and the
    cage follows the ring (faster than a fifth of pure rolling after it)."""
    engine = BearingDynamics(params)
    engine.initialise(0.0, 100.0)
    for i in range(200):
        engine.advance(CHUNK, axial_load=100.0 + 100.0 * (i + 1) / 200)
        assert_physical(engine, 0.0)
    engine.advance(0.8, axial_load=200.0)
    assert_physical(engine, 0.0)
    peak = run_up(engine, 20.0, 20.0, 200.0)
    assert engine.time == pytest.approx(2.0, abs=2e-3)
    assert engine.cage_speed > 0.2 * ROLLING_RATIO * peak


@pytest.mark.parametrize("rpm,load", [(6000, 700.0), (9000, 300.0)])
def test_run_up_from_rest_to_high_speed(params: BearingParameters, rpm: float, load: float) -> None:
    """Run-ups from rest at the rig's largest acceleration (config/rig.yaml: 1000 rad/s^2) to
    6000 rpm at 700 N and 9000 rpm at 300 N, then 0.2 s of hold: within the bounds throughout,
    and at the end a cage between rest and pure rolling at the largest loaded contact angle
    (under 25 deg at 1000 N: docs/model.md, Contacts)."""
    engine = BearingDynamics(params)
    engine.initialise(0.0, load)
    peak = run_up(engine, rpm * RPM, 1000.0, load)
    for _ in range(200):
        engine.advance(CHUNK, axial_load=load)
        assert_physical(engine, peak)
    assert 0.0 < engine.cage_speed < 0.5 * (1.0 - 0.0063 * math.cos(math.radians(25.0)) / 0.04245) * peak


def test_stop_to_rest_and_restart(params: BearingParameters) -> None:
    """A stop at the rig's largest deceleration to rest, 0.1 s at rest with a load change, and a
    restart: within the bounds; at rest the cage comes to rest (below the tolerance)."""
    engine = BearingDynamics(params)
    engine.initialise(3000 * RPM, 300.0)
    engine.advance(0.1)
    peak = engine.inner_ring_speed
    stop(engine, 1000.0, 300.0, peak)
    for i in range(100):
        engine.advance(CHUNK, axial_load=300.0 + 7.0 * i)
        assert_physical(engine, peak)
    assert abs(engine.cage_speed) < TOLERANCE
    run_up(engine, 100.0, 500.0, 1000.0)


@pytest.mark.parametrize("moment", [None, (2.0, 0.5)])
def test_run_up_from_rest_under_combined_load(params: BearingParameters, moment: tuple[float, float] | None) -> None:
    """Started at rest under 163 N axial, 500 N radial at 0.4 rad and (tilts free) a moment of
    (2.0, 0.5) N m, as the simulator starts the twin: 0.05 s at rest, a run-up at the rig's
    largest acceleration (1000 rad/s^2) to 3000 rpm and 0.1 s of hold, within the bounds
    throughout; at the end the cage turns between rest and pure rolling at the largest loaded
    contact angle (under 25 deg: docs/model.md, Contacts)."""
    engine = BearingDynamics(params)
    engine.initialise(0.0, 163.0, radial_load=500.0, radial_angle=0.4, moment=moment)
    for _ in range(50):
        engine.advance(CHUNK)
        assert_physical(engine, 0.0)
    peak = run_up(engine, 3000 * RPM, 1000.0, 163.0, 500.0)
    for _ in range(100):
        engine.advance(CHUNK)
        assert_physical(engine, peak)
    assert 0.0 < engine.cage_speed < 0.5 * (1.0 - 0.0063 * math.cos(math.radians(25.0)) / 0.04245) * peak


def test_load_change_at_rest_then_run_up_under_radial_load(params: BearingParameters) -> None:
    """The issue's axial case with a radial load and a moment: started at rest under 100 N
    axial and 200 N radial, both raised at rest over 0.2 s to 200 N and 600 N while the load
    turns by 1 rad and a moment of (1.5, -1.0) N m is applied, held at rest to 0.5 s, then a
    run-up at 20 rad/s^2 for 0.5 s in 1 ms chunks (the issue's slow start, where the axial
    case diverged) and at 1000 rad/s^2 on to 3000 rpm: within the bounds throughout, and the
    cage follows the ring (faster than a fifth of pure rolling after the slow part)."""
    engine = BearingDynamics(params)
    engine.initialise(0.0, 100.0, radial_load=200.0)
    engine.set_moment((1.5, -1.0))
    for i in range(200):
        f = (i + 1) / 200
        engine.advance(CHUNK, axial_load=100.0 + 100.0 * f, radial_load=200.0 + 400.0 * f, radial_angle=f)
        assert_physical(engine, 0.0)
    for _ in range(300):
        engine.advance(CHUNK)
        assert_physical(engine, 0.0)
    peak = run_up(engine, 10.0, 20.0, 200.0, 600.0)
    assert engine.cage_speed > 0.2 * ROLLING_RATIO * peak
    peak = run_up(engine, 3000 * RPM, 1000.0, 200.0, 600.0)
    assert engine.time == pytest.approx(1.0 + (3000 * RPM - 10.0) / 1000.0, abs=2e-3)
