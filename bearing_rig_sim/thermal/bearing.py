"""The bearing's thermal network and the engine's heat, term by term.

Nodes (capacity m c from the geometry of the bearing file and :mod:`.materials`):
inner ring, outer ring, balls (all Z lumped), cage, lubricant (the grease fill, or the oil-air
mist, or the jet's oil in the cavity), housing, spindle shaft. Boundaries: ambient air and, for
a jet-lubricated bearing, the oil inlet.

Conductances (W/K), each with its source (docs/thermal.md lists them with their values):

* ring seats (inner ring to shaft, outer ring to housing): a fit contact conductance on the
  seat in series with radial conduction through the ring, ln(r2/r1) / (2 pi k B) (the
  published bearing networks: Harris and Kotzalas, *Essential Concepts*, ch. "Friction in
  rolling bearings" / heat transfer; Takabi and Khonsari, Tribol. Int. 60:93, 2013);
* balls to rings: conduction through the Z Hertz contacts, each the constriction of a circular
  contact of the ellipse's area on both sides, 1/(4 k a_e) per body (Yovanovich 1971;
  Bejan and Kraus, Heat Transfer Handbook, ch. 4), a_e = sqrt(a b) at the mean contact load;
* wetted surfaces (balls, rings, cage) to the lubricant: laminar flat-plate convection,
  Nu = 0.664 Re^0.5 Pr^(1/3) over the length in the flow direction (Pohlhausen; Incropera and
  DeWitt, eq. 7.30), with the surface speed relative to the cavity's fluid (oil-air: the air;
  grease and oil: the base oil, on the wetted share for grease);
* cage to outer ring: conduction through the land film, k A_land / c (the land clearance);
* lubricant out of the bearing: the oil-air stream's m c_p (to ambient) or the jet's
  rho Q c_p (to the oil inlet);
* housing to ambient: h A with h of free convection and radiation, plus conduction to the frame;
* shaft to ambient: the rotating cylinder in still air, Nu_d = 0.133 Re_d^(2/3) Pr^(1/3)
  (Becker 1963, Int. J. Heat Mass Transfer 6:1053) over its free length, plus conduction into
  the motor.

Heat (:func:`heat_sources`, :func:`node_heat`): the engine's dissipation at the chunk's last
step split by where it arises: each raceway contact's sliding, spin and Heathcote loss half to
the ring, half to the ball (equal steel bodies at similar speeds: Blok's partition gives about
one half); the ball drag into the lubricant; the land's film shear half to the cage, half to the
outer ring; the rest of the dissipation (rolling resistance: hysteresis and EHL rolling, and
pocket friction) half to the balls and a quarter to each ring.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from bearing_rig_sim.config import ConfigError, shipped_bearing_file
from bearing_rig_sim.dynamics.bearing_file import BearingFile
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.engine import BearingDynamics
from bearing_rig_sim.dynamics.parameters import BearingParameters, derive
from bearing_rig_sim.bearing.file_record import file_field, file_record, file_values
from bearing_rig_sim.bearing.materials import AIR_40C, BEARING_STEEL, POLYIMIDE, Fluid
from bearing_rig_sim.thermal.network import Conductance, Node, ThermalNetwork
from bearing_rig_sim.settings_model import read_file

NODES = ("inner_ring", "outer_ring", "balls", "cage", "lubricant", "housing", "shaft")
AMBIENT = "ambient"
OIL_INLET = "oil_inlet"


@file_record
class ThermalConfig:
    """The bearing file's geometry the network needs and its ``thermal:`` section (SI, degC), each
    field read from the bearing-file key it names (:func:`~bearing_rig_sim.bearing.file_record.file_field`).

    Attributes:
        bore, outside_diameter, width: d, D, B of the bearing, m.
        inner_shoulder, outer_shoulder: ring land diameters, m.
        ambient: ambient temperature, degC.
        fit_conductance: ring seat contact conductance, W/(m^2 K).
        housing_mass (kg), housing_area (m^2), housing_film (W/(m^2 K)), frame_conductance (W/K).
        shaft_diameter, shaft_length (m), motor_conductance (W/K).
        grease_fill: share of the free volume holding grease, 1.
        air_flow: oil-air stream through the bearing, m^3/s.
        oil_flow: jet oil flow through the bearing, m^3/s (0: none).
        oil_inlet: jet oil inlet temperature, degC.
        source: file name.
    """

    bore: float = file_field("geometry.bore_m")
    outside_diameter: float = file_field("geometry.outside_diameter_m")
    width: float = file_field("geometry.width_m")
    inner_shoulder: float = file_field("geometry.inner_shoulder_diameter_m")
    outer_shoulder: float = file_field("geometry.outer_shoulder_diameter_m")
    ambient: float = file_field("thermal.ambient_temperature_c")
    fit_conductance: float = file_field("thermal.fit_contact_conductance_w_m2_k")
    housing_mass: float = file_field("thermal.housing.mass_kg")
    housing_area: float = file_field("thermal.housing.outer_area_m2")
    housing_film: float = file_field("thermal.housing.film_coefficient_w_m2_k")
    frame_conductance: float = file_field("thermal.housing.frame_conductance_w_k")
    shaft_diameter: float = file_field("thermal.shaft.diameter_m")
    shaft_length: float = file_field("thermal.shaft.length_m")
    motor_conductance: float = file_field("thermal.shaft.motor_conductance_w_k")
    grease_fill: float = file_field("thermal.grease_fill_fraction")
    air_flow: float = file_field("thermal.cavity_air_flow_m3_s")
    oil_flow: float = file_field("thermal.oil_flow_m3_s")
    oil_inlet: float = file_field("thermal.oil_inlet_temperature_c")  # absent from the file: the ambient (from_file)
    source: str = "<memory>"

    @classmethod
    def from_yaml(cls, path: str | Path | None = None) -> ThermalConfig:
        """The bearing file's thermal data (default: the shipped H7006C)."""
        path = path or shipped_bearing_file()
        return cls.from_file(read_file(BearingFile, path), str(path))

    @classmethod
    def from_file(cls, doc: BearingFile, source: str) -> ThermalConfig:
        """The thermal data of a validated bearing file (:class:`~bearing_rig_sim.dynamics.bearing_file.BearingFile`).

        Raises:
            ConfigError: the file has no ``thermal:`` section.
        """
        t = doc.thermal
        if t is None:
            raise ConfigError(source, "thermal", "missing (required)")
        inlet = {} if t.oil_inlet_temperature_c is not None else {"oil_inlet": t.ambient_temperature_c}
        return cls(**file_values(cls, doc, source=source, **inlet))


