"""A rig session: the three nodes as processes, the program run, recorded, shown, summarised.

:func:`run_session` is ``bearing-rig run``:

1. reads the program (errors name the file and the key), makes the run id and the bag
   directory ``<bag dir>/<run id>/`` with the run context in its metadata;
2. starts the simulator, load controller and monitor as separate processes on a private
   ``ROS_DOMAIN_ID`` (unless the user set one), discovery limited to this host (unless set),
   the session's Fast DDS transport profile (deeper shared-memory buffers, unless the user gave
   a profile; :mod:`.processes`), each node 5 steps nicer than the session process (the recorder
   comes first), their output in ``<bag dir>/<run id>/logs/<node>.log``;
3. is their lifecycle manager (:mod:`.lifecycle`, :mod:`.manager`): once every node's
   ``change_state`` service is up, configures all of them in order, waits until the recorder has
   matched the streams they will publish (at most ``MATCH_WAIT_S``), then activates all in reverse
   order (the simulator last: the others take its clock from the first message);
   each transition is an event line (also in ``logs/session.log``) and a ``/diagnostics`` status
   (``lifecycle_manager: <node>``, recorded). A node that fails a transition is named with its
   reason (its ``configure failed: ...`` line) and the session ends (exit status 1);
4. waits, up to ``startup_timeout_s`` in all, for each to come up: the simulator's first
   ``/clock`` and its command subscription, the load controller's first state and its set-point
   subscription, the monitor's status publisher and pulse subscription; otherwise stops with the
   name of the process that did not, and the tail of its output; attached to nodes managed
   elsewhere (``--attach``), also until the recorder has matched the streams the graph has a
   publisher of (read best effort where a publisher offers only that), at most ``MATCH_WAIT_S``;
5. sends the first segment's load set-point and starts the program once the load controller
   shows it in force (at most ``LOAD_UP_WAIT_S``), then runs it
   (:class:`~bearing_rig_sim.session.runner.ProgramRunner`) on the simulation clock while
   recording every rig topic and printing progress;
6. at the end, on Ctrl-C (SIGINT) or SIGTERM, or when a node fails or dies: stops the runner,
   deactivates the active nodes in order (the simulator first; at the end of a program run
   through, the monitor once its last status is in) and cleans up the configured ones in
   reverse order once the recorder holds every message they report having published (the nodes
   still running), stops the processes (SIGINT, then SIGTERM, then SIGKILL), finalises the bag,
   prints the summary so far.

Exit status: 0 the program ran to its end; 130 interrupted; 1 a node failed to come up or died,
or the simulator's engine diverged (its diagnostics' ``simulation_stopped``).
Everything ROS in the session process runs in one ``SingleThreadedExecutor``.
"""

from __future__ import annotations

import math
import os
import signal
import sys
import time
from dataclasses import dataclass, field
from datetime import datetime, UTC
from enum import Enum
from pathlib import Path
from types import FrameType
from typing import Any, TextIO
from collections.abc import Callable, Sequence

from bearing_rig_sim.dds_profile import apply_rig_profile
from bearing_rig_sim.config import rad_s_to_rpm
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import CLOCK, DIAGNOSTICS, SLIP_STATUS, SPEEDS
from bearing_rig_sim.bags import BagWriter
from bearing_rig_sim.rig.program import TestProgram, load_program
from bearing_rig_sim.session.context import check_bearing_file, check_parameter_file, make_run_id, node_parameters, parameter_arguments, run_context
from bearing_rig_sim.session.lifecycle import TransitionRecord, bring_up, shut_down
from bearing_rig_sim.session.processes import (
    NODES,
    DomainLease,
    NodeProcess,
    node_command,
    own_ros_environment,
    session_environment,
    stop_all,
)
from bearing_rig_sim.session.progress import ProgressPrinter, ProgressSnapshot, RealTimeFactor, format_delivery, format_progress, format_summary
from bearing_rig_sim.session.recorder import SessionRecorder
from bearing_rig_sim.simulation.settings import shipped_parameters as simulator_shipped_parameters
from bearing_rig_sim.session.runner import COMMAND_LEAD_S, REALTIME_COMMAND_LEAD_S, ProgramRunner, SegmentOutcome, SegmentPlan

__all__ = ["EXIT_CONDITIONS", "EXIT_FAILED", "EXIT_INTERRUPTED", "EXIT_OK", "SessionOptions", "run_session"]

