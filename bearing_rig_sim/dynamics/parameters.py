"""Bearing parameters: read and validated from ``config/bearings/*.yaml``, then derived.

:class:`BearingParameters` holds the primary data (SI units) and :func:`derive` computes
everything the kernels need (groove geometry, Hertz constants, masses, inertias, resistance
coefficients, and with ``friction.model: rheology`` the traction table of :mod:`.traction`) into a
flat float64 vector whose layout is defined in :mod:`.kernels` (the table appended after
``P_SIZE``). The lubricant comes from ``lubricant.file`` (:class:`.lubrication.Lubricant`).

Resistance models (what makes the cage slip; docs/model.md), each applied in the kernels; the
lubrication mode of the lubricant file selects the drag and land laws:

* Ball drag, oil-air or oil bath (Harris and Kotzalas, *Advanced Concepts*, ch. 7, sphere drag
  with C_d = 24/Re + C_d,inf): F = s (3 pi eta Dw v + 1/2 rho C_d (pi Dw^2/4) v|v|),
  v = ball-centre orbital speed, rho and eta of the oil-air mixture or of the oil times the fill.
* Ball drag, grease (Herschel-Bulkley): F = fill (3.5 pi Dw^2 tau_y + 3 pi K Dw^(2-n) v^n) plus
  the inertial term, the plastic drag of a sphere (Beris et al. 1985) and Stokes drag with the
  apparent viscosity at v/Dw.
* Cage land friction (outer-land guided cage): a Petroff short-journal film
  T_v = s_v 2 pi eta r^3 w omega_c / c (oil) or 2 pi r^2 w fill (tau_y + K (r omega_c/c)^n)
  (grease), times the eccentric film's shear factor, plus boundary friction T_b = s_b mu m_c g r
  with a horizontal spindle (smoothed sign) and mu N r when the cage touches its land.
* Cage land force (reduced model, the cage centre dynamic): Ocvirk's short journal bearing with
  whirl and squeeze on each land, viscosity that of the land torque (the grease's apparent
  viscosity at the land's shear rate), plus a Hunt-Crossley contact at the clearance.
* Houpert's EHL rolling force at each raceway contact, as a moment on the ball's rolling.
* Ball-pocket friction: mu_p times the pocket normal force, on the ball's spin.
* Elastic-hysteresis rolling resistance at each raceway contact (Harris and Kotzalas ch. 7):
  M = (3/16) alpha_h Q b, with b the semi-minor axis of the contact ellipse, on the ball's spin.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path
from collections.abc import Mapping
from typing import Any, cast

import numpy as np

from bearing_rig_sim.config import read_mapping, shipped_bearing_file, shipped_calibration_file
from bearing_rig_sim.dynamics.bearing_file import CALIBRATABLE_KEYS, FRICTION_MODELS, LUBRICANT_OVERRIDES, BearingFile, CalibrationFile
from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.bearing.file_record import file_field, file_keys, file_record, file_values
from bearing_rig_sim.bearing.hertz import HertzContact, point_contact, raceway_contacts
from bearing_rig_sim.dynamics.lubrication import Lubricant, rolling_force
from bearing_rig_sim.dynamics.ball_balance import thrust_contact_angles
from bearing_rig_sim.dynamics.traction import SRR_REF, ContactKinematics, build_table, mu_nodes, table_axes
from bearing_rig_sim.settings_model import read_file, validate_mapping

GRAVITY = 9.80665
"""Standard gravity, m/s^2 (CGPM 1901)."""


@file_record
class BearingParameters:
    """Primary bearing data, SI units, each field read from the bearing-file key it names
    (:func:`~bearing_rig_sim.bearing.file_record.file_field`; the key states the file's unit, its
    range and source are in :mod:`.bearing_file`, the values' sources in the file's comments).

    Geometry: ``ball_diameter`` Dw (m), ``pitch_diameter`` dm (m), ``contact_angle`` free
    contact angle (rad), ``ball_count`` Z, groove curvature ratios f_i, f_o (1), cage inner and
    outer diameter, width and pocket diameter (m), land radial clearance and wetted width (m;
    :data:`.bearing_file.LAND_CLEARANCE_RANGE`, :data:`.bearing_file.LAND_WIDTH_RANGE`), ``land_count`` (1 or 2 lands sharing
    the width), cage material loss factor (1).
    Materials: densities (kg/m^3), Young's moduli (Pa), Poisson ratios (1).
    Contact: Hunt-Crossley coefficient a_e (s/m) and exponent n (1); full-damping penetration (m).
    Friction: model name, mu_s, v_s (m/s), mu_d, v_d (m/s), EHL mu_max and SRR0, pocket mu.
    Lubricant: oil and air densities (kg/m^3) and viscosities (Pa s), oil volume fraction (1);
    with a lubricant file, ``lubricant`` (:class:`.lubrication.Lubricant`) and its
    ``lubricant_temperature`` (degC) set the oil values.
    Resistances: drag coefficient, scale factors (1), land friction coefficient (1),
    hysteresis factor alpha_h (1).
    Integration: time steps of the reduced and stiff models (s).
    Also: ``ehl_rolling_scale`` (1) on Houpert's force, ``composite_roughness`` (m, RMS; 0 if
    not given) for the film parameter, ``spindle_axis`` (``horizontal`` or ``vertical``).
    """

    name: str = file_field("bearing.name")
    ball_diameter: float = file_field("geometry.ball_diameter_m")
    pitch_diameter: float = file_field("geometry.pitch_diameter_m")
    contact_angle: float = file_field("geometry.contact_angle_deg", convert=math.radians)
    ball_count: int = file_field("geometry.ball_count")
    inner_curvature_ratio: float = file_field("geometry.inner_groove_curvature_ratio")
    outer_curvature_ratio: float = file_field("geometry.outer_groove_curvature_ratio")
    cage_inner_diameter: float = file_field("cage.inner_diameter_m")
    cage_outer_diameter: float = file_field("cage.outer_diameter_m")
    cage_width: float = file_field("cage.width_m")
    pocket_diameter: float = file_field("cage.pocket_diameter_m")
    land_clearance: float = file_field("cage.land_radial_clearance_m")
    land_width: float = file_field("cage.land_width_m")
    cage_loss_factor: float = file_field("cage.material_loss_factor")
    ring_density: float = file_field("materials.ring.density_kg_m3")
    ring_modulus: float = file_field("materials.ring.youngs_modulus_pa")
    ring_poisson: float = file_field("materials.ring.poisson_ratio")
    ball_density: float = file_field("materials.ball.density_kg_m3")
    ball_modulus: float = file_field("materials.ball.youngs_modulus_pa")
    ball_poisson: float = file_field("materials.ball.poisson_ratio")
    cage_density: float = file_field("materials.cage.density_kg_m3")
    cage_modulus: float = file_field("materials.cage.youngs_modulus_pa")
    cage_poisson: float = file_field("materials.cage.poisson_ratio")
    inner_ring_axial_mass: float = file_field("inner_ring.axial_mass_kg")
    hunt_crossley_coefficient: float = file_field("contact.hunt_crossley_coefficient_s_m")
    hunt_crossley_exponent: float = file_field("contact.hunt_crossley_exponent")
    full_damping_penetration: float = file_field("contact.full_damping_penetration_m")
    friction_model: str = file_field("friction.model")
    static_friction: float = file_field("friction.static_coefficient")
    stiction_velocity: float = file_field("friction.stiction_velocity_m_s")
    dynamic_friction: float = file_field("friction.dynamic_coefficient")
    transition_velocity: float = file_field("friction.transition_velocity_m_s")
    ehl_max_coefficient: float = file_field("friction.ehl_max_coefficient")
    ehl_reference_srr: float = file_field("friction.ehl_reference_slide_roll_ratio")
    pocket_friction: float = file_field("friction.pocket_coefficient")
    # the oil's three values: these inline keys, or the lubricant file's, or 0 when dry (from_file)
    oil_density: float = file_field("lubricant.oil_density_kg_m3")
    oil_viscosity: float = file_field("lubricant.oil_viscosity_pa_s")
    air_density: float = file_field("lubricant.air_density_kg_m3")
    air_viscosity: float = file_field("lubricant.air_viscosity_pa_s")
    oil_volume_fraction: float = file_field("lubricant.oil_volume_fraction")
    ball_drag_coefficient: float = file_field("resistances.ball_drag_coefficient")
    ball_drag_scale: float = file_field("resistances.ball_drag_scale")
    cage_land_viscous_scale: float = file_field("resistances.cage_land_viscous_scale")
    cage_land_friction: float = file_field("resistances.cage_land_friction_coefficient")
    cage_land_boundary_torque_scale: float = file_field("resistances.cage_land_boundary_torque_scale")
    rolling_hysteresis_factor: float = file_field("resistances.rolling_hysteresis_factor")
    reduced_time_step: float = file_field("integration.reduced_time_step_s")
    stiff_time_step: float = file_field("integration.stiff_time_step_s")
    dynamic_load_rating: float = file_field("bearing.dynamic_load_rating_n")
    lubricant: Lubricant | None  # the lubricant.file key's file, with the section's overrides (from_file)
    lubricant_temperature: float = file_field("lubricant.temperature_c")
    ehl_rolling_scale: float = file_field("resistances.ehl_rolling_scale")
    composite_roughness: float = file_field("geometry.composite_roughness_rq_m")
    spindle_axis: str = file_field("installation.spindle_axis")
    land_count: int = file_field("cage.land_count")
    dry: bool = file_field("lubricant.dry")
    ball_set_resistance: float = file_field("resistances.ball_set_resistance_n")
    ball_set_resistance_speed_exponent: float = file_field("resistances.ball_set_resistance_speed_exponent")
    ball_set_resistance_load_exponent: float = file_field("resistances.ball_set_resistance_load_exponent")
    ball_set_resistance_reference_load: float = file_field("resistances.ball_set_resistance_reference_load_n")
    source: str = "<memory>"

    # -- construction --------------------------------------------------------------------------
    @classmethod
    def from_yaml(cls, path: str | Path | None = None, calibration: str | Path | None = None) -> BearingParameters:
        """Load and validate a bearing file (default: the shipped H7006C), optionally with a
        calibration file laid over it (see :func:`overlay_calibration`)."""
        path = path or shipped_bearing_file()
        data, source = read_mapping(path), str(path)
        if calibration is not None:
            data, source = overlay_calibration(data, read_file(CalibrationFile, calibration)), f"{source} + {calibration}"
        return cls.from_mapping(data, source)

    @classmethod
    def calibrated(cls) -> BearingParameters:
        """The shipped H7006C with the shipped bench calibration (``config/calibration/``)."""
        return cls.from_yaml(None, shipped_calibration_file())

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], source: str) -> BearingParameters:
        """Validate a bearing document read from ``source`` (:class:`~.bearing_file.BearingFile`);
        errors name the file, the key and the allowed range."""
        return cls.from_file(validate_mapping(BearingFile, data, source), source)

    @classmethod
    def from_file(cls, doc: BearingFile, source: str) -> BearingParameters:
        """The parameters of a validated bearing file: each field from the key it names, in SI;
        the lubricant from its file, with the section's overrides (a calibration's) laid over it."""
        lub = doc.lubricant
        lubricant = Lubricant.from_yaml(lub.file) if lub.file is not None else None
        if lubricant is not None and lub.overrides():
            lubricant = lubricant.replace_rheology(**lub.overrides())
        # not a plain copy: with a lubricant file the oil's values are its own at the operating
        # temperature (the inline keys are absent); a dry bearing has none
        oil: dict[str, float] = {}
        if lubricant is not None:
            t = lub.temperature_c
            oil = {"oil_density": lubricant.density(t), "oil_viscosity": lubricant.dynamic_viscosity(t), "oil_volume_fraction": lubricant.oil_volume_fraction}
        elif lub.dry:
            oil = dict.fromkeys(("oil_density", "oil_viscosity", "oil_volume_fraction"), 0.0)
        return cls(**file_values(cls, doc, lubricant=lubricant, source=source, **oil))

    def replace(self, **changes: object) -> BearingParameters:
        """A copy with some fields changed (e.g. calibrated scale factors)."""
        return dataclasses.replace(self, **cast(dict[str, Any], changes))

    def without_resistances(self) -> BearingParameters:
        """All slip-causing resistances off: no drag, no cage land or pocket friction, no
        rolling hysteresis (used by the kinematic-limit test)."""
        return self.replace(
            ball_drag_scale=0.0,
            cage_land_viscous_scale=0.0,
            cage_land_boundary_torque_scale=0.0,
            pocket_friction=0.0,
            rolling_hysteresis_factor=0.0,
            ehl_rolling_scale=0.0,
        )

    def conservative(self) -> BearingParameters:
        """Friction, damping and resistances off: a conservative system (energy test)."""
        return self.without_resistances().replace(
            friction_model="paper",
            static_friction=0.0,
            dynamic_friction=0.0,
            ehl_max_coefficient=0.0,
            hunt_crossley_coefficient=0.0,
            cage_loss_factor=0.0,
        )

    # -- derived -------------------------------------------------------------------------------
    def with_lubricant(self, **changes: float) -> BearingParameters:
        """A copy whose lubricant has some rheology fields changed (calibrated values)."""
        if self.lubricant is None:
            raise ValueError("this bearing has no lubricant file")
        return self.replace(lubricant=self.lubricant.replace_rheology(**changes))

    def raceway_contacts(self, contact_angle: float | None = None) -> tuple[HertzContact, HertzContact]:
        """The ball-inner and ball-outer raceway Hertz contacts at ``contact_angle`` (rad; the
        free contact angle when None)."""
        a = self.contact_angle if contact_angle is None else contact_angle
        return raceway_contacts(
            self.ball_diameter,
            self.pitch_diameter,
            a,
            self.inner_curvature_ratio,
            self.outer_curvature_ratio,
            self.ball_modulus,
            self.ball_poisson,
            self.ring_modulus,
            self.ring_poisson,
        )

    def contact_kinematics(self) -> tuple[ContactKinematics, ContactKinematics]:
        """The inner and outer contacts' rolling geometry at the free contact angle, as the
        traction table is built on it: rolling radii Dw(1 -+ gamma)/2 and groove radii f Dw."""
        dw = self.ball_diameter
        gamma = dw * math.cos(self.contact_angle) / self.pitch_diameter
        inner, outer = self.raceway_contacts()
        return (
            ContactKinematics(inner, 0.5 * dw * (1.0 - gamma), self.inner_curvature_ratio * dw, True),
            ContactKinematics(outer, 0.5 * dw * (1.0 + gamma), self.outer_curvature_ratio * dw, False),
        )

    @property
    def combined_constant(self) -> float:
        """The inner and outer contacts' load-deflection constants in series at the free contact
        angle, K_n = (K_i^(-2/3) + K_o^(-2/3))^(-3/2), N/m^1.5 (Harris and Kotzalas Eq. 7.19)."""
        inner, outer = self.raceway_contacts()
        return float((inner.stiffness ** (-2.0 / 3.0) + outer.stiffness ** (-2.0 / 3.0)) ** -1.5)

    @property
    def epicyclic_ratio(self) -> float:
        """n_s / n_i at the free contact angle (paper Eq. 12), 1."""
        return 0.5 * (1.0 - self.ball_diameter * math.cos(self.contact_angle) / self.pitch_diameter)


def _calibratable() -> dict[str, tuple[str, str]]:
    names = {key: name for name, key in file_keys(BearingParameters).items()}
    names |= {f"lubricant.{key}": field for key, field in LUBRICANT_OVERRIDES.items()}
    return {names[key]: (key.partition(".")[0], key.partition(".")[2]) for key in CALIBRATABLE_KEYS}


CALIBRATABLE: dict[str, tuple[str, str]] = _calibratable()
"""Parameters a calibration file may set: name -> (section, key) in the bearing file. The keys
are those declared calibratable (:data:`.bearing_file.CALIBRATABLE_KEYS`); a name is that of the
:class:`BearingParameters` field reading the key, or of the :class:`.lubrication.Lubricant`
field the key overrides (:data:`.bearing_file.LUBRICANT_OVERRIDES`)."""


def overlay_calibration(bearing: Mapping[str, Any], calibration: CalibrationFile) -> dict[str, Any]:
    """Lay a validated calibration file over a bearing document: each entry of its
    ``parameters:`` (keyed ``section.key`` as in the bearing file, only the keys of
    :data:`CALIBRATABLE`, a physical quantity within its plausible range;
    :class:`~.bearing_file.CalibrationFile`) replaces the bearing file's value. The merged
    document is validated as a whole by :meth:`BearingParameters.from_mapping`."""
    merged = {k: dict(v) if isinstance(v, dict) else v for k, v in bearing.items()}
    for name, value in calibration.parameters.items():
        sec, key = name.split(".", 1)
        merged.setdefault(sec, {})[key] = value
    return merged


_TABLE_ANGLES: dict[tuple[float, ...], np.ndarray] = {}


def table_contact_angles(p: BearingParameters) -> np.ndarray:
    """The contact angles (alpha_i, alpha_o), rad, at the traction table's load and speed nodes
    (:func:`.ball_balance.thrust_contact_angles`), shape (N_LOAD, N_SPEED, 2). They depend on
    the geometry, the Hertz constants and the balls' density alone, so they are computed once per
    such bearing (about half a second) and shared by its tables at every temperature; a
    read-only array."""
    inner, outer = p.raceway_contacts()
    key = (
        float(p.ball_count),
        p.ball_diameter,
        p.pitch_diameter,
        p.contact_angle,
        p.inner_curvature_ratio,
        p.outer_curvature_ratio,
        p.ball_density,
        inner.stiffness,
        outer.stiffness,
    )
    angles = _TABLE_ANGLES.get(key)
    if angles is None:
        lu, lq = table_axes()
        angles = thrust_contact_angles(p, np.exp(lq), np.exp(lu))
        angles.setflags(write=False)
        _TABLE_ANGLES[key] = angles
    return angles


@functools.lru_cache(maxsize=8)
def _traction_table(p: BearingParameters) -> np.ndarray:
    lub = p.lubricant
    assert lub is not None
    return build_table(
        p.contact_kinematics(),
        lub,
        p.lubricant_temperature,
        angles=table_contact_angles(p),
        ball_diameter=p.ball_diameter,
        pitch_diameter=p.pitch_diameter,
    )


def traction_table(p: BearingParameters) -> np.ndarray:
    """The rheology traction table of a bearing (:func:`.traction.build_table`), built once per
    distinct geometry and film rheology (the grease's bulk rheology and the resistances do not
    enter it; a copy is returned)."""
    lub = p.lubricant
    assert lub is not None
    film_only = dataclasses.replace(lub, yield_stress=0.0, consistency=0.0, flow_index=1.0, fill_fraction=1.0)
    key = p.replace(
        lubricant=film_only, ball_drag_scale=1.0, cage_land_viscous_scale=1.0, pocket_friction=0.0, rolling_hysteresis_factor=0.0, ehl_rolling_scale=1.0
    )
    return _traction_table(key).copy()


@dataclass(frozen=True)
class DerivedGeometry:
    """Quantities derived from :class:`BearingParameters` (SI units), for reports and tests."""

    inner_groove_bottom_diameter: float
    outer_groove_bottom_diameter: float
    ball_mass: float
    ball_inertia: float
    cage_mass: float
    cage_segment_inertia: float
    cage_link_stiffness: float
    inner_hertz_stiffness: float
    outer_hertz_stiffness: float
    pocket_hertz_stiffness: float
    pocket_clearance: float


def _resistance_entries(p: BearingParameters, r_land: float, cage_mass: float) -> dict[int, float]:
    """The kernel entries of the resistances by lubrication mode (module doc; docs/model.md,
    Resistances): the ball drag (linear, quadratic, plastic and power-law terms, and the dry
    model's ball-set resistance with its load factor), the cage land's torque and its film's
    Ocvirk force terms. ``r_land`` the land radius (m), ``cage_mass`` kg."""
    dw = p.ball_diameter
    drag_yield = drag_pow = land_pow = 0.0
    drag_n = land_n = 1.0
    lub = p.lubricant
    if lub is not None and lub.kind == "grease":
        # Sphere in a Herschel-Bulkley grease: plastic drag 3.5 pi Dw^2 tau_y (Beris et al. 1985,
        # J. Fluid Mech. 158:219) plus Stokes drag with the apparent viscosity at v/Dw.
        fill = lub.fill_fraction
        drag_yield = p.ball_drag_scale * fill * 3.5 * math.pi * dw * dw * lub.yield_stress
        drag_pow = p.ball_drag_scale * fill * 3.0 * math.pi * lub.consistency * dw ** (2.0 - lub.flow_index)
        drag_n = lub.flow_index
        drag_lin = 0.0
        drag_quad = p.ball_drag_scale * fill * 0.5 * lub.density(p.lubricant_temperature) * p.ball_drag_coefficient * math.pi * 0.25 * dw * dw
        # Land: wall stress of the sheared grease film, tau_y + K (r omega / c)^n, on 2 pi r L.
        land_area_r = 2.0 * math.pi * r_land**2 * p.land_width * p.cage_land_viscous_scale * fill
        land_visc = 0.0
        land_yield = land_area_r * lub.yield_stress
        land_pow = land_area_r * lub.consistency * (r_land / p.land_clearance) ** lub.flow_index
        land_n = lub.flow_index
    else:
        fill = lub.fill_fraction if lub is not None else 1.0
        if lub is not None and lub.kind == "oil_bath":
            rho_mix, eta_mix = fill * p.oil_density, fill * p.oil_viscosity
        else:
            rho_mix = p.oil_volume_fraction * p.oil_density + (1.0 - p.oil_volume_fraction) * p.air_density
            eta_mix = p.oil_volume_fraction * p.oil_viscosity + (1.0 - p.oil_volume_fraction) * p.air_viscosity
        drag_lin = p.ball_drag_scale * 3.0 * math.pi * eta_mix * dw
        drag_quad = p.ball_drag_scale * 0.5 * rho_mix * p.ball_drag_coefficient * math.pi * 0.25 * dw * dw
        land_visc = p.cage_land_viscous_scale * fill * 2.0 * math.pi * p.oil_viscosity * r_land**3 * p.land_width / p.land_clearance
        land_yield = 0.0
        if p.ball_set_resistance > 0.0:
            # the dry model's stand-in for the resistance its source implies and does not state:
            # c (v / 1 m/s)^m on each ball's orbit, times (Q_mean / Q_ref)^k in the kernel
            drag_pow, drag_n = p.ball_set_resistance, p.ball_set_resistance_speed_exponent
    cage_weight_on_land = cage_mass * GRAVITY if p.spindle_axis == "horizontal" else 0.0
    land_coulomb = land_yield + p.cage_land_boundary_torque_scale * p.cage_land_friction * cage_weight_on_land * r_land
    # Land film (Ocvirk short journal bearing, kernels.land_force): the same fluid and fill as
    # the land torque; land_count lands of width land_width / land_count each.
    land_scale = p.cage_land_viscous_scale * fill
    each = p.land_width / p.land_count
    land_ocv = p.land_count * r_land * each**3 / p.land_clearance**2
    if lub is not None and lub.kind == "grease":
        land_eta, land_tauy, land_cons = 0.0, land_scale * lub.yield_stress, land_scale * lub.consistency
    else:
        land_eta, land_tauy, land_cons = land_scale * p.oil_viscosity, 0.0, 0.0
    return {
        kn.P_DRAG_LIN: drag_lin,
        kn.P_DRAG_QUAD: drag_quad,
        kn.P_LAND_VISC: land_visc,
        kn.P_LAND_COULOMB: land_coulomb,
        kn.P_DRAG_YIELD: drag_yield,
        kn.P_DRAG_POW: drag_pow,
        kn.P_DRAG_N: drag_n,
        kn.P_LAND_POW: land_pow,
        kn.P_LAND_N: land_n,
        kn.P_LAND_OCV: land_ocv,
        kn.P_LAND_ETA: land_eta,
        kn.P_LAND_TAUY: land_tauy,
        kn.P_LAND_CONS: land_cons,
        kn.P_DRAG_LOAD_EXP: p.ball_set_resistance_load_exponent if p.ball_set_resistance > 0.0 else 0.0,
        kn.P_DRAG_LOAD_REF: p.ball_set_resistance_reference_load,
    }


def derive(p: BearingParameters) -> tuple[np.ndarray, DerivedGeometry]:
    """Compute the kernel parameter vector and the derived geometry.

    Returns:
        (vector, geometry): the float64 vector laid out as :mod:`.kernels` ``P_*`` indices,
        and the derived quantities.
    """
    dw, dm, a0, z = p.ball_diameter, p.pitch_diameter, p.contact_angle, p.ball_count
    rball = 0.5 * dw
    rm = 0.5 * dm
    ri = p.inner_curvature_ratio * dw
    ro = p.outer_curvature_ratio * dw
    # Groove curvature centres (r, z) with zero clearance at the free contact angle.
    ci_r, ci_z = rm + (ri - rball) * math.cos(a0), (ri - rball) * math.sin(a0)
    co_r, co_z = rm - (ro - rball) * math.cos(a0), -(ro - rball) * math.sin(a0)
    inner, outer = p.raceway_contacts()
    # Ball in a cylindrical pocket (axis radial): concave radius d_p/2 across, straight along.
    pocket = point_contact(2.0 / dw, 2.0 / dw, -2.0 / p.pocket_diameter, 0.0, p.ball_modulus, p.ball_poisson, p.cage_modulus, p.cage_poisson)
    ball_mass = p.ball_density * math.pi * dw**3 / 6.0
    ball_inertia = 0.4 * ball_mass * rball**2
    # Cage: annulus less the pockets; one segment per pocket; rims carry the circumferential load.
    r_ci, r_co = 0.5 * p.cage_inner_diameter, 0.5 * p.cage_outer_diameter
    thickness = r_co - r_ci
    volume = math.pi * (r_co**2 - r_ci**2) * p.cage_width - z * math.pi * 0.25 * p.pocket_diameter**2 * thickness
    cage_mass = p.cage_density * volume
    seg_mass = cage_mass / z
    seg_inertia = seg_mass * 0.5 * (r_co**2 + r_ci**2)
    r_cage = 0.5 * (r_ci + r_co)
    pitch_len = 2.0 * math.pi * r_cage / z
    rim_area = 2.0 * 0.5 * (p.cage_width - p.pocket_diameter) * thickness
    link_k = p.cage_modulus * rim_area / pitch_len  # N/m
    link_kt = link_k * r_cage**2  # N m/rad
    link_omega = math.sqrt(4.0 * link_kt / seg_inertia)
    link_ct = p.cage_loss_factor * link_kt / link_omega
    r_land = r_co
    resistances = _resistance_entries(p, r_land, cage_mass)
    lub = p.lubricant
    b_in = inner.semi_axes(1.0)[1]
    b_out = outer.semi_axes(1.0)[1]
    # Cage on its land at eps = 1: two conforming cylinders (cage OD in the land bore, nearly equal
    # radii), linearised line-contact stiffness (pi/4) E* L (Johnson, Contact Mechanics, 5.3).
    e_star = 1.0 / ((1.0 - p.cage_poisson**2) / p.cage_modulus + (1.0 - p.ring_poisson**2) / p.ring_modulus)

    v = np.zeros(kn.P_SIZE)
    v[kn.P_Z] = z
    v[kn.P_RBALL] = rball
    v[kn.P_RM] = rm
    v[kn.P_RI_GAP] = ri - rball
    v[kn.P_RO_GAP] = ro - rball
    v[kn.P_CI_R], v[kn.P_CI_Z] = ci_r, ci_z
    v[kn.P_CO_R], v[kn.P_CO_Z] = co_r, co_z
    v[kn.P_K_IN] = inner.stiffness
    v[kn.P_K_OUT] = outer.stiffness
    v[kn.P_K_POCKET] = pocket.stiffness
    v[kn.P_POCKET_CLEAR] = 0.5 * (p.pocket_diameter - dw)
    v[kn.P_MBALL] = ball_mass
    v[kn.P_IBALL] = ball_inertia
    v[kn.P_JSEG] = seg_inertia
    v[kn.P_LINK_K] = link_kt
    v[kn.P_LINK_C] = link_ct
    v[kn.P_HC_A] = p.hunt_crossley_coefficient
    v[kn.P_HC_N] = p.hunt_crossley_exponent
    v[kn.P_HC_D] = p.full_damping_penetration
    v[kn.P_FRIC_MODEL] = FRICTION_MODELS[p.friction_model]
    v[kn.P_MU_S] = p.static_friction
    v[kn.P_V_S] = p.stiction_velocity
    v[kn.P_MU_D] = p.dynamic_friction
    v[kn.P_V_D] = p.transition_velocity
    v[kn.P_EHL_MU] = p.ehl_max_coefficient
    v[kn.P_EHL_SRR] = p.ehl_reference_srr
    v[kn.P_MU_POCKET] = p.pocket_friction
    v[kn.P_HYST] = p.rolling_hysteresis_factor
    v[kn.P_B_IN] = b_in
    v[kn.P_B_OUT] = b_out
    v[kn.P_M_INNER] = p.inner_ring_axial_mass
    # Q b = b(1 N) Q^(4/3) = b(1 N) K^(4/3) delta^2
    v[kn.P_HYST_IN] = 0.1875 * p.rolling_hysteresis_factor * b_in * inner.stiffness ** (4.0 / 3.0)
    v[kn.P_HYST_OUT] = 0.1875 * p.rolling_hysteresis_factor * b_out * outer.stiffness ** (4.0 / 3.0)
    for index, value in resistances.items():
        v[index] = value
    v[kn.P_CAGE_MASS] = cage_mass
    v[kn.P_LAND_R] = r_land
    v[kn.P_LAND_CLEAR] = p.land_clearance
    v[kn.P_LAND_K] = 0.25 * math.pi * e_star * p.land_width
    v[kn.P_LAND_MU] = p.cage_land_friction
    v[kn.P_PRELOAD_K] = z * p.combined_constant  # a rigid preload's partner (the engine sets P_PRELOAD_D)
    v[kn.P_CAGE_GRAV_Y] = -cage_mass * GRAVITY if p.spindle_axis == "horizontal" else 0.0
    # spin lever of each contact: the Hertz pressure's mean distance from the centre,
    # (3/8) a E(e^2) (a the semi-major axis, E the complete elliptic integral of the second kind
    # at e^2 = 1 - b^2/a^2; (3 pi/16) a on a circle, 3a/8 on a long ellipse); a grows as
    # Q^(1/3) = K^(1/3) delta^(1/2), so the value at 1 N times K^(1/3), x delta^(1/2)
    v[kn.P_SPIN_IN] = 0.375 * inner.semi_axes(1.0)[0] * inner.second_kind * inner.stiffness ** (1.0 / 3.0)
    v[kn.P_SPIN_OUT] = 0.375 * outer.semi_axes(1.0)[0] * outer.second_kind * outer.stiffness ** (1.0 / 3.0)
    gamma = dw * math.cos(a0) / dm
    rx_in, rx_out = rball * (1.0 - gamma), rball * (1.0 + gamma)
    if lub is not None:
        # Houpert rolling force F_R = c u^0.66 Q^0.47 per contact, c from the value at 1 m/s, 1 N.
        eta0 = lub.dynamic_viscosity(p.lubricant_temperature)
        for idx, con, rx in ((kn.P_FR_IN, inner, rx_in), (kn.P_FR_OUT, outer, rx_out)):
            v[idx] = p.ehl_rolling_scale * rolling_force(eta0, lub.pressure_viscosity, con.reduced_modulus, rx, con.ellipticity, 1.0, 1.0)
    if p.friction_model == "rheology" and lub is not None:
        v[kn.P_TABLE] = kn.P_SIZE
        table = traction_table(p)
        v = np.concatenate([v, table])
        # steepest d mu/d SRR of the table: its slope in xi = asinh(SRR/SRR_REF) over SRR_REF
        n_srr, xi_max = int(table[0]), table[3]
        mu = mu_nodes(table, 0)
        v[kn.P_MU_SLOPE_MAX] = float(np.max(np.abs(np.diff(mu, axis=1)))) / (2.0 * xi_max / (n_srr - 1)) / SRR_REF
    elif v[kn.P_FRIC_MODEL] == 1.0:
        v[kn.P_MU_SLOPE_MAX] = v[kn.P_EHL_MU] / v[kn.P_EHL_SRR]  # d mu/d SRR at SRR = 0
    else:
        v[kn.P_MU_SLOPE_MAX] = 1.5 * v[kn.P_MU_S] / v[kn.P_V_S]  # d mu/ds at s = 0, s/m
    geo = DerivedGeometry(
        inner_groove_bottom_diameter=2.0 * (ci_r - ri),
        outer_groove_bottom_diameter=2.0 * (co_r + ro),
        ball_mass=ball_mass,
        ball_inertia=ball_inertia,
        cage_mass=cage_mass,
        cage_segment_inertia=seg_inertia,
        cage_link_stiffness=link_kt,
        inner_hertz_stiffness=inner.stiffness,
        outer_hertz_stiffness=outer.stiffness,
        pocket_hertz_stiffness=pocket.stiffness,
        pocket_clearance=v[kn.P_POCKET_CLEAR],
    )
    return v, geo
