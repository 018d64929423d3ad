"""Shadow mode without ROS: the twin runs beside the bench on its measured inputs, predicts the
slip the bench should measure, and flags when the bench departs from it.

* :mod:`.settings`: :class:`ShadowSettings` (``config/shadow.yaml``);
* :mod:`.inputs`: spindle speed points and the load-cell force;
* :mod:`.predictor`: :class:`MeasuredDrive`, the engine following them;
* :mod:`.measured`: the monitor's slip windows and fault handling;
* :mod:`.residual`: the band and the anomaly rule;
* :mod:`.recalibration`: :class:`OnlineCalibration`, one parameter tracked online;
* :mod:`.twin`: :class:`ShadowTwin`, all of it, one message at a time;
* :mod:`.offline`: a bag in, ``residuals.csv`` and a report out.
"""

from bearing_rig_sim.shadow.residual import AnomalyRule, band_pct, likely_cause
from bearing_rig_sim.shadow.settings import NODE_NAME, SHIPPED_FILE, ShadowSettings, shipped_parameters
from bearing_rig_sim.shadow.twin import ResidualWindow, ShadowTwin

__all__ = [
    "NODE_NAME",
    "SHIPPED_FILE",
    "AnomalyRule",
    "ResidualWindow",
    "ShadowSettings",
    "ShadowTwin",
    "band_pct",
    "likely_cause",
    "shipped_parameters",
]
