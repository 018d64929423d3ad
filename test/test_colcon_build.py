"""Both packages build in a colcon workspace, as they would in a full ROS 2 Jazzy install.

The repository is copied into a temporary workspace as ``src/bearing-rig-sim`` and built with
the virtual environment as the underlay (``AMENT_PREFIX_PATH=CMAKE_PREFIX_PATH=$VENV``).
colcon does not descend into a package's subfolders, so both package paths are named:
``colcon build --paths src/bearing-rig-sim src/bearing-rig-sim/msg_defs``. Then, in the
environment of the workspace's ``install/setup.bash`` (what ``ros2 run`` sees), the
interfaces and the package must load from the workspace, not from the venv.

colcon comes with requirements.lock; without it the tests are skipped as tier ``colcon``, a
failure in CI unless ``BEARING_RIG_ALLOW_MISSING`` names the tier (test/conftest.py). Every
command is bounded by what is left of the test's :data:`TIMEOUT_S`.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import skip_missing, time_left

TIMEOUT_S = 600
"""Each test's limit, s: the workspace build (in the first test's set-up; about a minute here,
a few under load) and the test's own commands."""

pytestmark = pytest.mark.timeout(TIMEOUT_S)

REPO_ROOT = Path(__file__).resolve().parent.parent
VENV = Path(sys.prefix)
SOURCES = ("setup.py", "setup.cfg", "package.xml", "resource", "bearing_rig_sim", "config", "launch", "msg_defs", "test", "pytest.ini", "README.md", "docs")
IGNORE = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc", "*.egg-info", "node_modules")


