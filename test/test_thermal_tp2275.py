"""The second bearing (NASA TP-2275's 35 mm bore, jet-lubricated with MIL-L-23699) predicted with
no tuning, and bearing or lubricant files with a value outside its range refused."""

from __future__ import annotations

import contextlib
import io
import json
import math
from pathlib import Path
from typing import Any

import pytest

from bearing_rig_sim.cli import main
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.lubrication import film_thickness
from bearing_rig_sim.dynamics.parameters import BearingParameters, derive, traction_table
from bearing_rig_sim.dynamics.quasi_static import LoadCase, solve
from bearing_rig_sim.dynamics.traction import ellipse_traction, spin_and_heathcote, table_power

CONFIG = Path(__file__).resolve().parents[1] / "config"
TP2275 = CONFIG / "bearings" / "tp2275.yaml"
MIL = CONFIG / "lubricants" / "mil_l_23699.yaml"


REPORT = {28000.0: (350.0, 413.0), 48000.0: (700.0, 425.0), 64000.0: (1100.0, 435.0), 72000.0: (1400.0, 443.0)}
"""Measured heat generation (W) and outer-ring temperature (K) of the 35 mm bore bearing at
667 N thrust, MIL-L-23699 in at 394 K, by shaft speed (rpm): R. J. Parker, NASA TP-2275
(1984), Fig. 3, as digitised (about +-3 %) in the ADORE manuscript of the public repository
YUXinluhk/BallBearing-Dynamics (paper/manuscript.tex at commit 6953d26, table "Selected NASA
TP-2275 experimental measurements", which gives the outer-ring temperatures, "extracted from
Figs. 3, 6, and 13" of the report; the heat values also in paper/data/nasa_validation.csv). A
secondary source: the report itself could not be read. The same repository's later manuscript
(paper/manuscript_applsci.tex, commit dd2220c) says instead that per-node temperatures are not
available in TP-2275 for the 35 mm bearing, so the outer-ring values are the weaker of the two."""

HEAT_DIGITISATION = 0.03
"""Relative uncertainty of the heat values read off the report's figure: the secondary source's
own statement (paper/manuscript_applsci.tex, commit dd2220c: "digital curve-reading,
introducing an estimated digitization uncertainty of +-3 %")."""
HEAT_ACCEPTANCE = 0.30
"""Issue 33's acceptance: the twin's heat within 30 % of the report's at each speed."""
TEMPERATURE_READING_K = 0.01 * 420.0
"""Uncertainty of an outer-ring temperature read off the report's figures, K: ASSUMPTION, 1 % of
the value (no statement for the temperatures in the source; +-3 % of the heat's reading would be
+-13 K here, 1 % is the tighter and more usual figure-reading accuracy)."""
TREND_K = math.sqrt(2.0) * TEMPERATURE_READING_K
"""The rise of the outer ring from 28 000 to 72 000 rpm (the report's 30 K) holds two readings:
their uncertainties in quadrature, 5.9 K. It does not depend on the housing's offset."""
MODEL_FORM = (
    "model-form deficit, issue 33 item 3: no published law tried meets 30 % at all four speeds (docs/thermal.md, "
    "The published laws, tried): Parker's jet cavity share read in percent takes the drag away (0.37-0.73 x), read "
    "as a fraction it overshoots from 48 000 rpm (1.68-1.84 x), the inlet shear heating reduction of the rolling force "
    "lowers the 28 000 rpm point that is already short; the heat missing at the percent reading is 221-378 W, a "
    "near-constant torque of 0.05-0.075 N m (a load-dependent friction, not churning). The raceway contacts do not "
    "supply it: with the traction table's spin at the centrifugal contact angles (outer-raceway control, 2.1-5.3 x the "
    "equal-angle spin) the film's spin friction (0.0024 effective at 28 000 rpm) keeps the inner contacts' loss at "
    "4-143 W; the SKF model is outside its speed range here (3.4-21 x the report; docs/thermal.md, The raceway "
    "contacts examined)"
)
EQUAL_ANGLE_SPIN = (
    "the traction table's nodes take the inner contact's spin from the angles of the ball balance at their own load "
    "and speed (exact at the nodes), but between them it interpolates the loss linearly in ln u_e and ln Q over cells a "
    "factor 1.84 and 2.13 wide, across which the angles open apart fast at this bearing's speeds: at 28 000 rpm "
    "(85 N, 33.4 m/s; 29.3 / 21.1 deg) it gives 1.26 x the film law's loss, where it gave 0.30 x with the equal-angle "
    "spin (docs/thermal.md, The raceway contacts examined)"
)
STEEP_HEAT = (
    "the heat grows as about n^2.5 between 28 000 and 72 000 rpm against the report's n^1.5 (0.66 to 1.81 x the "
    "report's), and the outer ring's rise follows it: 36.7 K against 30 +- 5.9 K. It passed at 34.4 K while the "
    "traction table's speed axis ended at 40 m/s, which clamped the inner contacts' loss at 48 000-72 000 rpm "
    "(55.6-80.7 m/s): the clamp, not the model, kept the rise within the readings (docs/thermal.md)"
)
HOUSING = (
    "the assumed housing and shaft lead heat to 22 degC air; the report's rig (oil at 394 K, outer-ring cooling) "
    "is not described in anything read here (docs/thermal.md, Outer ring)"
)


