"""The style is enforced, not just described: ruff's lint and formatter (ruff.toml) and mypy
(setup.cfg) pass on the tree, ``mypy --strict`` on the interface contract and the parameter model, every remaining ``type: ignore`` says why,
and no function of the package runs over :data:`MAX_FUNCTION_LINES` lines."""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

from conftest import time_left

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent
MAX_FUNCTION_LINES = 150
"""The longest function (decorators and docstring included) the house allows: beyond it a function
does several stages' work, which belong in functions of their own."""


def run(tool: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(BIN / tool), *args], cwd=ROOT, capture_output=True, text=True, timeout=time_left(), check=False)


def test_ruff_passes() -> None:
    result = run("ruff", "check", "--no-cache", "bearing_rig_sim", "test")
    assert result.returncode == 0, result.stdout + result.stderr


def test_ruff_format_leaves_the_code_as_it_is() -> None:
    result = run("ruff", "format", "--check", "--no-cache", "bearing_rig_sim", "test", "setup.py", "launch")
    assert result.returncode == 0, "run `ruff format bearing_rig_sim test setup.py launch`:\n" + result.stdout + result.stderr


def test_mypy_passes_on_the_package() -> None:
    result = run("mypy", "--cache-dir", "/dev/null")
    assert result.returncode == 0, result.stdout + result.stderr


STRICT = (
    "bearing_rig_sim/bags",
    "bearing_rig_sim/interfaces.py",
    "bearing_rig_sim/settings_model.py",
    "bearing_rig_sim/dynamics/bearing_file.py",
    "bearing_rig_sim/sweep/spec.py",
    "bearing_rig_sim/rig/parameters.py",
    "bearing_rig_sim/rig/program.py",
    "bearing_rig_sim/nodes/parameters.py",
)
"""Modules held to ``mypy --strict`` (the modules they import are checked by the plain run):
the bag storage, the contract every other part imports, and the parameter model with what is
built on it (the bearing, lubricant and calibration files, the sweep specifications, the rig
file's records, the test programs, the nodes' ROS descriptors)."""


def test_mypy_strict_passes_on_the_bags_the_contract_and_the_parameter_model() -> None:
    result = run("mypy", "--strict", "--follow-imports=silent", "--cache-dir", "/dev/null", *STRICT)
    assert result.returncode == 0, result.stdout + result.stderr


def test_every_type_ignore_gives_its_reason() -> None:
    bare = []
    for path in sorted((ROOT / "bearing_rig_sim").rglob("*.py")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            match = re.search(r"# type: ignore(\[[^\]]*\])?(.*)$", line)
            if match and not re.search(r"[-#]\s*\w", match.group(2)):
                bare.append(f"{path.relative_to(ROOT)}:{number}")
    assert not bare, "type: ignore without a reason: " + ", ".join(bare)


def long_functions(source: str, limit: int = MAX_FUNCTION_LINES) -> list[tuple[str, int]]:
    """The functions and methods of a module's source longer than ``limit`` lines: (name, lines)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            first = min([node.lineno, *(d.lineno for d in node.decorator_list)])
            lines = (node.end_lineno or node.lineno) - first + 1
            if lines > limit:
                found.append((node.name, lines))
    return found


def test_no_function_runs_over_150_lines() -> None:
    giants = [
        f"{path.relative_to(ROOT)}:{name} ({lines} lines)"
        for path in sorted((ROOT / "bearing_rig_sim").rglob("*.py"))
        for name, lines in long_functions(path.read_text(encoding="utf-8"))
    ]
    assert not giants, f"functions over {MAX_FUNCTION_LINES} lines: " + ", ".join(giants)


def test_the_length_check_counts_a_long_function() -> None:
    """The check itself can fail: a decorated function of 151 lines is caught, one of 150 is not."""
    body = "".join(f"    x{i} = {i}\n" for i in range(148))
    source = f"@staticmethod\ndef f():\n{body}    return 0\n\ndef g():\n{body}    return 0\n"
    assert long_functions(source) == [("f", 151)]
