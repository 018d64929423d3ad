"""Models of the bench around the bearing, without ROS (docs/paper.md section 8); its instruments
are in :mod:`bearing_rig_sim.instruments`.

* :mod:`.loading`: the axial loading chain put together, with its interlocks;
  :mod:`.loading_elements` (linear brake, wire rope, lever, magnet clutch, housing) and
  :mod:`.force_control` (load cell, PI(D) force controller) are its parts.
* :mod:`.program`: test programs (segments of speed profile, axial load and end condition).
* :mod:`.parameters`: range-checked parameter records read from ``config/rig.yaml``.
"""