@dataclass(frozen=True)
class HeatSources:
    """The engine's dissipation at one instant, term by term, W.

    Attributes:
        inner_contacts: sliding, spin and Heathcote losses of the Z inner raceway contacts.
        outer_contacts: the same at the outer raceway.
        drag: ball drag in the cavity's lubricant.
        land: the cage land's film (or grease) shear.
        rolling_and_pockets: the rest: rolling resistance (hysteresis, EHL rolling) and pocket
            friction.
        damping: the pocket and land contacts' Hunt-Crossley damping and the cage rim's damping (the
            engine's :attr:`~bearing_rig_sim.dynamics.engine.ChunkAverage.damping_heat` over an
            interval; 0 at an instant or a steady state).
    """

    inner_contacts: float
    outer_contacts: float
    drag: float
    land: float
    rolling_and_pockets: float
    damping: float = 0.0

    @property
    def total(self) -> float:
        """All of it, W (the engine's :meth:`~BearingDynamics.power_loss` plus the damping)."""
        return self.inner_contacts + self.outer_contacts + self.drag + self.land + self.rolling_and_pockets + self.damping

    def scaled(self, power: float, damping: float) -> HeatSources:
        """These proportions carrying ``power`` W (all into ``rolling_and_pockets`` when every
        term is 0), with ``damping`` W of damping."""
        friction = self.total - self.damping
        if friction <= 0.0:
            return HeatSources(0.0, 0.0, 0.0, 0.0, power, damping)
        f = power / friction
        return HeatSources(f * self.inner_contacts, f * self.outer_contacts, f * self.drag, f * self.land, f * self.rolling_and_pockets, damping)


