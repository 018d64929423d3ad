"""The thermal network: steady temperatures against hand-calculated resistance networks, exact
time response of a single body, the energy account, and the bearing network's heat split."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters
from bearing_rig_sim.dynamics.lubrication import Lubricant
from bearing_rig_sim.thermal.bearing import NODES, ThermalConfig, build_network, heat_sources, node_heat
from bearing_rig_sim.thermal.coupling import ThermalCoupling, params_at_temperature
from bearing_rig_sim.thermal.network import Conductance, Node, ThermalNetwork, ThermalNetworkError

CONFIG = Path(__file__).resolve().parents[1] / "config"
BEARING = CONFIG / "bearings" / "h7006c.yaml"
"""This worktree's bearing file (the installed share folder may point at another checkout)."""


def test_series_and_parallel_paths_match_the_hand_calculation() -> None:
    """Q into the balls: balls -> outer ring -> housing -> ambient (series, 0.2 + 0.1 + 1.25 K/W
    = 1.55 K/W), and a parallel path balls -> ambient of 4 W/K: T = T_a + Q R_eq."""
    g1, g2, g3, g4 = 5.0, 10.0, 0.8, 4.0
    nodes = [Node("balls", 8.0, "-"), Node("outer_ring", 27.0, "-"), Node("housing", 1200.0, "-")]
    cond = [Conductance("balls", "outer_ring", g1, "-"), Conductance("outer_ring", "housing", g2, "-"), Conductance("housing", "ambient", g3, "-")]
    net = ThermalNetwork(nodes, cond, {"ambient": 20.0})
    t = net.steady({"balls": 10.0})
    assert t == pytest.approx([20.0 + 10.0 * (1 / g1 + 1 / g2 + 1 / g3), 20.0 + 10.0 * (1 / g2 + 1 / g3), 20.0 + 10.0 / g3])
    par = ThermalNetwork(nodes, [*cond, Conductance("balls", "ambient", g4, "-")], {"ambient": 20.0})
    r_series = 1 / g1 + 1 / g2 + 1 / g3
    r_eq = 1.0 / (1.0 / r_series + g4)
    assert par.temperature("balls") == 20.0
    assert par.steady({"balls": 10.0})[0] == pytest.approx(20.0 + 10.0 * r_eq, rel=1e-12)


def test_one_body_follows_its_exponential_at_any_step() -> None:
    """C = 100 J/K, G = 2 W/K, Q = 10 W: tau = 50 s, T(t) = T_a + (Q/G)(1 - exp(-t/tau)); one
    step of 10 tau (far beyond any explicit limit) lands on the steady state."""
    net = ThermalNetwork([Node("a", 100.0, "-")], [Conductance("a", "amb", 2.0, "-")], {"amb": 0.0})
    assert net.time_constants() == pytest.approx([50.0])
    for _ in range(10):
        net.step({"a": 10.0}, 5.0)
    assert net.temperature("a") == pytest.approx(5.0 * (1.0 - math.exp(-1.0)), rel=1e-12)
    net.step({"a": 10.0}, 500.0)
    assert net.temperature("a") == pytest.approx(5.0 * (1.0 - math.exp(-11.0)), rel=1e-9)


def test_energy_closes_over_a_changing_heat_input() -> None:
    """Heat in = stored + out (to rounding) over steps of every length, heat switched on and off."""
    nodes = [Node(n, c, "-") for n, c in (("a", 10.0), ("b", 3.0), ("c", 500.0))]
    cond = [Conductance("a", "b", 1.0, "-"), Conductance("b", "c", 4.0, "-"), Conductance("c", "amb", 0.5, "-"), Conductance("a", "oil", 0.2, "-")]
    net = ThermalNetwork(nodes, cond, {"amb": 20.0, "oil": 50.0})
    for k, h in enumerate([0.01, 0.5, 3.0, 40.0, 0.2, 600.0]):
        net.step({"a": 5.0 * (k % 2), "b": 1.0}, h)
    assert net.heat_in > 0.0
    assert abs(net.energy_residual()) < 1e-9 * max(net.heat_in, abs(net.heat_out))


def test_a_node_without_a_path_to_a_boundary_is_refused() -> None:
    with pytest.raises(ThermalNetworkError, match="no conductive path"):
        ThermalNetwork([Node("a", 1.0, "-"), Node("b", 1.0, "-")], [Conductance("a", "amb", 1.0, "-")], {"amb": 20.0})
    with pytest.raises(ThermalNetworkError, match="capacities"):
        ThermalNetwork([Node("a", 0.0, "-")], [Conductance("a", "amb", 1.0, "-")], {"amb": 20.0})


def test_bearing_network_capacities_from_the_geometry() -> None:
    """Ring capacities by hand: annuli of the file's diameters x B, 7800 kg/m^3, 475 J/(kg K)."""
    p = BearingParameters.from_yaml(BEARING)
    cfg = ThermalConfig.from_yaml(BEARING)
    net = build_network(p, cfg, 300.0, 100.0)
    assert net.names == NODES
    c_inner = 7800.0 * math.pi / 4 * (0.0369**2 - 0.030**2) * 0.013 * 475.0
    c_outer = 7800.0 * math.pi / 4 * (0.055**2 - 0.048**2) * 0.013 * 475.0
    c_balls = 16 * 7800.0 * math.pi / 6 * 0.0063**3 * 475.0
    assert net.capacity[:3] == pytest.approx([c_inner, c_outer, c_balls], rel=1e-9)
    taus = net.time_constants()
    assert 300.0 < taus[0] < 5000.0  # the housing's warm-up: minutes to an hour


