"""A logged bench run that settles the coupled twin's unmeasured inputs, and the fit to it.

The run is a CSV file, one row per reading, in the order the bench ran them (``#`` starts a
comment line; an empty cell is a quantity not measured at that reading):

| column | unit | meaning |
|---|---|---|
| ``inner_ring_rpm`` | rpm | spindle speed held (required) |
| ``axial_load_n`` | N | axial load (required) |
| ``hold_s`` | s | how long this speed was held before the reading, from the end of the previous row (empty: held until settled, the thermal steady state) |
| ``slip_pct`` | % | cage slip S_c at the nominal contact angle (paper Eq. 11-12) |
| ``outer_ring_temperature_c`` | degC | the outer-ring thermocouple |
| ``friction_torque_n_mm`` | N mm | the housing's reaction torque (the bearing's friction torque) |

At least one of the last three is needed per file. The first row starts from ambient (the
bearing file's ``thermal.ambient_temperature_c``); each following row starts from the state the
previous one left. A row held ``hold_s`` integrates the thermal network over the hold with the
engine's heat following the lubricant's temperature (the engine's steady heat at the hold's
start temperature and 10 K above it, linear between and beyond: the mechanics settle in
milliseconds, the network in minutes); a settled row is the coupled steady state
(:func:`~bearing_rig_sim.thermal.coupling.thermal_steady_state`).

:func:`fit_run` fits up to :data:`MAX_RUN_FITTED` lubricant parameters of
:data:`~bearing_rig_sim.studies.calibration.PHYSICAL_RANGES` (e.g. the yield stress, the
consistency and the consistency's temperature exponent) to every measured quantity at once,
each residual over its measurement uncertainty (:data:`SIGMA`), and refuses a fit outside a
physical range, as :func:`~bearing_rig_sim.studies.calibration.calibrate` does.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from collections.abc import Sequence

import numpy as np
from scipy.optimize import least_squares

from bearing_rig_sim.config import check_number, rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.studies.calibration import CalibrationError, check_in_range, current_value, data_lines, with_values
from bearing_rig_sim.thermal.bearing import ThermalConfig, build_network, node_heat

COLUMNS: dict[str, str] = {
    "inner_ring_rpm": "rpm",
    "axial_load_n": "N",
    "hold_s": "s",
    "slip_pct": "%",
    "outer_ring_temperature_c": "degC",
    "friction_torque_n_mm": "N mm",
}
"""The run's columns and their units (module doc)."""
MEASURED = ("slip_pct", "outer_ring_temperature_c", "friction_torque_n_mm")
SIGMA: dict[str, float] = {"slip_pct": 0.05, "outer_ring_temperature_c": 0.5, "friction_torque_n_mm": 0.05}
"""Measurement uncertainty of each quantity: slip 0.05 pp (Table 3's two decimals and the pulse
timing jitter), outer ring 0.5 K (a type K thermocouple cemented on the ring after calibration
at one point; the shadow twin's 0.9 K includes the model), torque 5 % of the reading (a
strain-gauge torque meter on the housing with its lever's friction; relative)."""
MAX_RUN_FITTED = 3
"""At most this many parameters from a run (slip, temperature and torque each inform one)."""
HEAT_SPAN_K = 10.0
"""Second temperature of a hold's heat law above its start temperature, K (module doc)."""
SUBSTEP_S = 0.5
"""Longest network step of a hold, s (below the bearing bodies' time constants)."""


@dataclass(frozen=True)
class RunRow:
    """One reading of a bench run (SI inside; NaN: not measured; ``hold`` inf: settled)."""

    inner_ring_speed: float
    axial_load: float
    hold: float
    slip_pct: float
    outer_ring_temperature: float
    friction_torque: float

    def measured(self) -> dict[str, float]:
        """The measured quantities in the file's units (column -> value)."""
        got = {"slip_pct": self.slip_pct, "outer_ring_temperature_c": self.outer_ring_temperature, "friction_torque_n_mm": self.friction_torque * 1e3}
        return {k: v for k, v in got.items() if math.isfinite(v)}


