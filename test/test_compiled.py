"""The compiled pulse path (bearing_rig_sim/compiled.py): in use after the set-up, the same
statuses to the bit as its sources, and set aside the moment a source it was built from changes."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim import compiled
from bearing_rig_sim.benchmarks.bags import _record_rig_bag
from bearing_rig_sim.numba_cache import sources_digest
from bearing_rig_sim.synthetic.bench import BenchScenario, Burst, write_bench_bag
from conftest import time_left

ANALYSE = """
import json, sys
from bearing_rig_sim import compiled
from bearing_rig_sim.offline.analysis import analyse_bag
out = {}
for bag, csv_dir in zip(sys.argv[1::2], sys.argv[2::2]):
    r = analyse_bag(bag, csv_dir=csv_dir)
    out[bag] = {"pulses": r.pulses, "windows": r.windows, "rows": r.status_rows, "problems": r.problems,
                "transitions": [list(t) for t in r.transitions], "segments": [repr(s) for s in r.segments],
                "final": repr(r.final_status)}
status = compiled.status()
print(json.dumps({"active": status.active, "reason": status.reason, "results": out}))
"""


def _analyse(pure: bool, bags: list[Path], out: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if k != compiled.PURE_PYTHON_VARIABLE}
    if pure:
        env[compiled.PURE_PYTHON_VARIABLE] = "1"
    args: list[str] = []
    for bag in bags:
        args += [str(bag), str(out / bag.name)]
    done = subprocess.run([sys.executable, "-c", ANALYSE, *args], env=env, capture_output=True, text=True, timeout=time_left(), check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.splitlines()[-1])


def test_the_pulse_path_runs_compiled_unless_told_not_to() -> None:
    """After ``./bootstrap.sh setup`` (which .ci/run calls) the modules load from the build;
    with BEARING_RIG_PURE_PYTHON set, from their sources, and the status says why."""
    probe = (
        "import json; from bearing_rig_sim import compiled; import bearing_rig_sim.offline.analysis, bearing_rig_sim.monitoring.windows as w; "
        "s = compiled.status(); print(json.dumps([s.active, s.reason, w.__file__]))"
    )
    env = {k: v for k, v in os.environ.items() if k != compiled.PURE_PYTHON_VARIABLE}
    active, reason, file = json.loads(
        subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=time_left(), check=True).stdout
    )
    assert active, f"the pulse path is not compiled: {reason}"
    assert file.endswith(".so") and Path(file).is_relative_to(compiled.BUILD_DIR)
    env[compiled.PURE_PYTHON_VARIABLE] = "1"
    active, reason, file = json.loads(
        subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=time_left(), check=True).stdout
    )
    assert not active and compiled.PURE_PYTHON_VARIABLE in reason and file == str(compiled.PACKAGE_DIR / "monitoring" / "windows.py")


def test_compiled_and_source_give_the_same_analysis_to_the_byte(tmp_path: Path) -> None:
    """Every CSV file (status rows, windows, segments), the segments, transitions and problems
    are the same, run compiled or from the sources, on bench-like data: lost pulses and a burst,
    a sensor that stops, pulses logged late (put back in stamp order), a load cell, a speed
    ramp with a slip transient; and on the rig's own traffic with its program."""
    bench = BenchScenario(
        duration_s=12.0,
        spindle_speed=lambda t: np.minimum(40.0 * np.asarray(t), 160.0),
        slip_pct=lambda t: 1.5 * np.exp(-(((np.asarray(t) - 3.0) / 1.2) ** 2)),
        jitter_s=5e-6,
        lost_fraction=0.01,
        bursts=(Burst("cage", 6.0, 9), Burst("spindle", 8.0, 5)),
        sensor_stops=(("cage", 10.5),),
        load_n=lambda t: 200.0 + 20.0 * np.sin(np.asarray(t)),
        seed=7,
    )
    bags = [
        write_bench_bag(tmp_path / "bench", bench, log_lag_s={"cage": 0.004}),
        tmp_path / "rig",
    ]
    _record_rig_bag(bags[1], 0.25)
    pure, built = (tmp_path / "pure", tmp_path / "built")
    from_source = _analyse(True, bags, pure)
    from_build = _analyse(False, bags, built)
    assert not from_source["active"] and from_build["active"], from_build["reason"]
    assert from_build["results"] == from_source["results"]
    for bag in bags:
        files = sorted(p.name for p in (pure / bag.name).iterdir())
        assert files and files == sorted(p.name for p in (built / bag.name).iterdir())
        for name in files:
            assert (built / bag.name / name).read_bytes() == (pure / bag.name / name).read_bytes(), f"{bag.name}/{name} differs"
    rows = from_source["results"][str(bags[0])]
    assert rows["windows"] > 50 and rows["rows"] > 100 and rows["pulses"]["cage"] > 0


