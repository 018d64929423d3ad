"""Node processes without ROS: a child that dies is described with its status and output tail; a
child that ignores SIGINT is still stopped; CPU time from /proc; the session's private domain and
environment; executables found next to the interpreter or refused with a clear error; run id and
run context.
"""

from __future__ import annotations

import os
import sys
import time
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

from conftest import time_left
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.program import load_program
from bearing_rig_sim.config import config_path
from bearing_rig_sim.session.context import make_run_id, run_context
from bearing_rig_sim.session.processes import (
    NODES,
    NodeProcess,
    NodeSpec,
    lease_domain,
    node_command,
    process_cpu_seconds,
    session_environment,
    stop_all,
)


def python_child(tmp_path: Path, name: str, code: str) -> NodeProcess:
    return NodeProcess(name, [sys.executable, "-c", code], tmp_path / "logs" / f"{name}.log")


def wait_for_output(child: NodeProcess, line: str) -> None:
    """Wait until ``child`` has printed ``line`` (it flushes it), or fail when the test's guard
    (:func:`conftest.time_left`) runs out: a child's start on a loaded host is what is waited for."""
    guard = time_left()
    deadline = time.monotonic() + guard
    while line not in child.output_tail().splitlines():
        assert child.poll() is None, child.describe_exit()
        assert time.monotonic() < deadline, f"{child.name} printed no {line!r} in {guard:.0f} s"
        child.wait(0.02)


def test_a_dead_child_is_described_with_its_status_and_output_tail(tmp_path: Path) -> None:
    child = python_child(tmp_path, "simulator", "import sys\nfor i in range(40): print('line', i, file=sys.stderr)\nsys.exit(3)")
    child.start(os.environ)
    assert child.wait(time_left()) == 3 and not child.running
    text = child.describe_exit(lines=5)
    assert text.startswith("simulator exited with status 3")
    assert "line 39" in text and "line 35" in text and "line 34" not in text
    stop_all([child])


def test_stop_all_stops_a_child_that_ignores_sigint(tmp_path: Path) -> None:
    """SIGINT first: a child that takes it exits cleanly, and stop_all returns once it has (its
    timeout only the bound for a child that does not); one that ignores it gets SIGTERM once the
    timeout has passed. Each is stopped on its own, so neither outcome depends on how soon a
    loaded host runs the polite child's handler."""
    stubborn = python_child(tmp_path, "monitor", "import signal, time\nsignal.signal(signal.SIGINT, signal.SIG_IGN)\nprint('up', flush=True)\ntime.sleep(600)")
    polite = python_child(
        tmp_path, "load_controller", "import time\ntry:\n    print('up', flush=True)\n    time.sleep(600)\nexcept KeyboardInterrupt:\n    pass"
    )
    for child in (stubborn, polite):
        child.start(os.environ)
    for child in (stubborn, polite):
        wait_for_output(child, "up")  # started, and the stubborn one ignores SIGINT
    stop_all([polite], timeout=time_left())
    assert polite.poll() == 0  # SIGINT: a clean exit
    stop_all([stubborn], timeout=0.5)
    assert stubborn.poll() is not None and stubborn.poll() < 0  # SIGTERM after the timeout
    assert stubborn.stop_requested and polite.stop_requested


def test_cpu_seconds_of_a_busy_child(tmp_path: Path) -> None:
    """The child spins until its own CPU time (``time.process_time``, since it started) has
    passed 0.35 s and says so; /proc then gives at least 0.3 s (user and system time, each in
    whole 10 ms ticks, lose at most 20 ms together)."""
    busy = python_child(tmp_path, "busy", "import time\nwhile time.process_time() < 0.35: pass\nprint('spent', flush=True)\ntime.sleep(600)")
    busy.start(os.environ)
    try:
        wait_for_output(busy, "spent")
        used = busy.cpu_seconds()
        assert used is not None and used >= 0.3
    finally:
        stop_all([busy])
    assert process_cpu_seconds(2**22 + 12345) is None  # no such process


