"""Steady operating points of the engine, calibration to bench data, and prediction.

The engine's uncertain parameters are physical properties of the lubricant (the paper's dry
model has none; docs/paper.md section 12). :func:`calibrate` fits at most two of them (by default the
grease's yield stress and consistency, see :data:`PHYSICAL_RANGES`) to measured (inner-ring
speed, axial load, slip) rows by nonlinear least squares on their logarithms, running the engine
to a steady state at every row; a best fit outside a parameter's physically plausible range is
an error, not a result. The slip of the bench rows and of the engine is the paper's S_c (paper
Eq. 11-12) at the nominal contact angle, computed from cage and inner-ring speeds.

With a thermal configuration (``thermal=``, the bearing file's ``thermal:`` section) every row is
the coupled thermal steady state (:func:`bearing_rig_sim.thermal.coupling.thermal_steady_state`):
the bench's slips are steady, warm values, so the fitted values are those at the bearing file's
lubricant temperature (the reference of the grease's temperature laws) that give the bench's
slips at the temperatures the bearing reaches at each row.
"""

from __future__ import annotations

import csv
import math
import os
from concurrent.futures import Executor
from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from pathlib import Path
from collections.abc import Callable, Iterable, Sequence

import numpy as np
import yaml
from scipy.optimize import least_squares

from bearing_rig_sim.config import check_number, rad_s_to_rpm, rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters, DynamicsDivergedError
from bearing_rig_sim.dynamics.parameters import CALIBRATABLE
from bearing_rig_sim.dynamics.steady import SteadyState, solver_for
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.executors import process_pool
from bearing_rig_sim.thermal.bearing import ThermalConfig

DEFAULT_FITTED: tuple[str, ...] = ("yield_stress", "consistency")
"""Parameters fitted by default: the Herschel-Bulkley yield stress and consistency of the grease
the balls and cage shear (a speed-independent and a speed-dependent resistance)."""

DEFAULT_FIXED: dict[str, float] = {}
"""Held fixed during the fit."""

MAX_FITTED = 2
"""At most this many parameters are fitted (more are not identifiable from slip alone)."""


@dataclass(frozen=True)
class PhysicalRange:
    """Unit, plausible interval and its reason, for a calibratable physical quantity."""

    unit: str
    low: float
    high: float
    reason: str


PHYSICAL_RANGES: dict[str, PhysicalRange] = {
    "yield_stress": PhysicalRange("Pa", 50.0, 2000.0, "rheometer yield stress of NLGI 1-3 lithium greases, sheared, 20-60 degC"),
    "consistency": PhysicalRange("Pa s^n", 1.0, 100.0, "Herschel-Bulkley consistency of NLGI 1-3 lithium greases (flow index 0.3-0.7)"),
    "fill_fraction": PhysicalRange("1", 0.02, 1.0, "share of the swept volume holding grease: channelled 0.02-0.1, running-in up to 1"),
    "eyring_stress": PhysicalRange("Pa", 2e6, 1e7, "Eyring stress of mineral and ester base oils (Johnson and Tevaarwerk 1977)"),
    "consistency_temperature_exponent": PhysicalRange(
        "1", 0.0, 1.0, "x of K(T) = K(T_ref) (eta(T)/eta(T_ref))^x: between the thickener alone (0) and the base oil's viscosity (1)"
    ),
    "ball_set_resistance": PhysicalRange(
        "N", 0.01, 2.0, "paper model: below 2 mu_s Q_ref = 2 N, the largest traction a ball's two contacts carry at the reference load of 10 N"
    ),
    "ball_set_resistance_speed_exponent": PhysicalRange("1", 0.05, 2.0, "paper model: a Coulomb-like (near 0) to an inertial-drag (2) speed law"),
}
"""Physical quantities :func:`calibrate` may fit, with their plausible ranges."""


class CalibrationError(RigError):
    """Bench data or calibration request that cannot be used."""


@dataclass(frozen=True)
class BenchPoint:
    """One measured operating point: inner-ring speed (rad/s), axial load (N), slip (%)."""

    inner_ring_speed: float
    axial_load: float
    slip_pct: float


@dataclass(frozen=True)
class CalibrationResult:
    """Outcome of :func:`calibrate`."""

    fitted: dict[str, float]
    fixed: dict[str, float]
    points: tuple[BenchPoint, ...]
    predicted: tuple[SteadyState, ...]
    rms_pct: float
    evaluations: int
    params: BearingParameters = field(repr=False)
    thermal: bool = False
    """Whether the rows were the coupled thermal steady states."""