BAD_PULSES = """
import json
import numpy as np
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.monitoring import SlipMonitor
from bearing_rig_sim.monitoring.schedule import StatusSchedule
from bearing_rig_sim.monitoring.settings import MonitorSettings
settings = MonitorSettings.from_yaml()
monitor = SlipMonitor(settings.kinematics(), settings)
schedule = StatusSchedule(monitor)
pulses = [Pulse("abc", 0, 4, 0, 0), Pulse(None, 0, 4, 0, 0), Pulse(np.float32(1.0), 0, 4, 0, 0), Pulse(1.0, np.int64(0), 4, 0, 0),
          Pulse(1.0, 0.5, 4, 0, 0), Pulse(1.0, 0, np.int32(4), 0, 0), Pulse(float("nan"), 0, 4, 0, 0), Pulse(True, 0, 4, 0, 2),
          Pulse(2, 0, 4, 0, 1), Pulse(3.0, 1, 4, 0, 3)]
seen = []
for shaft in ("spindle", "cage"):
    for pulse in pulses:
        try:
            out = schedule.on_pulse(shaft, pulse)
            seen.append([shaft, repr(pulse), [(s.reason, s.status.detail) for s in out], monitor.status().detail])
        except Exception as exc:
            seen.append([shaft, repr(pulse), "raised", repr(exc)])
print(json.dumps(seen))
"""


ROUND_TRIP = """
import copy, json, pickle, sys
from bearing_rig_sim import compiled
from bearing_rig_sim.offline.analysis import analyse_bag
r = analyse_bag(sys.argv[1], csv_dir=sys.argv[2])
records = [r, r.final_status, *r.segments]
back = [pickle.loads(pickle.dumps(x)) for x in records]
copies = [copy.deepcopy(x) for x in records]
print(json.dumps({"active": compiled.status().active, "segments": len(r.segments),
                  "pickled": [repr(b) == repr(x) and type(b) is type(x) for b, x in zip(back, records)],
                  "copied": [repr(c) == repr(x) and c is not x for c, x in zip(copies, records)]}))
"""


@pytest.mark.parametrize("pure", [False, True], ids=["compiled", "sources"])
def test_an_analysis_result_pickles_and_deep_copies_compiled_or_not(tmp_path: Path, pure: bool) -> None:
    """A result, its final status and its segments come back from pickle and ``copy.deepcopy``
    equal in every field (compared by repr, as NaN fields are not equal to themselves), whether
    the analysis ran compiled (frozen dataclasses without a ``__dict__``) or from the sources."""
    bench = BenchScenario(
        duration_s=8.0, spindle_speed=lambda t: np.minimum(40.0 * np.asarray(t), 160.0), slip_pct=lambda t: 0.8 + 0.0 * np.asarray(t), seed=11
    )
    bag = write_bench_bag(tmp_path / "bench", bench)
    env = {k: v for k, v in os.environ.items() if k != compiled.PURE_PYTHON_VARIABLE}
    if pure:
        env[compiled.PURE_PYTHON_VARIABLE] = "1"
    done = subprocess.run(
        [sys.executable, "-c", ROUND_TRIP, str(bag), str(tmp_path / "csv")], env=env, capture_output=True, text=True, timeout=time_left(), check=False
    )
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads(done.stdout.splitlines()[-1])
    assert out["active"] is not pure
    assert out["segments"] >= 1  # a held speed: at least one segment record to carry
    assert all(out["pickled"]) and all(out["copied"]), out


def test_bad_pulses_are_refused_the_same_way_compiled_never_raised() -> None:
    """A compiled module reads a field as the type Pulse declares and would raise on another: the
    monitor takes a pulse's fields as they come until it has checked them, so a stamp that is
    text, None or a numpy float32 and an index that is a numpy integer or a float are discarded
    with the reason, compiled as from the sources (the monitor "never raises on bad data")."""
    runs = []
    for pure in (True, False):
        env = {k: v for k, v in os.environ.items() if k != compiled.PURE_PYTHON_VARIABLE}
        if pure:
            env[compiled.PURE_PYTHON_VARIABLE] = "1"
        done = subprocess.run([sys.executable, "-c", BAD_PULSES], env=env, capture_output=True, text=True, timeout=time_left(), check=True)
        runs.append(json.loads(done.stdout))
    from_source, from_build = runs
    assert from_build == from_source
    assert not [row for row in from_build if row[2] == "raised"]
    details = " ".join(row[3] for row in from_build)
    for reason in (
        "time 'abc' is not a finite number",
        "time None is not a finite number",
        "strip_id np.int64(0) is not an integer >= 0",
        "strip_count np.int32(4) is not an integer >= 0",
        "time True is not a finite number",
    ):
        assert reason in details