EXIT_OK, EXIT_FAILED, EXIT_CONDITIONS, EXIT_INTERRUPTED = 0, 1, 3, 130
"""Exit statuses: all segments ran under their conditions; a node or the session failed; the
program ran to its end but some segment's speed or load was not as commanded, or was changed from
outside (the summary marks which); stopped by a signal."""

GRAPH_CHECK_PERIOD_S = 0.5
"""Wall time between two looks at the graph for a second rig, s (:meth:`Session._check_graph`)."""

CHUNK_SIZE = 256 * 1024
"""Uncompressed bytes per bag chunk: about 0.5 s of the rig's traffic, the most a killed session
loses, and a chunk compressed in some 15 ms, a short hold-up of the session's loop."""


MATCH_WAIT_S = 10.0
"""Longest wait, after every node is configured, for the recorder to match their streams before
they are activated; attached (``--attach``), before the program starts (wall s). Only a bound
against a stream that never matches: the wait ends when the recorder has matched."""


LOAD_UP_WAIT_S = 10.0
"""Longest wait, wall s, for the load controller to show the first segment's set-point in force
before the program starts anyway (its load then judged from when the load controller shows it):
a bound against a set-point that never comes, the wait ends when it does."""


MONITOR_GUARD_S = 30.0
"""Longest wait, wall s, for the monitor's statuses to reach a segment's end before it is judged
without them (:attr:`ProgramRunner.monitor_guard_s`), and at the end for its last status: a guard
against a monitor that stopped, the wait ends when the status comes."""

MONITOR_END_MARGIN_S = 0.2
"""At the end the monitor is deactivated once it has published a status stamped within this of
the clock's last time, s of sim time: two of its status periods (10 Hz of pulse time; its
statuses once the pulses stop carry the load cell's last stamp, the clock's)."""

DELIVERY_GUARD_S = 30.0
"""Longest wait, wall s, at the end for the recorder to hold every message the nodes report
having published (their delivery reports, :data:`bearing_rig_sim.nodes.shell.PUBLISHED_SUFFIX`):
a guard only, the wait ends when it does; what is still missing then is named in the summary."""

OWN_STATUS_GUARD_S = 30.0
"""Longest wait at the end for the recorder to take the session's own last lifecycle status
(wall s): a guard against a hang only, the wait ends when it is taken."""


@dataclass(frozen=True)
class SessionOptions:
    """Options of a session (``bearing-rig run``)."""

    program: Path
    """Test program file."""
    realtime: bool = True
    """Lock the simulator to the wall clock; False: as fast as it goes."""
    bag_dir: Path = Path("bags")
    """Folder of the run's bag directory."""
    quiet: bool = False
    """No live progress or event lines (the summary is printed anyway)."""
    startup_timeout_s: float = 60.0
    """Longest wait for the nodes to come up, s of wall time."""
    command_line: Sequence[str] = field(default_factory=tuple)
    """The command line, for the run context."""
    params_file: Path | None = None
    """A ROS 2 parameter file given to every node (blocks per node name), over the shipped ones."""
    attach: bool = False
    """Run the program on nodes already running and managed elsewhere (``launch/rig.launch.py``):
    no processes started, no lifecycle transitions, the environment's ROS domain as it is."""
    record: bool = True
    """Record the bag; False (``--no-record``, where ``ros2 bag record`` records): only the
    session log and summary."""
    foxglove_port: int | None = None
    """Serve the recorded topics live to the Foxglove app on this port of 127.0.0.1 (0: any
    free port); None: no live view."""
    transition_timeout_s: float = 10.0
    """Longest wait for a node to answer a deactivate or cleanup, wall s (bring-up transitions
    have ``startup_timeout_s``: a first configure compiles the engine's kernels)."""
    bearing_model: str | None = None
    """The simulator's named bearing model (``bench``, ``paper``; None: its parameter file's)."""


class _Phase(Enum):
    STARTING = "starting"
    RUNNING = "running"
    ENDED = "ended"


