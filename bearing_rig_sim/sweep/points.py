"""Evaluation of sweep points (what a worker runs; no Dask in here).

A :class:`SweepTask` is a small batch of points of one kind:

* ``rolling_start``: steady points, each solved from the engine's rolling start
  (:class:`~bearing_rig_sim.dynamics.steady.SteadySolver`, or integration with
  ``method="integrate"``);
* ``continuation``: one load row (same speed and parameters), solved upwards from its lowest
  load, each point from the previous one's steady state (the other branch where two exist);
* ``transient``: run-ups from rest under constant acceleration (time to stable by the paper's
  criterion, peak slip).

Each point becomes one row (:func:`evaluate`): a mapping of the columns of :data:`COLUMNS`.
Workers keep one solver per bearing parameter set
(:func:`~bearing_rig_sim.dynamics.steady.solver_for`), so the engine is built
and its compiled kernels are loaded once per worker process.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bearing_rig_sim.config import rad_s_to_rpm, rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.steady import (
    ORIGIN_CONTINUATION,
    ORIGIN_ROLLING_START,
    SKID_SLIP_PCT,
    STATE_ROLLING,
    STATE_SKID,
    SteadyState,
    solver_for,
)
from bearing_rig_sim.dynamics.quasi_static import LoadCase, QuasiStaticBearing
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.thermal.bearing import ThermalConfig
from bearing_rig_sim.sweep.spec import ACCELERATION_AXIS, AXES, LOAD_AXIS, MOMENT_AXIS, RADIAL_AXIS, SPEED_AXIS

KIND_ROLLING_START = ORIGIN_ROLLING_START
KIND_CONTINUATION = ORIGIN_CONTINUATION
KIND_TRANSIENT = "transient"

THERMAL_PREFIX = "thermal."
"""Axes whose parameter starts so set a field of the bearing's thermal data (:class:`ThermalConfig`)."""
LUBRICANT_PREFIX = "lubricant."
"""Axes whose parameter starts so set a rheology field of the bearing's lubricant file."""

SOLVE = "solve"
"""Steady points by the direct solver (default)."""
INTEGRATE = "integrate"
"""Steady points by time integration from the rolling start (the reference)."""

COLUMNS: dict[str, str] = {
    "point_key": "string",
    "branch": "string",
    "rpm": "float64",
    "axial_load_n": "float64",
    "cage_rpm": "float64",
    "slip_pct": "float64",
    "torque_n_m": "float64",
    "power_w": "float64",
    "film_min_inner_m": "float64",
    "film_min_outer_m": "float64",
    "state": "string",
    "method": "string",
    "newton_iterations": "int64",
    "stable": "bool_",
    "time_to_stable_s": "float64",
    "peak_slip_pct": "float64",
    "ball_load_max_n": "float64",
    "loaded_balls": "int64",
    "cage_whirl_radius_um": "float64",
    "cage_whirl_frequency_hz": "float64",
    "cage_whirl_ratio": "float64",
    "cage_whirl_reason": "string",
    "lubricant_temperature_c": "float64",
    "outer_ring_temperature_c": "float64",
    "error": "string",
}
"""Result columns (besides one float64 column per axis) and their Arrow types. ``branch`` is
how the point was reached (``rolling_start``, ``continuation`` or ``transient``); ``state`` is
``rolling`` or ``skid``; ``ball_load_max_n`` and ``loaded_balls`` are the quasi-static load
distribution at the point's speed (dynamics/quasi_static.py, as ``predict --radial-load``
gives it) on the steady points of a spec with a ``radial_load_n`` or ``moment_n_m`` axis
(NaN and 0 elsewhere); on such a spec's transient points ``ball_load_max_n`` is the engine's
own at the run's end (the largest contact load of any ball) and ``loaded_balls`` 0; ``cage_whirl_radius_um`` (the cage centre's distance from the axis at the window's
end), ``cage_whirl_frequency_hz`` (the centre's orbit about the axis, > 0 in the cage's
direction) and ``cage_whirl_ratio`` (over the cage's rotation frequency) are those of the
periodic steady state of the steady points under a combined load, as ``predict
--radial-load`` gives them (NaN elsewhere, and frequency and ratio NaN with
``cage_whirl_reason`` when the centre does not orbit:
:func:`~bearing_rig_sim.dynamics.steady.cage_whirl`); ``error`` is empty unless the point could
not be computed."""


