"""Ring and ball expansion change the operating clearance (issue 24): a hand calculation, and
what it does to the load distribution."""

from __future__ import annotations

from pathlib import Path

import pytest

from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.quasi_static import LoadCase, LoadDistributionError, solve, thermal_clearance_change
from bearing_rig_sim.bearing.materials import BEARING_STEEL

BEARING = Path(__file__).resolve().parents[1] / "config" / "bearings" / "h7006c.yaml"


def test_clearance_change_is_alpha_dt_times_the_diameters() -> None:
    """H7006C: d_m 42.45 mm, D_w 6.3 mm, so raceway diameters 48.75 mm (outer) and 36.15 mm
    (inner). Outer ring +5 K, inner ring +10 K, balls +12 K, alpha 11.9e-6 1/K, by hand:
    11.9e-6 (48.75 x 5 - 36.15 x 10 - 2 x 6.3 x 12) mm = -3.2005 um."""
    p = BearingParameters.from_yaml(BEARING)
    assert BEARING_STEEL.expansion == 11.9e-6
    assert thermal_clearance_change(p, 45.0, 40.0, 47.0, 35.0) == pytest.approx(-3.2005e-6, abs=1e-10)
    # each body alone: Delta = alpha dT diameter, the outer ring's with the clearance's sign
    assert thermal_clearance_change(p, 35.0, 45.0, 35.0, 35.0) == pytest.approx(11.9e-6 * 10.0 * 48.75e-3, rel=1e-12)
    assert thermal_clearance_change(p, 45.0, 35.0, 35.0, 35.0) == pytest.approx(-11.9e-6 * 10.0 * 36.15e-3, rel=1e-12)
    assert thermal_clearance_change(p, 35.0, 35.0, 45.0, 35.0) == pytest.approx(-11.9e-6 * 10.0 * 2.0 * 6.3e-3, rel=1e-12)
    assert thermal_clearance_change(p, 60.0, 60.0, 60.0, 60.0) == 0.0


def test_a_warm_inner_ring_takes_up_clearance_and_spreads_the_load_zone() -> None:
    """Under 163 N axial and 500 N radial (issue 23's case), a running spindle bearing whose inner
    ring and balls run 10 K above its outer ring loses clearance (5.8 um): the load zone spreads
    (no fewer balls loaded, the heaviest carrying less) and the lost clearance acts as a preload
    (the balls' loads add up to more)."""
    p = BearingParameters.from_yaml(BEARING)
    cold = solve(p, LoadCase(axial_load=163.0, radial_load=500.0))
    change = thermal_clearance_change(p, 45.0, 35.0, 45.0, 35.0)
    assert change < 0.0
    warm = solve(p, LoadCase(axial_load=163.0, radial_load=500.0, clearance=change))
    assert warm.loaded_balls >= cold.loaded_balls
    assert warm.ball_load_max < cold.ball_load_max
    assert float(warm.inner_loads.sum()) > float(cold.inner_loads.sum())


def test_an_impossible_temperature_is_refused() -> None:
    p = BearingParameters.from_yaml(BEARING)
    with pytest.raises(LoadDistributionError, match="inner_ring_c"):
        thermal_clearance_change(p, float("nan"), 35.0, 35.0, 35.0)
    with pytest.raises(LoadDistributionError, match="expansion"):
        thermal_clearance_change(p, 35.0, 35.0, 35.0, 35.0, expansion=1e-3)