@dataclass(frozen=True)
class RunState:
    """The twin at a reading: slip (%), outer ring and lubricant (degC), torque (N m)."""

    slip_pct: float
    outer_ring_temperature: float
    lubricant_temperature: float
    friction_torque: float

    def quantities(self) -> dict[str, float]:
        """In the run file's units (column -> value)."""
        return {"slip_pct": self.slip_pct, "outer_ring_temperature_c": self.outer_ring_temperature, "friction_torque_n_mm": self.friction_torque * 1e3}


def is_run_file(path: str | Path) -> bool:
    """Whether a bench CSV has any column beyond the slip table's (a run, not Table 3); False
    for a file that cannot be read as text (the slip table's reader then names the problem)."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return False
    for line in text.splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            names = [c.strip() for c in line.split(",")]
            return any(c in names for c in ("hold_s", "outer_ring_temperature_c", "friction_torque_n_mm"))
    return False


def read_bench_run(path: str | Path) -> list[RunRow]:
    """Read a bench run (module doc).

    Raises:
        CalibrationError: naming the file, the line and the column of the first bad value, an
            unknown column, or a file with nothing measured.
    """
    path = Path(path)
    reader = csv.DictReader(data_lines(path))
    names = [n.strip() for n in reader.fieldnames or ()]
    unknown = [n for n in names if n not in COLUMNS]
    if unknown:
        raise CalibrationError(f"{path}: unknown column {unknown[0]!r}; the columns are {', '.join(f'{k} ({u})' for k, u in COLUMNS.items())}")
    for need in ("inner_ring_rpm", "axial_load_n"):
        if need not in names:
            raise CalibrationError(f"{path}: the column {need} is required")
    if not any(m in names for m in MEASURED):
        raise CalibrationError(f"{path}: nothing measured: give at least one of {', '.join(MEASURED)}")
    bounds = {
        "inner_ring_rpm": {"gt": 0.0, "le": 100000.0},
        "axial_load_n": {"ge": 1.0, "le": 20000.0},
        "hold_s": {"gt": 0.0, "le": 86400.0},
        "slip_pct": {"gt": -100.0, "lt": 100.0},
        "outer_ring_temperature_c": {"gt": -40.0, "lt": 300.0},
        "friction_torque_n_mm": {"gt": 0.0, "lt": 1e5},
    }
    rows = []
    for i, raw in enumerate(reader, start=2):
        got: dict[str, float] = {}
        for key in names:
            text = (raw.get(key) or "").strip()
            if not text:
                if key in ("inner_ring_rpm", "axial_load_n"):
                    raise CalibrationError(f"{path}: line {i}: {key} is empty (required)")
                continue
            try:
                got[key] = check_number(float(text), str(path), f"line {i}: {key}", **bounds[key])
            except ValueError as exc:
                raise CalibrationError(f"{path}: line {i}: {key}: {exc}") from None
        rows.append(
            RunRow(
                rpm_to_rad_s(got["inner_ring_rpm"]),
                got["axial_load_n"],
                got.get("hold_s", math.inf),
                got.get("slip_pct", math.nan),
                got.get("outer_ring_temperature_c", math.nan),
                got.get("friction_torque_n_mm", math.nan) * 1e-3,
            )
        )
    if not rows:
        raise CalibrationError(f"{path}: no data rows")
    return rows


def run_states(params: BearingParameters, cfg: ThermalConfig, rows: Sequence[RunRow]) -> list[RunState]:
    """The twin through the run, row after row (module doc)."""
    from bearing_rig_sim.thermal.coupling import HeatAtTemperature, thermal_steady_state

    temperatures: np.ndarray | None = None
    out = []
    for row in rows:
        heat = HeatAtTemperature(params, row.inner_ring_speed, row.axial_load)
        if not math.isfinite(row.hold):
            ts = thermal_steady_state(params, cfg, row.inner_ring_speed, row.axial_load, heat=heat)
            net = build_network(params, cfg, row.inner_ring_speed, row.axial_load, lubricant_temperature=ts.temperatures["lubricant"])
            temperatures = np.array([ts.temperatures[n] for n in net.names])
            pt = ts.point
        else:
            net = build_network(params, cfg, row.inner_ring_speed, row.axial_load)
            if temperatures is not None:
                net.temperatures = temperatures.copy()
            t_a = net.temperature("lubricant")
            t_b = t_a + HEAT_SPAN_K
            q_a = net.heat_vector(node_heat(heat(t_a)[1]))
            q_b = net.heat_vector(node_heat(heat(t_b)[1]))
            n_sub = max(1, math.ceil(row.hold / SUBSTEP_S))
            for _ in range(n_sub):
                w = (net.temperature("lubricant") - t_a) / HEAT_SPAN_K
                net.step(np.maximum(q_a + w * (q_b - q_a), 0.0), row.hold / n_sub)
            temperatures = net.temperatures.copy()
            pt, _ = heat(net.temperature("lubricant"))
        names = list(net.names)
        out.append(RunState(pt.slip_pct, float(temperatures[names.index("outer_ring")]), float(temperatures[names.index("lubricant")]), pt.friction_torque))
    return out


@dataclass(frozen=True)
class RunFit:
    """Outcome of :func:`fit_run`: the values, the twin's states at the readings, the RMS of each
    measured quantity's residual (file units) and the parameters."""

    fitted: dict[str, float]
    states: tuple[RunState, ...]
    rms: dict[str, float]
    evaluations: int
    params: BearingParameters


