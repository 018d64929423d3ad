"""The bearing, lubricant and calibration files as declarative models (pydantic, through
:mod:`bearing_rig_sim.settings_model`): each key once, with its description, SI unit, the source
of its plausible range and the range itself; the checks across keys (a pitch diameter above the
ball diameter, a pocket wider than the ball) in the model's validators. Validating a file gives
one-line errors naming the file, the dotted key and the allowed range::

    config/bearings/h7006c.yaml: geometry.ball_diameter_m: must be > 0.0, got -0.0063

The values each file states, and where they come from, are in the file's comments; the ranges
here are what any bearing or lubricant of this kind may have. The objects the engine uses are
built from the validated files in :mod:`.parameters` (:class:`~.parameters.BearingParameters`)
and :mod:`.lubrication` (:class:`~.lubrication.Lubricant`); the thermal network reads the same
bearing file (:class:`~bearing_rig_sim.thermal.bearing.ThermalConfig`). Each field of those
records names its key here once (:mod:`bearing_rig_sim.bearing.file_record`); whether a
calibration file may set a key is stated at the key (``calibratable=True``). No ROS import.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Annotated, Any, Self, get_args

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, model_validator

from bearing_rig_sim.config import check_number
from bearing_rig_sim.settings_model import FileSection, Flag, Integer, Number, StatedQuantity, Text, field_error, one_of, quantity, validate_mapping

FRICTION_MODELS = {"paper": 0.0, "coulomb_step": 0.0, "ehl_traction": 1.0, "rheology": 2.0}
"""Traction laws (``friction.model``) and their kernel codes: ``paper`` (alias ``coulomb_step``)
the paper's stepped Coulomb law in the sliding speed; ``ehl_traction`` an exponential fit in the
slide-to-roll ratio; ``rheology`` the film rheology integrated over the Hertz ellipse
(:mod:`.traction`), which needs a lubricant file."""

SPINDLE_AXES = ("horizontal", "vertical")
"""Orientation of the bearing axis: with a horizontal axis the cage's weight presses it on its
land (boundary friction mu m_c g r); with a vertical axis the weight acts along the axis and the
land carries none of it (the balls' and cage's weights, about 0.2 N, are negligible against the
axial load and are not added to it)."""

LAND_CLEARANCE_RANGE = (1e-5, 1e-3)
"""Plausible radial land clearance of a land-guided cage, m: 0.1-0.5 % of the land diameter
for machined cages (Harris and Kotzalas, cage design; SKF super-precision catalogue), widened
to 10 um - 1 mm for small and large bearings."""
LAND_WIDTH_RANGE = (2e-4, 0.02)
"""Plausible total wetted width of the guiding land(s), m (a fraction of the bearing width)."""

KINDS = ("oil_air", "oil_bath", "grease")
"""Lubrication modes: oil-air mist, oil bath or jet (cavity flooded), grease."""

LUBRICANT_OVERRIDES = {
    "yield_stress_pa": "yield_stress",
    "consistency_pa_sn": "consistency",
    "fill_fraction": "fill_fraction",
    "eyring_stress_pa": "eyring_stress",
    "consistency_temperature_exponent": "consistency_temperature_exponent",
}
"""Keys of the bearing file's ``lubricant:`` section that override the lubricant file (a
calibration sets them): key -> :class:`~.lubrication.Lubricant` field."""

HARRIS = "Harris and Kotzalas, Essential Concepts of Bearing Technology (2006)"
SOLID = "an isotropic solid (Poisson ratio below 0.5)"
SCALE = "a multiplier on a physical law; 1 = the law as published, 0 = off"


# ---------------------------------------------------------------------------------------------
# The bearing file (config/bearings/*.yaml)
# ---------------------------------------------------------------------------------------------
class BearingIdentity(FileSection):
    """``bearing:``"""

    name: Text = Field(description="the bearing's designation")
    dynamic_load_rating_n: Number = quantity("basic dynamic load rating C (ISO 281)", unit="N", source="ISO 281", gt=0.0, default=13000.0)


class Geometry(FileSection):
    """``geometry:``; the pitch diameter lies above the ball diameter, the outside diameter above
    the bore, each shoulder between them."""

    bore_m: Number = quantity("bore d", unit="m", source="a rolling bearing below 1 m bore", gt=0.0, lt=1.0)
    outside_diameter_m: Number = quantity("outside diameter D (above the bore)", unit="m", source="a rolling bearing below 2 m", lt=2.0)
    width_m: Number = quantity("width B", unit="m", source="a rolling bearing below 0.5 m wide", gt=0.0, lt=0.5)
    ball_diameter_m: Number = quantity("ball diameter Dw", unit="m", source="balls of bearings below 1 m bore", gt=0.0, lt=0.1)
    ball_count: Integer = quantity("number of balls Z", unit="1", source=f"{HARRIS}: single-row ball bearings", ge=3, le=60)
    pitch_diameter_m: Number = quantity("pitch diameter dm (above Dw)", unit="m", source="a rolling bearing below 1 m", lt=1.0)
    contact_angle_deg: Number = quantity("nominal (free) contact angle", unit="deg", source=f"{HARRIS}: angular contact ball bearings", ge=0.0, lt=45.0)
    composite_roughness_rq_m: Number = quantity(
        "composite RMS roughness of ball and raceway", unit="m", source="ground and superfinished surfaces (Rq below 10 um)", ge=0.0, lt=1e-5, default=0.0
    )
    inner_groove_curvature_ratio: Number = quantity("inner groove radius over Dw", unit="1", source=f"{HARRIS}: 0.515-0.54", gt=0.5, lt=0.6)
    outer_groove_curvature_ratio: Number = quantity("outer groove radius over Dw", unit="1", source=f"{HARRIS}: 0.515-0.54", gt=0.5, lt=0.6)
    outer_shoulder_diameter_m: Number = quantity("outer-ring shoulder (land) diameter, between d and D", unit="m", source="the ring section")
    inner_shoulder_diameter_m: Number = quantity("inner-ring shoulder (land) diameter, between d and D", unit="m", source="the ring section")

    @model_validator(mode="after")
    def _nested_diameters(self) -> Self:
        check_number(self.outside_diameter_m, "", "outside_diameter_m", gt=self.bore_m, lt=2.0)
        check_number(self.pitch_diameter_m, "", "pitch_diameter_m", gt=self.ball_diameter_m, lt=1.0)
        for key in ("inner_shoulder_diameter_m", "outer_shoulder_diameter_m"):
            check_number(getattr(self, key), "", key, gt=self.bore_m, lt=self.outside_diameter_m)
        return self


class Cage(FileSection):
    """``cage:``; pocket, diameters and width against the balls and the pitch circle are checked
    by :class:`BearingFile`."""

    inner_diameter_m: Number = quantity("cage bore (below dm)", unit="m", source="the cage straddles the pitch circle", gt=0.0)
    outer_diameter_m: Number = quantity("cage outside diameter (dm to 2 dm)", unit="m", source="the cage straddles the pitch circle")
    width_m: Number = quantity("cage width (above the pocket diameter)", unit="m", source="cages of bearings below 0.5 m wide", lt=0.2)
    pocket_diameter_m: Number = quantity("pocket diameter (Dw to 2 Dw)", unit="m", source="a pocket holds one ball with clearance")
    guidance: Annotated[str, one_of(("outer_land",))] = Field(description="how the cage is guided (only outer_land is modelled)")
    land_radial_clearance_m: Number = quantity(
        "radial clearance of the cage on its land",
        unit="m",
        source="0.1-0.5 % of the land diameter (Harris and Kotzalas; SKF super-precision catalogue), widened",
        ge=LAND_CLEARANCE_RANGE[0],
        le=LAND_CLEARANCE_RANGE[1],
    )
    land_width_m: Number = quantity(
        "total wetted width of the guiding land(s)", unit="m", source="a fraction of the bearing width", ge=LAND_WIDTH_RANGE[0], le=LAND_WIDTH_RANGE[1]
    )
    land_count: Integer = quantity("lands sharing land_width_m", unit="1", source="one or two lands, one each side of the pockets", ge=1, le=2, default=1)
    material_loss_factor: Number = quantity("loss factor of the cage material (rim damping)", unit="1", source="a loss factor is a fraction", ge=0.0, le=1.0)


class Material(FileSection):
    """One of ``materials: ring / ball / cage``."""

    density_kg_m3: Number = quantity("density", unit="kg/m^3", source="a solid", gt=0.0)
    youngs_modulus_pa: Number = quantity("Young's modulus", unit="Pa", source="a solid", gt=0.0)
    poisson_ratio: Number = quantity("Poisson ratio", unit="1", source=SOLID, ge=0.0, lt=0.5)


class Materials(FileSection):
    """``materials:``"""

    ring: Material
    ball: Material
    cage: Material


class Installation(FileSection):
    """``installation:``"""

    spindle_axis: Annotated[str, one_of(SPINDLE_AXES)] = Field(default="horizontal", description="orientation of the bearing axis (SPINDLE_AXES)")


class InnerRing(FileSection):
    """``inner_ring:``"""

    axial_mass_kg: Number = quantity("axially moving mass carried by the balls (stiff model)", unit="kg", source="a mass", gt=0.0)


class Contact(FileSection):
    """``contact:``"""

    hunt_crossley_coefficient_s_m: Number = quantity(
        "Hunt-Crossley damping coefficient a_e",
        unit="s/m",
        source="Hunt and Crossley (1975): restitution 0.9-1 at impact speeds of 0.01-1 m/s",
        ge=0.0,
        le=10.0,
    )
    hunt_crossley_exponent: Number = quantity(
        "exponent of the penetration in the damping", unit="1", source="Palmgren (10/9) to Hertz point contact (1.5)", ge=1.0, le=2.0
    )
    full_damping_penetration_m: Number = quantity(
        "penetration of full damping, d of the IMPACT STEP", unit="m", source="below the Hertz deflection scale", gt=0.0, lt=1e-4
    )


class Friction(FileSection):
    """``friction:``; the transition velocity lies above the stiction velocity."""

    model: Annotated[str, one_of(tuple(FRICTION_MODELS))] = Field(description="traction law (FRICTION_MODELS)")
    static_coefficient: Number = quantity(
        "static friction coefficient mu_s (paper law)", unit="1", source="lubricated steel", ge=0.0, le=1.0, calibratable=True
    )
    stiction_velocity_m_s: Number = quantity("stiction velocity v_s (paper law)", unit="m/s", source="a speed", gt=0.0, calibratable=True)
    dynamic_coefficient: Number = quantity("dynamic friction coefficient mu_d (paper law)", unit="1", source="lubricated steel", ge=0.0, le=1.0)
    transition_velocity_m_s: Number = quantity("transition velocity v_d (paper law, above v_s)", unit="m/s", source="a speed above v_s")
    ehl_max_coefficient: Number = quantity(
        "largest traction coefficient (ehl_traction law)", unit="1", source="EHL traction of oils (below 0.5)", ge=0.0, le=0.5
    )
    ehl_reference_slide_roll_ratio: Number = quantity("slide-to-roll ratio scale (ehl_traction law)", unit="1", source="a ratio", gt=0.0, le=1.0)
    pocket_coefficient: Number = quantity("ball-pocket friction coefficient", unit="1", source="lubricated steel on polymer", ge=0.0, le=1.0)

    @model_validator(mode="after")
    def _transition_above_stiction(self) -> Self:
        check_number(self.transition_velocity_m_s, "", "transition_velocity_m_s", gt=self.stiction_velocity_m_s)
        return self


class BearingLubricant(FileSection):
    """``lubricant:`` of the bearing file: the lubricant file, the operating temperature, the cavity
    air and what a calibration overrides; without ``file`` (the legacy inline form) the oil's
    density, viscosity and volume fraction."""

    file: Text | None = Field(None, description="lubricant file, a name in config/lubricants/ or a path")
    dry: Flag = Field(
        default=False,
        description="no lubricant at all (the paper's own model): no film, no drag of oil or grease, no land film; the cavity air remains",
    )
    temperature_c: Number = quantity(
        "operating temperature of the lubricant", unit="degC", source="greases and oils of spindles", ge=-40.0, le=200.0, default=40.0
    )
    air_density_kg_m3: Number = quantity("cavity air density", unit="kg/m^3", source="a gas", gt=0.0)
    air_viscosity_pa_s: Number = quantity("cavity air dynamic viscosity", unit="Pa s", source="a gas", gt=0.0)
    oil_density_kg_m3: Number | None = quantity("oil density (inline form)", unit="kg/m^3", source="a liquid", gt=0.0, default=None)
    oil_viscosity_pa_s: Number | None = quantity("oil dynamic viscosity (inline form)", unit="Pa s", source="a liquid", gt=0.0, default=None)
    oil_volume_fraction: Number | None = quantity(
        "oil share of the oil-air mixture (inline form)", unit="1", source="a fraction", ge=0.0, le=1.0, default=None, calibratable=True
    )
    yield_stress_pa: Number | None = quantity(
        "grease yield stress override", unit="Pa", source="sheared NLGI 1-3 greases", ge=0.0, le=5e3, default=None, calibratable=True
    )
    consistency_pa_sn: Number | None = quantity(
        "grease consistency override", unit="Pa s^n", source="sheared NLGI 1-3 greases", ge=0.0, le=1e3, default=None, calibratable=True
    )
    fill_fraction: Number | None = quantity("fill fraction override", unit="1", source="a fraction", ge=0.0, le=1.0, default=None, calibratable=True)
    eyring_stress_pa: Number | None = quantity(
        "Eyring stress override", unit="Pa", source="EHL films of mineral and ester oils", ge=1e5, le=5e7, default=None, calibratable=True
    )
    consistency_temperature_exponent: Number | None = quantity(
        "grease consistency's temperature exponent override",
        unit="1",
        source="between the thickener alone (0) and the base oil (1)",
        ge=0.0,
        le=1.0,
        default=None,
        calibratable=True,
    )

    @model_validator(mode="after")
    def _inline_oil_complete(self) -> Self:
        if self.dry and self.file is not None:
            raise field_error("dry", "a dry bearing has no lubricant file (lubricant.file)")
        if self.file is None and not self.dry:
            for key in ("oil_density_kg_m3", "oil_viscosity_pa_s", "oil_volume_fraction"):
                if getattr(self, key) is None:
                    raise field_error(key, "missing (required)")
        return self

    def overrides(self) -> dict[str, float]:
        """The lubricant fields this section overrides (:data:`LUBRICANT_OVERRIDES`)."""
        return {field: value for key, field in LUBRICANT_OVERRIDES.items() if (value := getattr(self, key)) is not None}


class Resistances(FileSection):
    """``resistances:``"""

    ball_drag_coefficient: Number = quantity(
        "C_d of a sphere at high Reynolds number", unit="1", source=f"{HARRIS} ch. 7 (0.1-1 at Re 1e3-1e5)", ge=0.0, le=5.0
    )
    ball_drag_scale: Number = quantity("multiplier on the inertial sphere drag", unit="1", source=SCALE, ge=0.0, calibratable=True)
    cage_land_viscous_scale: Number = quantity("multiplier on the land's film torque", unit="1", source=SCALE, ge=0.0, calibratable=True)
    cage_land_friction_coefficient: Number = quantity(
        "boundary friction of the cage on its land", unit="1", source="lubricated polymer on steel", ge=0.0, le=1.0
    )
    cage_land_boundary_torque_scale: Number = quantity("multiplier on mu x cage weight x land radius", unit="1", source=SCALE, ge=0.0, calibratable=True)
    rolling_hysteresis_factor: Number = quantity(
        "elastic hysteresis factor alpha_h", unit="1", source=f"{HARRIS} ch. 7 (bearing steel about 0.007)", ge=0.0, le=0.5, calibratable=True
    )
    ehl_rolling_scale: Number = quantity("multiplier on Houpert's EHL rolling force", unit="1", source=SCALE, ge=0.0, default=1.0)
    ball_set_resistance_n: Number = quantity(
        "dry model only: resistance on each ball's orbit at an orbit speed of 1 m/s and a mean contact load of ball_set_resistance_reference_load_n",
        unit="N",
        source="the paper's model implies one and does not state it (docs/paper.md section 13): below the two raceway contacts' largest traction",
        ge=0.0,
        le=10.0,
        default=0.0,
        calibratable=True,
    )
    ball_set_resistance_speed_exponent: Number = quantity(
        "dry model only: exponent m of the orbit speed in the ball-set resistance",
        unit="1",
        source="Coulomb (0) to inertial drag (2)",
        ge=0.0,
        le=2.0,
        default=1.0,
        calibratable=True,
    )
    ball_set_resistance_load_exponent: Number = quantity(
        "dry model only: exponent k of the mean contact load in the ball-set resistance",
        unit="1",
        source="load independent (0) to proportional (1); 2n/3 = 0.741 follows the paper's contact damping C ~ delta^n, n = 10/9",
        ge=0.0,
        le=1.0,
        default=0.0,
    )
    ball_set_resistance_reference_load_n: Number = quantity(
        "dry model only: mean contact load at which ball_set_resistance_n is stated", unit="N", source="a load", gt=0.0, default=10.0
    )


class Integration(FileSection):
    """``integration:``; plausible ranges only: each step is checked at start against its model's
    stability limit over the rig's envelope (:mod:`.step_limit`)."""

    reduced_time_step_s: Number = quantity(
        "step of the reduced (default) model", unit="s", source="accuracy of transients (docs/model.md, Integration)", gt=0.0, le=2e-4
    )
    stiff_time_step_s: Number = quantity("step of the stiff reference model", unit="s", source="Hertz contact periods of 10-30 us", gt=0.0, le=5e-6)


