"""The thermal state under a combined load (issue 24): the heat split over the periodic state's
ball-pass periods, and the warm-up under a radial load."""

from __future__ import annotations

import numpy as np
import pytest

from bearing_rig_sim.commands.predict import load_parameters
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.dynamics.parameters import BearingParameters
from bearing_rig_sim.dynamics.steady import SteadySolver
from bearing_rig_sim.thermal.bearing import HeatSources, ThermalConfig, build_network, heat_sources, node_heat
from bearing_rig_sim.thermal.coupling import HeatAtTemperature, thermal_steady_state, warm_up

OMEGA = rpm_to_rad_s(900.0)
AXIAL, RADIAL = 163.0, 500.0  # N, issue 23's case


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return load_parameters(None, None, None)


@pytest.mark.slow
def test_under_a_radial_load_each_terms_heat_is_its_energy_over_whole_ball_pass_periods(params: BearingParameters) -> None:
    """At 900 rpm, 163 N axial and 500 N radial the balls' contact loads go round the load zone
    once a ball pass: the split of the heat must be each term's energy over the window over its
    length, not the last step's proportions. Independently here: the same periodic state, then
    as long a window stepped one step at a time, each step's terms times the step summed, and
    the engine's cumulative dissipation counter differenced over the window."""
    _, got = HeatAtTemperature(params, OMEGA, AXIAL, RADIAL)(params.lubricant_temperature)

    solver = SteadySolver(params)
    solver.periodic(OMEGA, AXIAL, RADIAL)
    window = solver.last_average
    assert window is not None
    e = solver.engine
    dt = e.time_step
    n = int(round(window.duration / dt))
    heat0, damp0 = e.dissipated, e.damping_dissipated
    energy = np.zeros(4)
    for _ in range(n):
        e.advance(dt)
        s = heat_sources(e)
        energy += dt * np.array([s.inner_contacts, s.outer_contacts, s.drag, s.land])
    duration = n * dt
    total = (e.dissipated - heat0) / duration
    damping = (e.damping_dissipated - damp0) / duration
    last = heat_sources(e)

    pin, pout, drag, land = energy / duration
    assert got.inner_contacts == pytest.approx(pin, rel=1e-9)
    assert got.outer_contacts == pytest.approx(pout, rel=1e-9)
    assert got.drag == pytest.approx(drag, rel=1e-9)
    assert got.land == pytest.approx(land, rel=1e-9)
    assert got.damping == pytest.approx(damping, rel=1e-9)
    assert got.total == pytest.approx(total, rel=1e-6)
    assert got.rolling_and_pockets > 0.0  # hysteresis, EHL rolling and pocket friction: dissipative
    # the network's node rates are the partition of these terms, and carry all of the heat
    expected = node_heat(HeatSources(pin, pout, drag, land, total - damping - (pin + pout + drag + land), damping))
    nodes = node_heat(got)
    for name, rate in expected.items():
        assert nodes[name] == pytest.approx(rate, rel=1e-6, abs=1e-12)
    assert sum(nodes.values()) == pytest.approx(total, rel=1e-6)
    # and the last step's proportions are not the period's: the inner contacts' share moves
    # by more than 5 % over a ball pass (the case the old split got wrong)
    assert abs(last.inner_contacts / (last.total - last.damping) - pin / (total - damping)) > 0.05 * pin / (total - damping)


@pytest.mark.slow
def test_the_warm_up_under_a_radial_load_rises_to_its_steady_state(params: BearingParameters) -> None:
    """The warm-up at 900 rpm, 163 N axial and 500 N radial: run for six of the network's
    longest time constants (e^-6 = 0.25 % of a rise under 15 K left: 0.04 K) it ends on the
    coupled steady state's temperatures within 0.05 K at every node. Under the steady state's
    constant heat from ambient a passive RC network only warms: dT/dt = C^-1 (q - G T) starts
    at C^-1 q >= 0 and obeys a system whose off-diagonal terms (conductance over capacity) are
    positive, so it stays >= 0 (every node rises monotonically), and the exact exponential
    steps end on the network's own steady temperatures."""
    cfg = ThermalConfig.from_yaml()
    steady = thermal_steady_state(params, cfg, OMEGA, AXIAL, radial_load=RADIAL)
    tau = steady.time_constants[0]
    rows = warm_up(params, cfg, OMEGA, AXIAL, 6.0 * tau, step=300.0, radial_load=RADIAL)
    for name, t_ss in steady.temperatures.items():
        assert rows[-1][f"{name}_c"] == pytest.approx(t_ss, abs=0.05), name
        assert rows[0][f"{name}_c"] < t_ss - 1.0  # it did warm up

    net = build_network(params, cfg, OMEGA, AXIAL, lubricant_temperature=steady.temperatures["lubricant"], initial=cfg.ambient)
    q = net.heat_vector(node_heat(steady.sources))
    assert np.all(q >= 0.0) and q.sum() > 0.0
    history = [net.temperatures.copy()]
    for _ in range(200):
        net.step(q, 0.05 * tau)
        history.append(net.temperatures.copy())
    rise = np.diff(np.array(history), axis=0)
    assert np.all(rise >= -1e-9), "a node cooled under constant positive heat"
    assert history[-1] == pytest.approx(net.steady(node_heat(steady.sources)), abs=0.05)


@pytest.mark.slow
def test_predict_transient_takes_a_radial_load(capsys: pytest.CaptureFixture[str]) -> None:
    """``predict --transient S --radial-load N``: one row per step, each naming its radial load,
    warming from ambient (the shipped bearing's 22 degC) as the steady state's heat goes in."""
    from bearing_rig_sim.cli import main
    import json

    argv = ["predict", "--rpm", "900", "--load", "163", "--radial-load", "500", "--transient", "1200", "--transient-step", "600", "--json"]
    assert main(argv) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [(r["time_s"], r["radial_load_n"]) for r in rows] == [(600.0, 500.0), (1200.0, 500.0)]
    assert ThermalConfig.from_yaml().ambient < rows[0]["lubricant_c"] < rows[1]["lubricant_c"]