@pytest.fixture(scope="module")
def predictions() -> list[dict[str, Any]]:
    """The twin at the report's four speeds, 667 N, thermal steady state (one run for the module)."""
    speeds = [f"{rpm:.0f}" for rpm in REPORT]
    argv = ["predict", "--bearing", str(TP2275), "--lubricant", str(MIL), "--rpm", *speeds, "--load", "667", "--thermal", "--json"]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(argv) == 0
    return [json.loads(line) for line in out.getvalue().splitlines()]


@pytest.mark.slow
def test_tp2275_heat_is_accounted_for_and_grows_with_speed(predictions: list[dict[str, Any]]) -> None:
    """28 000-72 000 rpm at 667 N, oil in at 394 K, no tuning and no calibration: the heat terms add
    up to the power loss, the heat grows with speed, and the jet carries at most all of it
    (housing and shaft lead the rest to the colder ambient), so the lubricant's rise over the
    inlet is below power / (rho Q c_p)."""
    rows = predictions
    powers = [r["power_loss_w"] for r in rows]
    assert powers == sorted(powers) and powers[0] > 0.0
    jet = 1000.0 * 3.15e-5 * 2000.0  # rho Q c_p of the file's jet, W/K (density at 15 degC: an upper bound)
    for r in rows:
        assert "slip_pct_low" not in r
        rise = r["lubricant_temperature_c"] - 120.85
        assert rise < 1.05 * r["power_loss_w"] / jet
        assert sum(r["heat_w"].values()) == pytest.approx(r["power_loss_w"], rel=2e-3)
    assert rows[-1]["lubricant_temperature_c"] > 120.85


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=MODEL_FORM)
def test_tp2275_heat_generation_within_30_percent_of_the_report(predictions: list[dict[str, Any]]) -> None:
    """The acceptance of issue 33: the heat within 30 % of the report's at every speed, widened by
    the reading's +-3 % (:data:`HEAT_DIGITISATION`). Today 0.65 / 1.27 / 1.71 / 1.81 x: expected to
    fail (strict: a pass is reported, so the marker goes when the model is fixed; :data:`MODEL_FORM`
    says what the published laws tried give)."""
    bound = HEAT_ACCEPTANCE + HEAT_DIGITISATION
    ratios = {r["rpm"]: r["power_loss_w"] / REPORT[r["rpm"]][0] for r in predictions}
    assert all(abs(ratio - 1.0) <= bound for ratio in ratios.values()), ratios


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=HOUSING)
def test_tp2275_outer_ring_temperature_against_the_reports_measurements(predictions: list[dict[str, Any]]) -> None:
    """The outer ring at thermal steady state against the report's 413 / 425 / 435 / 443 K within
    twice the reading's uncertainty (:data:`TEMPERATURE_READING_K`). The twin's runs 20-28 K
    cooler: expected to fail (strict)."""
    for r in predictions:
        measured_k = REPORT[r["rpm"]][1]
        assert abs(r["outer_ring_temperature_c"] + 273.15 - measured_k) <= 2.0 * TEMPERATURE_READING_K, (r["rpm"], r["outer_ring_temperature_c"])


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=STEEP_HEAT)
def test_tp2275_outer_ring_rises_with_speed_as_the_reports(predictions: list[dict[str, Any]]) -> None:
    """The outer ring's rise from 28 000 to 72 000 rpm, the report's 443 - 413 = 30 K, within the
    two readings' uncertainty (:data:`TREND_K`): a check of the heat's growth reaching the outer
    ring that the housing's offset does not enter (the twin: 36.9 K, expected to fail, strict)."""
    by_rpm = {r["rpm"]: r["outer_ring_temperature_c"] for r in predictions}
    twin_rise = by_rpm[72000.0] - by_rpm[28000.0]
    report_rise = REPORT[72000.0][1] - REPORT[28000.0][1]
    assert abs(twin_rise - report_rise) <= TREND_K, (twin_rise, report_rise)