class Housing(FileSection):
    """``thermal: housing:``"""

    mass_kg: Number = quantity("housing mass", unit="kg", source="bench housings", ge=0.5, le=20.0)
    outer_area_m2: Number = quantity("housing free surface", unit="m^2", source="bench housings", ge=0.005, le=0.5)
    film_coefficient_w_m2_k: Number = quantity(
        "free convection and radiation coefficient", unit="W/(m^2 K)", source="Incropera: free convection in air 2-25", ge=3.0, le=30.0
    )
    frame_conductance_w_k: Number = quantity("conduction to the bench frame", unit="W/K", source="lever and base plate", ge=0.0, le=5.0)


class Shaft(FileSection):
    """``thermal: shaft:``"""

    diameter_m: Number = quantity("shaft diameter", unit="m", source="spindle shafts", ge=0.005, le=0.2)
    length_m: Number = quantity("free spindle length to the motor bearings", unit="m", source="bench spindles", ge=0.02, le=1.0)
    motor_conductance_w_k: Number = quantity("conduction into the spindle motor", unit="W/K", source="k A / L of the shaft section", ge=0.0, le=5.0)


class Thermal(FileSection):
    """``thermal:`` (the lumped network of :mod:`bearing_rig_sim.thermal`)."""

    ambient_temperature_c: Number = quantity("laboratory air temperature", unit="degC", source="laboratories", ge=10.0, le=40.0)
    fit_contact_conductance_w_m2_k: Number = quantity(
        "ring seat contact conductance", unit="W/(m^2 K)", source="Madhusudana, Thermal Contact Conductance (1996): 1e4-1e5", ge=5e3, le=1e5
    )
    housing: Housing
    shaft: Shaft
    grease_fill_fraction: Number = quantity(
        "share of the free volume holding grease", unit="1", source="SKF super-precision bearings catalogue: 10-30 %", ge=0.05, le=0.5, default=0.2
    )
    cavity_air_flow_m3_s: Number = quantity(
        "oil-air stream through the bearing", unit="m^3/s", source="oil-air units: 5-50 l/min", ge=1e-5, le=2e-3, default=1.7e-4
    )
    oil_flow_m3_s: Number = quantity(
        "jet oil flow through the bearing (0: none)", unit="m^3/s", source="jet lubrication up to 60 l/min", ge=0.0, le=1e-3, default=0.0
    )
    oil_inlet_temperature_c: Number | None = quantity(
        "jet oil inlet temperature (absent: the ambient)", unit="degC", source="oils in service", ge=0.0, le=200.0, default=None
    )


