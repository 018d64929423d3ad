"""Exudyn's rigid 6-DOF ball bearing on this project's bearing: the reference that ``bench
dynamics`` measures the engine against.

Exudyn (Gerstmayr, Innsbruck; pinned in requirements.lock) builds a ball bearing from
``exudyn.machines.GetBallBearingData`` and ``CreateBallBearing``: every ball a rigid body with
6 DOF, a sphere-torus penalty contact with Coulomb friction at each raceway, the cage a rigid
body held to the balls by spring-dampers, no lubricant. This module sets it up with the bearing
file's geometry (Z, D_w, d_m, groove radii f D_w), a deep-groove pair of tori whose clearance
gives the free contact angle (cos a0 = A / (A + 2 delta), A = (f_i + f_o - 1) D_w), the inner
ring turning at the operating speed and loaded axially, with its radial motion and tilts held.
Contact and solver settings are those of Exudyn's own example ``ballBearningModel.py``
(linear contact 5e6 N/m, damping 50 N s/m, friction zone 1e-2 m/s, generalised-alpha with
modified Newton, a 1e-4 s step that the solver reduces where it must); the dry friction
coefficient is the bearing file's.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from bearing_rig_sim.dynamics import BearingParameters

CONTACT_STIFFNESS = 5e6
"""Ball-raceway contact stiffness, N/m (linear, as Exudyn's bearing example)."""
CONTACT_DAMPING = 50.0
"""Ball-raceway contact damping, N s/m (Exudyn's bearing example)."""
FRICTION_ZONE = 1e-2
"""Sliding speed below which Exudyn's friction is proportional to it, m/s (its example)."""
CAGE_SPRING = (1e5, 1e2)
"""Ball-cage spring stiffness (N/m) and damping (N s/m) (Exudyn's bearing example)."""
TIME_STEP = 1e-4
"""Nominal step, s (Exudyn's bearing example); the solver reduces it where Newton fails."""


@dataclass(frozen=True)
class ExudynRun:
    """One timed run of the Exudyn bearing."""

    sim_s: float
    wall_s: float
    cage_speed_rad_s: float

    @property
    def rtf(self) -> float:
        """Simulated seconds per wall-clock second."""
        return self.sim_s / self.wall_s


def run_exudyn(params: BearingParameters, speed: float, axial_load: float, sim_s: float, cage_start: float | None = None) -> ExudynRun:
    """Simulate Exudyn's rigid ball bearing for ``sim_s`` seconds at inner-ring speed ``speed``
    (rad/s) under ``axial_load`` (N), starting with the cage at ``cage_start`` (rad/s; default
    its pure-rolling speed); time the solve alone (model assembly excluded).

    Raises:
        ImportError: Exudyn is not installed.
    """
    import exudyn as exu
    from exudyn.itemInterface import MarkerBodyRigid, SensorBody
    from exudyn.machines import CreateBallBearing, GetBallBearingData
    from exudyn.utilities import InertiaCylinder

    dw, dm, a0 = params.ball_diameter, params.pitch_diameter, params.contact_angle
    ri, ro = params.inner_curvature_ratio * dw, params.outer_curvature_ratio * dw
    a = ri + ro - dw
    delta = 0.5 * a * (1.0 / math.cos(a0) - 1.0)
    density = params.ball_density
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    axis = [0.0, 0.0, 1.0]
    data = GetBallBearingData(
        axis,
        dm + 1.5 * dw,
        dm - 1.5 * dw,
        2.0 * dw,
        params.ball_count,
        radiusBalls=0.5 * dw,
        radiusCage=0.5 * dm,
        innerGrooveRadius=ri,
        outerGrooveRadius=ro,
    )
    data["radiusBalls"] = 0.5 * dw - delta
    ground = mbs.CreateGround()
    ring = mbs.CreateRigidBody(
        referencePosition=[0.0, 0.0, 0.0],
        nodeType=exu.NodeType.RotationRxyz,
        inertia=InertiaCylinder(density, 2.0 * dw, 0.5 * dm, axis=2),
        initialAngularVelocity=[0.0, 0.0, speed],
    )
    for held in (0, 1, 3, 4):
        mbs.CreateCoordinateConstraint(itemNumbers=[ring, None], coordinates=[held, None], show=False)
    # The constraint holds -(rotation speed) at the offset: a negative offset turns the ring forward.
    mbs.CreateCoordinateConstraint(itemNumbers=[ring, None], coordinates=[5, None], velocityLevel=True, offset=-speed, show=False)
    outer = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    inner = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ring, localPosition=[0.0, 0.0, 0.0]))
    contact = {
        "contactStiffness": CONTACT_STIFFNESS,
        "contactDamping": CONTACT_DAMPING,
        "dynamicFriction": params.dynamic_friction,
        "contactStiffnessExponent": 1,
        "frictionProportionalZone": FRICTION_ZONE,
    }
    items = CreateBallBearing(
        mbs,
        data,
        inner,
        outer,
        density,
        params.cage_density,
        cageInitialAngularVelocity=[0.0, 0.0, params.epicyclic_ratio * speed if cage_start is None else cage_start],
        springStiffnessCage=CAGE_SPRING[0],
        springDampingCage=CAGE_SPRING[1],
        contactParametersRingBalls=contact,
    )
    mbs.CreateForce(itemNumber=ring, loadVector=[0.0, 0.0, axial_load])
    sensor = mbs.AddSensor(SensorBody(bodyNumber=items["objectCage"], storeInternal=True, outputVariableType=exu.OutputVariableType.AngularVelocity))
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = max(1, round(sim_s / TIME_STEP))
    settings.timeIntegration.endTime = sim_s
    settings.timeIntegration.verboseMode = 0
    settings.timeIntegration.newton.useModifiedNewton = True
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    settings.parallel.numberOfThreads = 1
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = sim_s / 20.0
    settings.show.statistics = False
    start = time.perf_counter()
    mbs.SolveDynamic(settings)
    wall = time.perf_counter() - start
    cage = np.asarray(mbs.GetSensorStoredData(sensor), dtype=float)
    return ExudynRun(sim_s, wall, float(cage[-1, 3]))
