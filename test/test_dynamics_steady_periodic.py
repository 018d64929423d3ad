"""The steady state under a combined load (``SteadySolver.periodic``): periodic at the ball-pass
frequency, since the load zone is fixed in space while the balls orbit through it, so averaged
over whole ball-pass periods 2 pi / (Z Omega) (issue 23, item 6)."""

from __future__ import annotations

import math

import pytest

from bearing_rig_sim.bearing.kinematics import slip_pct
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.steady import METHOD_PERIODIC, SteadySolver

RPM = math.pi / 30.0


@pytest.fixture(scope="module")
def solver() -> SteadySolver:
    return SteadySolver(BearingParameters.calibrated())


def _slip(solver: SteadySolver, duration: float) -> float:
    avg = solver.engine.advance(duration)
    return float(slip_pct(avg.cage_speed, avg.inner_ring_speed, solver.epicyclic_ratio))


def test_without_a_radial_load_the_periodic_state_is_the_fixed_point(solver: SteadySolver) -> None:
    """Nothing breaks the symmetry: the periodic average is the direct solver's steady state
    (Newton on the step residual) within 0.01 pp of slip, the issue's bound for one model family."""
    for rpm, load in ((900, 100.0), (5000, 300.0)):
        periodic = solver.periodic(rpm * RPM, load, 0.0)
        assert periodic.method == METHOD_PERIODIC
        assert periodic.slip_pct == pytest.approx(solver.solve(rpm * RPM, load).slip_pct, abs=0.01)


def test_whole_ball_pass_periods_give_the_long_run_mean(solver: SteadySolver) -> None:
    """F_a = 163 N, F_r = 500 N at 900 rpm: the slip over whole ball-pass periods is the mean over
    a further second of the same run (about 100 periods) within 0.002 pp, while windows of half
    a period, at three phases, scatter by more than 0.1 pp: the window matters and is right."""
    point = solver.periodic(900 * RPM, 163.0, 500.0)
    long_run = _slip(solver, 1.0)
    assert point.slip_pct == pytest.approx(long_run, abs=0.002)
    period = 2.0 * math.pi / (solver.params.ball_count * point.cage_speed)
    halves = []
    for _ in range(3):
        halves.append(_slip(solver, 0.5 * period))
        solver.engine.advance(0.3 * period)
    assert max(halves) - min(halves) > 0.1