class BearingFile(FileSection):
    """A bearing file (``config/bearings/*.yaml``)."""

    bearing: BearingIdentity
    geometry: Geometry
    cage: Cage
    materials: Materials
    installation: Installation = Installation()
    inner_ring: InnerRing
    contact: Contact
    friction: Friction
    lubricant: BearingLubricant
    resistances: Resistances
    integration: Integration
    thermal: Thermal | None = None

    @model_validator(mode="after")
    def _cage_around_the_balls(self) -> Self:
        dw, dm, cage = self.geometry.ball_diameter_m, self.geometry.pitch_diameter_m, self.cage
        check_number(cage.pocket_diameter_m, "", "cage.pocket_diameter_m", gt=dw, lt=2.0 * dw)
        check_number(cage.inner_diameter_m, "", "cage.inner_diameter_m", gt=0.0, lt=dm)
        check_number(cage.outer_diameter_m, "", "cage.outer_diameter_m", gt=dm, lt=2.0 * dm)
        check_number(cage.width_m, "", "cage.width_m", gt=cage.pocket_diameter_m, lt=0.2)
        if self.friction.model == "rheology" and self.lubricant.file is None:
            raise field_error("friction.model", "rheology needs a lubricant file (lubricant.file)")
        if self.resistances.ball_set_resistance_n > 0.0 and not self.lubricant.dry:
            raise field_error(
                "resistances.ball_set_resistance_n",
                "is the dry model's stand-in for its unstated resistances; a lubricated bearing has its own (set lubricant.dry: true or 0)",
            )
        return self


