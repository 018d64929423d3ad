"""The load controller's core (no ROS): the operation of the axial loading chain
(:mod:`.operation`) and the node's validated settings (:mod:`.settings`)."""

from bearing_rig_sim.health import Health, HealthLevel
from bearing_rig_sim.load_control.operation import (
    AdvanceResult,
    AxialLoadOperation,
    RadialLoad,
    Reply,
    SetpointSource,
    closed_loop_time_constant,
    settle_band,
    settle_time_bound,
)
from bearing_rig_sim.load_control.settings import NODE_NAME, LoadControllerSettings, shipped_parameters

__all__ = [
    "NODE_NAME",
    "AdvanceResult",
    "AxialLoadOperation",
    "Health",
    "HealthLevel",
    "LoadControllerSettings",
    "RadialLoad",
    "Reply",
    "SetpointSource",
    "closed_loop_time_constant",
    "settle_band",
    "settle_time_bound",
    "shipped_parameters",
]
