"""Sweeps on Dask: rows written, resumed, kept through a lost worker, on an external cluster."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any
from collections.abc import Iterator

import pyarrow.parquet as pq
import pytest
from conftest import time_left

from bearing_rig_sim.sweep.points import INTEGRATE
from bearing_rig_sim.sweep.runner import run_sweep
from bearing_rig_sim.sweep.spec import load_spec
from bearing_rig_sim.sweep.table import SweepTableError, read_context

distributed = pytest.importorskip("distributed")

SPEC = """
sweep: {name: small, continuation: true}
grid:
  inner_ring_speed_rpm: [1000, 5000]
  axial_load_n: [100, 200, 300]
"""


def write_spec(tmp_path: Path, text: str = SPEC) -> Path:
    path = tmp_path / "small.yaml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def client() -> Iterator[Any]:
    import logging

    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.ERROR)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def read_rows(path: Path) -> list[dict[str, Any]]:
    return pq.read_table(path).to_pylist()


def test_two_worker_processes_write_the_expected_rows_and_a_second_run_computes_nothing(tmp_path: Path, client: Any) -> None:
    spec = load_spec(write_spec(tmp_path))
    pids = client.run(os.getpid)
    assert len(pids) == 2 and os.getpid() not in pids.values()
    out = tmp_path / "out"
    first = run_sweep(spec, out, client=client, progress=False, batch=2)
    rows = read_rows(first.path)
    # 2 speeds x 3 loads, from the rolling start and continued along each load row
    assert first.computed == first.points == len(rows) == 12
    assert {(r["branch"], r["rpm"], r["axial_load_n"]) for r in rows} == {
        (b, n, f) for b in ("rolling_start", "continuation") for n in (1000.0, 5000.0) for f in (100.0, 200.0, 300.0)
    }
    assert len({r["point_key"] for r in rows}) == 12
    assert all(r["error"] == "" and 0.0 < r["cage_rpm"] < r["rpm"] for r in rows)
    context = read_context(first.path)
    assert context["spec_hash"] == spec.spec_hash and context["bearing"] == "H7006C" and context["calibration"] == "shipped"
    again = run_sweep(spec, out, client=client, progress=False)
    assert again.computed == 0 and again.points == 12
    assert [(r["point_key"], r["slip_pct"]) for r in read_rows(again.path)] == [(r["point_key"], r["slip_pct"]) for r in rows]


def test_a_grown_spec_computes_only_the_new_points(tmp_path: Path, client: Any) -> None:
    out = tmp_path / "out"
    run_sweep(load_spec(write_spec(tmp_path)), out, client=client, progress=False)
    grown = load_spec(write_spec(tmp_path, SPEC.replace("[100, 200, 300]", "[100, 200, 300, 400]")))
    outcome = run_sweep(grown, out, client=client, progress=False)
    # the new rolling-start points (2) and the new continuation points (2)
    assert outcome.computed == 4 and outcome.points == 16


def test_results_of_another_model_are_not_reused(tmp_path: Path, client: Any) -> None:
    out = tmp_path / "out"
    run_sweep(load_spec(write_spec(tmp_path)), out, client=client, progress=False)
    other = load_spec(write_spec(tmp_path, SPEC.replace("continuation: true", "continuation: true, calibration: none")))
    with pytest.raises(SweepTableError, match="another model"):
        run_sweep(other, out, client=client, progress=False)


@pytest.mark.slow
def test_a_worker_killed_mid_sweep_loses_no_point_and_duplicates_none(tmp_path: Path) -> None:
    import logging

    spec = load_spec(write_spec(tmp_path, SPEC.replace("[100, 200, 300]", "[100, 200, 300, 400, 500, 600]")))
    killed: list[tuple[str, int]] = []

    def kill_a_busy_worker(c: Any, done: int) -> None:
        if killed:
            return
        # the scheduler may hand the freed worker its next task just after the client hears of the
        # result (both workers can finish at once): wait for a worker to hold one, 11 being left
        deadline = time.monotonic() + time_left()
        busy = [addr for addr, keys in c.processing().items() if keys]
        while not busy and time.monotonic() < deadline:
            time.sleep(0.01)
            busy = [addr for addr, keys in c.processing().items() if keys]
        assert busy, "no worker holds a task after the first result: the sweep is too small for this test"
        pid = c.run(os.getpid, workers=[busy[0]])[busy[0]]
        os.kill(pid, signal.SIGKILL)
        killed.append((busy[0], pid))

    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.CRITICAL)
    try:
        with distributed.Client(cluster) as c:
            outcome = run_sweep(spec, tmp_path / "out", client=c, method=INTEGRATE, progress=False, batch=1, on_batch=kill_a_busy_worker)
    finally:
        cluster.close()
    assert len(killed) == 1
    rows = read_rows(outcome.path)
    keys = [r["point_key"] for r in rows]
    assert len(rows) == len(set(keys)) == 12 == outcome.computed
    assert {(r["rpm"], r["axial_load_n"]) for r in rows} == {(n, f) for n in (1000.0, 5000.0) for f in (100.0, 200.0, 300.0, 400.0, 500.0, 600.0)}


def wait_for_file(path: Path, proc: subprocess.Popen[bytes], timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while not path.exists():
        if proc.poll() is not None:
            raise AssertionError(f"{proc.args} exited with {proc.returncode}")
        if time.monotonic() > deadline:
            raise AssertionError(f"{path} not written within {timeout} s")
        time.sleep(0.1)


@pytest.mark.slow
def test_the_same_sweep_on_a_dask_scheduler_and_worker_started_on_localhost(tmp_path: Path) -> None:
    """As docs/guide.md shows: `dask scheduler`, `dask worker`, then `bearing-rig sweep
    --scheduler` (loopback only)."""
    bindir = Path(sys.executable).parent
    scheduler_file = tmp_path / "scheduler.json"
    scheduler = subprocess.Popen(
        [str(bindir / "dask"), "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file", str(scheduler_file)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    worker = None
    try:
        wait_for_file(scheduler_file, scheduler, 60.0)
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        worker = subprocess.Popen(
            [str(bindir / "dask"), "worker", address, "--host", "127.0.0.1", "--nthreads", "1", "--no-dashboard"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        with distributed.Client(address, timeout="60s") as c:
            c.wait_for_workers(1, timeout=time_left())
        out = tmp_path / "out"
        result = subprocess.run(
            [str(bindir / "bearing-rig"), "sweep", str(write_spec(tmp_path)), "--out", str(out), "--scheduler", address, "--json", "--no-progress"],
            capture_output=True, text=True, timeout=time_left(),
        )  # fmt: skip
        assert result.returncode == 0, result.stderr
        summary = json.loads(result.stdout)
        assert summary["points"] == summary["computed"] == 12 and summary["workers"] == 1
        assert (out / "operating_map.png").exists()
    finally:
        for proc in (worker, scheduler):
            if proc is not None:
                proc.terminate()
                try:
                    proc.wait(timeout=20)  # not a hang guard: the grace a terminated worker gets before it is killed
                except subprocess.TimeoutExpired:
                    proc.kill()


def test_calibration_points_run_on_the_cluster_named_by_dask_scheduler_address(client: Any) -> None:
    import dask

    from bearing_rig_sim.config import rpm_to_rad_s
    from bearing_rig_sim.dynamics import BearingParameters
    from bearing_rig_sim.studies.calibration import steady_states

    params = BearingParameters.calibrated()
    points = [(rpm_to_rad_s(n), 100.0) for n in (900.0, 1800.0, 2700.0)]
    here = steady_states(params, points, workers=1)
    with dask.config.set({"scheduler-address": client.scheduler.address}):
        there = steady_states(params, points, workers=2)
    assert [s.slip_pct for s in there] == [s.slip_pct for s in here]
    prefixes = client.run_on_scheduler(lambda dask_scheduler: sorted(dask_scheduler.task_prefixes))
    assert "steady_state_job" in prefixes  # Dask drops the leading underscore of the key prefix


def test_an_interrupted_sweep_resumes_from_the_batches_it_wrote(tmp_path: Path, client: Any) -> None:
    spec = load_spec(write_spec(tmp_path))
    out = tmp_path / "out"

    def interrupt(c: Any, done: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_sweep(spec, out, client=client, progress=False, batch=2, on_batch=interrupt)
    assert not (out / "results.parquet").exists()
    parts = list((out / "parts").glob("part-*.parquet"))
    assert len(parts) == 1
    written = pq.read_table(parts[0]).num_rows
    assert 0 < written < 12
    resumed = run_sweep(spec, out, client=client, progress=False, batch=2)
    assert resumed.computed == 12 - written and resumed.points == 12
    assert not list((out / "parts").glob("part-*.parquet"))
