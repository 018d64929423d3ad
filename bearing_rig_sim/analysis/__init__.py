"""The paper's slip-analysis method, without ROS (docs/paper.md sections 6 and 7).

* :mod:`.slip`: slip rate from cage and inner-ring speeds (percent), also from sensor pulses;
* :mod:`.gaussian`: sums of Gaussians fitted to slip data, with the paper's quality figures;
* :mod:`.stability`: the slope criterion (Eq. 14) and the onset of the stable state;
* :mod:`.streaming`: the same criterion on points arriving one by one (the monitor's trailing
  slope with a confidence bound, and a streaming Gaussian refit).

Speeds are in rad/s, loads in N, times in s; the slip rate is in percent throughout.
"""

from bearing_rig_sim.analysis.inputs import AnalysisError

__all__ = ["AnalysisError"]
