"""Bearing dynamics engine (numpy + numba; no ROS import).

Public API: :class:`BearingParameters` (bearing data from YAML), :class:`BearingDynamics`
(the integrator), :class:`Mounting` (clearance, misalignment, preload), :class:`Observation`, :class:`Snapshot`. The numba kernels live in the
private module :mod:`.kernels`.
"""

from bearing_rig_sim.dynamics.engine import (
    MIN_AXIAL_LOAD,
    BearingDynamics,
    ChunkAverage,
    DynamicsDivergedError,
    DynamicsInputError,
    Mounting,
    Observation,
    Snapshot,
)
from bearing_rig_sim.dynamics.parameters import BearingParameters, DerivedGeometry, derive
from bearing_rig_sim.dynamics.step_limit import OperatingEnvelope, StepLimit, StepLimitError
from bearing_rig_sim.numba_cache import refresh_once

refresh_once()  # numba reads a cache at a function's first call; see numba_cache

__all__ = [
    "MIN_AXIAL_LOAD",
    "BearingDynamics",
    "BearingParameters",
    "ChunkAverage",
    "DerivedGeometry",
    "DynamicsDivergedError",
    "DynamicsInputError",
    "Mounting",
    "Observation",
    "OperatingEnvelope",
    "Snapshot",
    "StepLimit",
    "StepLimitError",
    "derive",
]
