"""What every node of the rig shares: QoS profiles, time stamps, diagnostics, the main shell.

The QoS profiles are the ones of the interface table (README, docs/interfaces.md). Nodes are
thin shells: each wires publishers, subscriptions, timers and parameters around a ROS-free core
and starts through :func:`run_node`, which spins it on rclpy's ``EventsExecutor`` (see
:func:`node_executor`).
"""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import rclpy
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.exceptions import InvalidParameterTypeException, InvalidParameterValueException
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from bearing_rig_sim.dds_profile import use_rig_profile
from bearing_rig_sim.config import config_path
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import QOS_DESCRIPTIONS, QOS_TABLE, QosEntry, Topic


def qos_profile(which: Topic | str | QosEntry) -> QoSProfile:
    """The rclpy QoS profile of a topic of the contract (its publisher's), of a profile named in
    :data:`bearing_rig_sim.interfaces.QOS_TABLE`, or of an entry of that table."""
    if isinstance(which, Topic):
        which = which.qos
    entry = QOS_TABLE[which] if isinstance(which, str) else which
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=entry.depth,
        reliability=ReliabilityPolicy.RELIABLE if entry.reliability == "reliable" else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if entry.durability == "transient_local" else DurabilityPolicy.VOLATILE,
    )


SENSOR_QOS = qos_profile("sensor_data")
"""Sensor streams (pulses, speeds, load cell, truth): best effort, keep last 100."""

RELIABLE_QOS = qos_profile("reliable")
"""Commands, set-points, /clock, /diagnostics, the force to the simulator: reliable, depth 10."""

RELIABLE_STREAM_QOS = qos_profile("reliable_stream")
"""The contract's ``reliable_stream`` profile: the publishers of the simulator's streams
(``/clock``, pulses, speeds, truth) and of the force on the bearing (see ``QOS_TABLE``)."""

PULSE_READER_QOS = qos_profile("pulse_reader")
"""The monitor's and the shadow node's pulse subscriptions: sensor data, but deep."""

STATUS_QOS = qos_profile("transient_local")
"""Latched state (slip status, spindle command): reliable, transient local, depth 10."""

UNKNOWN_NODE_NAME = "_NODE_NAME_UNKNOWN_"
"""The node name the ROS graph gives an endpoint whose node it has not discovered yet (rmw): the
endpoint is matched before its node's participant data has arrived."""


OK, WARN, ERROR, STALE = DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR, DiagnosticStatus.STALE


def to_stamp(seconds: float) -> Time:
    """A ``builtin_interfaces/Time`` for a time in seconds (>= 0)."""
    sec = math.floor(seconds)
    nanosec = int(round((seconds - sec) * 1e9))
    if nanosec >= 1_000_000_000:
        sec, nanosec = sec + 1, nanosec - 1_000_000_000
    return Time(sec=int(sec), nanosec=nanosec)


def from_stamp(stamp: Time) -> float:
    """Seconds of a ``builtin_interfaces/Time``."""
    return stamp.sec + stamp.nanosec * 1e-9


def diagnostic_status(name: str, level: bytes | int, message: str, values: Mapping[str, object], hardware_id: str = "bearing_rig") -> DiagnosticStatus:
    """One ``DiagnosticStatus`` with ``values`` as key/value strings."""
    lvl = level if isinstance(level, bytes) else bytes([level])
    return DiagnosticStatus(
        level=lvl, name=name, message=message, hardware_id=hardware_id, values=[KeyValue(key=str(k), value=str(v)) for k, v in values.items()]
    )


def diagnostic_array(stamp: Time, statuses: Sequence[DiagnosticStatus]) -> DiagnosticArray:
    """A ``DiagnosticArray`` for ``/diagnostics``."""
    msg = DiagnosticArray()
    msg.header.stamp = stamp
    msg.status = list(statuses)
    return msg


def default_params_file(node_name: str) -> Path:
    """The shipped parameter file of a node: ``config/<node_name>.yaml``."""
    return config_path(f"{node_name}.yaml")


def ros_args_with_defaults(node_name: str, argv: Sequence[str] | None) -> list[str]:
    """Command-line arguments for ``rclpy.init``: the given ones, with the shipped parameter file
    put first after ``--ros-args``, so parameter files and ``-p`` given by the user override it
    (a partial user file changes only what it names)."""
    args = list(sys.argv if argv is None else argv)
    path = default_params_file(node_name)
    if not path.exists():
        return args
    if "--ros-args" in args:
        i = args.index("--ros-args")
        return args[: i + 1] + ["--params-file", str(path)] + args[i + 1 :]
    return args + ["--ros-args", "--params-file", str(path)]


