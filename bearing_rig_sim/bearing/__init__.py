"""The bearing's shared facts, below the models that use them (no numba, no ROS import).

* :mod:`.kinematics`: the pure-rolling (epicyclic) cage speed and the cage slip rate (paper
  Eq. 11-12), the definitions the dynamics, the analysis and the monitor all use;
* :mod:`.hertz`: the elliptical Hertz contact of a ball in its raceways (load-deflection
  constant, contact ellipse);
* :mod:`.materials`: the thermal and elastic facts of the bearing's materials and the cavity's
  fluids, each with its source.
* :mod:`.file_record`: the engine's bearing records, each field declared once with the
  bearing-file key it is read from.

``dynamics/``, ``thermal/`` and ``analysis/`` import these; nothing here imports them.
"""
