"""Models of the bench around the bearing, without ROS (digest section 8).

* :mod:`.fibre_optic`: fibre-optic reflective speed sensors and the pulse counter.
* :mod:`.loading`: the axial loading chain (linear brake, wire rope, lever, magnet clutch,
  housing, load cell) and its closed-loop force control with interlocks.
* :mod:`.program`: test programs (segments of speed profile, axial load and end condition).
* :mod:`.parameters`: range-checked parameter records read from ``config/rig.yaml``.
"""