def run_session(options: SessionOptions, out: TextIO | None = None, err: TextIO | None = None) -> int:
    """Run a session (see the module documentation); returns the exit status.

    Raises:
        RigError: a malformed program or configuration, a bag directory that cannot be made, a
            node executable that cannot be found.
    """
    out = out if out is not None else sys.stdout
    err = err if err is not None else sys.stderr
    program = load_program(options.program)  # checked against the shipped rig, as the nodes use it
    if not options.attach:  # attached, the simulator's own bearing file is the one it uses
        check_bearing_file(program, options.program)
    commands = {} if options.attach else {name: node_command(spec) for name, spec in NODES.items()}
    simulator_defaults = simulator_shipped_parameters()
    overrides = {} if options.attach else node_parameters(program, simulator_defaults)  # the program's bearing, in every node
    if not options.realtime and not options.attach:
        overrides.setdefault("simulator", {})["realtime"] = False
    if options.bearing_model is not None and not options.attach:
        overrides.setdefault("simulator", {})["bearing_model"] = options.bearing_model
    if not options.attach:  # attached: the nodes' parameters are whoever started them's
        # the monitor judges slip against what the program's stability_criterion names
        overrides.setdefault("monitor", {})["criterion"] = program.stability_criterion
    for name, values in overrides.items():
        commands[name] = [*commands[name], "--ros-args", *parameter_arguments(values)]
    if options.params_file is not None:
        params = Path(options.params_file)
        if not params.is_file():
            raise RigError(f"--params-file: no such file: {params}")
        if not options.attach:
            check_parameter_file(params)
        for name in commands:
            commands[name] = commands[name] + ["--ros-args", "--params-file", str(params.resolve())]
    start = datetime.now(UTC)
    run_id = make_run_id(program.name, start)
    bag_path = _fresh_path(Path(options.bag_dir) / run_id)
    env, lease = (dict(os.environ), DomainLease(int(os.environ.get("ROS_DOMAIN_ID") or 0), None)) if options.attach else session_environment(os.environ)
    env.setdefault("ROS_DOMAIN_ID", str(lease.domain_id))
    context = run_context(
        program,
        run_id=run_id,
        start=start,
        command_line=options.command_line or sys.argv,
        extra={
            "ros_domain_id": env["ROS_DOMAIN_ID"],
            "realtime": str(options.realtime).lower(),
            **({"calibration": "none"} if overrides.get("simulator", {}).get("calibration_file") == "" else {}),
        },
    )
    try:
        writer: Any = BagWriter(bag_path, metadata=context, chunk_size=CHUNK_SIZE) if options.record else _NoBag(bag_path)
        if not options.attach:
            apply_rig_profile(env, writer.path / "logs")
        view = None
        if options.foxglove_port is not None:
            from bearing_rig_sim.live.foxglove import FoxgloveLiveView
            from bearing_rig_sim.bags.typestore import msg_definition_text

            view = FoxgloveLiveView(options.foxglove_port, msg_definition_text)
        try:
            session = _Session(options, program, writer, env, commands, out, err, view)
            return session.run()
        finally:
            if view is not None:
                view.close()
    finally:
        lease.release()


class _NoBag:
    """The writer of a session that records nothing (``--no-record``): its folder holds the logs."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        (self.path / "logs").mkdir(parents=True, exist_ok=True)

    def add_topic(self, name: str, msgtype: str, qos: str) -> None:
        """Nothing to set up."""

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None:
        """Nothing kept."""

    def close(self) -> None:
        """Nothing to finalise."""


def _failure_line(output: str, transition: str) -> str:
    """The node's own ``<transition> failed: ...`` reason from its output ("" when absent)."""
    marker = f"{transition} failed: "
    for line in reversed(output.splitlines()):
        if marker in line:
            return line[line.index(marker) + len(marker) :].strip()
    return ""


def _fresh_path(path: Path) -> Path:
    """``path``, or ``path-2``, ``path-3``... when it exists (two runs in the same second)."""
    candidate, n = path, 1
    while candidate.exists():
        n += 1
        candidate = path.with_name(f"{path.name}-{n}")
    return candidate


