"""Offline analysis of rig bags, without a ROS graph.

* :mod:`.analysis`: the monitor's own slip windows and verdicts replayed from a bag's pulse topics,
  deterministically (:func:`~bearing_rig_sim.offline.analysis.analyse_bag`).
* :mod:`.segments`: the run cut into program segments or constant-speed stretches, with a summary
  of each.
* :mod:`.series`: the status rows and slip windows streamed to CSV, decimated for plots.
* :mod:`.report`: the markdown report and PNG plots of ``bearing-rig analyze``.

Bags are read through :mod:`bearing_rig_sim.bags`; nothing here writes a bag.
"""
