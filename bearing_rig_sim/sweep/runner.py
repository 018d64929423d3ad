"""Running a sweep on Dask distributed: a ``LocalCluster`` on this machine's cores, or an
existing cluster (``dask scheduler`` and ``dask worker`` processes) given by its address.

The client (this process) alone writes the result table: each batch's rows are appended as
its result arrives, so a worker lost mid-sweep costs only its unfinished batches, which the
scheduler runs again elsewhere; a batch's rows are written once, when its one result arrives.
A second run computes only the points missing from the table.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import sys
import time
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from collections.abc import Callable

from bearing_rig_sim import __version__
from bearing_rig_sim.config import ConfigError, shipped_calibration_file
from bearing_rig_sim.dynamics.models import model_parameters
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.calibrations import NAMED, calibration_file
from bearing_rig_sim.thermal.bearing import ThermalConfig
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.executors import open_client
from bearing_rig_sim.sweep.points import (
    INTEGRATE,
    KIND_CONTINUATION,
    KIND_ROLLING_START,
    KIND_TRANSIENT,
    SOLVE,
    SweepTask,
    combined_load,
    evaluate,
    point_key,
    solver_for,
)
from bearing_rig_sim.sweep.spec import LOAD_AXIS, SweepSpec
from bearing_rig_sim.sweep.table import ResultTable

BATCH_POINTS = 12
"""Steady points per task: large enough to keep the scheduler's overhead small (a point takes
about a millisecond), small enough to spread over the workers and to lose little to a worker
that dies."""


class SweepRunError(RigError):
    """A sweep that cannot start (bad scheduler address, bad bearing or calibration file)."""


@dataclass(frozen=True)
class SweepOutcome:
    """What :func:`run_sweep` did.

    Attributes:
        path: the result table.
        points: rows the table now holds.
        computed: rows computed by this run.
        errors: rows of this run whose ``error`` column is set.
        seconds: wall-clock time of the computation (cluster start-up included).
        workers: workers the cluster had when the sweep started.
    """

    path: Path
    points: int
    computed: int
    errors: int
    seconds: float
    workers: int


def base_parameters(spec: SweepSpec) -> BearingParameters:
    """The bearing parameters of a spec before its parameter axes."""
    if spec.model != "bench":
        if spec.bearing is not None:
            raise ConfigError(spec.source, "sweep.bearing", f"the {spec.model} model names its own bearing file; leave bearing out")
        if spec.calibration in ("shipped", "none"):
            return model_parameters(spec.model, calibrated=spec.calibration == "shipped")
        return model_parameters(spec.model, calibration=Path(spec.calibration))
    if spec.calibration == "none":
        calibration: str | Path | None = None
    elif spec.calibration == "shipped":
        calibration = shipped_calibration_file()
    elif spec.calibration in NAMED:
        calibration = calibration_file(spec.calibration)
    else:
        calibration = Path(spec.calibration)
    return BearingParameters.from_yaml(spec.bearing, calibration)


def run_context(spec: SweepSpec, params: BearingParameters, method: str) -> dict[str, Any]:
    """The run context kept in the table's metadata. ``context_key`` hashes what the results
    depend on besides the points (bearing parameters, method, code version, engine and solver
    source): results with another key are not reused."""
    here = Path(__file__).resolve().parent.parent / "dynamics"
    sources = hashlib.sha256(b"".join((here / f).read_bytes() for f in ("kernels.py", "engine.py", "steady.py"))).hexdigest()
    fields = {k: v for k, v in dataclasses.asdict(params).items() if k != "source"}
    key_doc = {"params": fields, "method": method, "version": __version__, "sources": sources, "transient_s": spec.transient_duration}
    if spec.thermal:
        key_doc["thermal"] = dataclasses.asdict(ThermalConfig.from_yaml(spec.bearing))
    return {
        "context_key": hashlib.sha256(json.dumps(key_doc, sort_keys=True, default=str).encode()).hexdigest()[:16],
        "sweep": spec.name,
        "spec_file": spec.source,
        "spec_hash": spec.spec_hash,
        "bearing": params.name,
        "bearing_source": params.source,
        "calibration": spec.calibration,
        "parameters": fields,
        "method": method,
        "version": __version__,
        "engine_source_sha256": sources[:16],
    }


def plan_tasks(spec: SweepSpec, params: BearingParameters, done: set[str], method: str = SOLVE, batch: int = BATCH_POINTS) -> list[SweepTask]:
    """The tasks that compute every point of ``spec`` whose key is not in ``done``."""
    points = spec.points()
    tasks: list[SweepTask] = []
    if spec.transient:
        for i, p in enumerate(points):
            key = point_key(p, KIND_TRANSIENT)
            if key not in done:
                tasks.append(SweepTask(f"transient-{i}", KIND_TRANSIENT, params, (p,), (key,), frozenset([key]), method, spec.transient_duration))
        return tasks
    missing = [(p, point_key(p, KIND_ROLLING_START)) for p in points]
    missing = [(p, k) for p, k in missing if k not in done]
    for i in range(0, len(missing), batch):
        chunk = missing[i : i + batch]
        tasks.append(
            SweepTask(
                f"steady-{i // batch}",
                KIND_ROLLING_START,
                params,
                tuple(p for p, _ in chunk),
                tuple(k for _, k in chunk),
                frozenset(k for _, k in chunk),
                method,
                thermal=ThermalConfig.from_yaml(spec.bearing) if spec.thermal else None,
            )
        )
    if spec.continuation and method == SOLVE:
        # a load row followed upwards from the previous steady state: the four-number solve's, so
        # axial points only (a combined load's steady state is periodic, from the rolling start)
        rows: dict[str, list[dict[str, float]]] = defaultdict(list)
        for p in points:
            combined = combined_load(p)
            if combined is not None and (combined[0] > 0.0 or combined[1] is not None):
                continue
            rows[json.dumps({k: v for k, v in sorted(p.items()) if k != LOAD_AXIS})].append(p)
        for j, row in enumerate(rows.values()):
            row.sort(key=lambda q: q[LOAD_AXIS])
            keys = tuple(point_key(p, KIND_CONTINUATION) for p in row)
            wanted = frozenset(k for k in keys if k not in done)
            if wanted:
                tasks.append(SweepTask(f"continuation-{j}", KIND_CONTINUATION, params, tuple(row), keys, wanted, method))
    return tasks


def task_key(spec: SweepSpec, task: SweepTask, context: dict[str, Any]) -> str:
    """The Dask key of a task, from what it computes: a key the scheduler may still hold from
    an earlier (interrupted) run then names the same result, never another batch's."""
    content = json.dumps([context["context_key"], task.kind, task.method, task.keys, sorted(task.wanted)])
    return f"{spec.name}-{task.kind}-{hashlib.sha256(content.encode()).hexdigest()[:16]}"


