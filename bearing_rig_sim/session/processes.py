"""Starting, watching and stopping the rig's node processes (no ROS).

Each node runs as its own process from its console script (``bearing-rig-simulator``,
``bearing-rig-load-controller``, ``bearing-rig-monitor``), found next to the running Python (the
venv's ``bin/``), else on ``PATH``, else in a colcon install's ``lib/bearing_rig_sim/``. Its
standard output and error go to a log file, whose tail is what a failure report quotes.

The children run in their own session (a terminal's Ctrl-C reaches only the session process,
which stops them in order) and are asked by the kernel to terminate (SIGTERM) if the session
process dies without stopping them.

Graph isolation: unless the user set ``ROS_DOMAIN_ID``, a session takes a private domain id from
:data:`SESSION_DOMAIN_IDS`, held by an exclusive lock file for the session's life, so two sessions
(or a session and a benchmark) on one host never share a graph; and unless the user set
``ROS_AUTOMATIC_DISCOVERY_RANGE``, discovery stays on this host (``LOCALHOST``).

Transport: unless the user gave a Fast DDS profile (``FASTRTPS_DEFAULT_PROFILES_FILE`` or
``FASTDDS_DEFAULT_PROFILES_FILE``), every process of a session uses the rig's profile
(:mod:`bearing_rig_sim.dds_profile`: shared memory with deep buffers, a 50 ms writer heartbeat),
written to ``<run-id>/logs/fastdds_profile.xml``.
"""

from __future__ import annotations

import ctypes
import fcntl
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import IO
from collections.abc import Iterator, Mapping, Sequence

import psutil

from bearing_rig_sim.dds_profile import PROFILE_VARIABLES
from bearing_rig_sim.errors import RigError

__all__ = [
    "NODES",
    "SESSION_DOMAIN_IDS",
    "DomainLease",
    "NodeProcess",
    "NodeSpec",
    "lease_domain",
    "node_command",
    "own_ros_environment",
    "session_environment",
    "stop_all",
    "SESSION_VARIABLES",
]

SESSION_DOMAIN_IDS = range(102, 233)
"""Domain ids for sessions and benchmarks (the test suite uses 1-101; 232 is Fast DDS's last)."""

CHILD_NICENESS = 5
"""The nodes run this much nicer than the session process: on a busy host the simulation slows
down (lower real-time factor, overruns it reports) before the recorder falls behind and loses
messages."""

DOMAIN_LOCK_DIR = Path(tempfile.gettempdir()) / "bearing_rig_sim-session-domains"


@dataclass(frozen=True)
class NodeSpec:
    """One of the rig's nodes."""

    name: str
    """Its ROS node name and role: ``simulator``, ``load_controller``, ``monitor``."""
    script: str
    """Console script of the Python package, e.g. ``bearing-rig-simulator``."""


NODES: dict[str, NodeSpec] = {
    "simulator": NodeSpec("simulator", "bearing-rig-simulator"),
    "load_controller": NodeSpec("load_controller", "bearing-rig-load-controller"),
    "monitor": NodeSpec("monitor", "bearing-rig-monitor"),
}
"""The three nodes of a session, in the order they are started."""


def node_command(spec: NodeSpec) -> list[str]:
    """The command starting ``spec``'s node.

    Raises:
        RigError: its executable is nowhere to be found.
    """
    beside = Path(sys.executable).parent / spec.script
    if beside.is_file() and os.access(beside, os.X_OK):
        return [str(beside)]
    found = shutil.which(spec.script)
    if found:
        return [found]
    try:
        from ament_index_python.packages import get_package_prefix

        installed = Path(get_package_prefix("bearing_rig_sim")) / "lib" / "bearing_rig_sim" / spec.name
        if installed.is_file():
            return [str(installed)]
    except Exception:
        pass
    raise RigError(
        f"cannot find the {spec.name} node's executable {spec.script!r} next to {sys.executable}, on PATH "
        "or in an ament install; run ./bootstrap.sh setup (or source the colcon workspace)"
    )


