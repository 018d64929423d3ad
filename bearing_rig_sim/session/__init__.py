"""A rig session (``bearing-rig run``): the nodes as processes, a test program run on the
simulation clock, recorded to a bag, shown live and summarised.

* :mod:`.processes`: finding, starting, watching and stopping the node processes; the private
  ROS domain (no ROS).
* :mod:`.runner`: the program runner's segment and end-condition logic (no ROS).
* :mod:`.recorder`: the recorded topics and the log-time rule (no ROS).
* :mod:`.progress`: the live progress line and the summary table (no ROS).
* :mod:`.context`: run id and the run context stored in the bag (no ROS).
* :mod:`.lifecycle`: the lifecycle manager's bring-up and shut-down order (no ROS).
* :mod:`.readiness`: when the nodes are ready to run a program (no ROS).
* :mod:`.manager`: the lifecycle manager's ``lifecycle_msgs`` calls and ``/diagnostics``.
* :mod:`.node`: the session's ROS node (commands, recorder subscriptions).
* :mod:`.session`: :func:`run_session`, which puts it all together.

Importing this package does not import ROS; :func:`run_session` does, when it starts.
"""

from bearing_rig_sim.session.session import EXIT_CONDITIONS, EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, SessionOptions, run_session

__all__ = ["EXIT_CONDITIONS", "EXIT_FAILED", "EXIT_INTERRUPTED", "EXIT_OK", "SessionOptions", "run_session"]
