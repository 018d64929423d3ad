"""The paper's three experiments run on the engine (docs/paper.md sections 9-11), without analysis.

* :func:`validation_table`: steady slip at 100 N over 900-2700 rpm (Table 3 analogue);
* :func:`load_sweep`: steady slip over speed x axial load (Figures 7-8);
* :func:`acceleration_run`: slip against time while the inner ring accelerates at a constant
  rate from rest under 200 N (Figures 9-10).

Every result is simulated: cage speeds come from the engine; the slip rate is computed from
them with paper Eq. 11-12 at the nominal contact angle, as on the bench.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from collections.abc import Callable, Sequence

import numpy as np

from bearing_rig_sim.analysis.slip import BearingKinematics
from bearing_rig_sim.executors import process_pool
from bearing_rig_sim.studies.calibration import steady_states
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters
from bearing_rig_sim.dynamics.steady import SteadyState

VALIDATION_RPM: tuple[float, ...] = (900, 1200, 1500, 1800, 2100, 2400, 2700)
"""Digest section 9: 900-2700 rpm in steps of 300, at 100 N."""
VALIDATION_LOAD_N = 100.0
SWEEP_RPM: tuple[float, ...] = (1000, 3000, 5000, 7000, 9000)
"""Digest section 10: inner-ring speeds of the load sweep."""
SWEEP_LOADS_N: tuple[float, ...] = tuple(float(f) for f in range(50, 701, 50))
"""Digest section 10: 50-700 N."""
ACCELERATIONS: tuple[float, ...] = (20.0, 40.0, 60.0, 80.0)
"""Digest section 11: inner-ring angular accelerations, rad/s^2, at 200 N."""
ACCELERATION_LOAD_N = 200.0
MIN_SPEED_FOR_SLIP = 1.0
"""rad/s: below this inner-ring speed the slip rate is not sampled (0/0 at rest)."""


@dataclass(frozen=True)
class AccelerationSeries:
    """Slip against time under constant inner-ring acceleration.

    Attributes: acceleration (rad/s^2), axial_load (N), time (s, from the start of the ramp,
    window centres), inner_ring_speed and cage_speed (rad/s, window means), slip_pct (%);
    ball_load_max (N, the largest contact load of any ball at the run's end, inner or outer).
    """

    acceleration: float
    axial_load: float
    time: np.ndarray
    inner_ring_speed: np.ndarray
    cage_speed: np.ndarray
    slip_pct: np.ndarray
    ball_load_max: float = field(default=math.nan, kw_only=True)


def validation_table(
    params: BearingParameters,
    speeds_rpm: Sequence[float] = VALIDATION_RPM,
    load: float = VALIDATION_LOAD_N,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[SteadyState]:
    """Steady slip at ``load`` (N) for each inner-ring speed (rpm at the edge)."""
    return steady_states(params, [(rpm_to_rad_s(n), load) for n in speeds_rpm], workers, progress=progress)


def load_sweep(
    params: BearingParameters,
    speeds_rpm: Sequence[float] = SWEEP_RPM,
    loads: Sequence[float] = SWEEP_LOADS_N,
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[float, list[SteadyState]]:
    """Steady slip for every (speed, load) pair; keyed by speed in rpm."""
    flat = steady_states(params, [(rpm_to_rad_s(n), f) for n in speeds_rpm for f in loads], workers, progress=progress)
    k = len(loads)
    return {float(n): flat[i * k : (i + 1) * k] for i, n in enumerate(speeds_rpm)}


def acceleration_run(
    params: BearingParameters,
    acceleration: float,
    load: float = ACCELERATION_LOAD_N,
    duration: float = 3.0,
    window: float = 0.02,
    *,
    radial_load: float = 0.0,
    moment: tuple[float, float] | None = None,
) -> AccelerationSeries:
    """Accelerate the inner ring from rest at ``acceleration`` (rad/s^2) under ``load`` (N) for
    ``duration`` s, sampling mean speeds and slip over consecutive ``window`` s windows; with
    ``radial_load`` (N, along x) and ``moment`` ((M_x, M_y) N m, tilts free; None: held) the
    run is under that combined load (:meth:`BearingDynamics.initialise`)."""
    engine = BearingDynamics(params)
    engine.initialise(0.0, load, radial_load=radial_load, moment=moment)
    kin = BearingKinematics(params.ball_diameter, params.pitch_diameter, params.contact_angle)
    times, inner, cage = [], [], []
    n = int(round(duration / window))
    for i in range(n):
        avg = engine.advance(window, inner_ring_acceleration=acceleration)
        if avg.inner_ring_speed >= MIN_SPEED_FOR_SLIP:
            times.append((i + 0.5) * window)
            inner.append(avg.inner_ring_speed)
            cage.append(avg.cage_speed)
    inner_a, cage_a = np.array(inner), np.array(cage)
    slip = np.asarray(kin.slip_rate(cage_a, inner_a), dtype=float) if len(inner) else np.array([])
    obs = engine.observe()
    q_max = float(max(obs.inner_contact_loads.max(), obs.outer_contact_loads.max()))
    return AccelerationSeries(acceleration, load, np.array(times), inner_a, cage_a, slip, ball_load_max=q_max)


def _acceleration_job(job: tuple[BearingParameters, float, float, float]) -> AccelerationSeries:
    return acceleration_run(*job)


def acceleration_sweep(
    params: BearingParameters,
    accelerations: Sequence[float] = ACCELERATIONS,
    load: float = ACCELERATION_LOAD_N,
    duration: float = 3.0,
    workers: int | None = None,
) -> list[AccelerationSeries]:
    """:func:`acceleration_run` for each acceleration, on ``workers`` processes."""
    jobs = [(params, float(a), load, duration) for a in accelerations]
    workers = workers or os.cpu_count() or 1
    if workers <= 1:
        return [_acceleration_job(j) for j in jobs]
    with process_pool(min(workers, len(jobs))) as pool:
        return list(pool.map(_acceleration_job, jobs))
