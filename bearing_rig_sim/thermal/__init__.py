"""Heat in the bearing: a lumped transient thermal network coupled to the dynamics engine.

* :mod:`.network`: a linear lumped network C dT/dt = -L T + G_b T_b + q integrated exactly over
  a step (matrix exponential: unconditionally stable at any step), with its energy account.
* :mod:`.bearing`: the bearing's network (inner ring, outer ring, balls, cage, lubricant,
  housing, spindle shaft; ambient and oil inlet held fixed) from the bearing file's geometry
  and ``thermal:`` section, and the engine's dissipation split term by term onto its nodes.
* :mod:`.coupling`: the lubricant properties at the network's temperature, chunk-level
  coupling to a running engine, and the coupled thermal steady state.

The materials' and fluids' properties are the bearing's shared facts
(:mod:`bearing_rig_sim.bearing.materials`).

Temperatures are in degC (differences in K); heat in W, capacities J/K, conductances W/K.
"""
