"""The running digital twin, without ROS: what the simulator node wraps.

* :mod:`.drive`: :class:`SpindleDrive`, the spindle's speed command (STEP ramp or constant
  acceleration) turned into the engine's inner-ring acceleration chunk by chunk.
* :mod:`.twin`: :class:`RigTwin`, the dynamics engine with the drive, the axial load, the two
  fibre-optic sensors and their pulse counters; one :meth:`RigTwin.tick` per chunk.
* :mod:`.pacing`: :class:`RealTimePacer`, simulated time locked to the wall clock (or as fast as
  possible), overruns and the achieved real-time factor.
* :mod:`.settings`: :class:`SimulatorSettings`, the simulator's validated parameters.
* :mod:`.health`: :class:`SimulatorHealth`, the level and reasons for /diagnostics.
"""

from bearing_rig_sim.simulation.drive import SpindleCommand, SpindleCommandError, SpindleDrive
from bearing_rig_sim.health import Health, HealthLevel
from bearing_rig_sim.simulation.health import SimulatorHealth
from bearing_rig_sim.simulation.pacing import PacerError, RealTimePacer
from bearing_rig_sim.simulation.settings import SimulatorSettings
from bearing_rig_sim.simulation.twin import (
    AxialLoadError,
    MeasuredSpeeds,
    RigTwin,
    TickOutput,
    TruthSummary,
    TwinError,
    twin_options,
)

__all__ = [
    "AxialLoadError",
    "Health",
    "HealthLevel",
    "MeasuredSpeeds",
    "PacerError",
    "RealTimePacer",
    "RigTwin",
    "SimulatorHealth",
    "SimulatorSettings",
    "SpindleCommand",
    "SpindleCommandError",
    "SpindleDrive",
    "TickOutput",
    "TruthSummary",
    "TwinError",
    "twin_options",
]
