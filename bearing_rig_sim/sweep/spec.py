"""Sweep specifications: which operating points and parameter values to run (validated YAML).

A spec names its axes with their unit in the name, as every configuration file does::

    sweep:
      name: paper_load_grid
      calibration: shipped          # shipped (config/calibration) | none | a calibration file
      continuation: true            # also follow each load row upwards from its lowest load
    grid:                           # every combination of these values
      inner_ring_speed_rpm: [1000, 3000, 5000, 7000, 9000]
      axial_load_n: {from: 50, to: 700, step: 10}
    samples:                        # optional: random values, each sample crossed with the grid
      method: sobol                 # sobol | latin_hypercube (scipy.stats.qmc)
      count: 16
      seed: 1
      ranges:
        ball_diameter_m: [0.006297, 0.006303]

An axis is either ``inner_ring_speed_rpm`` (steady points at constant speed) or
``inner_ring_acceleration_rad_s2`` (transient points: a run-up from rest), always with
``axial_load_n``. Either kind may add a combined load: ``radial_load_n`` (along the
bearing's x axis) and ``moment_n_m`` (M_x, the moment in the radial load's plane, counted as
dynamics/quasi_static.py counts it; with this axis the inner ring's tilts are free, without it
they are held). A steady point's steady state is then periodic at the ball-pass frequency and is
averaged over whole periods (:meth:`~bearing_rig_sim.dynamics.steady.SteadySolver.periodic`);
a transient point runs up from rest under the combined load.
Any other axis of :data:`AXES` changes one bearing parameter. The speed, the acceleration and the
axial load are at most the shipped rig file's limits (``spindle.max_speed_rad_s``,
``spindle.max_acceleration_rad_s2``, ``loading_chain.max_setpoint_n``). Errors name the file and
the key (``grid.axial_load_n[0]: must be >= 1.0, got -5``).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Mapping
from typing import Annotated, Any, Self

import numpy as np
from pydantic import BeforeValidator, ConfigDict, Field, model_validator

from bearing_rig_sim.config import BEARING_MODELS, RPM_TO_RAD_S, check_number, read_mapping
from bearing_rig_sim.dynamics.engine import MIN_AXIAL_LOAD
from bearing_rig_sim.settings_model import FileSection, Flag, Integer, Number, Text, check_within_rig, field_error, one_of, quantity, validate_mapping


@dataclass(frozen=True)
class AxisDefinition:
    """One quantity a sweep may vary.

    Attributes:
        name: the key in a spec, its unit in the name.
        parameter: the :class:`~bearing_rig_sim.dynamics.BearingParameters` field it sets,
            ``lubricant.<field>`` for a rheology field of the bearing's lubricant file
            (``None`` for the operating conditions: speed, acceleration, load).
        low / high: the allowed range (inclusive), in the axis's unit.
        description: what it is, with its unit.
        rig_limit: the dotted key of the rig file holding a tighter upper bound (an operating
            condition the bench sets: speed, acceleration, axial load), or None.
        unit_in_si: the axis's unit in SI (for comparing with ``rig_limit``).
    """

    name: str
    parameter: str | None
    low: float
    high: float
    description: str
    rig_limit: str | None = None
    unit_in_si: float = 1.0

    def check(self, value: float, key: str) -> float:
        """``value`` at ``key`` (relative to the spec's mapping) within the axis's range and the
        rig's limit. Raises ConfigError naming ``key``, the bound and where it is written."""
        check_number(value, "", key, ge=self.low, le=self.high)
        if self.rig_limit is not None:
            check_within_rig(value, "", key, self.rig_limit, unit_in_si=self.unit_in_si)
        return value


SPEED_AXIS = "inner_ring_speed_rpm"
LOAD_AXIS = "axial_load_n"
ACCELERATION_AXIS = "inner_ring_acceleration_rad_s2"
RADIAL_AXIS = "radial_load_n"
MOMENT_AXIS = "moment_n_m"

AXES: dict[str, AxisDefinition] = {
    a.name: a
    for a in (
        AxisDefinition(SPEED_AXIS, None, 1.0, 60000.0, "inner-ring speed, rpm (steady points)", "spindle.max_speed_rad_s", RPM_TO_RAD_S),
        AxisDefinition(LOAD_AXIS, None, MIN_AXIAL_LOAD, 20000.0, "axial load on the inner ring, N", "loading_chain.max_setpoint_n"),
        AxisDefinition(
            ACCELERATION_AXIS, None, 0.1, 10000.0, "inner-ring acceleration from rest, rad/s^2 (transient points)", "spindle.max_acceleration_rad_s2"
        ),
        AxisDefinition(RADIAL_AXIS, None, 0.0, 20000.0, "radial load on the inner ring along x, N (steady and transient)"),
        AxisDefinition(MOMENT_AXIS, None, -1000.0, 1000.0, "moment M_x on the inner ring in the radial load's plane, N m; tilts free (steady and transient)"),
        # lubricant
        AxisDefinition("oil_viscosity_pa_s", "oil_viscosity", 1e-4, 10.0, "dynamic viscosity of the oil, Pa s"),
        AxisDefinition("oil_volume_fraction", "oil_volume_fraction", 0.0, 1.0, "oil share of the oil-air mixture, 1"),
        AxisDefinition("yield_stress_pa", "lubricant.yield_stress", 0.0, 1e5, "Herschel-Bulkley yield stress of the grease, Pa"),
        AxisDefinition("consistency_pa_sn", "lubricant.consistency", 0.0, 1e4, "Herschel-Bulkley consistency of the grease, Pa s^n"),
        AxisDefinition("fill_fraction", "lubricant.fill_fraction", 0.0, 1.0, "share of the swept volume holding grease, 1"),
        AxisDefinition("eyring_stress_pa", "lubricant.eyring_stress", 1e5, 1e9, "Eyring stress of the base oil, Pa"),
        AxisDefinition(
            "consistency_temperature_exponent", "lubricant.consistency_temperature_exponent", 0.0, 1.0, "x of the grease's K(T) = K_ref (eta/eta_ref)^x, 1"
        ),
        # thermal data (a spec with thermal: true)
        AxisDefinition("frame_conductance_w_k", "thermal.frame_conductance", 0.0, 5.0, "the housing's conduction to the bench frame, W/K"),
        # geometry tolerances
        AxisDefinition("ball_diameter_m", "ball_diameter", 1e-4, 0.1, "ball diameter Dw, m"),
        AxisDefinition("inner_groove_curvature_ratio", "inner_curvature_ratio", 0.5001, 0.5999, "inner groove radius / Dw, 1"),
        AxisDefinition("outer_groove_curvature_ratio", "outer_curvature_ratio", 0.5001, 0.5999, "outer groove radius / Dw, 1"),
        AxisDefinition("pocket_diameter_m", "pocket_diameter", 1e-4, 0.2, "cage pocket diameter (pocket clearance), m"),
        AxisDefinition("land_radial_clearance_m", "land_clearance", 1e-7, 0.005, "cage land radial clearance, m"),
        # calibration parameters
        AxisDefinition("ball_drag_scale", "ball_drag_scale", 0.0, 1e6, "multiplier on the ball drag, 1"),
        AxisDefinition("cage_land_viscous_scale", "cage_land_viscous_scale", 0.0, 1e6, "multiplier on the cage land Petroff torque, 1"),
        AxisDefinition("cage_land_boundary_torque_scale", "cage_land_boundary_torque_scale", 0.0, 1e6, "multiplier on the cage land boundary torque, 1"),
        AxisDefinition("rolling_hysteresis_factor", "rolling_hysteresis_factor", 0.0, 0.5, "elastic hysteresis factor alpha_h, 1"),
        AxisDefinition("stiction_velocity_m_s", "stiction_velocity", 1e-4, 10.0, "friction law stiction velocity v_s, m/s"),
        AxisDefinition("static_friction_coefficient", "static_friction", 0.0, 1.0, "friction law static coefficient mu_s, 1"),
    )
}
"""Every axis a spec may use, by name."""

SAMPLE_METHODS = ("sobol", "latin_hypercube")
CALIBRATION_CHOICES = ("shipped", "none")


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep specification.

    Attributes:
        name: the sweep's name.
        source: the file it was read from.
        grid: axis name -> its values (grid axes, in the spec's order).
        samples: rows of random values (axis name -> value), crossed with the grid; empty if
            the spec has no ``samples`` section.
        bearing: bearing file (``None``: the shipped H7006C).
        calibration: ``"shipped"`` (the model's own), ``"none"`` or a calibration file path.
        continuation: whether each load row is also followed upwards from its lowest load.
        transient_duration: s, simulated duration of a transient (acceleration) point.
        skid_slip_pct: slip (%) above which a point counts as skidding, for the map.
        minimum_load_factor_kn: SKF minimum axial load factor A, kN (F_am = A (n/1000)^2).
        document: the parsed spec (canonical form of its inputs), for the spec hash.
        model: the named bearing model (:data:`~bearing_rig_sim.config.BEARING_MODELS`).
        thermal: each steady point is the coupled thermal steady state (the bearing file's
            ``thermal:`` section; axes ``thermal.*`` change its data).
    """

    name: str
    source: str
    grid: dict[str, tuple[float, ...]]
    samples: tuple[dict[str, float], ...]
    bearing: str | None
    calibration: str
    continuation: bool
    transient_duration: float
    skid_slip_pct: float
    minimum_load_factor_kn: float
    document: dict[str, Any] = field(repr=False)
    model: str = "bench"
    thermal: bool = False

    @property
    def transient(self) -> bool:
        """True for a sweep of run-ups under acceleration, False for steady points."""
        return ACCELERATION_AXIS in self.grid or any(ACCELERATION_AXIS in s for s in self.samples)

    @property
    def axis_names(self) -> tuple[str, ...]:
        """Every axis of a point: the grid's, then the samples'."""
        names = list(self.grid)
        for row in self.samples[:1]:
            names.extend(k for k in row if k not in names)
        return tuple(names)

    @property
    def spec_hash(self) -> str:
        """sha256 (16 hex digits) of the spec's canonical inputs."""
        return hashlib.sha256(json.dumps(self.document, sort_keys=True).encode()).hexdigest()[:16]

    def points(self) -> list[dict[str, float]]:
        """Every point: the grid's combinations (the last axis varying fastest), each crossed
        with every sample row."""
        names = list(self.grid)
        combos = [dict(zip(names, values)) for values in itertools.product(*(self.grid[n] for n in names))]
        if not self.samples:
            return combos
        return [{**c, **s} for c in combos for s in self.samples]


def _definition(name: str) -> AxisDefinition:
    if name not in AXES:
        raise field_error(name, f"unknown axis; known axes: {', '.join(AXES)}")
    return AXES[name]


class AxisRange(FileSection):
    """A grid axis as ``{from, to, step}``: both ends included when ``to`` is a whole number of
    steps from ``from``."""

    model_config = ConfigDict(frozen=True, extra="forbid", populate_by_name=True)

    start: Number = Field(alias="from", description="first value, in the axis's unit")
    to: Number = Field(description="last value at most, in the axis's unit")
    step: Number = Field(gt=0.0, description="step, in the axis's unit")

    @model_validator(mode="after")
    def _not_empty(self) -> Self:
        if self.to < self.start:
            raise field_error("to", f"must be >= from ({self.start}), got {self.to}: the range is empty")
        return self

    def values(self) -> list[float]:
        """The values, rounded to 12 decimals (no 0.30000000000000004)."""
        count = int(math.floor((self.to - self.start) / self.step + 1e-9)) + 1
        return [float(round(self.start + i * self.step, 12)) for i in range(count)]


def axis_values(name: str, raw: object) -> tuple[float, ...]:
    """The values of grid axis ``name``: a list, or ``{from, to, step}`` (:class:`AxisRange`),
    each checked against the axis's range.

    Raises:
        ConfigError: naming the key relative to ``grid`` (:func:`~bearing_rig_sim.settings_model.field_error`).
    """
    definition = _definition(name)
    if isinstance(raw, Mapping):
        values = validate_mapping(AxisRange, raw, "", name).values()
    elif isinstance(raw, list):
        if not raw:
            raise field_error(name, "must not be empty")
        values = [check_number(v, "", f"{name}[{i}]") for i, v in enumerate(raw)]
    else:
        raise field_error(name, f"must be a list of values or a mapping {{from, to, step}}, got {raw!r}")
    for i, v in enumerate(values):
        definition.check(v, f"{name}[{i}]")
    if len(set(values)) != len(values):
        raise field_error(name, "has repeated values")
    return tuple(values)


def _grid(raw: object) -> dict[str, tuple[float, ...]]:
    if not isinstance(raw, Mapping):
        raise ValueError(f"must be a mapping, got {type(raw).__name__}")
    if not raw:
        raise field_error("", "must name at least one axis")
    return {str(name): axis_values(str(name), values) for name, values in raw.items()}


def _ranges(raw: object) -> dict[str, tuple[float, float]]:
    if not isinstance(raw, Mapping):
        raise ValueError(f"must be a mapping, got {type(raw).__name__}")
    if not raw:
        raise field_error("", "must name at least one axis")
    bounds: dict[str, tuple[float, float]] = {}
    for name, lo_hi in raw.items():
        definition = _definition(str(name))
        if not isinstance(lo_hi, list) or len(lo_hi) != 2:
            raise field_error(str(name), f"must be [low, high], got {lo_hi!r}")
        lo, hi = (definition.check(check_number(v, "", f"{name}[{i}]"), f"{name}[{i}]") for i, v in enumerate(lo_hi))
        if not hi > lo:
            raise field_error(str(name), f"high must be > low, got [{lo}, {hi}]: the range is empty")
        bounds[str(name)] = (lo, hi)
    return bounds


class Samples(FileSection):
    """``samples:``: random values of some axes, each row crossed with the grid."""

    method: Annotated[str, one_of(SAMPLE_METHODS)] = Field(description="sequence (scipy.stats.qmc)")
    count: Integer = Field(ge=1, le=1_000_000, description="number of rows")
    seed: Integer = Field(0, ge=0, description="seed of the sequence")
    ranges: Annotated[dict[str, tuple[float, float]], BeforeValidator(_ranges)] = Field(description="axis -> [low, high]")

    def draw(self) -> tuple[dict[str, float], ...]:
        """The rows: the unit-cube sequence scaled to the ranges."""
        from scipy.stats import qmc

        names = list(self.ranges)
        engine = qmc.Sobol(d=len(names), scramble=True, seed=self.seed) if self.method == "sobol" else qmc.LatinHypercube(d=len(names), seed=self.seed)
        unit = engine.random(self.count)
        scaled = qmc.scale(unit, [self.ranges[n][0] for n in names], [self.ranges[n][1] for n in names])
        return tuple({n: float(v) for n, v in zip(names, row)} for row in np.atleast_2d(scaled))


class SweepHead(FileSection):
    """``sweep:``"""

    name: Text = Field(description="the sweep's name")
    description: Text | None = Field(None, description="what the sweep is for")
    model: Annotated[str, one_of(BEARING_MODELS)] = Field(
        "bench", description="the named bearing model: bench (the bench twin) or paper (the paper's own model)"
    )
    bearing: Text | None = Field(None, description="bearing file (absent: the shipped H7006C; bench model only)")
    calibration: Text = Field(
        "shipped", description="shipped (the model's own; the bench twin's isothermal one), none, a named calibration (coupled, isothermal) or a file"
    )
    thermal: Flag = Field(False, description="each steady point at the coupled thermal steady state")
    continuation: Flag = Field(False, description="also follow each load row upwards from its lowest load")
    transient_duration_s: Number = quantity(
        "simulated duration of a transient (acceleration) point", unit="s", source="run-ups of the paper's rig last seconds", gt=0.0, le=60.0, default=3.0
    )


class MapView(FileSection):
    """``map:`` (the operating map's view)."""

    skid_slip_pct: Number = quantity("slip above which a point counts as skidding", unit="%", source="a share below 100 %", gt=0.0, lt=100.0, default=20.0)
    minimum_load_factor_kn: Number = quantity(
        "SKF minimum axial load factor A, F_am = A (n/1000)^2", unit="kN", source="SKF rolling bearings catalogue, Minimum load", gt=0.0, lt=1.0, default=0.0025
    )


class SweepFile(FileSection):
    """A sweep specification as its file states it (see the module documentation)."""

    sweep: SweepHead
    grid: Annotated[dict[str, tuple[float, ...]], BeforeValidator(_grid)] = Field(description="axis -> its values")
    samples: Samples | None = None
    map: MapView = MapView()

    @model_validator(mode="after")
    def _axes_of_a_point(self) -> Self:
        sampled = set(self.samples.ranges) if self.samples is not None else set()
        for key in sampled & set(self.grid):
            raise field_error(f"samples.ranges.{key}", "is also a grid axis; give it in one place")
        names = set(self.grid) | sampled
        if LOAD_AXIS not in names:
            raise field_error("grid", f"must include {LOAD_AXIS} (in grid or samples)")
        if (SPEED_AXIS in names) == (ACCELERATION_AXIS in names):
            raise field_error("grid", f"must include exactly one of {SPEED_AXIS} (steady points) and {ACCELERATION_AXIS} (transient points)")
        for key in names:
            parameter = AXES[key].parameter
            if parameter is not None and parameter.startswith("thermal.") and (not self.sweep.thermal or ACCELERATION_AXIS in names):
                raise field_error(key, "changes the thermal data: needs sweep.thermal true and steady points")
        return self


def spec_from_mapping(data: Mapping[str, Any], source: str) -> SweepSpec:
    """Validate a parsed spec read from ``source``; errors name the file and the key."""
    doc = validate_mapping(SweepFile, data, source)
    head, view = doc.sweep, doc.map
    samples = doc.samples.draw() if doc.samples is not None else ()
    document = {
        "name": head.name,
        "bearing": head.bearing,
        "calibration": head.calibration,
        **({"model": head.model} if head.model != "bench" else {}),
        "continuation": head.continuation,
        "transient_duration_s": head.transient_duration_s,
        "grid": {k: list(v) for k, v in doc.grid.items()},
        "samples": [dict(s) for s in samples],
        **({"thermal": True} if head.thermal else {}),
    }
    return SweepSpec(
        head.name, source, dict(doc.grid), samples, head.bearing, head.calibration, head.continuation, head.transient_duration_s,
        view.skid_slip_pct, view.minimum_load_factor_kn, document, head.model, head.thermal,
    )  # fmt: skip


def load_spec(path: str | Path) -> SweepSpec:
    """Read and validate a sweep spec (YAML).

    Raises:
        ConfigError: naming the file and the key.
    """
    return spec_from_mapping(read_mapping(path), str(path))
