"""The calibration's uncertainty: the linearised formulas against ordinary least squares by hand,
the identifiability rule, and predict's interval."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.cli import main
from bearing_rig_sim.studies.uncertainty import MAX_CORRELATION, FitUncertainty, IdentifiabilityError, check_identifiable, linear_uncertainty, read_uncertainty

CONFIG = Path(__file__).resolve().parents[1] / "config"


def test_straight_line_fit_has_the_textbook_standard_errors() -> None:
    """y = a + b x at x = 0, 1, 2, 3 with residuals (0.1, -0.2, 0.15, -0.05): s^2 = sum r^2 /
    (n - 2), var b = s^2 / Sxx, var a = s^2 (1/n + xbar^2 / Sxx), cov = -xbar s^2 / Sxx (any
    regression text). A load offset that shifts every row by c is absorbed by the intercept:
    da/ddelta = -c, db/ddelta = 0."""
    x = np.array([0.0, 1.0, 2.0, 3.0])
    r = np.array([0.1, -0.2, 0.15, -0.05])
    j = np.column_stack([np.ones(4), x])
    lin = linear_uncertainty(j, np.full(4, 0.3), r, load_sigma=2.0)
    s2 = float(np.sum(r**2)) / 2
    sxx = float(np.sum((x - 1.5) ** 2))
    assert lin["s"] ** 2 == pytest.approx(s2)
    assert lin["noise_cov"][1, 1] == pytest.approx(s2 / sxx)
    assert lin["noise_cov"][0, 0] == pytest.approx(s2 * (0.25 + 1.5**2 / sxx))
    assert lin["noise_cov"][0, 1] == pytest.approx(-1.5 * s2 / sxx)
    assert lin["dtheta_dload"] == pytest.approx([-0.3, 0.0], abs=1e-12)
    assert lin["cov"][0, 0] == pytest.approx(lin["noise_cov"][0, 0] + 0.09 * 4.0)
    assert lin["dof"] == 2
    assert abs(lin["load_correlation"][0]) == pytest.approx(1.0)  # the intercept and the offset: inseparable


def test_parameters_the_data_cannot_separate_are_refused() -> None:
    x = np.linspace(0.0, 1.0, 6)
    j = np.column_stack([x, 2.0 * x + 1e-4 * np.sin(7 * x)])
    lin = linear_uncertainty(j, np.zeros(6), np.full(6, 0.01), load_sigma=0.0)
    corr = lin["noise_cov"] / np.sqrt(np.outer(np.diag(lin["noise_cov"]), np.diag(lin["noise_cov"])))
    assert abs(corr[0, 1]) > MAX_CORRELATION
    with pytest.raises(IdentifiabilityError, match="yield_stress and consistency are not identifiable"):
        check_identifiable(["yield_stress", "consistency"], corr, lin["condition"])
    with pytest.raises(IdentifiabilityError, match="rows cannot give"):
        linear_uncertainty(j[:2], np.zeros(2), np.zeros(2), 1.0)


def test_shipped_calibration_states_its_uncertainty() -> None:
    """The shipped block reads back; its parameters are identifiable by the rule, and the load
    is not separable from them (the Table 3 rows are all at 100 N)."""
    unc = read_uncertainty(CONFIG / "calibration" / "h7006c_table3.yaml")
    assert isinstance(unc, FitUncertainty)
    assert unc.names == ("yield_stress", "consistency")
    check_identifiable(unc.names, np.array(unc.noise_correlation), unc.condition_number)
    assert all(0.0 < se < 1.0 for se in unc.standard_errors)
    assert FitUncertainty.from_dict(unc.as_dict()) == unc
    assert min(abs(c) for c in unc.load_correlation) > 0.99


@pytest.mark.slow
def test_predict_gives_a_95_percent_interval(capsys: pytest.CaptureFixture[str]) -> None:
    argv = [
        "predict",
        "--rpm",
        "1200",
        "--load",
        "100",
        "--json",
        "--bearing",
        str(CONFIG / "bearings" / "h7006c.yaml"),
        "--calibration",
        str(CONFIG / "calibration" / "h7006c_table3.yaml"),
    ]
    assert main(argv) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["slip_pct_low"] < row["slip_pct"] < row["slip_pct_high"]
    half = 0.5 * (row["slip_pct_high"] - row["slip_pct_low"])
    assert half == pytest.approx(row["slip_pct_high"] - row["slip_pct"], rel=1e-3)  # symmetric, linearised
    assert 0.0 < half < 1.0 and math.isfinite(half)