def _warm_worker(params: BearingParameters) -> bool:
    """Build the worker's solver and compile (or load) the engine's kernels once."""
    solver = solver_for(params)
    solver.solve(100.0, 100.0)
    return True


def _progress_bar(total: int, enabled: bool) -> Any:
    from tqdm import tqdm

    return tqdm(total=total, unit="pt", desc="sweep", disable=not enabled, file=sys.stderr, smoothing=0.1)


def run_sweep(
    spec: SweepSpec,
    out_dir: str | Path,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    method: str = SOLVE,
    progress: bool = True,
    client: Any = None,
    batch: int = BATCH_POINTS,
    on_batch: Callable[[Any, int], None] | None = None,
) -> SweepOutcome:
    """Compute the points of ``spec`` missing from ``out_dir/results.parquet`` and merge them in.

    Args:
        spec: the sweep.
        out_dir: result folder (``results.parquet`` and, while running, ``parts/``).
        scheduler: address of an existing Dask scheduler (``tcp://HOST:8786``).
        workers: size of the ``LocalCluster`` when there is no scheduler (default: cores).
        method: :data:`~bearing_rig_sim.sweep.points.SOLVE` (steady solver) or
            :data:`~bearing_rig_sim.sweep.points.INTEGRATE` (time integration, the reference).
        progress: show a progress bar (points, rate, ETA) on stderr.
        client: an open Dask client to use instead (left open).
        batch: steady points per task.
        on_batch: called as ``on_batch(client, rows_so_far)`` after each batch is written.
    """
    if method not in (SOLVE, INTEGRATE):
        raise SweepRunError(f"method must be {SOLVE} or {INTEGRATE}, got {method!r}")
    params = base_parameters(spec)
    context = run_context(spec, params, method)
    table = ResultTable(out_dir, spec.axis_names, context)
    done = table.done_keys()
    tasks = plan_tasks(spec, params, done, method, batch)
    wanted = sum(len(t.wanted) for t in tasks)
    start = time.perf_counter()
    computed = errors = 0
    n_workers = 0
    if tasks:
        own = client is None
        cluster = None
        if own:
            client, cluster = open_client(scheduler, workers)
        try:
            from distributed import as_completed

            n_workers = len(client.scheduler_info().get("workers", {}))
            client.run(_warm_worker, params)
            futures = [client.submit(evaluate, t, key=task_key(spec, t, context), pure=False) for t in tasks]
            with _progress_bar(wanted, progress) as bar:
                for future in as_completed(futures):
                    rows = future.result()
                    computed += table.append(rows)
                    errors += sum(1 for r in rows if r["error"])
                    bar.update(len(rows))
                    if on_batch is not None:
                        on_batch(client, computed)
        finally:
            if own:
                client.close()
                if cluster is not None:
                    cluster.close()
    path = table.finish(sort_by=["branch", *spec.axis_names])
    from pyarrow.parquet import read_metadata

    return SweepOutcome(path, read_metadata(path).num_rows, computed, errors, time.perf_counter() - start, n_workers)
