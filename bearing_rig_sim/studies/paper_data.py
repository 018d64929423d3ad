"""The paper's published numbers (Yang et al., Lubricants 2023, 11, 298; docs/paper.md sections
9-11), in one place for the reproduction's run and its report.

Units as the paper gives them: speeds in rpm, loads in N, slip in percent, time in s,
accelerations in rad/s^2.
"""

from __future__ import annotations

PAPER_TABLE3: dict[int, tuple[float, float]] = {900: (3.22, 3.17), 1500: (4.07, 3.95), 2100: (4.64, 4.76), 2700: (5.28, 5.17)}
"""rpm -> (bench slip %, the paper's simulated slip %), 100 N (the four calibration rows; the
1200, 1800 and 2400 rpm rows are withheld as a blind check)."""

PAPER_TABLE4: dict[int, tuple[float, float, float]] = {1: (0.012, 0.9996, 0.045), 2: (0.007, 0.9993, 0.040)}
"""Slip vs load fit quality, pooled over speeds: terms -> (SSE %^2, R^2, RMSE %)."""

PAPER_TABLE5_1000RPM: tuple[float, ...] = (5.18, 2.05, -4.14, 530.0, 214.0, 469.0)
"""2-term parameters at 1000 rpm (a1 %, a2 %, b1 N, b2 N, c1 N, c2 N); the other rows are garbled
in the source."""

PAPER_TABLE6: dict[int, tuple[float, float, float]] = {1: (1.16e-4, 0.9997, 0.0048), 2: (1.92e-4, 0.9994, 0.0098)}
"""Slip vs time fit quality: terms -> (SSE %^2, R^2, RMSE %)."""

PAPER_TABLE7: dict[float, tuple[float, float, float]] = {
    20.0: (3.5, -1.52, 1.29),
    40.0: (1.64, -0.73, 0.9),
    60.0: (1.33, -0.49, 0.72),
    80.0: (0.76, -0.09, 0.45),
}
"""rad/s^2 -> (lambda %, k s, d s) of the slip of a run-up from rest at 200 N,
y = lambda exp(-((t - k)/d)^2)."""

PAPER_ACCELERATION_LOAD_N: float = 200.0
"""Axial load of the acceleration experiment, N."""