def _residuals(rows: Sequence[RunRow], states: Sequence[RunState]) -> np.ndarray:
    res = []
    for row, st in zip(rows, states):
        model = st.quantities()
        for key, value in row.measured().items():
            sigma = SIGMA[key] * (abs(value) if key == "friction_torque_n_mm" else 1.0)
            res.append((model[key] - value) / sigma)
    return np.array(res)


def fit_run(params: BearingParameters, cfg: ThermalConfig, rows: Sequence[RunRow], fitted: Sequence[str]) -> RunFit:
    """Fit ``fitted`` (lubricant parameters, each as its logarithm from its value in ``params``)
    to every measured quantity of the run (module doc).

    Raises:
        CalibrationError: too many parameters for the run, or a best fit outside its physical
            range (nothing to write).
    """
    n_measured = sum(len(r.measured()) for r in rows)
    if len(fitted) > MAX_RUN_FITTED or len(fitted) > n_measured:
        raise CalibrationError(f"{n_measured} measured values and at most {MAX_RUN_FITTED} parameters: cannot fit {', '.join(fitted)}")
    with_values(params, {k: 1.0 for k in fitted})  # validates the names
    x0 = np.array([math.log(max(current_value(params, k), 1e-6)) for k in fitted])
    evaluations = 0

    def residuals(x: np.ndarray) -> np.ndarray:
        nonlocal evaluations
        evaluations += 1
        return _residuals(rows, run_states(with_values(params, {k: float(math.exp(v)) for k, v in zip(fitted, x)}), cfg, rows))

    fit = least_squares(residuals, x0, diff_step=1e-2, xtol=1e-2, ftol=1e-3, max_nfev=30)  # 1 % of each value: well inside the measurements
    values = {k: float(math.exp(v)) for k, v in zip(fitted, fit.x)}
    check_in_range(values)
    final = with_values(params, values)
    states = run_states(final, cfg, rows)
    rms = {}
    for key in MEASURED:
        pairs = [(st.quantities()[key], r.measured()[key]) for r, st in zip(rows, states) if key in r.measured()]
        if pairs:
            rms[key] = float(np.sqrt(np.mean([(m - d) ** 2 for m, d in pairs])))
    return RunFit(values, tuple(states), rms, evaluations, final)


def write_run(rows: Sequence[RunRow], states: Sequence[RunState], path: str | Path) -> None:
    """Write a run file (module doc) with the twin's values at the readings: a synthetic run
    generated from known parameters, in the bench's form."""
    from bearing_rig_sim.config import rad_s_to_rpm

    lines = [",".join(COLUMNS)]
    for row, st in zip(rows, states):
        q = st.quantities()
        hold = "" if not math.isfinite(row.hold) else f"{row.hold:g}"
        lines.append(
            f"{rad_s_to_rpm(row.inner_ring_speed):.6g},{row.axial_load:g},{hold},{q['slip_pct']:.6f},{q['outer_ring_temperature_c']:.6f},{q['friction_torque_n_mm']:.6f}"
        )
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