class _Session:
    """One session's state; :meth:`run` does it all."""

    def __init__(
        self,
        options: SessionOptions,
        program: TestProgram,
        writer: Any,
        env: dict[str, str],
        commands: dict[str, list[str]],
        out: TextIO,
        err: TextIO,
        view: Any = None,
    ) -> None:
        self.options = options
        self.program = program
        self.writer = writer
        self.env = env
        self.out = out
        self.err = err
        self.printer = ProgressPrinter(out, quiet=options.quiet)
        lead = REALTIME_COMMAND_LEAD_S if options.realtime else COMMAND_LEAD_S  # without real time the simulator runs ahead
        # set-points: in real time as the commands (a queue outliving an interrupted session holds
        # at most a second); without real time every fixed start's at once (see the runner)
        self.runner = ProgramRunner(program, command_lead_s=lead, setpoint_lead_s=lead if options.realtime else math.inf, monitor_guard_s=MONITOR_GUARD_S)
        self.view = view
        if view is not None:
            from bearing_rig_sim.live.foxglove import TeeWriter

            self.recorder = SessionRecorder(TeeWriter(writer, view))
        else:
            self.recorder = SessionRecorder(writer)
        self.rtf = RealTimeFactor()
        logs = writer.path / "logs"
        self.children = [NodeProcess(name, commands[name], logs / f"{name}.log") for name in NODES if name in commands]
        self.phase = _Phase.STARTING
        self.status: int | None = None
        self.failure = ""
        self.signal_received: int | None = None
        self.node: Any = None
        self.manager: Any = None
        self.bringing_up = False
        self._activations: list[Any] = []
        """The activations of the bring-up, held back until the recorder has matched the streams."""
        self._match_deadline: float | None = None
        self._load_up_deadline: float | None = None
        """Wall time after which the program starts without the first set-point shown in force."""
        self.deadline = 0.0
        logs.mkdir(parents=True, exist_ok=True)
        self.session_log = open(logs / "session.log", "a", encoding="utf-8")

    # -- main -------------------------------------------------------------------------------------
    def run(self) -> int:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.signals import SignalHandlerOptions

        from bearing_rig_sim.session.manager import LifecycleManager
        from bearing_rig_sim.session.node import DRAIN_PERIOD_S, SessionNode

        segments = len(self.program.segments)
        self._event(
            f"run {self.writer.path.name}: program {self.program.name} ({segments} segments, "
            f"{'real time' if self.options.realtime else 'no real time'}), ROS_DOMAIN_ID {self.env['ROS_DOMAIN_ID']}, "
            f"bag {self.writer.path}"
        )
        if self.view is not None:
            self._event(f"Foxglove live view: {self.view.urls} (layout to import: config/foxglove/rig.json)")
        previous_handlers = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
        context = rclpy.Context()
        executor = None
        try:
            for sig in previous_handlers:
                signal.signal(sig, self._on_signal)
            for child in self.children:  # before rclpy: no middleware threads while forking
                child.start(self.env)
            with own_ros_environment(self.env):
                rclpy.init(args=[], context=context, domain_id=int(self.env["ROS_DOMAIN_ID"]), signal_handler_options=SignalHandlerOptions.NO)
                self.node = SessionNode(self.recorder, self.runner, context=context, on_event=self._event)
                node = self.node
                if not self.options.attach:
                    self.manager = LifecycleManager(node, list(NODES), self._on_transition, lambda: node.sim_time)
            executor = SingleThreadedExecutor(context=context)
            executor.add_node(self.node)
            self.node.create_timer(DRAIN_PERIOD_S, self._tick)
            self.node.create_timer(1.0, self._show_progress)
            self.node.create_timer(GRAPH_CHECK_PERIOD_S, self._check_graph)
            self.deadline = time.monotonic() + self.options.startup_timeout_s
            while self.phase is not _Phase.ENDED:
                executor.spin_once(timeout_sec=0.1)
                if self.signal_received is not None and self.phase is not _Phase.ENDED:
                    self._end(EXIT_INTERRUPTED, f"stopped by {signal.Signals(self.signal_received).name}")
        except KeyboardInterrupt:  # a second Ctrl-C while stopping
            self._end(EXIT_INTERRUPTED, "stopped by a second SIGINT")
        finally:
            try:
                self._deactivate_nodes(executor)
            except KeyboardInterrupt:  # a second Ctrl-C: stop the processes at once
                self.failure = self.failure or "stopped by a second SIGINT"
            self._shut_down(context, executor)
            for sig, handler in previous_handlers.items():
                signal.signal(sig, handler)
        return self._report()

    def _on_signal(self, signum: int, _frame: FrameType | None) -> None:
        if self.signal_received is not None and signum == signal.SIGINT:
            raise KeyboardInterrupt
        self.signal_received = signum

    def _end(self, status: int, reason: str = "") -> None:
        if self.phase is _Phase.ENDED:
            return
        self.phase = _Phase.ENDED
        self.status = status
        self.failure = reason

    # -- the timer ------------------------------------------------------------------------------------
    def _tick(self) -> None:
        if self.phase is _Phase.ENDED or self.node is None:
            return
        node = self.node
        node.take()
        try:
            self._step(node.sim_time)
        finally:
            node.record_pending()
            node.send_progress()  # what is taken is recorded: the simulator may run on from it

    def _step(self, now: float) -> None:
        """Watch the children; start the program once every node is up; run it."""
        assert self.node is not None
        if self.node.clock_count:
            self.rtf.add(time.monotonic(), now)
        for child in self.children:
            if child.poll() is not None and not child.stop_requested:
                when = "during start-up" if self.phase is _Phase.STARTING else "during the run"
                if self.manager is not None:
                    self.manager.drop(child.name)
                self._end(EXIT_FAILED, f"the {child.name} node stopped {when}: {child.describe_exit()}")
                return
        if self.node.simulator_stopped:
            self._end(EXIT_FAILED, f"the simulator stopped the simulation: {self.node.simulator_stopped}")
            return
        if self.phase is _Phase.STARTING:
            if not self._bring_up():
                return
            missing = self.node.missing()
            if not missing and self.options.attach and self._recorder_unmatched(attached=True):
                return
            if not missing:
                start = self._loaded_up(now)
                if start is None:
                    return
                self.phase = _Phase.RUNNING
                self._start_segment(self.runner.start(start, setpoint_sent=True))
                self._send_commands(start)
            elif time.monotonic() > self.deadline:
                name, what = next(iter(missing.items()))
                child = next(c for c in self.children if c.name == name)
                others = "; ".join(f"{n}: {w}" for n, w in list(missing.items())[1:])
                self._end(
                    EXIT_FAILED,
                    f"the {name} node did not come up within {self.options.startup_timeout_s:g} s ({what})"
                    + (f"; also {others}" if others else "")
                    + f"; the end of its output ({child.log_path}):\n{child.output_tail()}",
                )
            return
        done = len(self.runner.outcomes)
        started = self.runner.update(now)
        for outcome in self.runner.outcomes[done:]:
            self._segment_ended(outcome)
        for plan in started:
            self._start_segment(plan)
        self._send_commands(now)
        if self.runner.finished:
            off = [o.name for o in self.runner.outcomes if o.conditions]
            if off:
                self._end(EXIT_CONDITIONS, f"conditions not met in {len(off)} segment(s): {', '.join(off)}")
            else:
                self._end(EXIT_OK)

    def _bring_up(self) -> bool:
        """Drive the lifecycle bring-up; True once every node is active."""
        manager = self.manager
        if manager is None:  # attached to nodes managed elsewhere
            return True
        manager.poll()
        if not self.bringing_up:
            missing = manager.services_missing()
            if not missing:
                self.bringing_up = True
                steps = bring_up(list(NODES))
                self._activations = [s for s in steps if s.transition == "activate"]
                manager.run([s for s in steps if s.transition != "activate"], self.options.startup_timeout_s)  # configure compiles the kernels on a first run
                manager.poll()
            elif time.monotonic() > self.deadline:
                name = missing[0]
                child = next(c for c in self.children if c.name == name)
                self._end(
                    EXIT_FAILED,
                    f"the {name} node did not come up within {self.options.startup_timeout_s:g} s (no /{name}/change_state "
                    f"service); the end of its output ({child.log_path}):\n{child.output_tail()}",
                )
            return False
        failed = manager.failed
        if failed is not None:
            child = next(c for c in self.children if c.name == failed.step.node)
            self._end(
                EXIT_FAILED,
                f"the {failed.step.node} node failed to {failed.step.transition}: {failed.detail}; "
                f"the end of its output ({child.log_path}):\n{child.output_tail()}",
            )
            return False
        if manager.busy:
            return False
        if self._activations:
            # Every node configured: activate once the recorder has matched their streams
            if self._recorder_unmatched(attached=False):
                return False
            manager.run(self._activations, self.options.startup_timeout_s)
            self._activations = []
            manager.poll()
            return False
        return True

    def _recorder_unmatched(self, *, attached: bool) -> bool:
        """True while the recorder has not matched the nodes' streams yet
        (:meth:`SessionNode.unmatched_streams`; attached, those the graph has a publisher of,
        read best effort where the publisher offers only that), so that the program's samples
        are recorded from the first. Failing that within MATCH_WAIT_S, an event line names the
        streams, and from then on False."""
        if not self.options.record or self._match_deadline == math.inf:
            return False
        unmatched = self.node.unmatched_streams(published_only=attached)
        if unmatched and self._match_deadline is None:
            self._match_deadline = time.monotonic() + MATCH_WAIT_S
        if unmatched and time.monotonic() < (self._match_deadline or 0.0):
            return True
        if unmatched:
            self._event(f"recorder: not matched after {MATCH_WAIT_S:g} s with {', '.join(unmatched)}; their first samples may be missing")
        self._match_deadline = math.inf  # settled: not looked at again
        return False

    def _on_transition(self, record: TransitionRecord) -> None:
        """A transition answered: the node's own reason for a failure, an event line."""
        if not record.success:
            child = next((c for c in self.children if c.name == record.step.node), None)
            reason = _failure_line(child.output_tail(40), record.step.transition) if child is not None else ""
            if reason:
                record = TransitionRecord(record.step, False, reason)
                if self.manager is not None:
                    self.manager.failed = record
        self._event(record.line())

    def _deactivate_nodes(self, executor: Any) -> None:
        """Deactivate and clean up the nodes still running (see the module documentation): the
        simulator first (the clock stops), the monitor once its last status is in (at the end of
        a program run through), and the cleanups once the recorder holds every message the
        deactivated nodes report having published (or the guards ran out)."""
        manager, node = self.manager, self.node
        if manager is None or node is None or executor is None:
            return
        gone = [c.name for c in self.children if c.poll() is not None]
        for name in gone:
            manager.drop(name)
        steps = shut_down(list(NODES), manager.states, gone)
        if not steps:
            return
        ran_through = self.status in (EXIT_OK, EXIT_CONDITIONS)
        for step in steps:
            if step.transition == "cleanup" and step == next(s for s in steps if s.transition == "cleanup"):
                self._await(executor, self._undelivered, DELIVERY_GUARD_S, "the recorder still misses")
            elif step.transition == "deactivate" and step.node == "monitor" and ran_through:
                self._await(executor, self._monitor_behind, MONITOR_GUARD_S, "the monitor's last status")
            manager.run([step], self.options.transition_timeout_s)
            self._await(executor, lambda: "busy" if manager.busy else "", self.options.transition_timeout_s * 2, "")

    def _await(self, executor: Any, pending: Callable[[], str], guard_s: float, what: str) -> None:
        """Spin, taking what the recorder receives, until ``pending()`` says nothing is (an empty
        string), at most ``guard_s`` of wall time; then an event line says what still is."""
        node, manager = self.node, self.manager
        assert node is not None
        deadline = time.monotonic() + guard_s
        while (left := pending()) and time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.02)
            if manager is not None:
                manager.poll()
            node.drain()
        if left and what:
            self._event(f"end: not waiting longer than {guard_s:g} s for {what}: {left}")

    def _own_published(self) -> dict[str, int]:
        """What the session published itself besides commands and set-points: its lifecycle statuses."""
        return {DIAGNOSTICS.name: self.manager.published} if self.manager is not None else {}

    def _undelivered(self) -> str:
        """The topics the recorder holds fewer messages of than were published, in words ("" when none)."""
        assert self.node is not None
        return ", ".join(f"{topic} ({got} of {sent})" for topic, (sent, got) in self.node.undelivered(self._own_published()).items())

    def _monitor_behind(self) -> str:
        """Why the monitor's last status is not in yet ("" once it is): every message of the
        simulator recorded (its clock's last time known), and a status stamped within
        :data:`MONITOR_END_MARGIN_S` of it."""
        node = self.node
        assert node is not None
        if "simulator" in node.reports and self._undelivered():
            return f"the simulator's last messages: {self._undelivered()}"
        through = self.runner.status_through
        if through < node.sim_time - MONITOR_END_MARGIN_S:
            return f"its statuses reach {through:.3f} s, the clock {node.sim_time:.3f} s"
        return ""

    def _loaded_up(self, now: float) -> float | None:
        """The program's start, s of sim time, once the load controller shows the first segment's
        axial set-point in force (sent here, at ``now``, the first time), or after
        :data:`LOAD_UP_WAIT_S` without it; None meanwhile. A simulator that runs ahead of the
        session (attached, without real time or a recorder, it ran 6 times faster than the wall
        clock) would otherwise be in the program by the time the set-point reached the load
        controller: the first segment's dwell could end, and the next segment begin, with the
        bearing still unloaded (CI saw 1 N on it 0.3 s into a 900 rpm segment after a 0.3 s
        load-up)."""
        node = self.node
        assert node is not None
        first = self.runner.program.segments[0]
        if self._load_up_deadline is None:
            node.send_load(first, now)
            self._load_up_deadline = time.monotonic() + LOAD_UP_WAIT_S
        shown = node.axial_setpoint
        if shown is not None and shown[1] == first.axial_load:
            return max(now, shown[0])
        if time.monotonic() < self._load_up_deadline:
            return None
        self._event(f"load controller: {first.axial_load:g} N not shown in force after {LOAD_UP_WAIT_S:g} s; the program starts without it")
        return now

    def _send_commands(self, now: float) -> None:
        """Send the spindle commands and load set-points due (the running segment's and those of
        the next segments whose start is fixed, ahead of time, each stamped with its segment's
        start: :meth:`ProgramRunner.commands_due`, :meth:`ProgramRunner.setpoints_due`)."""
        assert self.node is not None
        for plan in self.runner.commands_due(now):
            self.node.send_command(plan)
        for plan in self.runner.setpoints_due(now):
            self.node.send_setpoint(plan)

    def _start_segment(self, plan: SegmentPlan) -> None:
        seg = plan.segment
        hold = f"until stable (at most {seg.timeout:g} s)" if seg.until_stable else f"dwell {seg.dwell:g} s"
        self._event(
            f"segment {plan.index + 1}/{self.runner.segment_count} {seg.name}: {rad_s_to_rpm(seg.target_speed):.0f} rpm, "
            f"{seg.axial_load:g} N, speed change {plan.ramp_end - plan.start_time:.2f} s, {hold}"
        )

    def _segment_ended(self, outcome: SegmentOutcome) -> None:
        slip = f", slip {outcome.measured_slip:.3f} %" if outcome.measured_slip is not None and math.isfinite(outcome.measured_slip) else ""
        if outcome.time_to_stable is None:
            stable = ""
        elif outcome.run_up:
            speed = f" (at {rad_s_to_rpm(outcome.stable_speed):.0f} rpm)" if outcome.stable_speed is not None else ""
            stable = f" {outcome.time_to_stable:.2f} s after the run-up's start{speed}"
        else:
            stable = f" {outcome.time_to_stable:.2f} s after the ramp"
        self._event(f"segment {outcome.index + 1}/{self.runner.segment_count} {outcome.name}: {outcome.verdict.value}{stable}{slip}")

    def _event(self, line: str) -> None:
        if not self.session_log.closed:
            self.session_log.write(f"{datetime.now(UTC):%Y-%m-%dT%H:%M:%S.%fZ} {line}\n")
            self.session_log.flush()
        if not self.options.quiet:
            self.printer.message(line)

    def _check_graph(self) -> None:
        """Adapt the recorder to best-effort publishers (:meth:`SessionNode.adapt_to_publishers`);
        end the session when a second rig shares its graph (see
        :meth:`SessionNode.rival_publishers`): its results would mix two rigs."""
        if self.phase is _Phase.ENDED or self.node is None:
            return
        for line in self.node.adapt_to_publishers():
            self._event(line)
        rivals = self.node.rival_publishers()
        if rivals:
            self._end(
                EXIT_FAILED,
                f"more than one rig on ROS domain {self.env['ROS_DOMAIN_ID']}: {rivals}; a session runs one rig: "
                "stop the other nodes, or run this session on a ROS_DOMAIN_ID of its own",
            )

    def _show_progress(self) -> None:
        if self.phase is _Phase.ENDED or self.node is None or self.options.quiet:
            return
        live = self.node.live
        live.decode_speeds()
        plan = self.runner.current
        now = self.node.sim_time
        status = self.runner.latest_status
        if plan is None:
            number, name, phase = 0, "-", "starting" if self.phase is _Phase.STARTING else "done"
        else:
            number, name = plan.index + 1, plan.segment.name
            phase = "ramp" if now < plan.ramp_end else "hold"
        self.printer.show(
            format_progress(
                ProgressSnapshot(
                    segment_number=number,
                    segment_count=self.runner.segment_count,
                    segment_name=name,
                    phase=phase,
                    sim_time=now,
                    inner_ring_speed=live.inner_ring_speed,
                    cage_speed=live.cage_speed,
                    slip_rate=status.slip_rate if status is not None else None,
                    slip_state=status.state if status is not None else None,
                    real_time_factor=self.rtf.value,
                )
            )
        )

    # -- the end ----------------------------------------------------------------------------------
    def _shut_down(self, context: object, executor: object) -> None:
        """Stop the runner and the nodes, take what is still queued, finalise the bag."""
        if self.phase is not _Phase.ENDED:  # an exception got us here
            self._end(EXIT_FAILED, "the session stopped on an error")
        node = self.node
        if not self.runner.finished and self.runner.started:
            self.runner.interrupt(node.sim_time if node is not None else 0.0)
        try:
            if node is not None:
                node.drain()
            stop_all(self.children)
            if node is not None:
                time.sleep(0.2)  # the nodes' last messages
                node.drain()
                self._take_own_statuses()
        finally:
            try:
                self.writer.close()
            finally:
                if executor is not None:
                    executor.shutdown(timeout_sec=1.0)  # type: ignore[attr-defined]  # rclpy objects carry no type information
                if node is not None:
                    node.close()
                    node.destroy_node()
                context.try_shutdown()  # type: ignore[attr-defined]  # rclpy objects carry no type information

    def _take_own_statuses(self) -> None:
        """Take what comes until the recorder has the lifecycle manager's last ``/diagnostics``
        status (one writer, reliable: in order, so every one before it too), published just
        before the end, however slow its way back on a loaded host; at most
        :data:`OWN_STATUS_GUARD_S`."""
        manager, node = self.manager, self.node
        if manager is None or node is None or not manager.records:
            return
        from bearing_rig_sim.session.manager import DIAGNOSTIC_PREFIX
        from bearing_rig_sim.session.node import DRAIN_PERIOD_S

        last = manager.records[-1]
        expected = (DIAGNOSTIC_PREFIX + last.step.node, last.step.transition, last.state)
        deadline = time.monotonic() + OWN_STATUS_GUARD_S
        while node.last_lifecycle_status != expected and time.monotonic() < deadline:
            time.sleep(DRAIN_PERIOD_S)
            node.drain()

    def _report(self) -> int:
        self.printer.done()
        status = EXIT_FAILED if self.status is None else self.status
        heading = {
            EXIT_OK: "summary",
            EXIT_CONDITIONS: "summary (conditions not met)",
            EXIT_INTERRUPTED: "summary (interrupted)",
            EXIT_FAILED: "summary (failed)",
        }[status]
        summary = f"{heading}: program {self.program.name}, {len(self.runner.outcomes)}/{self.runner.segment_count} segments\n"
        summary += format_summary(self.runner.outcomes, self.runner.sweeps) + "\n"
        if not self.session_log.closed:  # the log says how the session ended, and its summary
            reason = f": {self.failure}" if status != EXIT_OK and self.failure else ""
            self.session_log.write(f"{datetime.now(UTC):%Y-%m-%dT%H:%M:%S.%fZ} session ended, exit status {status}{reason}\n{summary}")
        self.session_log.close()
        if status == EXIT_FAILED:
            self.err.write(f"bearing-rig run: {self.failure}\n")
        elif status == EXIT_CONDITIONS:
            self.err.write(f"bearing-rig run: {self.failure} (see the summary)\n")
        elif status == EXIT_INTERRUPTED:
            self.err.write(f"bearing-rig run: {self.failure}; the summary so far and the bag are complete to this point\n")
        self.out.write(f"\n{summary}")
        counts = self.recorder.counts
        total = sum(counts.values())
        if not self.options.record:
            self.out.write(f"\nnot recorded (--no-record); session log in {self.writer.path / 'logs'}\n")
            self.out.flush()
            return status
        self.out.write(
            f"\nbag: {self.writer.path} ({total} messages; "
            + ", ".join(f"{t.name} {counts.get(t.name, 0)}" for t in (CLOCK, SPEEDS, SLIP_STATUS))
            + f"); node logs in {self.writer.path / 'logs'}\n"
        )
        if self.node is not None:
            # a node that was never active published nothing; one that was reports when deactivated
            activated = {r.step.node for r in self.manager.records if r.success and r.step.transition == "activate"} if self.manager is not None else set()
            unreported = [name for name in NODES if name in activated and name not in self.node.reports]
            published = self.node.published(self._own_published())
            delivery = format_delivery(published, self.recorder.counts, unreported)
            self.out.write(f"\ndelivery (messages per topic):\n{delivery}\n")
            short = [line for line in delivery.splitlines() if line.startswith(("NOT ALL RECORDED", "NO DELIVERY REPORT"))]
            for line in short:
                self.err.write(f"bearing-rig run: {line}\n")
        rule = self.recorder.rule
        if rule.clock_guard.refused or rule.clock_guard.jumps:
            first = f"; first: {rule.clock_notes[0]}" if rule.clock_notes else ""
            self.out.write(
                f"clock: {rule.clock_guard.refused} {CLOCK.name} stamp(s) refused (kept off the bag's timeline), "
                f"{rule.clock_guard.jumps} confirmed jump(s){first}\n"
            )
        self.out.flush()
        return status