AUTOSTART_FLAG = "--autostart"
"""Command-line flag of every node's console script: configure and activate at once (what a
lifecycle manager would do), exit status 2 with the reason if configure fails."""


def split_autostart(argv: Sequence[str]) -> tuple[list[str], bool]:
    """``argv`` without :data:`AUTOSTART_FLAG`, and whether it was there."""
    args = list(argv)
    return [a for a in args if a != AUTOSTART_FLAG], AUTOSTART_FLAG in args


def _rcl_message(exc: Exception) -> str:
    """rcl's error text without the C source locations it appends (", at /path/file.c:123")."""
    return re.sub(r", at [^,]*\.c:\d+", "", " ".join(str(exc).split()))


EXECUTOR_ENV = "BEARING_RIG_EXECUTOR"
"""Environment variable naming the executor of the nodes: ``events`` (default) or ``single``."""

SPIN_SLICE_S = 0.5
"""Longest wait of one ``spin_once`` of the node loop, s: how soon a shutdown is seen when idle."""


def node_executor(kind: str | None = None) -> Executor:
    """The executor a node of the rig spins on.

    ``events`` (the default): rclpy's ``EventsExecutor`` (``rclpy.experimental``, in Jazzy since
    rclpy 7.1.4), which dispatches in C++ the events the middleware reports. The
    ``SingleThreadedExecutor`` rebuilds a wait set in Python over every timer, subscription,
    service and QoS event handler of the node at each wake-up; a lifecycle node has some twenty of
    them and wakes hundreds of times a second, so that walk costs more than the work it dispatches
    (``bearing-rig bench rig``: the monitor took 16 % of a core on it, 7 % on the events
    executor). ``single``: the ``SingleThreadedExecutor`` (``BEARING_RIG_EXECUTOR=single``), for
    comparison or should the events executor misbehave on some middleware.

    Raises:
        RigError: an unknown kind.
    """
    import os

    chosen = (kind if kind is not None else os.environ.get(EXECUTOR_ENV, "events")).strip().lower()
    if chosen == "single":
        return SingleThreadedExecutor()
    if chosen != "events":
        raise RigError(f"{EXECUTOR_ENV}={chosen!r}: expected 'events' or 'single'")
    from rclpy.experimental import EventsExecutor

    return EventsExecutor()


def spin_until_shutdown(executor: Executor, logger: Any = None) -> None:
    """Spin ``executor`` until the context shuts down (Ctrl-C, SIGTERM, ``rclpy.shutdown``).

    One ``spin_once`` at a time: the events executor's own ``spin()`` in rclpy 7.1.6 neither runs
    timers nor returns on a signal, its ``spin_once`` does both. An exception raised by a
    callback (service, subscription, timer) never ends the node: it is logged on ``logger`` (at
    most once a second) and the spin goes on.
    """
    while rclpy.ok():
        try:
            executor.spin_once(timeout_sec=SPIN_SLICE_S)
        except (KeyboardInterrupt, ExternalShutdownException):
            raise
        except Exception as exc:
            if not rclpy.ok():
                break
            if logger is not None:
                text = " ".join(str(exc).split()) or type(exc).__name__
                logger.error(f"a callback failed, the node carries on: {type(exc).__name__}: {text}", throttle_duration_sec=1.0)


def quiet_interrupt() -> None:
    """Let Ctrl-C (SIGINT) end the node through rclpy's shutdown alone, not as a Python
    ``KeyboardInterrupt``.

    rclpy's own signal handler shuts the context down, which ends :func:`spin_until_shutdown`'s
    loop; it then chains to Python's handler, whose ``KeyboardInterrupt`` can land inside a
    Python callback the events executor runs from C++ (seen in ``event_handler.__exit__`` after
    the node's cleanup, in 4 of 5 program runs under load). pybind11 cannot carry it through
    the C++ frame and the process aborts ("terminate called after throwing an instance of
    'pybind11::error_already_set'"). With a Python handler that does nothing, nothing is raised
    there, and the node exits 0 through its ``finally``. An interrupt that comes before rclpy's
    handler is installed is remembered (:data:`INTERRUPTED`) and ends the node once rclpy is up.
    """
    import signal

    def remember(_signum: int, _frame: object) -> None:
        INTERRUPTED.append(True)

    signal.signal(signal.SIGINT, remember)


INTERRUPTED: list[bool] = []
"""A SIGINT has come since :func:`quiet_interrupt` (non-empty when so)."""