@dataclass(frozen=True)
class SweepTask:
    """A batch of points for one worker.

    Attributes:
        task_id: unique within the sweep (used as the Dask key).
        kind: :data:`KIND_ROLLING_START`, :data:`KIND_CONTINUATION` or :data:`KIND_TRANSIENT`.
        params: the bearing parameters before the points' own parameter axes.
        points: each an axis name -> value mapping (a continuation row sorted by load).
        keys: the points' keys (:func:`point_key`), in the same order.
        wanted: which of the points to return (a continuation row is solved whole, but only
            its missing points are returned).
        method: :data:`SOLVE` or :data:`INTEGRATE`.
        transient_duration: s, for transient points.
        thermal: the bearing's thermal data: each steady point is the coupled thermal steady
            state (``thermal.*`` axes change these data), None: isothermal.
    """

    task_id: str
    kind: str
    params: BearingParameters
    points: tuple[dict[str, float], ...]
    keys: tuple[str, ...]
    wanted: frozenset[str]
    method: str = SOLVE
    transient_duration: float = 3.0
    thermal: ThermalConfig | None = None


def point_key(point: dict[str, float], branch: str) -> str:
    """A stable identifier of a point and its branch (16 hex digits)."""
    doc = {"branch": branch, **{k: float(f"{v:.12g}") for k, v in sorted(point.items())}}
    return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:16]


def parameters_for(base: BearingParameters, point: dict[str, float]) -> BearingParameters:
    """``base`` with the point's parameter axes applied."""
    changes: dict[str, object] = {}
    rheology: dict[str, float] = {}
    for name, value in point.items():
        field = AXES[name].parameter
        if field is not None and field.startswith(THERMAL_PREFIX):
            continue  # the thermal data's (thermal_for)
        if field is not None and field.startswith(LUBRICANT_PREFIX):
            rheology[field[len(LUBRICANT_PREFIX) :]] = value
        elif field is not None:
            changes[field] = value
    params = base.replace(**changes) if changes else base
    return params.with_lubricant(**rheology) if rheology else params


def thermal_for(base: ThermalConfig, point: dict[str, float]) -> ThermalConfig:
    """``base`` with the point's thermal axes applied."""
    changes: dict[str, Any] = {f[len(THERMAL_PREFIX) :]: v for n, v in point.items() if (f := AXES[n].parameter) is not None and f.startswith(THERMAL_PREFIX)}
    return dataclasses.replace(base, **changes) if changes else base


def evaluate(task: SweepTask) -> list[dict[str, Any]]:
    """Compute the task's wanted points; one row each (see :data:`COLUMNS`)."""
    if task.kind == KIND_TRANSIENT:
        return [_transient_row(task, p, k) for p, k in zip(task.points, task.keys) if k in task.wanted]
    if task.kind == KIND_CONTINUATION:
        return _continuation_rows(task)
    return [_steady_row(task, p, k) for p, k in zip(task.points, task.keys) if k in task.wanted]


def _base_row(point: dict[str, float], key: str, branch: str) -> dict[str, Any]:
    row: dict[str, Any] = {
        "point_key": key,
        "branch": branch,
        "rpm": float(point.get(SPEED_AXIS, math.nan)),
        "axial_load_n": float(point[LOAD_AXIS]),
        "cage_rpm": math.nan,
        "slip_pct": math.nan,
        "torque_n_m": math.nan,
        "power_w": math.nan,
        "film_min_inner_m": math.nan,
        "film_min_outer_m": math.nan,
        "state": "",
        "method": "",
        "newton_iterations": 0,
        "stable": False,
        "time_to_stable_s": math.nan,
        "peak_slip_pct": math.nan,
        "ball_load_max_n": math.nan,
        "loaded_balls": 0,
        "cage_whirl_radius_um": math.nan,
        "cage_whirl_frequency_hz": math.nan,
        "cage_whirl_ratio": math.nan,
        "cage_whirl_reason": "",
        "lubricant_temperature_c": math.nan,
        "outer_ring_temperature_c": math.nan,
        "error": "",
    }
    row.update({k: float(v) for k, v in point.items()})
    return row


def _fill(row: dict[str, Any], result: SteadyState) -> dict[str, Any]:
    row.update(
        cage_rpm=rad_s_to_rpm(result.cage_speed),
        slip_pct=result.slip_pct,
        torque_n_m=result.friction_torque,
        power_w=result.power_loss,
        film_min_inner_m=result.film_min_inner,
        film_min_outer_m=result.film_min_outer,
        state=result.state,
        method=result.method,
        newton_iterations=result.iterations,
        stable=result.stable,
    )
    return row


def combined_load(point: dict[str, float]) -> tuple[float, tuple[float, float] | None] | None:
    """The point's radial load (N, along x) and moment ((M_x, 0) N m, tilts free; None: held),
    or None for a purely axial point."""
    if RADIAL_AXIS not in point and MOMENT_AXIS not in point:
        return None
    moment = (float(point[MOMENT_AXIS]), 0.0) if MOMENT_AXIS in point else None
    return float(point.get(RADIAL_AXIS, 0.0)), moment


