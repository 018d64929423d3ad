"""The Exudyn reference of ``bench dynamics``: a bearing, not just a timed model.

Exudyn's rigid ball bearing, set up with this bearing's geometry and turned at 900 rpm under
100 N, must bring its cage from rest to the pure-rolling speed of the kinematics (Harris and Kotzalas,
Eq. 8.26 with no sliding: omega_c = omega_i (1 - D_w cos(a) / d_m) / 2), since it has neither
lubricant drag nor pocket friction to make it slip; and the bench row must carry the ratio the
engine issue asks for.
"""

from __future__ import annotations

import argparse
import math

import pytest

from bearing_rig_sim.benchmarks import dynamics
from bearing_rig_sim.benchmarks.exudyn_bearing import run_exudyn
from bearing_rig_sim.dynamics import BearingParameters


def test_exudyn_bearing_cage_turns_at_pure_rolling_speed() -> None:
    params = BearingParameters.calibrated()
    speed = 900.0 * math.pi / 30.0
    run = run_exudyn(params, speed, 100.0, 0.01, cage_start=0.0)  # from rest: the contacts must carry it
    gamma = params.ball_diameter * math.cos(params.contact_angle) / params.pitch_diameter
    expected = 0.5 * speed * (1.0 - gamma)
    assert run.cage_speed_rad_s == pytest.approx(expected, rel=0.02)
    assert run.wall_s > 0.0


def test_bench_row_compares_the_engine_with_exudyn_in_the_same_run() -> None:
    parser = argparse.ArgumentParser()
    dynamics.add_arguments(parser)
    args = parser.parse_args(["--models", "reduced", "exudyn", "--repeats", "1", "--sim-seconds", "0.01", "--exudyn-sim-seconds", "0.002"])
    rows = list(dynamics.run(args))
    exudyn = [r for r in rows if r["model"] == "exudyn"]
    reduced = next(r for r in rows if r["model"] == "reduced" and (r["rpm"], r["axial_load_n"]) == dynamics.EXUDYN_POINT)
    assert len(exudyn) == 1
    assert exudyn[0]["reduced_over_exudyn"] == pytest.approx(reduced["rtf"] / exudyn[0]["rtf"], rel=0.01)
