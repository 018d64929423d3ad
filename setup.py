"""ament_python package bearing_rig_sim.

Builds with ``colcon build`` in a ROS 2 Jazzy workspace and installs with ``pip install -e .``
into the project's virtual environment (see bootstrap.sh).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from setuptools import find_packages, setup

PACKAGE_NAME = "bearing_rig_sim"
HERE = Path(__file__).resolve().parent


def read_version() -> str:
    """The version declared in bearing_rig_sim/__init__.py (single source)."""
    text = (HERE / PACKAGE_NAME / "__init__.py").read_text(encoding="utf-8")
    match = re.search(r'^__version__ = "([^"]+)"', text, re.MULTILINE)
    if match is None:
        raise RuntimeError(f"{PACKAGE_NAME}/__init__.py: no __version__ line")
    return match.group(1)


def config_data_files() -> list[tuple[str, list[str]]]:
    """Every file under config/, installed into share/bearing_rig_sim/config/<same subfolder>."""
    entries = []
    for folder, _dirs, files in sorted(os.walk(HERE / "config")):
        if files:
            relative = os.path.relpath(folder, HERE)
            entries.append((os.path.join("share", PACKAGE_NAME, relative), sorted(os.path.join(relative, f) for f in files)))
    return entries


setup(
    name=PACKAGE_NAME,
    version=read_version(),
    packages=find_packages(exclude=["test", "test.*"]),
    package_data={PACKAGE_NAME: ["py.typed"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE_NAME}"]),
        (f"share/{PACKAGE_NAME}", ["package.xml"]),
        (f"share/{PACKAGE_NAME}/launch", ["launch/rig.launch.py"]),
        *config_data_files(),
    ],
    install_requires=["setuptools"],
    # colcon test runs pytest (not unittest's discovery, which finds none of the suite) for a
    # package with pytest among its test dependencies.
    extras_require={"test": ["pytest"]},
    zip_safe=True,
    maintainer="bearing-rig-sim maintainers",
    maintainer_email="bearing-rig-sim@example.org",
    description="Digital twin of the H7006C angular contact ball bearing cage-slip test rig",
    license="Apache-2.0",
    entry_points={
        "console_scripts": [
            "bearing-rig = bearing_rig_sim.cli:main",
            # ROS 2 node executables (`ros2 run bearing_rig_sim <name>`), each also under a
            # bearing-rig-* name for shells without ROS.
            "load_controller = bearing_rig_sim.nodes.load_controller:main",
            "bearing-rig-load-controller = bearing_rig_sim.nodes.load_controller:main",
            "simulator = bearing_rig_sim.nodes.simulator:main",
            "bearing-rig-simulator = bearing_rig_sim.nodes.simulator:main",
            "monitor = bearing_rig_sim.nodes.monitor:main",
            "bearing-rig-monitor = bearing_rig_sim.nodes.monitor:main",
            "shadow = bearing_rig_sim.nodes.shadow:main",
            "bearing-rig-shadow = bearing_rig_sim.nodes.shadow:main",
        ],
    },
)