def test_lubricant_follows_the_walther_law_and_the_grease_softens() -> None:
    """Consistency scales with the base oil viscosity (ASTM D341 through 25 and 5 mm^2/s, by
    hand), the yield stress falls exp(-c dT)."""
    lub = Lubricant.from_yaml(CONFIG / "lubricants" / "nlgi2_grease.yaml")

    def nu(t: float) -> float:
        y1, y2 = math.log10(math.log10(25.7)), math.log10(math.log10(5.7))
        b = (y1 - y2) / (math.log10(373.15) - math.log10(313.15))
        return 10 ** (10 ** (y1 - b * (math.log10(t + 273.15) - math.log10(313.15)))) - 0.7

    warm = lub.at_temperature(60.0, 35.0)
    rho = lub.density(60.0) / lub.density(35.0)
    assert warm.consistency / lub.consistency == pytest.approx(nu(60.0) / nu(35.0) * rho, rel=1e-9)
    assert warm.yield_stress / lub.yield_stress == pytest.approx(math.exp(-lub.yield_stress_temperature_coefficient * 25.0), rel=1e-12)
    assert lub.yield_stress_temperature_coefficient > 0.0


def test_heat_split_adds_up_to_the_engine_power_and_energy_closes_while_running() -> None:
    """The split (contacts, drag, land, rest) sums to the engine's power loss; coupled to a
    running engine for 1 s at 2700 rpm the network's heat in = stored + out to rounding, and the
    heat in is the sampled power over the time."""
    p = BearingParameters.from_yaml(BEARING, CONFIG / "calibration" / "h7006c_table3.yaml")
    engine = BearingDynamics(p)
    engine.initialise(2700 * math.pi / 30, 100.0)
    engine.advance(0.01)
    src = heat_sources(engine)
    assert src.total == pytest.approx(engine.power_loss(), rel=1e-9)
    assert min(src.inner_contacts, src.outer_contacts, src.drag, src.land) > 0.0
    assert sum(node_heat(src).values()) == pytest.approx(src.total, rel=1e-12)
    coupling = ThermalCoupling(engine, ThermalConfig.from_yaml(BEARING), interval=0.1)
    powers = []
    for _ in range(1000):
        engine.advance(1e-3)
        if coupling.advance(1e-3):
            powers.append(coupling.sources.total)
    net = coupling.network
    assert len(powers) == 10
    assert net.heat_in == pytest.approx(sum(powers) * 0.1, rel=1e-9)
    # the step integrates its heat exactly (docs/thermal.md): what is left is rounding, each of the
    # 10 steps rounding, node by node, sums whose largest terms are C_i T_i (the stored energy is
    # a difference of such sums) and the heats in and out: eps of the largest, per node and step
    largest = float(np.sum(net.capacity * np.maximum(np.abs(net.temperatures), np.abs(net.initial_temperatures)))) + net.heat_in + abs(net.heat_out)
    assert abs(net.energy_residual()) <= len(powers) * len(net.names) * np.finfo(float).eps * largest, (net.energy_residual(), largest)
    assert net.temperature("balls") > net.temperature("housing") > ThermalConfig.from_yaml(BEARING).ambient


def test_engine_resistances_follow_the_lubricant_temperature() -> None:
    """Retuned to 60 degC, the grease's drag yield term falls by exp(-c 25 K) and the oil's
    Houpert rolling force by (eta(60)/eta(35))^0.66."""
    p = BearingParameters.from_yaml(BEARING, CONFIG / "calibration" / "h7006c_table3.yaml")
    from bearing_rig_sim.dynamics import kernels as kn
    from bearing_rig_sim.dynamics.parameters import derive

    v35, _ = derive(p)
    v60, _ = derive(params_at_temperature(p, 60.0))
    lub = p.lubricant
    assert lub is not None
    assert v60[kn.P_DRAG_YIELD] / v35[kn.P_DRAG_YIELD] == pytest.approx(math.exp(-lub.yield_stress_temperature_coefficient * 25.0), rel=1e-9)
    assert v60[kn.P_FR_IN] / v35[kn.P_FR_IN] == pytest.approx((lub.dynamic_viscosity(60.0) / lub.dynamic_viscosity(35.0)) ** 0.66, rel=1e-9)
    assert np.all(np.isfinite(v60))


def test_twin_with_the_network_warms_up_chunk_by_chunk() -> None:
    """A twin at 2700 rpm / 100 N with the network attached: the outer ring warms above ambient
    within a second and the network has taken the engine's heat ten times a second."""
    from bearing_rig_sim.simulation.twin import RigTwin

    twin = RigTwin.from_files(
        BEARING, CONFIG / "calibration" / "h7006c_table3.yaml", CONFIG / "rig.yaml", initial_speed=2700 * math.pi / 30, initial_axial_load=100.0
    )
    coupling = twin.attach_thermal(BEARING)
    start = coupling.temperature("outer_ring")
    for _ in range(1000):
        twin.tick(with_truth=False)
    assert coupling.network.time == pytest.approx(1.0, abs=1e-9)
    assert coupling.temperature("outer_ring") > start
    assert coupling.network.heat_in > 0.0
