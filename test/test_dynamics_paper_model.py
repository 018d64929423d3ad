"""The paper model (config/models/paper.yaml, bearing_rig_sim/dynamics/models.py) against the
paper's stated laws and closed forms of its friction law.

Closed form used here (docs/paper.md section 13): with no lubricant and a resistance R on each
ball's orbit (the model's stand-in), a ball with two equally loaded contacts and no other
resistance carries R/2 at each (its spin balance), and each contact slides at the speed s where
the paper's law gives mu(s) = R / (2 Q). The sum of the two slidings is the orbit's deficit
times the pitch diameter, so the cage slips against the pure-rolling speed at the loaded
contact angle by s / (r_m w_m0), w_m0 that pure-rolling orbit speed and Q = F_a / (Z sin a) with a
from Harris's thrust equilibrium. The law's peak mu_s Q bounds R: above 2 mu_s Q no rolling
state exists (gross skid).
"""

from __future__ import annotations

import math

import pytest
from scipy.optimize import brentq

from bearing_rig_sim.analysis.slip import BearingKinematics, ThrustContact
from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.dynamics.models import MODELS, model_parameters
from bearing_rig_sim.dynamics.steady import SKID_SLIP_PCT, SteadySolver

# The paper's Eq. 7-9 with its labels corrected (docs/paper.md section 4).
MU_S, V_S, MU_D, V_D = 0.1, 0.1, 0.02, 1.0
RPM_TO_RAD_S = math.pi / 30.0


def law(v: float) -> float:
    """The paper's STEP law below v_s (docs/paper.md sections 4-5), written out independently."""
    d = (v + V_S) / (2.0 * V_S)
    return -MU_S + 2.0 * MU_S * d * d * (3.0 - 2.0 * d)


@pytest.fixture(scope="module")
def paper():
    return model_parameters("paper")


def coulomb_resistance(params, newtons: float):
    """The paper model with a speed- and load-independent ball-set resistance of ``newtons``."""
    return params.replace(ball_set_resistance=newtons, ball_set_resistance_speed_exponent=0.0, ball_set_resistance_load_exponent=0.0)


def thrust(params) -> ThrustContact:
    b = params.inner_curvature_ratio + params.outer_curvature_ratio - 1.0
    return ThrustContact(params.ball_count, params.contact_angle, b, params.ball_diameter, params.combined_constant)


def test_the_paper_model_states_the_papers_laws(paper):
    assert paper.friction_model == "paper"
    assert (paper.static_friction, paper.stiction_velocity, paper.dynamic_friction, paper.transition_velocity) == (MU_S, V_S, MU_D, V_D)
    assert paper.lubricant is None and paper.dry
    assert paper.hunt_crossley_exponent == pytest.approx(10.0 / 9.0)  # paper Eq. 5-6
    assert paper.ball_drag_scale == 0.0 and paper.cage_land_viscous_scale == 0.0 and paper.rolling_hysteresis_factor == 0.0
    # the two fitted quantities inside the ranges their calibration file states
    assert 0.01 <= paper.ball_set_resistance <= 2.0
    assert 0.05 <= paper.ball_set_resistance_speed_exponent <= 2.0


def test_models_are_named_and_an_unknown_one_is_refused():
    assert MODELS == ("bench", "paper")
    with pytest.raises(ConfigError, match="model: must be one of bench, paper"):
        model_parameters("adams")


def test_without_a_resistance_the_cage_rolls_at_the_loaded_angle(paper):
    params = paper.replace(ball_set_resistance=0.0)
    point = SteadySolver(params).solve(900 * RPM_TO_RAD_S, 100.0)
    angle = thrust(params).loaded_contact_angle(100.0)
    loaded = BearingKinematics(params.ball_diameter, params.pitch_diameter, angle).slip_rate(point.cage_speed, point.inner_ring_speed)
    # nothing resists the orbit: at most the centrifugal split of the contact angles, F_c/Q
    # = 0.04 N / 22 N at 900 rpm, moves the pure-rolling speed (0.01 pp covers 5x that)
    assert abs(float(loaded)) < 0.01