def calibratable_keys(model: type[BaseModel], prefix: str = "") -> tuple[str, ...]:
    """The dotted keys of ``model`` and the sections nested in it whose :func:`quantity` a
    calibration file may set (``calibratable=True``), in the file's order."""
    keys: list[str] = []
    for name, info in model.model_fields.items():
        if isinstance(info.json_schema_extra, dict) and info.json_schema_extra.get("calibratable"):
            keys.append(prefix + name)
        for kind in (info.annotation, *get_args(info.annotation)):
            if isinstance(kind, type) and issubclass(kind, BaseModel):
                keys.extend(calibratable_keys(kind, f"{prefix}{name}."))
    return tuple(keys)


CALIBRATABLE_KEYS: tuple[str, ...] = calibratable_keys(BearingFile)
"""The bearing-file keys a calibration file may set (``section.key``); the engine's names for
them: :data:`~.parameters.CALIBRATABLE`."""


# ---------------------------------------------------------------------------------------------
# The lubricant file (config/lubricants/*.yaml)
# ---------------------------------------------------------------------------------------------
class LubricantIdentity(FileSection):
    """``lubricant:``"""

    name: Text = Field(description="label")
    kind: Annotated[str, one_of(KINDS)] = Field(description="lubrication mode (KINDS)")


