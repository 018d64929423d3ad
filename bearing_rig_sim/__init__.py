"""bearing-rig-sim: a digital twin of the H7006C angular contact ball bearing slip test rig.

Layers, with one direction of dependency (see the README's architecture): everything but the
nodes, the session, replay and the live view runs without ROS.

* :mod:`bearing_rig_sim.interfaces`: the topic and service contract, written once.
* :mod:`bearing_rig_sim.config`: validated YAML configuration; :mod:`bearing_rig_sim.errors`.
* :mod:`bearing_rig_sim.settings_model`: the declarative model of a node's parameters (pydantic).
* :mod:`bearing_rig_sim.health`: the health levels every node core reports.
* :mod:`bearing_rig_sim.clock_guard`: validation of a simulation clock read from outside.
* :mod:`bearing_rig_sim.executors`: where many independent jobs run (forked processes or Dask).
* :mod:`bearing_rig_sim.bearing`: the bearing's shared facts (slip rate, pure-rolling cage speed, Hertz contact, materials).
* :mod:`bearing_rig_sim.dynamics`: the bearing's equations of motion and steady states (numpy + numba).
* :mod:`bearing_rig_sim.thermal`: the bearing's thermal network, coupled to the dynamics.
* :mod:`bearing_rig_sim.instruments`: the bench's instruments (fibre-optic sensors, thermocouple, torque meter).
* :mod:`bearing_rig_sim.rig`: the loading chain, mounting, speed profile and test programs of the bench.
* :mod:`bearing_rig_sim.analysis`: slip rate, Gaussian fits, slope criterion, streaming verdict.
* :mod:`bearing_rig_sim.simulation`: the simulator's core (drive, twin, pacing, settings, health).
* :mod:`bearing_rig_sim.monitoring`: the monitor's core (slip windows, verdicts, schedule).
* :mod:`bearing_rig_sim.load_control`: the load controller's core and settings.
* :mod:`bearing_rig_sim.shadow`: shadow mode, the twin on the bench's measured inputs.
* :mod:`bearing_rig_sim.bags`: rosbag2 bags with MCAP storage: writer, reader, repair.
* :mod:`bearing_rig_sim.offline`: offline analysis of a bag and its report.
* :mod:`bearing_rig_sim.replay`: republishing a bag into ROS 2 with its timing.
* :mod:`bearing_rig_sim.synthetic`: generated messages and recordings for tests and benchmarks.
* :mod:`bearing_rig_sim.studies`: steady states, calibration, the paper's experiments, reproduction.
* :mod:`bearing_rig_sim.sweep`: operating-map sweeps on Dask.
* :mod:`bearing_rig_sim.live`: the live view in the Foxglove app.
* :mod:`bearing_rig_sim.nodes`: thin ROS 2 node shells; :mod:`bearing_rig_sim.session`: ``bearing-rig run``.
* :mod:`bearing_rig_sim.compiled`: the monitor's pulse path compiled to C (mypyc), its sources the fallback.
* :mod:`bearing_rig_sim.commands` and :mod:`bearing_rig_sim.benchmarks`: the command line and its benchmarks.
"""

__version__ = "0.1.0"

from bearing_rig_sim import compiled as _compiled

_compiled.install()