@pytest.mark.parametrize(("rpm", "load", "resistance"), [(900, 100.0, 1.0), (900, 100.0, 3.0), (1000, 300.0, 2.0)])
def test_slip_follows_the_papers_law_in_closed_form(paper, rpm, load, resistance):
    params = coulomb_resistance(paper, resistance)
    point = SteadySolver(params).solve(rpm * RPM_TO_RAD_S, load)
    angle = thrust(params).loaded_contact_angle(load)
    q = load / (params.ball_count * math.sin(angle))
    sliding = brentq(lambda v: law(v) - resistance / (2.0 * q), 0.0, V_S)
    kinematics = BearingKinematics(params.ball_diameter, params.pitch_diameter, angle)
    orbit = kinematics.epicyclic_ratio() * rpm * RPM_TO_RAD_S
    expected = 100.0 * sliding / (0.5 * params.pitch_diameter * orbit)
    measured = float(kinematics.slip_rate(point.cage_speed, point.inner_ring_speed))
    # 1 %: the closed form leaves out the centrifugal force (F_c/Q below 0.2 % here) and the two
    # contacts' different rolling radii
    assert measured == pytest.approx(expected, rel=0.01)


def test_a_resistance_beyond_the_laws_peak_skids(paper):
    load = 100.0
    q = load / (paper.ball_count * math.sin(thrust(paper).loaded_contact_angle(load)))
    capacity = 2.0 * MU_S * q  # both contacts at the law's peak
    below = SteadySolver(coulomb_resistance(paper, 0.8 * capacity)).solve(900 * RPM_TO_RAD_S, load)
    above = SteadySolver(coulomb_resistance(paper, 1.2 * capacity)).solve(900 * RPM_TO_RAD_S, load)
    assert below.slip_pct < 10.0 and below.state == "rolling"
    assert above.slip_pct > SKID_SLIP_PCT and above.state == "skid"


def test_the_calibrated_paper_model_falls_with_load_without_a_cliff_at_1000_rpm(paper):
    solver = SteadySolver(paper)
    slips = [solver.solve(1000 * RPM_TO_RAD_S, f).slip_pct for f in (50.0, 100.0, 200.0, 300.0, 500.0, 700.0)]
    assert all(a > b for a, b in zip(slips, slips[1:]))
    assert slips[0] / slips[1] <= 2.0
    assert max(slips) < 10.0


def resistance_at(params, rpm: float, load: float) -> tuple[float, float]:
    """The stand-in resistance per ball (N) at the pure-rolling orbit speed and the capacity
    2 mu_s Q of its two contacts, from the model file's law (not from the engine)."""
    angle = thrust(params).loaded_contact_angle(load)
    q = load / (params.ball_count * math.sin(angle))
    v = BearingKinematics(params.ball_diameter, params.pitch_diameter, angle).epicyclic_ratio() * rpm * RPM_TO_RAD_S * 0.5 * params.pitch_diameter
    r = (
        params.ball_set_resistance
        * v**params.ball_set_resistance_speed_exponent
        * (q / params.ball_set_resistance_reference_load) ** params.ball_set_resistance_load_exponent
    )
    return r, 2.0 * MU_S * q


def test_the_load_the_ball_set_needs_to_roll_grows_with_speed(paper):
    """Where the model's resistance exceeds its contacts' capacity the ball set skids; the
    lightest rolling load of the sweep grows with speed (the paper's finding, section 4.1)."""
    solver = SteadySolver(paper)
    lightest = {}
    for rpm in (1000.0, 5000.0, 9000.0):
        rolling = [f for f in (50.0, 100.0, 200.0, 300.0, 500.0, 700.0) if solver.solve(rpm * RPM_TO_RAD_S, f).slip_pct < SKID_SLIP_PCT]
        lightest[rpm] = min(rolling, default=math.inf)
        for f in (50.0, 100.0, 200.0, 300.0, 500.0, 700.0):
            r, capacity = resistance_at(paper, rpm, f)
            if r > 1.05 * capacity:  # 5 %: the resistance at the orbit speed of pure rolling, not of the solution
                assert f not in rolling, f"{rpm} rpm, {f} N: resistance {r:.2f} N over capacity {capacity:.2f} N, yet rolling"
    assert lightest[1000.0] <= lightest[5000.0] <= lightest[9000.0]
    assert lightest[9000.0] > lightest[1000.0]


def test_both_integration_models_accept_the_paper_models_steps(paper):
    """The shipped steps lie within each model's stability limit over the rig's envelope (the
    engine refuses them otherwise, dynamics/step_limit.py): the paper's damping exponent needs a
    shorter stiff step than the bench twin's."""
    from bearing_rig_sim.dynamics import BearingDynamics

    for model in ("reduced", "stiff"):
        engine = BearingDynamics(paper, model=model)
        assert engine.time_step <= engine.step_limit.limit
