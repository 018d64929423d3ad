"""The suite's own rules (test/conftest.py), run on small suites of their own in a subprocess:

* a test skipped because its tier's tool is missing is a skip outside CI and a failure in CI
  (``CI`` set) unless ``BEARING_RIG_ALLOW_MISSING`` names the tier; a skip that names no tier
  fails in CI; a wrong tier name in the variable stops the run, naming it;
* ``time_left()`` is the test's own timeout (its marker, else pytest.ini's) less what it has run
  and the margin;
* no test of the suite bounds a wait with a number of its own (pytest.ini's one timeout policy).
"""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
from pathlib import Path
from conftest import time_left


HERE = Path(__file__).resolve().parent

SUITE = {
    "test_tiers.py": """
import pytest
from conftest import skip_missing

def test_needs_node():
    skip_missing("foxglove-client", "no node on PATH")

def test_plain_skip():
    pytest.skip("for no tier")

def test_runs():
    pass
""",
    "test_module_tier.py": """
import pytest
pytest.importorskip("distributed")

def test_cluster():
    pass
""",
    # importorskip finds this module first: the import fails as for a package not installed
    "distributed.py": "raise ModuleNotFoundError('not installed here', name='distributed')\n",
    "test_timeouts.py": """
import pytest
from conftest import GUARD_MARGIN_S, time_left

@pytest.mark.timeout(50)
def test_marked():
    assert 50 - GUARD_MARGIN_S - 5 < time_left() <= 50 - GUARD_MARGIN_S

def test_ini():
    assert 300 - GUARD_MARGIN_S - 5 < time_left() <= 300 - GUARD_MARGIN_S
""",
}


def run_suite(tmp_path: Path, *args: str, **env: str) -> subprocess.CompletedProcess[str]:
    shutil.copy(HERE / "conftest.py", tmp_path / "conftest.py")
    shutil.copy(HERE.parent / "pytest.ini", tmp_path / "pytest.ini")
    (tmp_path / "pytest.ini").write_text((tmp_path / "pytest.ini").read_text(encoding="utf-8").replace("testpaths = test", "testpaths = ."), encoding="utf-8")
    for name, text in SUITE.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    environ = {k: v for k, v in os.environ.items() if k not in ("CI", "BEARING_RIG_ALLOW_MISSING", "PYTEST_ADDOPTS")}
    environ.update(env)
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-rA", *args],
        cwd=tmp_path,
        env=environ,
        capture_output=True,
        text=True,
        timeout=time_left(),
    )


def test_outside_ci_a_missing_tier_is_a_skip_with_its_reason(tmp_path: Path) -> None:
    """And ``time_left()`` in test_timeouts.py is the marker's or pytest.ini's timeout less the
    margin (its two tests among the passed)."""
    result = run_suite(tmp_path)
    assert result.returncode == 0, result.stdout[-3000:]
    assert "SKIPPED [1] test_tiers.py:6: missing foxglove-client: no node on PATH" in result.stdout, result.stdout[-3000:]
    assert "could not import 'distributed'" in result.stdout
    assert "3 passed, 3 skipped" in result.stdout and "PASSED test_timeouts.py::test_marked" in result.stdout, result.stdout[-1000:]


def test_in_ci_every_skip_fails_and_names_the_variable_that_allows_its_tier(tmp_path: Path) -> None:
    result = run_suite(tmp_path, "--continue-on-collection-errors", CI="true")
    assert result.returncode == 1, result.stdout[-3000:]
    out = result.stdout
    assert "FAILED test_tiers.py::test_needs_node" in out and "BEARING_RIG_ALLOW_MISSING=foxglove-client" in out, out[-3000:]
    assert "FAILED test_tiers.py::test_plain_skip" in out and "only a missing tier may be allowed" in out, out[-3000:]
    assert "ERROR test_module_tier.py" in out and "BEARING_RIG_ALLOW_MISSING=distributed" in out, out[-3000:]
    assert "3 passed" in out and "skipped" not in out.splitlines()[-1], out[-1000:]


