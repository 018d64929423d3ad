"""The spindle drive's limits, the ``spindle`` section of ``config/rig.yaml``.

The simulator's drive refuses commands beyond them, and a test program is checked against them
when it is loaded (:func:`bearing_rig_sim.rig.program.load_program`), so a program the drive
would refuse never starts.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from bearing_rig_sim.rig.parameters import ParameterRecord, bounded

PLAUSIBLE_SPINDLE_SPEED_RAD_S = 4000.0
"""Top of the plausible range of a bench spindle motor's speed, rad/s (about 38 000 rpm): the
bound of a rig file's spindle limit and of a node's start speed before the rig file is read."""


@dataclass(frozen=True)
class SpindleConfig(ParameterRecord):
    """The ``spindle`` section of ``config/rig.yaml`` (sources and reasons beside the values)."""

    SECTION: ClassVar[str] = "spindle"

    max_speed_rad_s: float = bounded(gt=0.0, le=PLAUSIBLE_SPINDLE_SPEED_RAD_S)
    """Highest inner-ring speed the drive accepts, rad/s (plausible for a bench spindle motor:
    up to about 38 000 rpm, 4000 rad/s)."""
    max_acceleration_rad_s2: float = bounded(gt=0.0, le=1.0e5)
    """Highest angular acceleration the drive accepts, rad/s^2; a STEP ramp's peak acceleration
    (1.5 times its mean) counts against it too."""
