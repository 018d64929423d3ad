"""bearing-rig-sim: a digital twin of the H7006C angular contact ball bearing slip test rig.

Layers, with one direction of dependency (see README):

* :mod:`bearing_rig_sim.config`: validated YAML configuration.
* :mod:`bearing_rig_sim.dynamics`: the bearing's equations of motion (numpy + numba, no ROS).
* :mod:`bearing_rig_sim.rig`: sensor and loading-chain models of the bench (no ROS).
* :mod:`bearing_rig_sim.analysis`: slip rate, Gaussian fits, stability criterion (no ROS).
* :mod:`bearing_rig_sim.bags`: rosbag2/MCAP recording, replay and offline analysis.
* :mod:`bearing_rig_sim.load_control`: the load controller's core and settings (no ROS).
* :mod:`bearing_rig_sim.live`: the live view in the Foxglove app (no ROS).
* :mod:`bearing_rig_sim.nodes`: thin ROS 2 managed-node shells.
"""

__version__ = "0.1.0"