def test_in_ci_an_allowed_tier_stays_a_skip(tmp_path: Path) -> None:
    result = run_suite(tmp_path, "-k", "not plain", CI="true", BEARING_RIG_ALLOW_MISSING="foxglove-client, distributed")
    assert result.returncode == 0, result.stdout[-3000:]
    assert "3 passed, 2 skipped" in result.stdout, result.stdout[-1000:]


def test_an_unknown_tier_stops_the_run_naming_it(tmp_path: Path) -> None:
    result = run_suite(tmp_path, CI="true", BEARING_RIG_ALLOW_MISSING="foxglove-clients")
    assert result.returncode == 4, result.stdout[-2000:] + result.stderr[-2000:]
    assert "BEARING_RIG_ALLOW_MISSING: unknown tier(s) foxglove-clients (tiers: ros, ros2-cli" in result.stderr, result.stderr[-2000:]


EXEMPT_WAIT = "# not a hang guard"
"""Written on a line of the call whose ``timeout=`` is a measured interval or a grace period,
not a bound for a hang."""


def fixed_waits(source: str) -> list[tuple[int, str]]:
    """The ``timeout=`` arguments of ``source`` that are a number of seconds (1 s or more),
    written into the call or a module-level constant holding one (``WAIT = 60.0``), as (line,
    call); lines marked :data:`EXEMPT_WAIT` left out."""
    lines = source.splitlines()
    tree = ast.parse(source)
    numbers: dict[str, float] = {}
    for statement in tree.body:
        target = statement.targets[0] if isinstance(statement, ast.Assign) and len(statement.targets) == 1 else getattr(statement, "target", None)
        value = getattr(statement, "value", None)
        if isinstance(target, ast.Name) and isinstance(value, ast.Constant) and type(value.value) in (int, float):
            numbers[target.id] = value.value
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        for keyword in node.keywords:
            value = keyword.value
            if isinstance(value, ast.Constant) and type(value.value) in (int, float):
                seconds = value.value
            elif isinstance(value, ast.Name):
                seconds = numbers.get(value.id, 0.0)
            else:
                continue
            if keyword.arg == "timeout" and seconds >= 1:
                span = lines[node.lineno - 1 : (node.end_lineno or node.lineno)]  # the formatter may move a comment to the call's last line
                if not any(EXEMPT_WAIT in line for line in span):
                    found.append((value.lineno, ast.unparse(node.func)))
    return found


def test_fixed_waits_are_found() -> None:
    source = (
        "p.communicate(timeout=150)\ng.spin_until(f, timeout=time_left())\nq.wait(timeout=0.5)\nr.wait(timeout=20)  # not a hang guard: grace\n"
        "s.wait(\n    f, timeout=1.0\n)  # not a hang guard: watched\nu.wait(\n    timeout=2.0\n)\n"
        "WAIT = 60.0\nSHORT: float = 0.5\nv.communicate(timeout=WAIT)\nw.wait(timeout=SHORT)\nx.wait(timeout=UNKNOWN)\n"
    )
    assert fixed_waits(source) == [(1, "p.communicate"), (9, "u.wait"), (13, "v.communicate")]


def test_every_wait_of_the_suite_is_bounded_by_the_tests_guard() -> None:
    """pytest.ini: every wait inside a test is bounded by ``time_left()``, so a test's timeout
    marker is the one number that bounds it. A fixed ``timeout=150`` is either shorter than the
    guard (a bet on the host's speed that a loaded host loses) or longer (never the real bound)."""
    offenders = [f"{path.name}:{line} {call}" for path in sorted(HERE.glob("test_*.py")) for line, call in fixed_waits(path.read_text(encoding="utf-8"))]
    assert offenders == [], "waits with their own timeout instead of time_left(): " + ", ".join(offenders)
