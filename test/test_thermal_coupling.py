"""The session's engine follows the thermal network (two-way coupling, thermal/coupling.py).

* A traction table built a slice at a time is the table ``traction_table`` builds for the
  lubricant at that temperature, node for node.
* The grid's blend is linear in temperature between its two neighbouring tables.
* A twin coupled both ways: every 0.1 s network step sets the engine's temperature-dependent
  entries to those of its lubricant at the lubricant node's temperature (the same numbers
  ``derive`` gives for the bearing at that temperature), its traction table to the grid's
  blend, and a warming grease drags less, so the slip falls (the grease's temperature laws:
  consistency with the base oil's viscosity, yield stress exp(-c dT)); coupled one way the
  engine keeps its parameters.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.parameters import derive, traction_table
from bearing_rig_sim.dynamics.traction import HEADER
from bearing_rig_sim.thermal.coupling import (
    TEMPERATURE_DEPENDENT,
    TableBuild,
    TractionTableGrid,
    params_at_temperature,
    steepest_traction_slope,
)

CONFIG = Path(__file__).resolve().parents[1] / "config"
BEARING = CONFIG / "bearings" / "h7006c.yaml"
CALIBRATION = CONFIG / "calibration" / "h7006c_table3.yaml"


@pytest.fixture(scope="module")
def params() -> BearingParameters:
    return BearingParameters.from_yaml(BEARING, CALIBRATION)


def test_a_table_built_slice_by_slice_is_the_table_at_that_temperature(params: BearingParameters) -> None:
    build = TableBuild(params, 45.0)
    with pytest.raises(RuntimeError, match="slices still to build"):
        build.table()
    steps = 0
    while not build.done:
        build.step()
        steps += 1
    assert steps == 2 * 12 * 14 * 4  # contacts x loads x speeds x SRR quarters
    reference = traction_table(params_at_temperature(params, 45.0))
    assert np.array_equal(build.table(), reference)
    # and the slope the kernels cap with is derive's for that table
    vector, _ = derive(params_at_temperature(params, 45.0))
    assert steepest_traction_slope(reference) == pytest.approx(vector[kn.P_MU_SLOPE_MAX], rel=1e-12)


def test_the_grid_blends_its_neighbours_linearly_and_falls_back_to_the_nearer(params: BearingParameters) -> None:
    grid = TractionTableGrid(params, step_k=5.0)
    assert grid.bracket(32.0) == (6, 7, pytest.approx(0.4))
    assert grid.blend(32.0) is None
    grid.build_now(6)
    got = grid.blend(32.0)
    assert got is not None
    only, stands_for = got
    assert stands_for == 30.0 and np.array_equal(only, grid.tables[6])
    grid.want(7)
    assert grid.busy
    finished = sum(grid.work() for _ in range(2 * 12 * 14 * 4))  # contacts x loads x speeds x SRR quarters
    assert finished == 1 and not grid.busy
    a, b = grid.tables[6], grid.tables[7]
    assert np.array_equal(b, traction_table(params_at_temperature(params, 35.0)))
    got = grid.blend(32.0)
    assert got is not None
    blended, stands_for = got
    assert stands_for == 32.0
    assert np.array_equal(blended[:HEADER], a[:HEADER])
    np.testing.assert_allclose(blended[HEADER:], 0.6 * a[HEADER:] + 0.4 * b[HEADER:], rtol=1e-12, atol=1e-15)


@pytest.mark.slow
def test_twin_coupled_both_ways_follows_the_lubricant_and_its_slip_falls_as_it_warms(params: BearingParameters) -> None:
    from bearing_rig_sim.simulation.twin import RigTwin

    def twin() -> RigTwin:
        return RigTwin.from_files(BEARING, CALIBRATION, CONFIG / "rig.yaml", initial_speed=2700 * math.pi / 30, initial_axial_load=100.0)

    two_way = twin()
    coupling = two_way.attach_thermal(BEARING)
    ambient = coupling.config.ambient
    assert coupling.applied_temperature == ambient and coupling.grid is not None
    slips, temperatures = [], []
    for _ in range(3):
        for _ in range(500):
            two_way.tick(with_truth=False)
        slips.append(two_way.truth().slip_rate)
        temperatures.append(coupling.temperature("lubricant"))
    # every network step (0.1 s) set the engine to the lubricant node's temperature
    assert coupling.network.time == pytest.approx(1.5, abs=1e-9)
    assert coupling.applied_temperature == coupling.temperature("lubricant")
    expected, _ = derive(params_at_temperature(params, coupling.applied_temperature))
    for i in TEMPERATURE_DEPENDENT:
        assert two_way.engine.vector[i] == pytest.approx(expected[i], rel=1e-12), i
    got = coupling.grid.blend(coupling.applied_temperature)
    assert got is not None
    table, stands_for = got
    base = int(two_way.engine.vector[kn.P_TABLE])
    assert np.array_equal(two_way.engine.vector[base : base + table.size], table)
    assert coupling.table_temperature == stands_for
    # warming: less drag, less slip
    assert temperatures[0] > ambient + 1.0 and temperatures[0] < temperatures[1] < temperatures[2]
    assert slips[0] > slips[1] > slips[2] > 0.0

    one_way = twin()
    before = one_way.engine.vector.copy()
    one_way.attach_thermal(BEARING, feedback=False)
    for _ in range(500):
        one_way.tick(with_truth=False)
    assert one_way.thermal is not None and one_way.thermal.temperature("lubricant") > ambient + 1.0
    assert np.array_equal(one_way.engine.vector, before)


def test_the_network_starts_at_ambient_or_the_given_rise_above_it() -> None:
    from bearing_rig_sim.simulation.twin import RigTwin, TwinError

    twin = RigTwin.from_files(BEARING, CALIBRATION, CONFIG / "rig.yaml")
    with pytest.raises(TwinError, match="initial_rise_k"):
        twin.attach_thermal(BEARING, initial_rise_k=-1.0)
    coupling = twin.attach_thermal(BEARING, initial_rise_k=10.0)
    ambient = coupling.config.ambient
    assert np.all(coupling.network.temperatures == ambient + 10.0)
    assert coupling.applied_temperature == ambient + 10.0