def _relative_files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A colcon workspace with both packages built and installed (built once for the module)."""
    if not (VENV / "bin" / "colcon").is_file():
        skip_missing("colcon", f"no {VENV / 'bin' / 'colcon'} (./bootstrap.sh setup installs it from requirements.lock)")
    ws = tmp_path_factory.mktemp("colcon_ws")
    source = ws / "src" / "bearing-rig-sim"
    source.mkdir(parents=True)
    for name in SOURCES:
        origin = REPO_ROOT / name
        if origin.is_dir():
            shutil.copytree(origin, source / name, ignore=IGNORE)
        else:
            shutil.copy2(origin, source / name)
    env = dict(os.environ)
    env.update(
        PATH=f"{VENV / 'bin'}{os.pathsep}{env.get('PATH', '')}",
        AMENT_PREFIX_PATH=str(VENV),
        CMAKE_PREFIX_PATH=str(VENV),
        COLCON_HOME=str(ws / ".colcon"),
    )
    env.pop("COLCON_DEFAULTS_FILE", None)
    command = [
        str(VENV / "bin" / "colcon"),
        "build",
        "--paths",
        "src/bearing-rig-sim",
        "src/bearing-rig-sim/msg_defs",
        "--event-handlers",
        "console_direct-",
        "--cmake-args",
        f"-DPython3_EXECUTABLE={VENV / 'bin' / 'python'}",
        "-DBUILD_TESTING=OFF",
    ]
    result = subprocess.run(command, cwd=ws, env=env, capture_output=True, text=True, timeout=time_left())
    assert result.returncode == 0, f"colcon build failed:\n{result.stdout[-4000:]}\n{result.stderr[-4000:]}"
    for package in ("bearing_rig_msgs", "bearing_rig_sim"):
        assert f"Finished <<< {package}" in result.stdout, result.stdout[-2000:]
    return ws


def _in_workspace(ws: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    """Run ``argv`` in the workspace after sourcing its install/setup.bash."""
    env = dict(os.environ)
    env["PATH"] = f"{VENV / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["AMENT_PREFIX_PATH"] = str(VENV)
    env.pop("PYTHONPATH", None)
    return subprocess.run(
        ["bash", "-c", 'source install/setup.bash && exec "$@"', "bash", *argv],
        cwd=ws,
        env=env,
        capture_output=True,
        text=True,
        timeout=min(120.0, time_left()),
    )


@pytest.mark.slow
def test_interface_package_is_installed(workspace: Path) -> None:
    prefix = workspace / "install" / "bearing_rig_msgs"
    assert (prefix / "share" / "bearing_rig_msgs" / "package.xml").is_file()
    assert (prefix / "share" / "ament_index" / "resource_index" / "packages" / "bearing_rig_msgs").is_file()
    interfaces = prefix / "share" / "ament_index" / "resource_index" / "rosidl_interfaces" / "bearing_rig_msgs"
    listed = set(interfaces.read_text(encoding="utf-8").split())
    for definition in (REPO_ROOT / "msg_defs").glob("*/*.*"):
        if definition.suffix in (".msg", ".srv"):
            assert f"{definition.parent.name}/{definition.name}" in listed
    assert (prefix / "lib" / "libbearing_rig_msgs__rosidl_typesupport_c.so").is_file()
    assert (prefix / "lib" / "libbearing_rig_msgs__rosidl_typesupport_fastrtps_c.so").is_file()
    site = prefix / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    assert (site / "bearing_rig_msgs" / "msg" / "_slip_status.py").is_file()


@pytest.mark.slow
def test_python_package_is_installed_the_ament_way(workspace: Path) -> None:
    prefix = workspace / "install" / "bearing_rig_sim"
    script = prefix / "lib" / "bearing_rig_sim" / "bearing-rig"
    assert script.is_file() and os.access(script, os.X_OK), "console script not in lib/bearing_rig_sim"
    assert (prefix / "share" / "ament_index" / "resource_index" / "packages" / "bearing_rig_sim").is_file()
    assert (prefix / "share" / "bearing_rig_sim" / "package.xml").is_file()
    installed_config = _relative_files(prefix / "share" / "bearing_rig_sim" / "config")
    assert installed_config == _relative_files(REPO_ROOT / "config")
    assert installed_config, "config/ is empty"


@pytest.mark.slow
def test_workspace_packages_load_from_the_workspace(workspace: Path) -> None:
    code = (
        "import json\n"
        "import bearing_rig_msgs.msg as m, bearing_rig_sim\n"
        "from rclpy.serialization import serialize_message, deserialize_message\n"
        "from ament_index_python.packages import get_package_share_directory\n"
        "msg = m.FibreOpticPulse(sensor_id='cage', revolution=12)\n"
        "back = deserialize_message(serialize_message(msg), m.FibreOpticPulse)\n"
        "assert back == msg, back\n"
        "libs = [l.split()[-1] for l in open('/proc/self/maps') if 'libbearing_rig_msgs__' in l]\n"
        "print(m.__file__); print(bearing_rig_sim.__file__)\n"
        "print(get_package_share_directory('bearing_rig_sim'))\n"
        "print(json.dumps(sorted(set(libs))))\n"
    )
    result = _in_workspace(workspace, "python", "-c", code)
    assert result.returncode == 0, result.stderr
    msgs_file, sim_file, share, libs = result.stdout.strip().splitlines()[-4:]
    install = str(workspace / "install")
    assert msgs_file.startswith(install), msgs_file
    assert sim_file.startswith(install), sim_file
    assert share == str(workspace / "install" / "bearing_rig_sim" / "share" / "bearing_rig_sim")
    loaded = json.loads(libs)
    assert loaded and all(path.startswith(install) for path in loaded), loaded


@pytest.mark.slow
def test_console_script_runs_from_the_workspace(workspace: Path) -> None:
    result = _in_workspace(workspace, "install/bearing_rig_sim/lib/bearing_rig_sim/bearing-rig", "--version")
    assert result.returncode == 0, result.stderr
    from bearing_rig_sim import __version__

    assert result.stdout.strip() == f"bearing-rig {__version__}"


@pytest.mark.slow
def test_launch_file_is_installed_and_byte_compiles(workspace: Path) -> None:
    """``ros2 launch bearing_rig_sim rig.launch.py`` finds it in share/ (launch itself is not on
    PyPI, so it is not run here: it must at least compile, with the node executables it names
    installed beside)."""
    installed = workspace / "install" / "bearing_rig_sim" / "share" / "bearing_rig_sim" / "launch" / "rig.launch.py"
    assert installed.is_file()
    assert installed.read_bytes() == (REPO_ROOT / "launch" / "rig.launch.py").read_bytes()
    compile(installed.read_text(encoding="utf-8"), str(installed), "exec")
    for name in ("simulator", "load_controller", "monitor"):
        executable = workspace / "install" / "bearing_rig_sim" / "lib" / "bearing_rig_sim" / name
        assert executable.is_file() and os.access(executable, os.X_OK), name
        assert f'"{name}"' in installed.read_text(encoding="utf-8")


@pytest.mark.slow
def test_colcon_test_runs_the_package_tests_with_pytest(workspace: Path) -> None:
    """``colcon test`` runs the package's tests with pytest (for a package without pytest among
    its test dependencies it falls back to unittest's discovery, which finds none of them and
    reports 0 tests as a pass). A small file of the suite here; CI's colcon test runs it all."""
    env = dict(os.environ)
    env.update(PATH=f"{VENV / 'bin'}{os.pathsep}{env.get('PATH', '')}", AMENT_PREFIX_PATH=str(VENV), COLCON_HOME=str(workspace / ".colcon"))
    colcon = str(VENV / "bin" / "colcon")
    result = subprocess.run(
        [colcon, "test", "--paths", "src/bearing-rig-sim", "--event-handlers", "console_direct-", "--pytest-args", "test/test_interfaces.py"],
        cwd=workspace,
        env=env,
        capture_output=True,
        text=True,
        timeout=time_left(),
    )
    assert result.returncode == 0, f"{result.stdout[-3000:]}\n{result.stderr[-3000:]}"
    summary = subprocess.run(
        [colcon, "test-result", "--test-result-base", "build/bearing_rig_sim"],
        cwd=workspace,
        env=env,
        capture_output=True,
        text=True,
        timeout=min(120.0, time_left()),
    )
    line = summary.stdout.strip().splitlines()[-1]
    tests = int(line.split()[1])
    assert tests > 0 and "0 errors, 0 failures" in line, summary.stdout
