"""The rig on a full ROS 2 Jazzy install: ``ros2 launch bearing_rig_sim rig.launch.py``.

Starts the simulator, the load controller and the monitor as managed (lifecycle) nodes and brings
them up as ``bearing-rig run`` does: configure each in turn (simulator, load controller, monitor),
then activate each in turn, every step on the previous one's transition event. Each step of the
bring-up is taken once: a node cycled by hand afterwards (``ros2 lifecycle set /simulator
deactivate``, then ``activate``) changes that node alone, and the program and recorder are not
started again. Then, with a ``program``, runs it with ``python -m bearing_rig_sim.cli run PROGRAM
--attach --no-record`` (the program runner, live progress and summary, on these nodes; the
interpreter running the launch, so no ``bearing-rig`` on PATH is needed); when it ends the launch
shuts down, with exit status 0 when the program passed and 1 otherwise. With ``record:=true`` it
records the rig's topics with ``ros2 bag record`` (MCAP storage) into ``bag_dir``: every topic of
the interface contract (``bearing_rig_sim.interfaces.TOPICS``), as a session records them.

Arguments:
  program:=PROGRAM    test program: a YAML file or a shipped program's name (validation); empty (default): the nodes only
  record:=true|false  record with ros2 bag record (default false)
  bag_dir:=DIR        where ros2 bag record writes (default bags/launch)
  realtime:=true|false  simulator locked to the wall clock (default true)

The nodes read their shipped parameter files (config/<node>.yaml) by themselves; override single
parameters in the usual launch ways (a wrapping launch file, ``--ros-args`` in ``ros2 run``).

launch and launch_ros are not on PyPI: this file runs on a full ROS 2 install, or from the
README's set-up with the stock tools of ``../shared/ros2`` (docs/ros.md); ``bearing-rig run`` needs
neither.
"""

from __future__ import annotations

import sys

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, EmitEvent, ExecuteProcess, RegisterEventHandler, Shutdown
from launch.conditions import IfCondition
from launch.event_handlers import OnProcessExit
from launch.events import matches_action
from launch.events.process import ProcessExited
from launch.launch_context import LaunchContext
from launch.substitutions import LaunchConfiguration, PythonExpression
from launch_ros.actions import LifecycleNode
from launch_ros.event_handlers import OnStateTransition
from launch_ros.events.lifecycle import ChangeState
from lifecycle_msgs.msg import Transition

from bearing_rig_sim.interfaces import TOPICS

NODES = ("simulator", "load_controller", "monitor")
"""Bring-up order: the source of /clock first."""

RECORDED: tuple[str, ...] = tuple(topic.name for topic in TOPICS)
"""What ``record:=true`` records: the interface contract's topics, as a session records them."""


def _change(node: LifecycleNode, transition: int) -> EmitEvent:
    return EmitEvent(event=ChangeState(lifecycle_node_matcher=matches_action(node), transition_id=transition))


def _on(node: LifecycleNode, goal: str, action: EmitEvent | ExecuteProcess) -> RegisterEventHandler:
    """``action`` the first time ``node`` reaches ``goal`` (never again: see the module docstring)."""
    return RegisterEventHandler(OnStateTransition(target_lifecycle_node=node, goal_state=goal, entities=[action], handle_once=True))


def _program_ended(event: ProcessExited, _context: LaunchContext) -> list[Shutdown]:
    """Shut the launch down when the program runner ends; a failed program fails the launch."""
    if event.returncode != 0:
        raise RuntimeError(f"the program ended with exit status {event.returncode}")
    return [Shutdown(reason="the program ended")]


def generate_launch_description() -> LaunchDescription:
    program = LaunchConfiguration("program")
    record = LaunchConfiguration("record")
    nodes = [
        LifecycleNode(
            package="bearing_rig_sim",
            executable=name,
            name=name,
            namespace="",
            output="screen",
            parameters=[{"realtime": LaunchConfiguration("realtime")}] if name == "simulator" else [],
        )
        for name in NODES
    ]
    steps: list[RegisterEventHandler | EmitEvent] = [_change(nodes[0], Transition.TRANSITION_CONFIGURE)]
    # configure each in turn, then activate each in turn
    for previous, following in zip(nodes, nodes[1:]):
        steps.append(_on(previous, "inactive", _change(following, Transition.TRANSITION_CONFIGURE)))
    steps.append(_on(nodes[-1], "inactive", _change(nodes[0], Transition.TRANSITION_ACTIVATE)))
    for previous, following in zip(nodes, nodes[1:]):
        steps.append(_on(previous, "active", _change(following, Transition.TRANSITION_ACTIVATE)))
    runner = ExecuteProcess(
        cmd=[sys.executable, "-m", "bearing_rig_sim.cli", "run", program, "--attach", "--no-record"],
        output="screen",
        condition=IfCondition(PythonExpression(["'", program, "' != ''"])),
    )
    recorder = ExecuteProcess(
        cmd=["ros2", "bag", "record", "-s", "mcap", "-o", LaunchConfiguration("bag_dir"), *RECORDED],
        output="screen",
        condition=IfCondition(record),
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument("program", default_value="", description="test program: a YAML file or a shipped program's name; empty: the nodes only"),
            DeclareLaunchArgument("record", default_value="false", description="record the rig's topics with ros2 bag record"),
            DeclareLaunchArgument("bag_dir", default_value="bags/launch", description="output of ros2 bag record"),
            DeclareLaunchArgument("realtime", default_value="true", description="simulator locked to the wall clock"),
            *nodes,
            *steps,
            _on(nodes[-1], "active", recorder),
            _on(nodes[-1], "active", runner),
            RegisterEventHandler(OnProcessExit(target_action=runner, on_exit=_program_ended)),
        ]
    )
