"""The reproduction's gates: a fit is a result only inside physical bounds and quality gates."""

from __future__ import annotations

import numpy as np

from bearing_rig_sim.analysis.gaussian import fit_gaussians
from bearing_rig_sim.studies import reproduction, reproduction_report
from bearing_rig_sim.studies.paper_data import PAPER_TABLE7
from bearing_rig_sim.studies.reproduction_report import acceleration_fit_problem


def test_the_papers_run_up_curves_pass_the_gates_and_a_decay_from_skid_does_not() -> None:
    """The paper's own Table 7 curves, sampled over 3 s, fit inside every gate; a slip falling
    from 65 % as 1/(spindle speed), which only the tail of a far-off Gaussian of huge amplitude
    can follow, is refused with the amplitude named."""
    t = np.linspace(0.0, 3.0, 150)
    for lam, k, d in PAPER_TABLE7.values():
        fit = fit_gaussians(t, lam * np.exp(-(((t - k) / d) ** 2)), 1)
        assert acceleration_fit_problem(fit) == ""
        assert fit.params[0][0] < 100.0
    t = np.linspace(0.5, 3.0, 150)
    decay = 65.0 / (1.0 + 20.0 * t)
    problem = acceleration_fit_problem(fit_gaussians(t, decay, 1))
    assert problem and ("lambda" in problem or "centre" in problem or "R^2" in problem or "RMSE" in problem)


def test_the_run_and_the_report_import_in_one_direction() -> None:
    """The paper's tables live in paper_data, imported by both; the report imports nothing of
    the run module (no import circle)."""
    assert reproduction.RawResults is reproduction_report.RawResults
    source = open(reproduction_report.__file__, encoding="utf-8").read()
    assert "studies.reproduction import" not in source and "studies import reproduction" not in source