@njit(cache=True)
def _split(p: np.ndarray, ball: np.ndarray, cage: np.ndarray, out: np.ndarray, ring: np.ndarray) -> tuple[float, float, float, float, float]:
    """(inner contacts, outer contacts, drag, land, total) W, with the engine's kernels."""
    z = ball.shape[0]
    omega_i = ring[kn.R_OMEGA]
    pin = 0.0
    pout = 0.0
    drag = 0.0
    land = 0.0
    total = 0.0
    for j in range(z):
        rb, zb, wm = ball[j, kn.B_R], ball[j, kn.B_Z], ball[j, kn.B_OMEGA]
        _, nir, niz, _, _, nor, noz, _ = kn.raceway_geometry(p, rb, zb, ring[kn.R_DELTA])
        r_ci, r_co, _, _, _, _, _, _, _ = kn.ball_kinematics(p, nir, niz, nor, noz, rb)
        qi, qo = out[j, kn.O_QI], out[j, kn.O_QO]
        if qi > 0.0:
            pin += kn.contact_power(p, 0, out[j, kn.O_SI], abs((omega_i - wm) * r_ci), qi)
        if qo > 0.0:
            pout += kn.contact_power(p, 1, out[j, kn.O_SO], abs(wm * r_co), qo)
        fd, _ = kn.ball_drag(p, rb * wm, 0.5 * (qi + qo))
        drag += abs(fd * rb * wm)
        w = cage[j, kn.C_OMEGA]
        # the whirling cage's film: its eccentricity's shear factor and the land contact's force
        tl, _ = kn.cage_land_torque(p, w, z, ring[kn.R_LAND_F] or 1.0, ring[kn.R_LAND_N])
        land += abs(tl * w)
        total += out[j, kn.O_POWER]
    return pin, pout, drag, land, total + land


def heat_sources(engine: BearingDynamics) -> HeatSources:
    """Split the engine's dissipation at its last step (:meth:`BearingDynamics.power_loss`)
    into its terms, with the engine's own kernels (contact power, drag, land torque)."""
    pin, pout, drag, land, total = _split(engine.vector, engine.ball, engine.cage, engine.out, engine.ring)
    rest = max(total - pin - pout - drag - land, 0.0)
    return HeatSources(pin, pout, drag, land, rest)


class HeatLedger:
    """Cumulative heat of an engine, term by term, J: the engine stepped one time step at a time
    and each step's terms (:func:`heat_sources` of its state) times the step, so the means over
    a window are energy-weighted (a ball passing through a radial load zone, the terms vary over
    a ball-pass period; the proportions of one step are not those of the period).

    The four named terms (:attr:`energy` order: inner contacts, outer contacts, drag, land) are
    the step sums; the rolling and pocket term is what the engine's own cumulative counter
    (:attr:`BearingDynamics.dissipated` less its damping) holds beyond them, so the terms close
    on the engine's dissipation exactly.
    """

    def __init__(self, engine: BearingDynamics) -> None:
        self.engine = engine
        self.energy = np.zeros(4)
        """Inner contacts, outer contacts, drag and land heat since the ledger began, J."""
        self.time = 0.0
        """Simulated time since the ledger began, s."""
        self._start = (engine.dissipated, engine.damping_dissipated)

    def advance(self, duration: float) -> None:
        """Step the engine ``duration`` seconds (whole steps), one step at a time."""
        e = self.engine
        dt = e.time_step
        for _ in range(int(round(duration / dt))):
            e.advance(dt)
            s = heat_sources(e)
            self.energy += dt * np.array([s.inner_contacts, s.outer_contacts, s.drag, s.land])
            self.time += dt

    def mean(self) -> HeatSources:
        """The mean heat since the ledger began, term by term, W (each term's energy over the
        time); the terms sum to the engine's dissipation over the time."""
        if self.time <= 0.0:
            raise ValueError("the ledger has not run: no mean")
        heat = self.engine.dissipated - self._start[0]
        damping = self.engine.damping_dissipated - self._start[1]
        pin, pout, drag, land = self.energy / self.time
        rest = (heat - damping) / self.time - (pin + pout + drag + land)
        return HeatSources(float(pin), float(pout), float(drag), float(land), float(rest), damping / self.time)


def node_heat(sources: HeatSources) -> dict[str, float]:
    """Heat into each node (W) by the partition rules of this module's doc."""
    s = sources
    return {
        "inner_ring": 0.5 * s.inner_contacts + 0.25 * s.rolling_and_pockets,
        "outer_ring": 0.5 * s.outer_contacts + 0.25 * s.rolling_and_pockets + 0.5 * s.land,
        "balls": 0.5 * (s.inner_contacts + s.outer_contacts) + 0.5 * s.rolling_and_pockets + 0.25 * s.damping,
        "cage": 0.5 * s.land + 0.75 * s.damping,
        "lubricant": s.drag,
    }


def _plate_conductance(fluid: Fluid, speed: float, length: float, area: float) -> float:
    """h A of laminar flat-plate convection, Nu_L = 0.664 Re_L^0.5 Pr^(1/3), W/K."""
    re = max(abs(speed), 1e-6) * length / fluid.kinematic_viscosity
    return 0.664 * math.sqrt(re) * fluid.prandtl ** (1.0 / 3.0) * fluid.conductivity / length * area


