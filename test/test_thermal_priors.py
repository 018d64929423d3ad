"""The coupled twin's unmeasured inputs (studies/priors.py), its named calibrations and the
grease's temperature law with its exponent.

* K(T) = K_ref (eta(T)/eta_ref)^x: x = 0 holds K, x = 1 is the viscosity ratio, x = 1/2 its
  square root (closed form from the Walther law's viscosities).
* The named calibrations: the names resolve to files, the coupled one is fitted through the
  thermal steady states, every calibrated value inside its physical range.
* The linear refit: a change of the rows in the span of the fit's Jacobian, r = J c, is absorbed
  whole (d theta = -c), so a prediction whose own change is g . c moves by nothing; a change
  orthogonal to the span is not absorbed at all.
* The interval: each side's parametric half-width and model-form shift in quadrature.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.dynamics.parameters import CALIBRATABLE
from bearing_rig_sim.dynamics.calibrations import COUPLED, DEFAULT_CALIBRATION, ISOTHERMAL, NAMED, calibration_file, is_coupled
from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.settings_model import read_file
from bearing_rig_sim.studies.calibration import PHYSICAL_RANGES
from bearing_rig_sim.studies.priors import PRIORS, SHORT_HOLD_S, ModelForm, running_time, spread, widen


def test_the_grease_consistency_follows_the_base_oil_to_the_power_x() -> None:
    lub = BearingParameters.from_yaml().lubricant
    assert lub is not None
    ratio = lub.dynamic_viscosity(55.0) / lub.dynamic_viscosity(35.0)
    assert 0.3 < ratio < 0.7  # the base oil thins by about half over 20 K (Walther, 25 / 5 mm^2/s)
    for x, expected in ((0.0, 1.0), (0.5, math.sqrt(ratio)), (1.0, ratio)):
        warm = lub.replace_rheology(consistency_temperature_exponent=x).at_temperature(55.0, 35.0)
        assert warm.consistency == pytest.approx(lub.consistency * expected, rel=1e-12)
        assert warm.yield_stress == pytest.approx(lub.yield_stress * math.exp(-lub.yield_stress_temperature_coefficient * 20.0), rel=1e-12)


def test_the_named_calibrations_resolve_and_state_how_they_were_fitted() -> None:
    assert DEFAULT_CALIBRATION == COUPLED and set(NAMED) == {COUPLED, ISOTHERMAL}
    assert calibration_file(ISOTHERMAL).name == "h7006c_table3.yaml"
    assert is_coupled(calibration_file(COUPLED)) and not is_coupled(calibration_file(ISOTHERMAL))
    with pytest.raises(ConfigError, match="coupled, isothermal"):
        calibration_file("warm")
    for name in NAMED:
        doc = read_file(CalibrationFile, calibration_file(name))
        for key, value in doc.parameters.items():
            field = next(k for k, (sec, entry) in CALIBRATABLE.items() if f"{sec}.{entry}" == key)
            rng = PHYSICAL_RANGES[field]
            assert rng.low <= value <= rng.high, (name, key, value)
    coupled = BearingParameters.from_yaml(None, calibration_file(COUPLED))
    assert coupled.lubricant is not None and coupled.lubricant.consistency_temperature_exponent == 0.0


def test_the_running_time_of_the_rising_program() -> None:
    assert running_time(900.0) == SHORT_HOLD_S
    assert running_time(2700.0) == 7 * SHORT_HOLD_S  # the seventh speed of 900, 1200, ..., 2700
    assert running_time(500.0) == SHORT_HOLD_S
    assert running_time(1800.0, 100.0) == 400.0


def _form(jacobian: np.ndarray, row_effects: dict[str, list[list[float]]]) -> ModelForm:
    absorption = np.linalg.pinv(jacobian.T @ jacobian) @ jacobian.T
    return ModelForm(
        {k: tuple(tuple(r) for r in v) for k, v in row_effects.items()},
        tuple(tuple(r) for r in absorption),
        ("yield_stress", "consistency"),
        (300.0, 50.0),  # well inside both ranges: small refits stay there
    )


def test_a_change_in_the_fits_span_is_absorbed_and_an_orthogonal_one_is_not() -> None:
    jac = np.array([[1.0, 0.5], [1.0, 1.0], [1.0, 1.5], [1.0, 2.0]])  # slip per log-parameter at four rows
    c = np.array([0.02, -0.01])
    span = jac @ c  # rows' slip change at the exponent's far end (0.25)
    zero = {p.name: [[0.0] * len(p.evaluated) for _ in range(4)] for p in PRIORS}
    effects = dict(zero)
    effects["consistency_temperature_exponent"] = [[0.0, float(v)] for v in span]
    g = np.array([1.0, 1.25])  # the prediction between the second and third rows
    point = {p.name: tuple([0.0] * len(p.evaluated)) for p in PRIORS}
    point["consistency_temperature_exponent"] = (0.0, float(g @ c))
    lo, hi, kept = spread(point, _form(jac, effects), g)
    assert kept > 0 and abs(lo) < 1e-12 and abs(hi) < 1e-12
    # orthogonal to the span: the fit does not move, the prediction keeps its own change
    orth = np.array([1.0, -1.0, -1.0, 1.0])
    assert np.allclose(jac.T @ orth, 0.0)
    effects["consistency_temperature_exponent"] = [[0.0, float(v)] for v in 0.1 * orth]
    point["consistency_temperature_exponent"] = (0.0, 0.2)  # 0.2 pp at x = 0.25, linear beyond
    lo, hi, kept = spread(point, _form(jac, effects), g)
    # x uniform on [0, 1]: the shift 0.8 x is uniform on [0, 0.8] pp; its 2.5 and 97.5 % points
    assert lo == pytest.approx(0.8 * 0.025, abs=0.02) and hi == pytest.approx(0.8 * 0.975, abs=0.02)


def test_a_refit_out_of_range_is_discarded() -> None:
    jac = np.array([[1.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 1.0]])
    effects = {p.name: [[0.0] * len(p.evaluated) for _ in range(4)] for p in PRIORS}
    # the exponent lowers the first two rows by 1 pp at 0.25: the fit raises log(yield) by 1 per
    # 0.25, so 300 Pa leaves its 2000 Pa limit beyond x = 0.25 ln(2000/300) = 0.474
    effects["consistency_temperature_exponent"] = [[0.0, -1.0], [0.0, -1.0], [0.0, 0.0], [0.0, 0.0]]
    point = {p.name: tuple([0.0] * len(p.evaluated)) for p in PRIORS}
    _, _, kept = spread(point, _form(jac, effects), np.zeros(2), count=200)
    assert kept / 200 == pytest.approx(0.25 * math.log(2000.0 / 300.0), abs=0.02)


def test_the_interval_adds_each_sides_parts_in_quadrature() -> None:
    low, high = widen(4.0, 0.1, -0.3, 0.05)
    hw = 1.959963984540054 * 0.1
    assert low == pytest.approx(4.0 - math.hypot(hw, 0.3), rel=1e-12)
    assert high == pytest.approx(4.0 + math.hypot(hw, 0.05), rel=1e-12)
    low, high = widen(4.0, 0.1, 0.2, 0.3)  # both shifts upwards: the low side is parametric only
    assert low == pytest.approx(4.0 - hw, rel=1e-12) and high == pytest.approx(4.0 + math.hypot(hw, 0.3), rel=1e-12)
