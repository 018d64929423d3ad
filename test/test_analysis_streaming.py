"""The monitor's slope test: its Student's t quantile against a printed table. The verdicts of
:class:`~bearing_rig_sim.analysis.streaming.TrailingSlope` are tested through the monitor
(test_monitoring.py, test_monitoring_bench.py)."""

from __future__ import annotations

import pytest

from bearing_rig_sim.analysis.streaming import t_quantile_95


# -- the Student's t quantile of the monitor's slope test --------------------------------------
@pytest.mark.parametrize(
    ("dof", "table"),
    [(1, 6.314), (2, 2.920), (5, 2.015), (10, 1.812), (20, 1.725), (21, 1.721), (30, 1.697), (40, 1.684), (60, 1.671), (120, 1.658)],
)
def test_t_quantile_matches_the_one_sided_5_percent_column_of_a_t_table(dof: int, table: float) -> None:
    """t(0.95; dof) as any statistics table prints it to three decimals (e.g. the NIST/SEMATECH
    e-Handbook, table 1.3.6.7.2, column 0.05); above 20 degrees of freedom it stays above the
    normal 1.645, which would make the test anti-conservative."""
    assert t_quantile_95(dof) == pytest.approx(table, abs=5e-4)
    if dof > 20:
        assert t_quantile_95(dof) > 1.645 + 0.01
