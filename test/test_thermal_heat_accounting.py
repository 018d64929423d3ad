"""The heat the thermal network takes is the heat the engine dissipated (issue 24): the interval's
mean dissipation rather than the power at its end, the whirling cage's land film with its
eccentricity, and the pocket and rim damping counted as heat."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.special import ellipk

from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingDynamics, BearingParameters
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.thermal.bearing import ThermalConfig, heat_sources
from bearing_rig_sim.thermal.coupling import ThermalCoupling
from bearing_rig_sim.thermal.network import Conductance, Node, ThermalNetwork, ThermalNetworkError

CONFIG = Path(__file__).resolve().parents[1] / "config"
BEARING = CONFIG / "bearings" / "h7006c.yaml"


def insulated_body(capacity: float) -> ThermalNetwork:
    """One capacity (J/K) with no path to its boundary: its temperature is its heat / C."""
    return ThermalNetwork([Node("a", capacity, "-")], [Conductance("a", "amb", 0.0, "-")], {"amb": 0.0}, insulated=True)


def test_a_ramp_of_power_into_one_capacity_fed_its_interval_means_is_exact_at_the_interval_ends() -> None:
    """P(t) = a t into C: T = a t^2 / (2 C) (the integral of the power over C). Fed each
    interval's mean power, the energy (a/2)(t1^2 - t0^2) over h, the network lands on it at every
    interval end; fed the power at the interval's end it runs ahead by a h t / (2 C), half an
    interval of the ramp."""
    a, c, h = 40.0, 8.0, 0.1  # W/s, J/K, s
    mean, end = insulated_body(c), insulated_body(c)
    for k in range(50):
        t0, t1 = k * h, (k + 1) * h
        mean.step({"a": 0.5 * a * (t1 * t1 - t0 * t0) / h}, h)
        end.step({"a": a * t1}, h)
        assert mean.temperature("a") == pytest.approx(a * t1 * t1 / (2.0 * c), rel=1e-12, abs=1e-12)
        assert end.temperature("a") - a * t1 * t1 / (2.0 * c) == pytest.approx(a * h * t1 / (2.0 * c), rel=1e-9)
    assert abs(mean.energy_residual()) < 1e-12 * mean.heat_in
    with pytest.raises(ThermalNetworkError, match="no steady state"):
        mean.steady({"a": 1.0})


def grease_twin() -> BearingParameters:
    """The shipped bench twin: H7006C with the calibrated running-in grease."""
    return BearingParameters.from_yaml(BEARING, CONFIG / "calibration" / "h7006c_table3.yaml")


def test_over_a_run_up_the_network_takes_exactly_the_heat_the_engine_dissipated() -> None:
    """Run-up from rest to 2700 rpm at 500 rad/s^2 and a hold of at least 0.3 s in 1 ms chunks, the network
    stepping every 0.1 s: its heat in equals the engine's own step-by-step dissipation (friction
    and damping) to 1e-9, and drive work = heat + mechanical energy change within 1 %."""
    engine = BearingDynamics(grease_twin())
    engine.initialise(0.0, 100.0)
    coupling = ThermalCoupling(engine, ThermalConfig.from_yaml(BEARING), interval=0.1, feedback=False)
    e0 = engine.energy()
    chunk = 1e-3
    target = rpm_to_rad_s(2700.0)
    n_up = int(round(target / 500.0 / chunk))
    n_total = 100 * math.ceil((n_up + 300) / 100)  # whole intervals: at least a 0.3 s hold
    work = damping = 0.0
    steps = 0
    for k in range(n_total):
        accel = 500.0 if k < n_up else 0.0
        if k == n_up - 1:
            accel = (target - engine.inner_ring_speed) / chunk
        avg = engine.advance(chunk, inner_ring_acceleration=accel)
        work += avg.drive_work
        damping += avg.damping_heat
        steps += coupling.advance(chunk)
    assert steps == n_total // 100
    assert engine.dissipated > 0.0 and damping > 0.0  # the cage's settling is damped
    assert coupling.network.heat_in == pytest.approx(engine.dissipated, rel=1e-9)
    assert coupling.network.heat_in + engine.energy() - e0 == pytest.approx(work, rel=0.01)


@pytest.mark.parametrize("eps", [0.3, 0.7])
def test_the_land_films_shear_factor_is_petroffs_eccentric_journal(eps: float) -> None:
    """Mean over the land of (c/h)^n, h = c (1 - eps cos theta). Oil (n = 1): 1/sqrt(1 - eps^2),
    the eccentric journal's Petroff torque (Ocvirk's short bearing; Hamrock, Fundamentals of
    Fluid Film Lubrication, ch. 10): 1.04828 at 0.3, 1.40028 at 0.7. Grease (n = 1/2):
    (2/pi) K(m) / sqrt(1 + eps), m = 2 eps / (1 + eps) (theta = pi - 2 phi turns the mean into the
    complete elliptic integral of the first kind)."""
    p = np.zeros(kn.P_SIZE)
    p[kn.P_LAND_N] = 1.0
    assert kn.land_shear_factor(p, eps) == pytest.approx({0.3: 1.0482848367, 0.7: 1.4002800840}[eps], rel=1e-4)
    assert kn.land_shear_factor(p, eps) == pytest.approx(1.0 / math.sqrt(1.0 - eps * eps), rel=1e-4)
    p[kn.P_LAND_N] = 0.5
    assert kn.land_shear_factor(p, eps) == pytest.approx(2.0 / math.pi * ellipk(2.0 * eps / (1.0 + eps)) / math.sqrt(1.0 + eps), rel=1e-4)


def test_the_heat_split_takes_the_land_film_of_the_whirling_cage() -> None:
    """With the cage centre at eps = 0.7 the land's heat is the engine's land power with the
    eccentric film's factor (it was the centred film's), and the split still adds up to the
    engine's power loss."""
    engine = BearingDynamics(grease_twin())
    engine.initialise(rpm_to_rad_s(900.0), 100.0)
    engine.advance(0.01)
    centred = heat_sources(engine)
    factor = kn.land_shear_factor(engine.vector, 0.7)
    engine.ring[kn.R_LAND_F] = factor
    whirling = heat_sources(engine)
    assert factor > 1.1  # grease, n = 1/2: 1.130
    assert whirling.land > centred.land
    assert whirling.total == pytest.approx(engine.power_loss(), rel=2e-3)
    v, z = engine.vector, engine.params.ball_count
    # the viscous and power-law (consistency) parts scale with the factor, the yield part does not
    coulomb = sum(abs(kn.cage_land_torque(v, w, z, 0.0, 0.0)[0] * w) for w in engine.cage[:, kn.C_OMEGA])
    assert whirling.land - coulomb == pytest.approx(factor * (centred.land - coulomb), rel=1e-9)