@pytest.fixture()
def package_copy(tmp_path: Path) -> Path:
    """A copy of the package's sources with a build folder whose manifest matches them (its
    extension files stand-ins: the finder is asked, nothing is loaded)."""
    package = tmp_path / "pkg" / "bearing_rig_sim"
    shutil.copytree(compiled.PACKAGE_DIR, package, ignore=shutil.ignore_patterns("__pycache__"))
    build = tmp_path / "build"
    sources = compiled.dependencies(compiled.COMPILED_MODULES, package)
    extensions = {}
    for name in (*compiled.COMPILED_MODULES, compiled.GROUP):
        file = build / "lib" / (name.replace(".", "/") + ".so")
        file.parent.mkdir(parents=True, exist_ok=True)
        file.write_bytes(b"")
        extensions[name] = str(file.relative_to(build))
    manifest = {
        "cache_tag": sys.implementation.cache_tag,
        "digest": sources_digest(sources),
        "sources": [str(s.relative_to(package)) for s in sources],
        "extensions": extensions,
    }
    (build / compiled.MANIFEST_NAME).write_text(json.dumps(manifest), encoding="utf-8")
    return package


def _finder_status(package: Path, monkeypatch: pytest.MonkeyPatch) -> compiled.Status:
    monkeypatch.delenv(compiled.PURE_PYTHON_VARIABLE, raising=False)
    finder = compiled._Finder(package.parent.parent / "build", package)
    spec = finder.find_spec("bearing_rig_sim.monitoring.windows")
    assert finder.status is not None
    assert (spec is not None) == finder.status.active
    assert finder.find_spec("bearing_rig_sim.monitoring.settings") is None  # never compiled
    return finder.status


def test_a_current_build_is_served(package_copy: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert _finder_status(package_copy, monkeypatch).active


@pytest.mark.parametrize(
    "changed",
    [
        "monitoring/windows.py",  # a compiled module
        "instruments/fibre_optic.py",  # the Pulse the windows are compiled against
        "analysis/stability.py",  # imported by the schedule
    ],
)
def test_a_changed_source_sets_the_whole_build_aside(package_copy: Path, monkeypatch: pytest.MonkeyPatch, changed: str) -> None:
    with open(package_copy / changed, "a", encoding="utf-8") as source:
        source.write("\n# edited after the build\n")
    status = _finder_status(package_copy, monkeypatch)
    assert not status.active and "sources changed" in status.reason


def test_a_build_for_another_interpreter_or_told_not_to_is_not_served(package_copy: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    manifest_path = package_copy.parent.parent / "build" / compiled.MANIFEST_NAME
    manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
    manifest_path.write_text(json.dumps({**manifest, "cache_tag": "cpython-399"}), encoding="utf-8")
    status = _finder_status(package_copy, monkeypatch)
    assert not status.active and "cpython-399" in status.reason
    manifest_path.write_text(json.dumps(manifest), encoding="utf-8")
    monkeypatch.setenv(compiled.PURE_PYTHON_VARIABLE, "1")
    finder = compiled._Finder(package_copy.parent.parent / "build", package_copy)
    assert finder.find_spec("bearing_rig_sim.monitoring.windows") is None and compiled.PURE_PYTHON_VARIABLE in str(finder.status)
    manifest_path.unlink()
    assert not _finder_status(package_copy, monkeypatch).active


def test_the_build_covers_what_the_compiled_modules_import() -> None:
    """The digest's sources: each compiled module and, read from their import lines by hand, the
    package modules they import (the stand-in for mypyc's view of their types)."""
    files = {str(f.relative_to(compiled.PACKAGE_DIR)) for f in compiled.dependencies()}
    expected = {
        "monitoring/windows.py",
        "instruments/fibre_optic.py",  # windows: from bearing_rig_sim.instruments.fibre_optic import TWO_PI, Pulse
        "instruments/__init__.py",
        "analysis/stability.py",  # schedule: from bearing_rig_sim.analysis.stability import SlipState
        "offline/analysis.py",
        "picklable.py",  # analysis: from bearing_rig_sim import picklable
        "bags/cdr.py",
        "__init__.py",
    }
    assert expected <= files
    assert "dynamics/kernels.py" not in files  # the engine is not on the pulse path