def cavity_fluid(params: BearingParameters, temperature_c: float) -> Fluid:
    """The fluid the wetted surfaces see: air for oil-air (the mist is about 1 % oil), the base
    oil for grease and oil bath or jet, at ``temperature_c``."""
    lub = params.lubricant
    if lub is None or lub.kind == "oil_air":
        return AIR_40C
    return Fluid(lub.density(temperature_c), lub.specific_heat, lub.thermal_conductivity, lub.kinematic_viscosity(temperature_c))


def build_network(
    params: BearingParameters,
    cfg: ThermalConfig,
    inner_ring_speed: float,
    axial_load: float,
    *,
    lubricant_temperature: float | None = None,
    initial: float | None = None,
) -> ThermalNetwork:
    """The bearing's network at an operating point (inner-ring speed rad/s, axial load N): the
    convection and contact conductances depend on both; rebuild it when they change.

    Args:
        lubricant_temperature: degC for the fluid properties (default: the bearing file's).
        initial: start temperature of every node, degC (default: ambient).
    """
    steel, cagem = BEARING_STEEL, POLYIMIDE
    t_lub = params.lubricant_temperature if lubricant_temperature is None else lubricant_temperature
    lub = params.lubricant
    dw, dm, z, a0 = params.ball_diameter, params.pitch_diameter, params.ball_count, params.contact_angle
    d, big_d, b = cfg.bore, cfg.outside_diameter, cfg.width
    d_is, d_os = cfg.inner_shoulder, cfg.outer_shoulder
    _, geo = derive(params.replace(friction_model="ehl_traction")) if params.friction_model == "rheology" else derive(params)
    omega = max(abs(inner_ring_speed), 1e-3)
    gamma = dw * math.cos(a0) / dm
    omega_cage = 0.5 * omega * (1.0 - gamma)
    omega_roll = 0.5 * omega * dm / dw * (1.0 - gamma * gamma)

    # capacities
    m_inner = params.ring_density * math.pi / 4.0 * (d_is**2 - d**2) * b
    m_outer = params.ring_density * math.pi / 4.0 * (big_d**2 - d_os**2) * b
    m_balls = z * params.ball_density * math.pi * dw**3 / 6.0
    free = math.pi / 4.0 * (d_os**2 - d_is**2) * b - m_balls / params.ball_density - geo.cage_mass / params.cage_density
    rho_c = cavity_fluid(params, t_lub)
    if lub is not None and lub.kind == "grease":
        lub_mass, lub_cp, lub_src = (
            cfg.grease_fill * free * lub.density(t_lub),
            lub.specific_heat,
            f"grease fill {cfg.grease_fill:g} of the free volume {free * 1e6:.2f} cm^3",
        )
    elif lub is not None and lub.kind == "oil_bath":
        lub_mass, lub_cp, lub_src = lub.fill_fraction * free * lub.density(t_lub), lub.specific_heat, "oil in the cavity (fill fraction of the free volume)"
    else:
        lub_mass, lub_cp, lub_src = free * rho_c.density, rho_c.specific_heat, "oil-air mist filling the free volume"
    m_shaft = params.ring_density * math.pi / 4.0 * cfg.shaft_diameter**2 * cfg.shaft_length
    nodes = [
        Node("inner_ring", m_inner * steel.specific_heat, "annulus d to the inner shoulder x B, bearing steel"),
        Node("outer_ring", m_outer * steel.specific_heat, "annulus outer shoulder to D x B, bearing steel"),
        Node("balls", m_balls * steel.specific_heat, "Z balls, bearing steel"),
        Node("cage", geo.cage_mass * cagem.specific_heat, "cage mass (dynamics.derive), polyimide"),
        Node("lubricant", max(lub_mass * lub_cp, 1e-6), lub_src),
        Node("housing", cfg.housing_mass * steel.specific_heat, f"{cfg.source}: thermal.housing.mass_kg, steel"),
        Node("shaft", m_shaft * steel.specific_heat, "free spindle length, steel"),
    ]

    k = steel.conductivity
    r_in_mean, r_out_mean = 0.25 * (d + d_is), 0.25 * (d_os + big_d)
    g_seat_in = 1.0 / (1.0 / (cfg.fit_conductance * math.pi * d * b) + math.log(r_in_mean / (0.5 * d)) / (2.0 * math.pi * k * b))
    g_seat_out = 1.0 / (1.0 / (cfg.fit_conductance * math.pi * big_d * b) + math.log(0.5 * big_d / r_out_mean) / (2.0 * math.pi * k * b))
    inner, outer = params.raceway_contacts(a0)
    q = max(axial_load, 1.0) / (z * math.sin(a0))
    g_contacts = []
    for con in (inner, outer):
        sa, sb = con.semi_axes(q)
        g_contacts.append(z * 2.0 * k * math.sqrt(sa * sb))  # two constrictions 1/(4 k a_e) in series
    # grease: only the surfaces the grease wets exchange heat with it (about twice its volume
    # share of the free volume: the grease lies as a layer on them); oils wet everything
    wet = min(1.0, 2.0 * cfg.grease_fill) if lub is not None and lub.kind == "grease" else 1.0
    g_ball_lub = wet * _plate_conductance(rho_c, omega_roll * 0.5 * dw, dw, z * math.pi * dw * dw)
    g_inner_lub = wet * _plate_conductance(rho_c, (omega - omega_cage) * 0.5 * d_is, math.pi * d_is / z, math.pi * d_is * b)
    g_outer_lub = wet * _plate_conductance(rho_c, omega_cage * 0.5 * d_os, math.pi * d_os / z, math.pi * d_os * b)
    g_cage_lub = wet * _plate_conductance(
        rho_c,
        omega_cage * 0.25 * (params.cage_inner_diameter + params.cage_outer_diameter),
        math.pi * params.cage_outer_diameter / z,
        math.pi * (params.cage_inner_diameter + params.cage_outer_diameter) * params.cage_width,
    )
    k_land = lub.thermal_conductivity if lub is not None and lub.kind != "oil_air" else 0.13
    g_land = k_land * math.pi * params.cage_outer_diameter * params.land_width / params.land_clearance
    air = AIR_40C
    re_shaft = omega * cfg.shaft_diameter**2 / air.kinematic_viscosity
    h_shaft = 0.133 * re_shaft ** (2.0 / 3.0) * air.prandtl ** (1.0 / 3.0) * air.conductivity / cfg.shaft_diameter
    g_shaft_air = h_shaft * math.pi * cfg.shaft_diameter * cfg.shaft_length
    cond = [
        Conductance("inner_ring", "shaft", g_seat_in, "fit contact conductance on pi d B in series with ring conduction ln(r2/r1)/(2 pi k B)"),
        Conductance("outer_ring", "housing", g_seat_out, "fit contact conductance on pi D B in series with ring conduction ln(r2/r1)/(2 pi k B)"),
        Conductance("balls", "inner_ring", g_contacts[0], "Z inner Hertz contacts, constriction 1/(4 k sqrt(a b)) per body (Yovanovich)"),
        Conductance("balls", "outer_ring", g_contacts[1], "Z outer Hertz contacts, constriction 1/(4 k sqrt(a b)) per body (Yovanovich)"),
        Conductance("balls", "lubricant", g_ball_lub, "ball surfaces, laminar flat plate Nu = 0.664 Re^0.5 Pr^(1/3), L = Dw"),
        Conductance("inner_ring", "lubricant", g_inner_lub, "inner land, laminar flat plate over one ball pitch"),
        Conductance("outer_ring", "lubricant", g_outer_lub, "outer land, laminar flat plate over one ball pitch"),
        Conductance("cage", "lubricant", g_cage_lub, "cage bore and rim, laminar flat plate over one pocket pitch"),
        Conductance("cage", "outer_ring", g_land, "land film conduction k pi D_c L_land / c"),
        Conductance("housing", AMBIENT, cfg.housing_film * cfg.housing_area + cfg.frame_conductance, "h A free convection and radiation, plus the frame"),
        Conductance("shaft", AMBIENT, g_shaft_air + cfg.motor_conductance, "rotating cylinder Nu = 0.133 Re^(2/3) Pr^(1/3) (Becker 1963), plus the motor"),
    ]
    boundaries = {AMBIENT: cfg.ambient}
    if cfg.oil_flow > 0.0 and lub is not None:
        boundaries[OIL_INLET] = cfg.oil_inlet
        cond.append(Conductance("lubricant", OIL_INLET, lub.density(t_lub) * cfg.oil_flow * lub.specific_heat, "jet oil flow rho Q c_p"))
    elif lub is None or lub.kind == "oil_air":
        cond.append(Conductance("lubricant", AMBIENT, air.density * cfg.air_flow * air.specific_heat, "oil-air stream m c_p"))
    else:
        # grease: the cavity closes; heat leaves the grease through the surfaces above only
        pass
    return ThermalNetwork(nodes, cond, boundaries, initial=cfg.ambient if initial is None else initial)


def heat_balance(network: ThermalNetwork) -> dict[str, float]:
    """The network's energy account since its start, J."""
    return {"heat_in_j": network.heat_in, "stored_j": network.stored_energy(), "heat_out_j": network.heat_out, "residual_j": network.energy_residual()}