def _steady_row(task: SweepTask, point: dict[str, float], key: str) -> dict[str, Any]:
    row = _base_row(point, key, KIND_ROLLING_START)
    try:
        solver = solver_for(parameters_for(task.params, point))
        omega = rpm_to_rad_s(point[SPEED_AXIS])
        combined = combined_load(point)
        if task.thermal is not None and combined is None:
            from bearing_rig_sim.thermal.coupling import thermal_steady_state

            ts = thermal_steady_state(solver.params, thermal_for(task.thermal, point), omega, point[LOAD_AXIS])
            row.update(lubricant_temperature_c=ts.temperatures["lubricant"], outer_ring_temperature_c=ts.temperatures["outer_ring"])
            return _fill(row, ts.point)
        if combined is not None and (combined[0] > 0.0 or combined[1] is not None):
            # periodic at the ball-pass frequency: integrated and averaged over whole periods (either method)
            result = solver.periodic(omega, point[LOAD_AXIS], combined[0], moment=combined[1])
            whirl = solver.last_whirl
            row["cage_whirl_radius_um"] = solver.engine.cage_whirl_radius * 1e6
            if whirl is not None:
                row.update(
                    cage_whirl_frequency_hz=math.nan if whirl.frequency is None else whirl.frequency,
                    cage_whirl_ratio=math.nan if whirl.ratio is None else whirl.ratio,
                    cage_whirl_reason=whirl.reason or "",
                )
        elif task.method == INTEGRATE:
            result = solver.integrate(omega, point[LOAD_AXIS])
        else:
            result = solver.solve(omega, point[LOAD_AXIS])
        if combined is not None:
            case = LoadCase(point[LOAD_AXIS], combined[0], combined[1], inner_ring_speed=omega)
            distribution = QuasiStaticBearing(solver.params).solve(case)
            row.update(ball_load_max_n=distribution.ball_load_max, loaded_balls=distribution.loaded_balls)
    except (RigError, ValueError, ArithmeticError) as exc:
        row["error"] = str(exc) or type(exc).__name__
        return row
    return _fill(row, result)


def _continuation_rows(task: SweepTask) -> list[dict[str, Any]]:
    rows: list[dict[str, Any]] = []
    previous: SteadyState | None = None
    for point, key in zip(task.points, task.keys):
        row = _base_row(point, key, KIND_CONTINUATION)
        try:
            solver = solver_for(parameters_for(task.params, point))
            previous = solver.solve(rpm_to_rad_s(point[SPEED_AXIS]), point[LOAD_AXIS], previous)
            _fill(row, previous)
        except (RigError, ValueError, ArithmeticError) as exc:
            row["error"] = str(exc) or type(exc).__name__
            previous = None
        if key in task.wanted:
            rows.append(row)
    return rows


def _transient_row(task: SweepTask, point: dict[str, float], key: str) -> dict[str, Any]:
    from bearing_rig_sim.analysis.gaussian import fit_gaussians
    from bearing_rig_sim.analysis.stability import K2_TIME, stable_onset
    from bearing_rig_sim.studies.experiments import acceleration_run

    row = _base_row(point, key, KIND_TRANSIENT)
    try:
        params = parameters_for(task.params, point)
        combined = combined_load(point)
        radial, moment = combined if combined is not None else (0.0, None)
        series = acceleration_run(params, point[ACCELERATION_AXIS], point[LOAD_AXIS], task.transient_duration, radial_load=radial, moment=moment)
        if len(series.slip_pct) < 4:
            raise RigError(f"run-up of {task.transient_duration} s gives too few slip samples")
        fit = fit_gaussians(series.time, series.slip_pct, 1)
        onset = stable_onset(fit, float(series.time.min()), float(series.time.max()), K2_TIME).onset
        peak = float(np.max(series.slip_pct))
        last = float(series.slip_pct[-1])
        row.update(
            rpm=rad_s_to_rpm(float(series.inner_ring_speed[-1])),
            cage_rpm=rad_s_to_rpm(float(series.cage_speed[-1])),
            slip_pct=last,
            state=STATE_SKID if last > SKID_SLIP_PCT else STATE_ROLLING,
            method="integration",
            stable=onset is not None,
            time_to_stable_s=math.nan if onset is None else float(onset),
            peak_slip_pct=peak,
        )
        if combined is not None:
            row["ball_load_max_n"] = series.ball_load_max
    except (RigError, ValueError, ArithmeticError, RuntimeError) as exc:
        row["error"] = str(exc) or type(exc).__name__
    return row