@pytest.mark.xfail(strict=True, reason=EQUAL_ANGLE_SPIN)
def test_the_tables_inner_spin_loss_follows_outer_raceway_control_at_speed() -> None:
    """At 28 000 rpm and 667 N the inner contact's loss in rolling (SRR 0) that the traction table
    gives equals the film law's at the spin of outer-raceway control: the ball's angular velocity
    normal to the outer contact's normal, rolling without slip at both contacts (Harris and
    Kotzalas, raceway control), which with the angles alpha_i, alpha_o of the quasi-static
    solution (centrifugal force in) spins the inner contact at
    omega_i sin(alpha_i) + omega_m (d_m / D_w) sin(alpha_i - alpha_o). Within 25 % (the table's
    interpolation in load and speed: at 2000 rpm, where the angles stay equal, the two agree
    within 1 %). Today 1.26 times the film law's (the nodes' spin is exact, the interpolation
    between them is not): expected to fail (strict)."""
    params = BearingParameters.from_yaml(TP2275)
    lub = params.lubricant
    assert lub is not None
    temp, omega_i = params.lubricant_temperature, 28000.0 * math.pi / 30.0
    r, rm = 0.5 * params.ball_diameter, 0.5 * params.pitch_diameter
    state = solve(params, LoadCase(axial_load=667.0, inner_ring_speed=omega_i))
    ai, ao, load = state.inner_angles[0], state.outer_angles[0], state.inner_loads[0]
    omega_m = omega_i * (rm - r * math.cos(ai)) / (rm * (1.0 + math.cos(ai - ao)))
    spin = omega_i * math.sin(ai) + omega_m * rm / r * math.sin(ai - ao)
    entrainment = (omega_i - omega_m) * (rm - r * math.cos(ai))
    inner = params.contact_kinematics()[0]
    a, b = inner.hertz.semi_axes(load)
    p_max = inner.hertz.max_pressure(load)
    film = film_thickness(lub, temp, inner.hertz.reduced_modulus, inner.rx, inner.hertz.ellipticity, b, p_max, entrainment, load).central
    heathcote = spin_and_heathcote(inner, ai, 2.0 * r, 2.0 * rm)[1]
    _, expected = ellipse_traction(
        p_max,
        a,
        b,
        film,
        lub.dynamic_viscosity(temp),
        lub.roelands_index(temp),
        lub.eyring_stress,
        lub.limiting_shear_coefficient,
        lub.shear_modulus,
        entrainment,
        0.0,
        spin / entrainment,
        heathcote,
    )
    tabulated = table_power(traction_table(params), 0, 0, 0.0, entrainment, load)
    assert tabulated == pytest.approx(expected, rel=0.25)


@pytest.mark.parametrize("speed", [10.0, 72.0])
def test_the_jet_oils_drag_is_the_sphere_drag_in_the_cavitys_mixture(speed: float) -> None:
    """The jet oil's drag on a ball is the effective-density sphere drag that a cavity oil share
    such as Parker's is defined for: F = C_d (1/2) (phi rho) (pi D^2/4) v^2 + 3 pi (phi eta) D v,
    phi the oil's volume share of the cavity (``supply.fill_fraction``), the form the ADORE
    manuscript writes (rho_eff = phi rho_oil + (1 - phi) rho_air; the air's share is not in the
    twin). At 10 m/s and 72 m/s (the balls' centres at 72 000 rpm), with the files' values."""
    params = BearingParameters.from_yaml(TP2275).replace(friction_model="paper")  # no traction table: the drag alone
    vector, _ = derive(params)
    lub = params.lubricant
    assert lub is not None and lub.kind == "oil_bath"
    phi, temp, dw = lub.fill_fraction, params.lubricant_temperature, params.ball_diameter
    rho, eta = lub.density(temp), lub.dynamic_viscosity(temp)
    expected = 0.5 * params.ball_drag_coefficient * phi * rho * 0.25 * math.pi * dw**2 * speed**2 + 3.0 * math.pi * phi * eta * dw * speed
    force, _ = kn.ball_drag(vector, speed, 100.0)
    assert force == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    ("name", "old", "new", "key"),
    [
        ("bearings/tp2275.yaml", "    mass_kg: {value: 5.0,", "    mass_kg: {value: 50.0,", "thermal.housing.mass_kg"),
        ("bearings/tp2275.yaml", "  oil_inlet_temperature_c: {value: 120.85,", "  oil_inlet_temperature_c: {value: 160.85,", "thermal.oil_inlet_temperature_c"),
        ("lubricants/mil_l_23699.yaml", "  specific_heat_j_kg_k: {value: 2000.0,", "  specific_heat_j_kg_k: {value: 200.0,", "base_oil.specific_heat_j_kg_k"),
    ],
)
def test_a_value_outside_its_range_is_refused_naming_file_key_and_range(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, old: str, new: str, key: str
) -> None:
    bearing, lubricant = tmp_path / "tp2275.yaml", tmp_path / "mil.yaml"
    bearing.write_text(TP2275.read_text())
    lubricant.write_text(MIL.read_text())
    target = bearing if name.startswith("bearings") else lubricant
    text = target.read_text()
    assert old in text
    target.write_text(text.replace(old, new))
    assert main(["predict", "--bearing", str(bearing), "--lubricant", str(lubricant), "--rpm", "28000", "--load", "667", "--thermal"]) == 2
    err = capsys.readouterr().err
    assert target.name in err and key in err and ("<=" in err or ">=" in err or "range" in err or "[" in err), err
