"""The pure-rolling cage speed and the cage slip rate (paper Eq. 11-12; docs/paper.md section 6).

The epicyclic (pure-rolling) cage speed is

    n_s = n_i / 2 * (1 - Dw cos(alpha) / dm)

and the slip rate, in **percent**, is

    S_c = (1 - n_c / n_s) * 100

with n_i the inner-ring speed, n_c the cage speed (rad/s; any common unit cancels), Dw the ball
diameter, dm the pitch diameter (m) and alpha the contact angle (rad).

These are the definitions alone, on floats or numpy arrays, with no checks: the analysis wraps
them with its input checks (:class:`bearing_rig_sim.analysis.slip.BearingKinematics`), the
engine calls them on its own validated geometry.
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np
import numpy.typing as npt

Speed = TypeVar("Speed", float, npt.NDArray[np.float64])
"""A speed, rad/s: one value or an array of them."""


def epicyclic_ratio(ball_diameter: float, pitch_diameter: float, contact_angle: float) -> float:
    """n_s / n_i = (1 - Dw cos(alpha) / dm) / 2, dimensionless (0.4283 for H7006C at 15 deg).

    Args:
        ball_diameter: Dw, m.
        pitch_diameter: dm, m.
        contact_angle: alpha, rad.
    """
    return 0.5 * (1.0 - ball_diameter * math.cos(contact_angle) / pitch_diameter)


def slip_pct(cage_speed: Speed, inner_ring_speed: Speed, ratio: float) -> Speed:
    """Cage slip rate in **percent**, (1 - n_c / (ratio n_i)) * 100; Eq. 11.

    Args:
        cage_speed: n_c, rad/s.
        inner_ring_speed: n_i, rad/s (not zero: the slip rate is undefined at rest).
        ratio: the epicyclic ratio n_s / n_i (:func:`epicyclic_ratio`).
    """
    return (1.0 - cage_speed / (ratio * inner_ring_speed)) * 100.0