def run_node(node_name: str, factory: Callable[[], Node], argv: Sequence[str] | None = None) -> int:
    """Initialise rclpy (with the node's shipped parameter file), spin the node made by
    ``factory`` on :func:`node_executor` until Ctrl-C or shutdown, then clean up.

    A lifecycle node starts unconfigured, driven by the standard ``lifecycle_msgs`` services;
    with ``--autostart`` it configures and activates itself first.

    Returns:
        The process exit status: 0, or 2 when ``--autostart`` could not configure or activate.

    Raises:
        RigError: malformed ROS arguments; the node could not be made (a parameter given at
            start out of its range or of the wrong type); an unknown executor kind.
    """
    args, autostart = split_autostart(sys.argv if argv is None else argv)
    quiet_interrupt()
    use_rig_profile()  # the rig's Fast DDS profile unless the user gave one (writer heartbeat)
    try:
        rclpy.init(args=ros_args_with_defaults(node_name, args))
    except RuntimeError as exc:  # rcl refused a malformed --params-file or -p: a user's error, said in one line
        raise RigError(f"ROS arguments refused: {_rcl_message(exc)}") from None
    if INTERRUPTED:  # Ctrl-C while starting, before rclpy's handler could shut the context down
        rclpy.try_shutdown()
        return 0
    node = None
    try:
        executor = node_executor()
    except RigError:
        rclpy.try_shutdown()
        raise
    try:
        try:
            node = factory()
        except (InvalidParameterTypeException, InvalidParameterValueException) as exc:
            raise RigError(f"parameter refused: {exc}") from None
        if autostart and hasattr(node, "trigger_configure"):
            failed = _autostart(node)
            if failed:
                print(f"{node_name}: error: {failed}", file=sys.stderr)
                return 2
        executor.add_node(node)
        spin_until_shutdown(executor, node.get_logger())
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            close = getattr(node, "close", None)
            if callable(close):
                close()
        # Release the executor's hold on the node's handles first: Jazzy's destroy_node waits
        # for them forever if a callback failed during shutdown.
        executor.shutdown(timeout_sec=1.0)
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


def node_main(node_name: str, factory: Callable[[], Node], argv: Sequence[str] | None = None) -> int:
    """A node's console script: :func:`run_node`, with a user's error (malformed ROS arguments, a
    parameter refused at start) said in one line ``<node_name>: error: ...`` on stderr.

    Returns:
        The process exit status: :func:`run_node`'s, or 2 after such an error.
    """
    try:
        return run_node(node_name, factory, argv)
    except RigError as exc:
        print(f"{node_name}: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2


def _autostart(node: Node) -> str:
    """Configure then activate a lifecycle node; why it failed, or "" when it is active."""
    from rclpy.lifecycle import TransitionCallbackReturn

    if node.trigger_configure() != TransitionCallbackReturn.SUCCESS:  # type: ignore[attr-defined]  # rclpy's lifecycle node has no type information
        return getattr(node, "configure_error", "") or "configure failed"
    if node.trigger_activate() != TransitionCallbackReturn.SUCCESS:  # type: ignore[attr-defined]  # rclpy's lifecycle node has no type information
        return "activate failed"
    return ""


def drain(subscription: Any, msgtype: type, serialized: bool = True) -> list[tuple[Any, dict[str, Any]]]:
    """Take every message queued in ``subscription``'s reader, oldest first, without an executor:
    ``(message, info)`` pairs, the message as CDR bytes when ``serialized`` (read in place, no
    message object) else decoded; ``info`` has rmw's ``source_timestamp`` and
    ``received_timestamp`` (ns).

    The one place the rig takes from a reader by hand (rclpy has no public call for it in
    Jazzy: the subscription's handle's ``take_message``), for readers whose queue a timer empties
    at its own pace instead of one callback per message (the load controller's ``/clock``, the
    simulator's force, the session's recorder).
    """
    taken_all: list[tuple[Any, dict[str, Any]]] = []
    handle = subscription.handle
    with handle:
        while (taken := handle.take_message(msgtype, serialized)) is not None:
            taken_all.append((taken[0], taken[1]))
    return taken_all


def unspun_reader(tap: Node, msgtype: type, topic: str, qos: QoSProfile) -> Any:
    """A subscription of ``tap``, a node no executor spins, whose queue is taken by hand
    (:func:`drain`): no callback runs for its messages and no QoS-event handler is installed
    (an executor would otherwise walk it on every wake-up)."""
    return tap.create_subscription(msgtype, topic, _never_called, qos, event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False))


def _never_called(_msg: object) -> None:  # pragma: no cover - an unspun reader's node is never spun
    """Callback of an :func:`unspun_reader`; its queue is taken by :func:`drain`."""


CONTRACT_QOS_PROFILES: dict[str, QoSProfile] = {name: qos_profile(name) for name in QOS_DESCRIPTIONS}
"""The rclpy profile of each QoS name of the interface contract (:mod:`bearing_rig_sim.interfaces`)."""
