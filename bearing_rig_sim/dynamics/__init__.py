"""Bearing dynamics engine (numpy + numba; no ROS import).

Public API: :class:`BearingParameters` (bearing data from YAML), :class:`BearingDynamics`
(the integrator), :class:`Mounting` (clearance, misalignment, preload), :class:`Observation`, :class:`Snapshot`. The numba kernels live in the
private module :mod:`.kernels`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from bearing_rig_sim.numba_cache import refresh_once

refresh_once()  # numba reads a cache at a function's first call; see numba_cache

if TYPE_CHECKING:
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

_HOME = {
    **dict.fromkeys(
        ("MIN_AXIAL_LOAD", "BearingDynamics", "ChunkAverage", "DynamicsDivergedError", "DynamicsInputError", "Mounting", "Observation", "Snapshot"), "engine"
    ),
    **dict.fromkeys(("BearingParameters", "DerivedGeometry", "derive"), "parameters"),
    **dict.fromkeys(("OperatingEnvelope", "StepLimit", "StepLimitError"), "step_limit"),
}
"""Where each public name lives: imported on first use (PEP 562), so that a user of a light
module of the package (``bearing_file``: a bearing file's validation) does not load numba and
the kernels (60 MB and a third of a second)."""


def __getattr__(name: str) -> Any:
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{home}"), name)


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
