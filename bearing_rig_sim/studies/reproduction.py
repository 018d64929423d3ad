"""Reproduction of the paper's experiments with the calibrated twin (issue 4): the RUN.

:func:`reproduce` runs the three experiments of :mod:`bearing_rig_sim.studies.experiments` (cached by
a hash of every input) and hands the raw results to
:func:`bearing_rig_sim.studies.reproduction_report.write_report`, which applies the paper's method
(Gaussian fits, slope criterion) and writes into ``out_dir``: one CSV per experiment, one PNG per
paper figure (5-10 analogues) and ``report.md`` with the paper's numbers beside the twin's.
This module runs the experiments and caches their raw results; the paper's numbers are in
:mod:`bearing_rig_sim.studies.paper_data`, the raw-result types with the report.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import sys
from pathlib import Path
from typing import Any
from collections.abc import Callable, Sequence

import numpy as np
from tqdm import tqdm

from bearing_rig_sim import __version__
from bearing_rig_sim.dynamics.steady import SteadyState
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.studies.experiments import (
    ACCELERATION_LOAD_N,
    ACCELERATIONS,
    SWEEP_LOADS_N,
    SWEEP_RPM,
    VALIDATION_LOAD_N,
    VALIDATION_RPM,
    AccelerationSeries,
    acceleration_sweep,
    load_sweep,
    validation_table,
)

from bearing_rig_sim.dynamics.models import MODELS, model_parameters
from bearing_rig_sim.studies.comparison import write_comparison
from bearing_rig_sim.studies.reproduction_report import Outputs, RawResults, write_report

ACCELERATION_DURATION_S = 3.0
"""Simulated duration of each acceleration run, s (the paper's fits reach the stable state
within about 2 s)."""


def inputs_key(params: BearingParameters) -> str:
    """Hash of every input of the experiments: bearing parameters, grids, code version and the
    engine's kernel and steady-solver source."""
    dynamics = Path(__file__).parent.parent / "dynamics"
    kernels = b"".join((dynamics / name).read_bytes() for name in ("kernels.py", "steady.py"))
    fields = {k: v for k, v in dataclasses.asdict(params).items() if k != "source"}
    doc = {
        "params": fields,
        "grids": [VALIDATION_RPM, VALIDATION_LOAD_N, SWEEP_RPM, SWEEP_LOADS_N, ACCELERATIONS, ACCELERATION_LOAD_N, ACCELERATION_DURATION_S],
        "version": __version__,
        "kernels": hashlib.sha256(kernels).hexdigest(),
    }
    return hashlib.sha256(json.dumps(doc, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _state_to_json(s: SteadyState) -> list[float]:
    return [s.inner_ring_speed, s.axial_load, s.cage_speed, s.slip_pct, s.friction_torque, s.power_loss, s.film_min_inner, s.film_min_outer]


def _state_from_json(v: list[float]) -> SteadyState:
    speed, load, cage, slip, torque, power, film_inner, film_outer = map(float, v)
    return SteadyState(speed, load, cage, slip, torque, power, film_inner, film_outer)


def save_raw(raw: RawResults, path: Path) -> None:
    """Write raw results as JSON (the cache)."""
    doc = {
        "validation": [_state_to_json(s) for s in raw.validation],
        "sweep": {str(k): [_state_to_json(s) for s in v] for k, v in raw.sweep.items()},
        "acceleration": [{k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in dataclasses.asdict(a).items()} for a in raw.acceleration],
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc))


def load_raw(path: Path) -> RawResults:
    """Read raw results written by :func:`save_raw`."""
    doc = json.loads(path.read_text())
    accel = [
        AccelerationSeries(a["acceleration"], a["axial_load"], *(np.array(a[k]) for k in ("time", "inner_ring_speed", "cage_speed", "slip_pct")))
        for a in doc["acceleration"]
    ]
    return RawResults(
        [_state_from_json(v) for v in doc["validation"]],
        {float(k): [_state_from_json(v) for v in vals] for k, vals in doc["sweep"].items()},
        accel,
    )


def _bar(label: str, enabled: bool, total: int | None = None) -> Any:
    """A tqdm progress bar on stderr for one experiment (silent when ``enabled`` is false)."""
    return tqdm(desc=f"{label:<18}", total=total, unit="pt", disable=not enabled, file=sys.stderr)


def _follow(bar: Any) -> Callable[[int, int], None]:
    """The ``progress(done, total)`` callback of the experiments, moving ``bar``."""

    def progress(done: int, total: int) -> None:
        bar.total = total
        bar.update(done - bar.n)

    return progress


def run_experiments(params: BearingParameters, workers: int | None = None, progress: bool = True) -> RawResults:
    """Run the three experiments (both cores by default)."""
    with _bar("validation table", progress) as bar:
        validation = validation_table(params, workers=workers, progress=_follow(bar))
    with _bar("load sweep", progress) as bar:
        sweep = load_sweep(params, workers=workers, progress=_follow(bar))
    with _bar("acceleration sweep", progress, total=len(ACCELERATIONS)) as bar:
        accel = acceleration_sweep(params, duration=ACCELERATION_DURATION_S, workers=workers)
        bar.update(len(ACCELERATIONS))
    return RawResults(validation, sweep, accel)


def reproduce(
    out_dir: str | Path,
    params: BearingParameters | None = None,
    workers: int | None = None,
    use_cache: bool = True,
    progress: bool = True,
) -> Outputs:
    """Run (or reuse) the experiments, analyse them and write CSVs, PNGs and report.md."""
    params = params or BearingParameters.calibrated()
    out = Path(out_dir)
    raw, cached = experiments(out, params, workers, use_cache, progress)
    return write_report(raw, out, params, cached)


def experiments(out: Path, params: BearingParameters, workers: int | None, use_cache: bool, progress: bool) -> tuple[RawResults, bool]:
    """The raw results of the three experiments for ``params``: from ``out``'s cache when its
    inputs match (second value True), else run and cached."""
    out.mkdir(parents=True, exist_ok=True)
    cache = out / ".cache" / f"{inputs_key(params)}.json"
    if use_cache and cache.exists():
        return load_raw(cache), True
    raw = run_experiments(params, workers, progress)
    save_raw(raw, cache)
    return raw, False


def reproduce_models(
    out_dir: str | Path, models: Sequence[str] = MODELS, workers: int | None = None, use_cache: bool = True, progress: bool = True
) -> dict[str, Outputs]:
    """:func:`reproduce` for each named model (:mod:`bearing_rig_sim.dynamics.models`) into
    ``out_dir/<model>/``, and, with more than one, ``out_dir/report.md`` setting them side by
    side with the paper's Tables 3, 5 (1000 rpm row) and 7
    (:func:`~bearing_rig_sim.studies.comparison.write_comparison`)."""
    out = Path(out_dir)
    results: dict[str, tuple[RawResults, Outputs]] = {}
    for name in models:
        params = model_parameters(name)
        raw, cached = experiments(out / name, params, workers, use_cache, progress)
        results[name] = (raw, write_report(raw, out / name, params, cached))
    if len(results) > 1:
        write_comparison(out, results)
    return {name: outputs for name, (_, outputs) in results.items()}
