"""The monitor's core without ROS: settings, whole-revolution windows with lost-pulse accounting,
the monitor and verdict, and the check/report schedule that the node and offline analysis share.

* :mod:`~bearing_rig_sim.monitoring.settings`: :class:`MonitorSettings` (``config/monitor.yaml``);
* :mod:`~bearing_rig_sim.monitoring.windows`: :class:`SlipWindows`, the bench counter's books;
* :mod:`~bearing_rig_sim.monitoring.monitor`: :class:`SlipMonitor`, :class:`MonitorStatus`;
* :mod:`~bearing_rig_sim.monitoring.schedule`: :class:`StatusSchedule`, :class:`TimeToStable`,
  :class:`PulseMerger` (live) and :class:`StampOrder` (offline) for the pulses' order.
"""

from bearing_rig_sim.analysis.stability import SlipState
from bearing_rig_sim.monitoring.monitor import MonitorState, MonitorStatus, MonitorWindow, SlipMonitor
from bearing_rig_sim.monitoring.schedule import PulseMerger, ScheduledStatus, StampOrder, StatusSchedule, TimeToStable
from bearing_rig_sim.monitoring.settings import DIAGNOSTIC_NAME, NODE_NAME, PARAMETER_KEY_PREFIX, SHIPPED_FILE, MonitorSettings, shipped_parameters
from bearing_rig_sim.monitoring.windows import LossRules, SlipWindow, SlipWindows, unstamped

__all__ = [
    "DIAGNOSTIC_NAME",
    "NODE_NAME",
    "PARAMETER_KEY_PREFIX",
    "SHIPPED_FILE",
    "LossRules",
    "MonitorSettings",
    "MonitorState",
    "MonitorStatus",
    "MonitorWindow",
    "PulseMerger",
    "ScheduledStatus",
    "SlipMonitor",
    "SlipState",
    "SlipWindow",
    "SlipWindows",
    "StampOrder",
    "StatusSchedule",
    "TimeToStable",
    "shipped_parameters",
    "unstamped",
]
