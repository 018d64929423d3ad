"""The shipped bearing, calibration and rig files are named in one place (bearing_rig_sim.config),
and the node parameter files and the test programs that name them name the same files."""

from __future__ import annotations

import re
from pathlib import Path

import yaml

from bearing_rig_sim import config
from bearing_rig_sim.dynamics.calibrations import NAMED

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "bearing_rig_sim"

SHIPPED_NAME = re.compile(r"h7006c\.yaml|h7006c_table3\.yaml")


def test_the_shipped_files_exist_where_config_names_them() -> None:
    assert config.shipped_bearing_file().is_file() and config.shipped_bearing_file().name == "h7006c.yaml"
    assert config.shipped_calibration_file().is_file() and config.shipped_calibration_file().parent.name == "calibration"
    assert config.shipped_rig_file().is_file()


def test_no_other_module_spells_the_shipped_names() -> None:
    """Outside config.py (and its docstring example) no code names the shipped bearing or
    calibration file: every default goes through config.shipped_bearing_file() /
    shipped_calibration_file()."""
    spelled = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        name = str(path.relative_to(ROOT))
        code = re.sub(r'"""(?:.|\n)*?"""', "", path.read_text(encoding="utf-8"))  # docstrings may cite the files
        code = "\n".join(line.split("#", 1)[0] for line in code.splitlines())
        if name != "bearing_rig_sim/config.py" and SHIPPED_NAME.search(code):
            spelled.add(name)
    assert not spelled, sorted(spelled)


def test_the_node_files_name_the_shipped_bearing_and_calibration() -> None:
    """The nodes' defaults (their parameter files) are the same files the commands and cores use."""
    for node, keys in (("simulator", ("bearing_file", "calibration_file")), ("shadow", ("bearing_file", "calibration_file")), ("monitor", ("bearing_file",))):
        values = yaml.safe_load((ROOT / "config" / f"{node}.yaml").read_text(encoding="utf-8"))[node]["ros__parameters"]
        shipped = {"bearing_file": {config.SHIPPED_BEARING_FILE}, "calibration_file": {config.SHIPPED_CALIBRATION_FILE, *NAMED}}
        for key in keys:  # a calibration by its file or by its name in the registry (dynamics/calibrations.py)
            assert values[key] in shipped[key], (node, key)
