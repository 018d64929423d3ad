"""The style is enforced, not just described: ruff (ruff.toml) and mypy (setup.cfg) pass on the
tree, ``mypy --strict`` on the interface contract and the parameter model, and every remaining ``type: ignore`` says why."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from conftest import time_left

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent


def run(tool: str, *args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(BIN / tool), *args], cwd=ROOT, capture_output=True, text=True, timeout=time_left(), check=False)


def test_ruff_passes() -> None:
    result = run("ruff", "check", "--no-cache", "bearing_rig_sim", "test")
    assert result.returncode == 0, result.stdout + result.stderr


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