def _prepare_child() -> None:  # pragma: no cover - runs in the child between fork and exec
    """Ask the kernel for SIGTERM when the parent dies (Linux ``PR_SET_PDEATHSIG``), lower the
    child's priority by :data:`CHILD_NICENESS`, and give it the default SIGINT: a session started
    in the background by a script inherits SIGINT ignored, and its nodes would then ignore the
    SIGINT that :func:`stop_all` stops them with."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)
    except (OSError, AttributeError):
        pass
    try:
        os.nice(CHILD_NICENESS)
    except OSError:
        pass


class NodeProcess:
    """A node running as a child process, its output going to ``log_path``.

    Args:
        name: the node's name (for messages).
        command: the command line.
        log_path: file receiving its standard output and error.
    """

    def __init__(self, name: str, command: Sequence[str], log_path: Path) -> None:
        self.name = name
        self.command = list(command)
        self.log_path = Path(log_path)
        self._process: subprocess.Popen[bytes] | None = None
        self._log: IO[bytes] | None = None
        self.stop_requested = False
        """True once :meth:`request_stop` or :meth:`stop` ran: an exit is then expected."""

    def start(self, env: Mapping[str, str]) -> None:
        """Start the process with ``env``.

        Raises:
            RigError: it could not be started.
        """
        self.log_path.parent.mkdir(parents=True, exist_ok=True)
        self._log = open(self.log_path, "wb")
        try:
            self._process = subprocess.Popen(
                self.command,
                env=dict(env),
                stdin=subprocess.DEVNULL,
                stdout=self._log,
                stderr=subprocess.STDOUT,
                start_new_session=True,
                preexec_fn=_prepare_child if sys.platform.startswith("linux") else None,
            )
        except OSError as exc:
            self._log.close()
            raise RigError(f"cannot start the {self.name} node ({' '.join(self.command)}): {exc}") from None

    @property
    def pid(self) -> int | None:
        return self._process.pid if self._process is not None else None

    def poll(self) -> int | None:
        """Exit status once it ended, else None."""
        return self._process.poll() if self._process is not None else None

    @property
    def running(self) -> bool:
        return self._process is not None and self._process.poll() is None

    def output_tail(self, lines: int = 15) -> str:
        """The last ``lines`` lines of its output ("" when there is none)."""
        try:
            with open(self.log_path, "rb") as log:
                log.seek(0, os.SEEK_END)
                size = log.tell()
                log.seek(max(0, size - 16384))
                text = log.read().decode("utf-8", errors="replace")
        except OSError:
            return ""
        return "\n".join(text.splitlines()[-lines:])

    def describe_exit(self, lines: int = 15) -> str:
        """``<name> exited with status N`` (or the signal) and its output's tail."""
        status = self.poll()
        if status is None:
            what = f"{self.name} is still running"
        elif status < 0:
            what = f"{self.name} was killed by signal {signal.Signals(-status).name}"
        else:
            what = f"{self.name} exited with status {status}"
        tail = self.output_tail(lines)
        return f"{what}; the end of its output ({self.log_path}):\n{tail}" if tail else f"{what} (no output; log {self.log_path})"

    def request_stop(self, sig: int = signal.SIGINT) -> None:
        """Send ``sig`` (default SIGINT: rclpy shuts the node down cleanly) if it runs."""
        self.stop_requested = True
        if self.running:
            assert self._process is not None
            try:
                self._process.send_signal(sig)
            except ProcessLookupError:
                pass

    def wait(self, timeout: float) -> int | None:
        """Wait up to ``timeout`` s for the exit; its status, or None if still running."""
        if self._process is None:
            return None
        try:
            return self._process.wait(timeout=max(0.0, timeout))
        except subprocess.TimeoutExpired:
            return None

    def kill(self) -> None:
        """SIGKILL, and reap."""
        if self.running:
            assert self._process is not None
            self._process.kill()
            self._process.wait()

    def close_log(self) -> None:
        if self._log is not None and not self._log.closed:
            self._log.close()

    def cpu_seconds(self) -> float | None:
        """User + system CPU time it used so far, s; None if unknown."""
        pid = self.pid
        if pid is None:
            return None
        return process_cpu_seconds(pid)


