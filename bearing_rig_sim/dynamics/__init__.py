"""Bearing dynamics engine (numpy + numba; no ROS import).

Public API: :class:`BearingParameters` (bearing data from YAML), :class:`BearingDynamics`
(the integrator), :class:`Observation`, :class:`Snapshot`. The numba kernels live in the
private module :mod:`.kernels`.
"""

from bearing_rig_sim.dynamics.engine import (
    MIN_AXIAL_LOAD,
    BearingDynamics,
    ChunkAverage,
    DynamicsInputError,
    Observation,
    Snapshot,
)
from bearing_rig_sim.dynamics.parameters import BearingParameters, DerivedGeometry, derive

__all__ = [
    "MIN_AXIAL_LOAD",
    "BearingDynamics",
    "BearingParameters",
    "ChunkAverage",
    "DerivedGeometry",
    "DynamicsInputError",
    "Observation",
    "Snapshot",
    "derive",
]
