"""The bench's instruments, one home: each a small model with a settings block in the rig file's
``sensors`` section (config/rig.yaml), published on a topic of the contract. No ROS import.

* :mod:`.base`: what every instrument is (its common settings keys, the measurand it is shown
  each chunk, the readings it gives back as message fields).
* :mod:`.fibre_optic`: fibre-optic reflective speed sensors on the spindle and the cage, and the
  bench's pulse counter (docs/paper.md section 8).
* :mod:`.first_order`: the outer-ring thermocouple and the housing torque meter (first-order
  lags with noise, read at a fixed rate).
* :mod:`.registry`: the models by name and the ``sensors`` section read into them
  (:class:`~bearing_rig_sim.instruments.registry.InstrumentSet`).
"""
