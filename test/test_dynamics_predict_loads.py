"""``bearing-rig predict --radial-load N [--moment M_X M_Y]``: the quasi-static load distribution
(dynamics/quasi_static.py; the closed forms are tested in test_dynamics_quasi_static.py) beside
the engine's steady slip under the combined load, averaged over whole ball-pass periods
(test_dynamics_steady_periodic.py)."""

from __future__ import annotations

import json
import math

import pytest

from bearing_rig_sim.cli import main


def test_predict_gives_the_load_distribution_of_a_combined_load(capsys: pytest.CaptureFixture[str]) -> None:
    """F_r = 500 N, F_a = 163 N at 900 rpm (a half-loaded ring, Stribeck/Sjovall
    Q_max = 4.37 F_r / (Z cos 15 deg) = 141.4 N; the centrifugal force at 900 rpm, 0.03 N,
    changes nothing measurable): the keys of the contract, Q_max within 3 %, half the balls loaded,
    the tilt held with a reaction moment about the axis across the load (M_x > 0, M_y = 0), the
    cage pushed off the axis within its land clearance, and a slip other than the axial load's
    alone."""
    assert main(["predict", "--rpm", "900", "--load", "163", "--radial-load", "500", "--calibration", "isothermal", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["ball_load_max_n"] == pytest.approx(4.37 * 500 / (16 * math.cos(math.radians(15.0))), rel=0.03)
    assert row["ball_load_min_n"] < 0.03  # behind the load zone a ball is wedged by F_c alone
    assert 7 <= row["loaded_balls"] <= 9
    assert 10.0 < row["contact_angle_max_load_deg"] < 20.0
    mx, my = row["reaction_moment_n_m"]
    assert mx > 0.0 and abs(my) < 1e-6
    assert 1.0 < row["cage_whirl_radius_um"] < 100.0  # the H7006C's land clearance: 100 um
    assert main(["predict", "--rpm", "900", "--load", "163", "--calibration", "isothermal", "--json"]) == 0
    axial = json.loads(capsys.readouterr().out)
    assert abs(row["slip_pct"] - axial["slip_pct"]) > 0.1


def test_a_given_moment_tilts_the_ring_instead(capsys: pytest.CaptureFixture[str]) -> None:
    """With --moment the tilt is free and reported; no radial load and no moment: every ball
    alike (pure thrust), and the slip that of the axial load alone within 0.01 pp."""
    assert main(["predict", "--rpm", "900", "2700", "--load", "200", "--radial-load", "0", "--moment", "0", "0", "--calibration", "isothermal", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    for row in rows:
        assert row["loaded_balls"] == 16
        assert row["ball_load_min_n"] == pytest.approx(row["ball_load_max_n"], rel=0.05)  # outer carries F_c too
        assert max(abs(t) for t in row["tilt_mrad"]) < 1e-6
        assert "reaction_moment_n_m" not in row
    assert main(["predict", "--rpm", "900", "2700", "--load", "200", "--calibration", "isothermal", "--json"]) == 0
    axial = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    for row, plain in zip(rows, axial, strict=True):
        assert row["slip_pct"] == pytest.approx(plain["slip_pct"], abs=0.01)


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["--radial-load", "-5"], "--radial-load"),
        (["--radial-load", "1", "2", "3"], "one per speed"),
        (["--moment", "1", "0"], "--moment needs --radial-load"),
        (["--radial-load", "100", "--moment", "nan", "0"], "--moment"),
    ],
)
def test_bad_combined_load_options_are_refused(capsys: pytest.CaptureFixture[str], argv: list[str], needle: str) -> None:
    assert main(["predict", "--rpm", "900", "--load", "100", *argv]) == 2
    err = capsys.readouterr().err
    assert needle in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_predict_thermal_under_a_radial_load_runs_warmer_than_under_the_axial_load_alone(capsys: pytest.CaptureFixture[str]) -> None:
    """``predict --thermal --radial-load``: at 900 rpm under 163 N axial, a 500 N radial load
    adds contact load (the loaded balls carry up to Stribeck's 141 N against 35 N each under
    the axial load alone) and pushes the cage off centre into its land (more shear): the coupled
    steady state dissipates more than the axial-only one at the same axial load and so settles
    warmer (lubricant and outer ring), and more still at 500 N than at 250 N (monotonic in the
    radial load). The point also carries the load distribution, Q_max within 3 % of
    4.37 F_r / (Z cos 15 deg) = 141.4 N, and its network converged (residual within the 0.2 K
    tolerance)."""
    argv = ["predict", "--rpm", "900", "900", "900", "--load", "163", "--radial-load", "0", "250", "500", "--thermal", "--json"]
    assert main(argv) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    axial, quarter, half = rows
    assert [r["radial_load_n"] for r in rows] == [0.0, 250.0, 500.0]
    assert axial["power_loss_w"] < quarter["power_loss_w"] < half["power_loss_w"]
    assert axial["lubricant_temperature_c"] < quarter["lubricant_temperature_c"] < half["lubricant_temperature_c"]
    assert axial["outer_ring_temperature_c"] < half["outer_ring_temperature_c"]
    assert half["ball_load_max_n"] == pytest.approx(4.37 * 500 / (16 * math.cos(math.radians(15.0))), rel=0.03)
    assert all(abs(r["thermal_residual_k"]) <= 0.2 for r in rows)
    assert "slip_pct_low" not in half and "slip_pct_low" in axial  # the calibration's interval is an axial-load one
