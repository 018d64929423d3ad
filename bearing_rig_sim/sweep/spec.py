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
``axial_load_n``; any other axis of :data:`AXES` changes one bearing parameter. Errors name the
file and the key (``grid.axial_load_n[0]: must be >= 1.0, got -5``).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bearing_rig_sim.config import ConfigError, Section, check_number, load_yaml
from bearing_rig_sim.dynamics.engine import MIN_AXIAL_LOAD


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
    """

    name: str
    parameter: str | None
    low: float
    high: float
    description: str


SPEED_AXIS = "inner_ring_speed_rpm"
LOAD_AXIS = "axial_load_n"
ACCELERATION_AXIS = "inner_ring_acceleration_rad_s2"

AXES: dict[str, AxisDefinition] = {
    a.name: a
    for a in (
        AxisDefinition(SPEED_AXIS, None, 1.0, 60000.0, "inner-ring speed, rpm (steady points)"),
        AxisDefinition(LOAD_AXIS, None, MIN_AXIAL_LOAD, 20000.0, "axial load on the inner ring, N"),
        AxisDefinition(ACCELERATION_AXIS, None, 0.1, 10000.0, "inner-ring acceleration from rest, rad/s^2 (transient points)"),
        # lubricant
        AxisDefinition("oil_viscosity_pa_s", "oil_viscosity", 1e-4, 10.0, "dynamic viscosity of the oil, Pa s"),
        AxisDefinition("oil_volume_fraction", "oil_volume_fraction", 0.0, 1.0, "oil share of the oil-air mixture, 1"),
        AxisDefinition("yield_stress_pa", "lubricant.yield_stress", 0.0, 1e5, "Herschel-Bulkley yield stress of the grease, Pa"),
        AxisDefinition("consistency_pa_sn", "lubricant.consistency", 0.0, 1e4, "Herschel-Bulkley consistency of the grease, Pa s^n"),
        AxisDefinition("fill_fraction", "lubricant.fill_fraction", 0.0, 1.0, "share of the swept volume holding grease, 1"),
        AxisDefinition("eyring_stress_pa", "lubricant.eyring_stress", 1e5, 1e9, "Eyring stress of the base oil, Pa"),
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
        calibration: ``"shipped"``, ``"none"`` or a calibration file path.
        continuation: whether each load row is also followed upwards from its lowest load.
        transient_duration: s, simulated duration of a transient (acceleration) point.
        skid_slip_pct: slip (%) above which a point counts as skidding, for the map.
        minimum_load_factor_kn: SKF minimum axial load factor A, kN (F_am = A (n/1000)^2).
        document: the parsed spec (canonical form of its inputs), for the spec hash.
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


def axis_values(section: Section, name: str) -> tuple[float, ...]:
    """The values of grid axis ``name``: a list, or ``{from, to, step}`` (both ends included
    when ``to`` is a whole number of steps from ``from``), each checked against the axis's
    range."""
    definition = _definition(section, name)
    raw = section.data.get(name)
    path = section.key_path(name)
    if isinstance(raw, dict):
        rng = section.section(name)
        rng.reject_unknown(["from", "to", "step"])
        start = rng.number("from")
        stop = rng.number("to")
        step = rng.number("step", gt=0.0)
        if stop < start:
            raise rng.error("to", f"must be >= from ({start}), got {stop}: the range is empty")
        count = int(math.floor((stop - start) / step + 1e-9)) + 1
        values = [start + i * step for i in range(count)]
        values = [float(round(v, 12)) for v in values]
    elif isinstance(raw, list):
        if not raw:
            raise ConfigError(section.source, path, "must not be empty")
        values = [check_number(v, section.source, f"{path}[{i}]") for i, v in enumerate(raw)]
    else:
        raise ConfigError(section.source, path, f"must be a list of values or a mapping {{from, to, step}}, got {raw!r}")
    for i, v in enumerate(values):
        _check_in_range(definition, v, section.source, f"{path}[{i}]")
    if len(set(values)) != len(values):
        raise ConfigError(section.source, path, "has repeated values")
    return tuple(values)


def _definition(section: Section, name: str) -> AxisDefinition:
    if name not in AXES:
        raise section.error(name, f"unknown axis; known axes: {', '.join(AXES)}")
    return AXES[name]


def _check_in_range(definition: AxisDefinition, value: float, source: str, key: str) -> None:
    check_number(value, source, key, ge=definition.low, le=definition.high)


def _samples(section: Section) -> tuple[dict[str, float], ...]:
    from scipy.stats import qmc

    section.reject_unknown(["method", "count", "seed", "ranges"])
    method = section.choice("method", SAMPLE_METHODS)
    count = section.integer("count", ge=1, le=1_000_000)
    seed = section.integer("seed", ge=0, default=0)
    ranges = section.section("ranges")
    names = list(ranges.keys())
    if not names:
        raise section.error("ranges", "must name at least one axis")
    bounds = []
    for name in names:
        definition = _definition(ranges, name)
        lo_hi = ranges.number_list(name, min_len=2)
        if len(lo_hi) != 2:
            raise ranges.error(name, f"must be [low, high], got {ranges.data[name]!r}")
        lo, hi = lo_hi
        if not hi > lo:
            raise ranges.error(name, f"high must be > low, got [{lo}, {hi}]: the range is empty")
        _check_in_range(definition, lo, ranges.source, f"{ranges.key_path(name)}[0]")
        _check_in_range(definition, hi, ranges.source, f"{ranges.key_path(name)}[1]")
        bounds.append((lo, hi))
    engine = qmc.Sobol(d=len(names), scramble=True, seed=seed) if method == "sobol" else qmc.LatinHypercube(d=len(names), seed=seed)
    unit = engine.random(count)
    scaled = qmc.scale(unit, [b[0] for b in bounds], [b[1] for b in bounds])
    return tuple({n: float(v) for n, v in zip(names, row)} for row in np.atleast_2d(scaled))


def spec_from_section(doc: Section) -> SweepSpec:
    """Validate a parsed spec; errors name the file and the key."""
    doc.reject_unknown(["sweep", "grid", "samples", "map"])
    head = doc.section("sweep")
    head.reject_unknown(["name", "description", "bearing", "calibration", "continuation", "transient_duration_s"])
    name = head.string("name")
    bearing = head.string("bearing") if "bearing" in head and head.data["bearing"] is not None else None
    calibration = head.string("calibration", default="shipped")
    continuation = head.boolean("continuation", default=False)
    duration = head.number("transient_duration_s", gt=0.0, le=60.0, default=3.0)
    grid_section = doc.section("grid")
    if not list(grid_section.keys()):
        raise doc.error("grid", "must name at least one axis")
    grid = {str(k): axis_values(grid_section, str(k)) for k in grid_section.keys()}
    samples = _samples(doc.section("samples")) if "samples" in doc and doc.data["samples"] is not None else ()
    sampled = set(samples[0]) if samples else set()
    for key in sampled & set(grid):
        raise doc.section("samples").section("ranges").error(key, "is also a grid axis; give it in one place")
    names = set(grid) | sampled
    if LOAD_AXIS not in names:
        raise doc.error("grid", f"must include {LOAD_AXIS} (in grid or samples)")
    if (SPEED_AXIS in names) == (ACCELERATION_AXIS in names):
        raise doc.error("grid", f"must include exactly one of {SPEED_AXIS} (steady points) and {ACCELERATION_AXIS} (transient points)")
    view = doc.section("map", default={})
    view.reject_unknown(["skid_slip_pct", "minimum_load_factor_kn"])
    skid = view.number("skid_slip_pct", gt=0.0, lt=100.0, default=20.0)
    factor = view.number("minimum_load_factor_kn", gt=0.0, lt=1.0, default=0.0025)
    document = {
        "name": name,
        "bearing": bearing,
        "calibration": calibration,
        "continuation": continuation,
        "transient_duration_s": duration,
        "grid": {k: list(v) for k, v in grid.items()},
        "samples": [dict(s) for s in samples],
    }
    return SweepSpec(name, doc.source, grid, samples, bearing, calibration, continuation, duration, skid, factor, document)


def load_spec(path: str | Path) -> SweepSpec:
    """Read and validate a sweep spec (YAML).

    Raises:
        ConfigError: naming the file and the key.
    """
    return spec_from_section(load_yaml(path))