def test_session_environment_keeps_the_users_domain_or_leases_a_private_one() -> None:
    env, lease = session_environment({"ROS_DOMAIN_ID": "42", "PATH": "/bin"})
    assert env["ROS_DOMAIN_ID"] == "42" and env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    lease.release()
    env, lease = session_environment({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"})
    try:
        assert 102 <= int(env["ROS_DOMAIN_ID"]) <= 232 and env["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "SUBNET"
        other = lease_domain()  # a second session meanwhile gets another domain
        assert other.domain_id != lease.domain_id
        other.release()
    finally:
        lease.release()
    with pytest.raises(RigError, match="whole number"):
        session_environment({"ROS_DOMAIN_ID": "seven"})


def test_node_executables_are_found_or_refused_by_name() -> None:
    command = node_command(NODES["load_controller"])
    assert Path(command[0]).name == "bearing-rig-load-controller" and os.access(command[0], os.X_OK)
    with pytest.raises(RigError, match="no-such-node-script"):
        node_command(NodeSpec("phantom", "no-such-node-script"))


def test_run_id_and_run_context() -> None:
    start = datetime(2025, 6, 12, 11, 30, 15, tzinfo=timezone(timedelta(hours=2)))
    assert make_run_id("validation", start) == "20250612T093015Z-validation"
    assert make_run_id("my test/1", start).endswith("-my_test_1")
    with pytest.raises(ValueError):
        make_run_id("x", datetime(2025, 1, 1))
    program = load_program(config_path("programs", "validation.yaml"))
    context = run_context(program, run_id="r", start=start, command_line=["bearing-rig", "run", "a b"], extra={"k": "v"})
    assert "segments:" in context["program"] and context["program_file"].endswith("validation.yaml")
    assert "geometry" in context["bearing"] and "loading_chain:" in context["rig"]
    assert any(key.startswith("calibration/h7006c_") for key in context)
    assert context["command_line"] == "bearing-rig run 'a b'" and context["k"] == "v"
    assert all(isinstance(v, str) for v in context.values())


def test_the_programs_bearing_is_the_one_the_nodes_use(tmp_path: Path) -> None:
    """A program naming another bearing file gets it passed to the simulator and the monitor,
    uncalibrated (the shipped calibration is the H7006C's); the shipped bearing needs nothing."""
    from bearing_rig_sim.session.context import node_parameters
    from bearing_rig_sim.simulation.settings import shipped_parameters

    defaults = shipped_parameters()
    shipped = load_program(config_path("programs", "validation.yaml"))
    assert node_parameters(shipped, defaults) == {}
    other = tmp_path / "h7006c_copy.yaml"
    other.write_text(config_path("bearings", "h7006c.yaml").read_text(encoding="utf-8"), encoding="utf-8")
    program = tmp_path / "p.yaml"
    program.write_text(
        config_path("programs", "validation.yaml").read_text(encoding="utf-8").replace("bearings/h7006c.yaml", str(other)),
        encoding="utf-8",
    )
    overrides = node_parameters(load_program(program), defaults)
    assert overrides == {
        "simulator": {"bearing_file": str(other.resolve()), "calibration_file": ""},
        "monitor": {"bearing_file": str(other.resolve())},
    }


@pytest.mark.ros
def test_parameter_arguments_reach_a_node_unchanged(ros_graph: object) -> None:
    """What ``bearing-rig run`` passes with ``-p`` is read back by rcl as it was meant: an
    empty string (an uncalibrated run's ``calibration_file``; bare it made rcl refuse the whole
    command line), a path with ``: `` and ``#`` in it, strings that read as a boolean or a
    number, a boolean and a float."""
    import rclpy
    from rclpy.node import Node

    from bearing_rig_sim.session.context import parameter_arguments

    values: dict[str, str | bool | int | float] = {
        "empty": "",
        "path": "/data/bearings: v2 #1/h7006c.yaml",
        "word": "true",
        "digits": "1.5",
        "flag": False,
        "rate": 2.5,
        "count": 3,
    }
    context = rclpy.Context()
    rclpy.init(args=["probe", "--ros-args", *parameter_arguments(values)], context=context)
    try:
        node = Node("probe", context=context)
        read = {name: node.declare_parameter(name, type(value)() if not isinstance(value, bool) else True).value for name, value in values.items()}
        node.destroy_node()
    finally:
        context.try_shutdown()
    assert read == values
    assert all(type(read[k]) is type(v) for k, v in values.items())


def test_a_program_naming_a_file_that_is_no_bearing_data_is_refused_at_load(tmp_path: Path) -> None:
    """The audit's case: a program naming any readable file (here a rig file) got it embedded as
    the run's bearing; now it is read as the simulator would read it, and refused by key."""
    from bearing_rig_sim.config import ConfigError
    from bearing_rig_sim.session.context import check_bearing_file

    program = tmp_path / "p.yaml"
    program.write_text(
        config_path("programs", "validation.yaml").read_text(encoding="utf-8").replace("bearings/h7006c.yaml", str(config_path("rig.yaml"))),
        encoding="utf-8",
    )
    with pytest.raises(ConfigError, match=r"p\.yaml: bearing: not usable bearing data: .*rig\.yaml"):
        check_bearing_file(load_program(program), program)
    check_bearing_file(load_program(config_path("programs", "validation.yaml")), "validation.yaml")  # the shipped one reads


@pytest.mark.parametrize(
    "text, problem",
    [
        ("root:x:0:0:root:/root:/bin/bash\n", "maps node names to blocks; its top level is a str"),
        (
            "simulater:\n  ros__parameters:\n    rate: 2.0\n",
            "simulater: no node of a session has this name (its nodes: simulator, load_controller, monitor; did you mean simulator?)",
        ),
        ("load_controller:\n  ros__parameters:\n    kp: 3.0\n", "load_controller.ros__parameters.kp: load_controller has no such parameter"),
        ("/**:\n  ros__parameters:\n    nosuch: 1\n", "/**.ros__parameters.nosuch: simulator load_controller monitor have no such parameter"),
        ("simulator:\n  ros__parameters:\n    rate: -5.0\n", "simulator.ros__parameters: rate: must be > 0"),
        ("simulator:\n  ros__parameters:\n    rate: fast\n", "simulator.ros__parameters: rate: must be a number"),
        ("monitor:\n  rate: 2.0\n", "monitor: must be a mapping with a ros__parameters mapping"),
    ],
)
def test_a_parameter_file_is_checked_against_the_nodes_before_a_run(tmp_path: Path, text: str, problem: str) -> None:
    """rclpy drops a parameter no node declares without a word, so a misspelt name or node
    would change nothing; each case is refused by name before any node starts."""
    from bearing_rig_sim.config import ConfigError
    from bearing_rig_sim.session.context import check_parameter_file

    path = tmp_path / "params.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as caught:
        check_parameter_file(path)
    assert str(caught.value).startswith(f"{path}: ") and problem in str(caught.value), str(caught.value)


def test_a_sound_parameter_file_passes(tmp_path: Path) -> None:
    from bearing_rig_sim.session.context import check_parameter_file

    path = tmp_path / "params.yaml"
    path.write_text(
        "/**:\n  ros__parameters:\n    use_sim_time: false\n    rate: 2.0\n/rig/load_controller:\n  ros__parameters:\n    use_sim_time: true\n",
        encoding="utf-8",
    )
    check_parameter_file(path)


DUMPED = """/load_controller:
  ros__parameters:
    axial_load_setpoint_n: 250.0
    qos_overrides:
      /parameter_events:
        publisher:
          depth: 1000
          durability: volatile
          history: keep_last
          reliability: reliable
    start_type_description_service: true
    state_rate_hz: 50.0
    use_sim_time: true
"""
"""What ``ros2 param dump /load_controller`` writes (ros2param's layout: the node's fully qualified
name, nested ``qos_overrides`` of the parameter-events publisher, and the parameters every Jazzy
node declares beside the node's own)."""


def test_a_file_written_by_ros2_param_dump_passes_and_a_parameter_the_node_lacks_is_still_refused(tmp_path: Path) -> None:
    from bearing_rig_sim.config import ConfigError
    from bearing_rig_sim.session.context import check_parameter_file

    path = tmp_path / "dumped.yaml"
    path.write_text(DUMPED, encoding="utf-8")
    check_parameter_file(path)
    path.write_text(DUMPED + "    kp: 3.0\n", encoding="utf-8")
    with pytest.raises(ConfigError, match=r"load_controller\.ros__parameters\.kp: load_controller has no such parameter"):
        check_parameter_file(path)
    path.write_text(DUMPED.replace("state_rate_hz: 50.0", "state_rate_hz: -1.0"), encoding="utf-8")
    with pytest.raises(ConfigError, match=r"state_rate_hz"):  # the node's own are still checked
        check_parameter_file(path)