class BaseOil(FileSection):
    """``base_oil:``; the viscosity at 100 degC lies below the one at 40 degC."""

    viscosity_40c_mm2_s: Number = quantity("kinematic viscosity at 40 degC", unit="mm^2/s", source="ISO VG 2-3200 (ISO 3448)", gt=1.0, lt=5000.0)
    viscosity_100c_mm2_s: Number = quantity("kinematic viscosity at 100 degC (below the 40 degC one)", unit="mm^2/s", source="ISO VG 2-3200 (ISO 3448)", gt=0.5)
    density_15c_kg_m3: Number = quantity("density at 15 degC", unit="kg/m^3", source="mineral, synthetic and ester oils", gt=600.0, lt=2000.0)
    pressure_viscosity_coefficient_1_pa: Number = quantity(
        "Barus pressure-viscosity coefficient alpha", unit="1/Pa", source="Hamrock, Fundamentals of Fluid Film Lubrication: 5-40 1/GPa", ge=5e-9, le=4e-8
    )
    thermal_conductivity_w_m_k: Number = quantity("thermal conductivity", unit="W/(m K)", source="lubricating oils 0.1-0.2", ge=0.08, le=0.3)
    specific_heat_j_kg_k: Number = quantity(
        "specific heat of the lubricant",
        unit="J/(kg K)",
        source="mineral and ester oils and their greases at 20-150 degC",
        ge=1600.0,
        le=2400.0,
        default=1900.0,
    )

    @model_validator(mode="after")
    def _thinner_when_hot(self) -> Self:
        check_number(self.viscosity_100c_mm2_s, "", "viscosity_100c_mm2_s", gt=0.5, lt=self.viscosity_40c_mm2_s)
        return self