def process_cpu_seconds(pid: int) -> float | None:
    """User + system CPU time of a process (not its children), s, by psutil; None when it cannot
    be read (no such process, or no access)."""
    try:
        times = psutil.Process(pid).cpu_times()
    except psutil.Error:
        return None
    return float(times.user + times.system)


def stop_all(processes: Sequence[NodeProcess], timeout: float = 5.0) -> None:
    """Stop every process: SIGINT to all, up to ``timeout`` s for them to exit, then SIGTERM and
    SIGKILL to what is left; logs closed."""
    for process in processes:
        process.request_stop(signal.SIGINT)
    deadline = time.monotonic() + timeout
    for process in processes:
        process.wait(deadline - time.monotonic())
    for process in processes:
        if process.running:
            process.request_stop(signal.SIGTERM)
            if process.wait(1.0) is None:
                process.kill()
        process.close_log()


class DomainLease:
    """An exclusive claim on a ROS domain id (a ``flock`` on a lock file); None-safe release."""

    def __init__(self, domain_id: int, handle: IO[str] | None) -> None:
        self.domain_id = domain_id
        self._handle = handle

    def release(self) -> None:
        if self._handle is not None and not self._handle.closed:
            fcntl.flock(self._handle, fcntl.LOCK_UN)
            self._handle.close()


def lease_domain(ids: Sequence[int] = SESSION_DOMAIN_IDS) -> DomainLease:
    """Claim a free domain id of ``ids`` (random start, first free).

    Raises:
        RigError: every id is claimed by another session.
    """
    DOMAIN_LOCK_DIR.mkdir(parents=True, exist_ok=True)
    try:
        DOMAIN_LOCK_DIR.chmod(0o1777)  # shared by every user's sessions, like /tmp itself
    except OSError:
        pass
    ordered = list(ids)
    start = random.randrange(len(ordered))
    for domain_id in ordered[start:] + ordered[:start]:
        handle = open(DOMAIN_LOCK_DIR / f"{domain_id}.lock", "a+", encoding="utf-8")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            continue
        return DomainLease(domain_id, handle)
    raise RigError(f"no free ROS domain id in {ids.start}..{ids.stop - 1}" if isinstance(ids, range) else "no free ROS domain id")


def session_environment(base: Mapping[str, str]) -> tuple[dict[str, str], DomainLease]:
    """The environment of a session's processes, and the domain it holds.

    The user's ``ROS_DOMAIN_ID`` and ``ROS_AUTOMATIC_DISCOVERY_RANGE`` are kept when set;
    otherwise a private domain is leased and discovery limited to this host.

    Raises:
        RigError: a ``ROS_DOMAIN_ID`` that is not a whole number; no free domain.
    """
    env = dict(base)
    env.setdefault("PYTHONUNBUFFERED", "1")
    user_domain = env.get("ROS_DOMAIN_ID", "").strip()
    if user_domain:
        if not user_domain.isdigit():
            raise RigError(f"ROS_DOMAIN_ID must be a whole number, got {user_domain!r}")
        lease = DomainLease(int(user_domain), None)
    else:
        lease = lease_domain()
        env["ROS_DOMAIN_ID"] = str(lease.domain_id)
    if not env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "").strip():
        env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    return env, lease


SESSION_VARIABLES = ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", *PROFILE_VARIABLES)
"""What :func:`session_environment` may set, for the session process's own ROS context."""


@contextmanager
def own_ros_environment(env: Mapping[str, str]) -> Iterator[None]:
    """This process's :data:`SESSION_VARIABLES` taken from ``env`` for the block (its own ROS
    context then joins the nodes' graph with the same transport), restored afterwards."""
    saved = {key: os.environ.get(key) for key in SESSION_VARIABLES}
    try:
        for key in SESSION_VARIABLES:
            if key in env:
                os.environ[key] = env[key]
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