def data_lines(path: Path) -> list[str]:
    """The lines of a CSV data file without blank and comment (``#``) lines.

    Raises:
        CalibrationError: the file cannot be read or is not UTF-8 text.
    """
    try:
        return [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    except OSError as exc:
        raise CalibrationError(f"{path}: cannot read ({exc.strerror or exc})") from exc
    except UnicodeDecodeError as exc:
        raise CalibrationError(f"{path}: not UTF-8 text (byte {exc.start})") from None


def read_bench_csv(path: str | Path) -> list[BenchPoint]:
    """Read ``inner_ring_rpm,axial_load_n,slip_pct`` rows (``#`` starts a comment line).

    Raises:
        CalibrationError: naming file, line and column of the first bad value.
    """
    path = Path(path)
    reader = csv.DictReader(data_lines(path))
    need = ("inner_ring_rpm", "axial_load_n", "slip_pct")
    if reader.fieldnames is None or any(k not in reader.fieldnames for k in need):
        raise CalibrationError(f"{path}: header must name the columns {', '.join(need)}, got {reader.fieldnames}")
    points = []
    for i, row in enumerate(reader, start=2):
        try:
            rpm = check_number(float(row["inner_ring_rpm"]), str(path), f"line {i}: inner_ring_rpm", gt=0.0)
            load = check_number(float(row["axial_load_n"]), str(path), f"line {i}: axial_load_n", ge=1.0)
            slip = check_number(float(row["slip_pct"]), str(path), f"line {i}: slip_pct", gt=-100.0, lt=100.0)
        except (TypeError, ValueError) as exc:
            raise CalibrationError(f"{path}: line {i}: {exc}") from exc
        points.append(BenchPoint(rpm_to_rad_s(rpm), load, slip))
    if not points:
        raise CalibrationError(f"{path}: no data rows")
    return points


def steady_state(params: BearingParameters, inner_ring_speed: float, axial_load: float, thermal: ThermalConfig | None = None) -> SteadyState:
    """The default engine's steady state reached from the rolling start, by the direct solver
    (which integrates where Newton cannot settle it; :mod:`bearing_rig_sim.dynamics.steady`);
    with ``thermal``, the coupled thermal steady state (the lubricant at the temperature its own
    heat gives it)."""
    if thermal is not None:
        from bearing_rig_sim.thermal.coupling import thermal_steady_state

        ts = thermal_steady_state(params, thermal, inner_ring_speed, axial_load)
        return replace(ts.point, lubricant_temperature=ts.temperatures["lubricant"], outer_ring_temperature=ts.temperatures["outer_ring"])
    return solver_for(params).solve(inner_ring_speed, axial_load)


def _steady_state_job(job: tuple[BearingParameters, float, float, ThermalConfig | None]) -> SteadyState:
    return steady_state(*job)


def steady_states(
    params: BearingParameters,
    points: Iterable[tuple[float, float]],
    workers: int | None = None,
    pool: Executor | None = None,
    progress: Callable[[int, int], None] | None = None,
    thermal: ThermalConfig | None = None,
) -> list[SteadyState]:
    """Steady states of many (inner-ring speed rad/s, axial load N) points, on ``pool`` or on
    ``workers`` new processes (default: all cores). Order is kept; results do not depend on
    the number of processes. ``progress(done, total)`` is called as points complete. With
    ``thermal``, each is the coupled thermal steady state (:func:`steady_state`)."""
    jobs = [(params, float(w), float(f), thermal) for w, f in points]
    workers = workers or os.cpu_count() or 1
    if pool is None and (workers <= 1 or len(jobs) <= 1):
        return _collect(map(_steady_state_job, jobs), len(jobs), progress)
    if pool is not None:
        return _collect(pool.map(_steady_state_job, jobs), len(jobs), progress)
    with process_pool(min(workers, len(jobs))) as new_pool:
        return _collect(new_pool.map(_steady_state_job, jobs), len(jobs), progress)


def _collect(results: Iterable[SteadyState], total: int, progress: Callable[[int, int], None] | None) -> list[SteadyState]:
    out = []
    for item in results:
        out.append(item)
        if progress is not None:
            progress(len(out), total)
    return out


LUBRICANT_FIELDS = ("yield_stress", "consistency", "fill_fraction", "eyring_stress", "consistency_temperature_exponent")
"""Calibratable names that are properties of the bearing's lubricant."""


def with_values(params: BearingParameters, values: dict[str, float]) -> BearingParameters:
    """``params`` with calibratable fields replaced (names of :data:`CALIBRATABLE`)."""
    unknown = [k for k in values if k not in CALIBRATABLE]
    if unknown:
        raise CalibrationError(f"not calibratable: {', '.join(unknown)}; choose from {', '.join(CALIBRATABLE)}")
    lub = {k: v for k, v in values.items() if k in LUBRICANT_FIELDS}
    rest = {k: v for k, v in values.items() if k not in LUBRICANT_FIELDS}
    out = params.replace(**rest) if rest else params
    if lub:
        if out.lubricant is None:
            raise CalibrationError(f"{', '.join(lub)}: the bearing file names no lubricant file")
        out = out.with_lubricant(**lub)
    return out


def current_value(params: BearingParameters, name: str) -> float:
    """The value of a calibratable parameter in ``params``."""
    if name in LUBRICANT_FIELDS:
        if params.lubricant is None:
            raise CalibrationError(f"{name}: the bearing file names no lubricant file")
        return float(getattr(params.lubricant, name))
    return float(getattr(params, name))


def check_in_range(values: dict[str, float], what: str = "best fit") -> None:
    """Raise :class:`CalibrationError` naming the first value outside its physical range."""
    for name, value in values.items():
        rng = PHYSICAL_RANGES.get(name)
        if rng is not None and not rng.low <= value <= rng.high:
            raise CalibrationError(
                f"{what} of {name} = {value:.4g} {rng.unit} is outside its physical range [{rng.low:g}, {rng.high:g}] {rng.unit} "
                f"({rng.reason}); nothing written: the model lacks a mechanism the data contain"
            )


def calibrate(
    params: BearingParameters,
    points: Sequence[BenchPoint],
    fitted: Sequence[str] = DEFAULT_FITTED,
    fixed: dict[str, float] | None = None,
    workers: int | None = None,
    thermal: ThermalConfig | None = None,
) -> CalibrationResult:
    """Fit ``fitted`` physical parameters so the engine's steady slip matches ``points``.

    Each parameter is fitted as its logarithm (it must stay positive), starting from its value
    in ``params``; ``fixed`` values are set first. The residuals are slip differences in
    percentage points. With ``thermal`` every row is the coupled thermal steady state (module
    doc) and the values fitted are those at the bearing file's lubricant temperature.

    Raises:
        CalibrationError: more than :data:`MAX_FITTED` parameters, or a best fit outside the
            parameter's :data:`PHYSICAL_RANGES` (the message names it), or a trial on which the
            engine diverged (naming the parameter out of its range, else the fault).
    """
    if len(points) < len(fitted):
        raise CalibrationError(f"{len(points)} data rows cannot determine {len(fitted)} parameters")
    if len(fitted) > MAX_FITTED:
        raise CalibrationError(f"at most {MAX_FITTED} parameters can be fitted, got {len(fitted)}: {', '.join(fitted)}")
    fixed = dict(DEFAULT_FIXED if fixed is None else fixed)
    base = with_values(params, fixed)
    with_values(base, {k: 1.0 for k in fitted})  # validates the names
    x0 = np.array([math.log(max(current_value(base, k), 1e-6)) for k in fitted])
    target = np.array([pt.slip_pct for pt in points])
    evaluations = 0

    speeds_loads = [(pt.inner_ring_speed, pt.axial_load) for pt in points]
    workers = workers or os.cpu_count() or 1

    def model(x: np.ndarray, pool: Executor | None) -> list[SteadyState]:
        nonlocal evaluations
        evaluations += 1
        values = {k: float(math.exp(v)) for k, v in zip(fitted, x)}
        trial = with_values(base, values)
        try:
            return steady_states(trial, speeds_loads, 1, pool, thermal=thermal)
        except DynamicsDivergedError as exc:
            # No slip to fit there: name the parameter that left its range, else the fault.
            check_in_range(values, "the fit's trial value")
            shown = ", ".join(f"{k} = {v:.4g}" for k, v in values.items())
            raise CalibrationError(f"the engine diverged at the fit's trial {shown}: {exc}") from None

    with process_pool(min(workers, len(points))) if workers > 1 else nullcontext() as pool:
        # Slip is reported to 0.01 %: a relative step of 1e-4 in the log-parameters is ample.
        fit = least_squares(lambda x: np.array([s.slip_pct for s in model(x, pool)]) - target, x0, diff_step=1e-3, xtol=1e-4, ftol=1e-6, max_nfev=40)
        values = {k: float(math.exp(v)) for k, v in zip(fitted, fit.x)}
        final = with_values(base, values)
        predicted = steady_states(final, speeds_loads, 1, pool, thermal=thermal)
    rms = float(np.sqrt(np.mean((np.array([s.slip_pct for s in predicted]) - target) ** 2)))
    check_in_range(values)
    return CalibrationResult(values, fixed, tuple(points), tuple(predicted), rms, evaluations, final, thermal is not None)


PAPER_HEADER = (
    "# Calibration of the paper model (config/models/paper.yaml) against the paper's own simulated\n"
    "# slip (Table 3). Regenerate with `bearing-rig calibrate config/calibration/paper_table3.csv\n"
    "# --model paper --fit ball_set_resistance ball_set_resistance_speed_exponent --out THIS --force`.\n"
    "# The fitted quantities state the resistance on the ball set that the paper's results imply and\n"
    "# its text leaves out; the RMS is large because the paper's friction law saturates at 100 mm/s of\n"
    "# sliding, below what its 2100-2700 rpm rows need (docs/paper.md section 13).\n"
)
"""Header of the paper model's calibration file."""


def calibration_entries(values: dict[str, float], data_name: str) -> dict[str, object]:
    """A calibration file's ``parameters:``: ``section.key`` -> ``{value, unit, range, source}``
    (a plain number for a parameter without a physical range)."""

    def entry(name: str, value: float) -> object:
        rng = PHYSICAL_RANGES.get(name)
        if rng is None:
            return float(f"{value:.6g}")
        return {"value": float(f"{value:.6g}"), "unit": rng.unit, "range": [rng.low, rng.high], "source": f"fitted to {data_name}; range: {rng.reason}"}

    return {f"{CALIBRATABLE[k][0]}.{CALIBRATABLE[k][1]}": entry(k, v) for k, v in values.items()}


def write_calibration(result: CalibrationResult, path: str | Path, data_name: str, header: str | None = None) -> None:
    """Write a calibration file readable by ``BearingParameters.from_yaml(bearing, path)``: each
    fitted value as ``{value, unit, range, source}``; ``header`` replaces the bench
    calibration's comment lines."""

    names = {**result.fixed, **result.fitted}
    params = calibration_entries(names, data_name)
    doc = {
        "calibration": {
            "data": data_name,
            "fitted": [f"{CALIBRATABLE[k][0]}.{CALIBRATABLE[k][1]}" for k in result.fitted],
            "fixed": {f"{CALIBRATABLE[k][0]}.{CALIBRATABLE[k][1]}": float(v) for k, v in result.fixed.items()},
            "rms_slip_pct": round(float(result.rms_pct), 4),
            "thermal": bool(result.thermal),
            "rows": [
                {
                    "rpm": round(float(rad_s_to_rpm(p.inner_ring_speed)), 3),
                    "axial_load_n": float(p.axial_load),
                    "measured_slip_pct": float(p.slip_pct),
                    "model_slip_pct": round(float(s.slip_pct), 4),
                    **(
                        {
                            "lubricant_temperature_c": round(float(s.lubricant_temperature), 2),
                            "outer_ring_temperature_c": round(float(s.outer_ring_temperature), 2),
                        }
                        if result.thermal
                        else {}
                    ),
                }
                for p, s in zip(result.points, result.predicted)
            ],
        },
        "parameters": params,
    }
    header = header or (
        "# Calibration of the twin against bench slip data. Regenerate with `bearing-rig calibrate`.\n"
        "# The fitted quantities are physical properties of the grease the balls and cage shear in the\n"
        "# bearing's running-in state; each carries its plausible range (a fit outside it fails).\n"
        "# What they mean and what the bench should measure: docs/model.md, section Calibration.\n"
        + (
            "# Thermal: every row is the coupled thermal steady state (the bench's slips are warm, steady\n"
            "# values); the values are the grease's at the bearing file's lubricant temperature, the\n"
            "# reference of its temperature laws (config/lubricants/).\n"
            if result.thermal
            else ""
        )
    )
    Path(path).write_text(header + yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