class Film(FileSection):
    """``film:`` (rheology of the EHL film)."""

    eyring_stress_pa: Number = quantity("Eyring stress tau_0", unit="Pa", source="EHL films of mineral and ester oils", ge=1e5, le=5e7)
    limiting_shear_coefficient: Number = quantity("limiting shear stress over pressure", unit="1", source="Bair and Winer: 0.03-0.1", ge=0.01, le=0.15)
    shear_modulus_pa: Number = quantity("elastic shear modulus of the film (Maxwell)", unit="Pa", source="EHL films", ge=1e7, le=1e10)


class Supply(FileSection):
    """``supply:``"""

    meniscus_ratio: Number = quantity(
        "inlet meniscus distance over the Hertz half-width plus one", unit="1", source="Hamrock and Dowson (1977)", gt=1.0, le=1e3
    )
    oil_volume_fraction: Number | None = quantity(
        "oil share of the oil-air mixture (oil_air only)", unit="1", source="a fraction", ge=0.0, le=1.0, default=None
    )
    fill_fraction: Number = quantity("share of the cavity the balls and cage shear", unit="1", source="a fraction", ge=0.0, le=1.0)


class Grease(FileSection):
    """``grease:`` (Herschel-Bulkley rheology tau = tau_y + K gamma_dot^n)."""

    yield_stress_pa: Number = quantity("yield stress tau_y", unit="Pa", source="rheometer data of NLGI 1-3 greases", ge=0.0, le=5e3)
    consistency_pa_sn: Number = quantity("consistency K", unit="Pa s^n", source="rheometer data of NLGI 1-3 greases", gt=0.0, le=1e3)
    flow_index: Number = quantity("flow index n (shear thinning below 1)", unit="1", source="rheometer data of NLGI 1-3 greases", gt=0.0, le=1.0)
    yield_stress_temperature_coefficient_1_k: Number = quantity(
        "c of tau_y(T) = tau_y(T_ref) exp(-c (T - T_ref))", unit="1/K", source="lithium greases between 25 and 75 degC", ge=0.0, le=0.05, default=0.0
    )
    consistency_temperature_exponent: Number = quantity(
        "x of K(T) = K(T_ref) (eta(T) / eta(T_ref))^x", unit="1", source="between the thickener alone (0) and the base oil (1)", ge=0.0, le=1.0, default=1.0
    )


class RunningIn(FileSection):
    """``running_in:`` of a grease file: the first-order law of its fill against running time,
    fill(t) = f_end + (f_0 - f_end) exp(-t / tau) (:mod:`.running_in`), f_0 the supply's fill."""

    time_constant_s: Number = quantity(
        "time constant tau of the fill's fall to its channelled value", unit="s", source="running-in of greased bearings: minutes to a day", ge=60.0, le=86400.0
    )
    channelled_fill_fraction: Number = quantity("fill once channelled, f_end (at most the supply's fill)", unit="1", source="a fraction", ge=0.0, le=1.0)


class LubricantFile(FileSection):
    """A lubricant file (``config/lubricants/*.yaml``): an oil-air lubricant states its oil share,
    a grease its rheology (and may state its running-in)."""

    lubricant: LubricantIdentity
    base_oil: BaseOil
    film: Film
    supply: Supply
    grease: Grease | None = None
    running_in: RunningIn | None = None

    @model_validator(mode="after")
    def _what_the_kind_needs(self) -> Self:
        if self.lubricant.kind == "oil_air" and self.supply.oil_volume_fraction is None:
            raise field_error("supply.oil_volume_fraction", "missing (required)")
        if self.lubricant.kind == "grease" and self.grease is None:
            raise field_error("grease", "missing (required)")
        if self.running_in is not None:
            if self.lubricant.kind != "grease":
                raise field_error("running_in", f"only a grease runs in, this lubricant is {self.lubricant.kind}")
            check_number(self.running_in.channelled_fill_fraction, "", "running_in.channelled_fill_fraction", ge=0.0, le=self.supply.fill_fraction)
        return self


# ---------------------------------------------------------------------------------------------
# The calibration file (config/calibration/*.yaml)
# ---------------------------------------------------------------------------------------------
def _calibrated_values(raw: object) -> dict[str, float]:
    """``parameters:`` of a calibration file: ``section.key`` -> a number (>= 0) or a
    :class:`~bearing_rig_sim.settings_model.StatedQuantity`; only the keys of :data:`CALIBRATABLE_KEYS`."""
    if not isinstance(raw, Mapping):
        raise ValueError(f"must be a mapping, got {type(raw).__name__}")
    allowed = sorted(CALIBRATABLE_KEYS)
    values: dict[str, float] = {}
    for name, entry in raw.items():
        if name not in allowed:
            raise field_error(str(name), f"not a calibratable parameter; allowed: {', '.join(allowed)}")
        if isinstance(entry, Mapping):
            values[name] = validate_mapping(StatedQuantity, entry, "", name).value
        else:
            values[name] = check_number(entry, "", name, ge=0.0)
    return values


class Provenance(FileSection):
    """``calibration:`` (written by ``bearing-rig calibrate``: data, fitted parameters, rows)."""

    model_config = ConfigDict(frozen=True, extra="allow")

    rms_slip_pct: Number | None = quantity("RMS of the fit's slip residuals", unit="pp", source="a spread", ge=0.0, default=None)
    thermal: Flag = Field(default=False, description="fitted through the thermal steady states")


class CalibrationFile(FileSection):
    """A calibration file: provenance, the calibrated values laid over a bearing file
    (:func:`~.parameters.overlay_calibration`) and the fit's uncertainty."""

    calibration: Provenance = Provenance()
    parameters: Annotated[dict[str, float], BeforeValidator(_calibrated_values)] = Field(description="section.key -> value")
    uncertainty: dict[str, Any] | None = Field(None, description="the fit's uncertainty (studies.uncertainty.FitUncertainty)")
