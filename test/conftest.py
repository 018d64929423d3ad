"""Shared fixtures: an isolated ROS graph per test.

``ros_graph`` gives each test its own DDS domain so tests never see each other's topics, nor
those of another test run on the same machine:

* ``ROS_DOMAIN_ID`` is taken from 1..101 (0, the default domain, is left to users) and held
  for the test by an exclusive lock file under the system temp folder
  (``bearing_rig_sim-ros-domains/<id>.lock``), so parallel test runs (CI jobs, pytest-xdist
  workers, two checkouts) on one host never share a domain. Within a run each test gets an
  id no earlier test used until all 101 have been used.
* ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``: discovery stays on this host.
* A domain id some live process still runs on (read from ``/proc/<pid>/environ``: an orphan of
  an earlier run killed before its teardown) is passed over, and at teardown any process left on
  the test's domain (a grandchild its parent did not stop) is killed and named in a warning
  before the id is released, so no test ever attaches to another test's node.
* Children started through the fixture die with the test process (``PR_SET_PDEATHSIG``), even
  when pytest itself is killed.

Both variables are set in ``os.environ`` for the test (undone afterwards) and in
:attr:`RosGraph.env` for subprocesses. Contexts, nodes, executors and subprocesses made
through the fixture are shut down, destroyed or killed at teardown, in that order of
dependency, whatever the test's outcome.

Example::

    @pytest.mark.ros
    def test_talk(ros_graph):
        node = ros_graph.node("listener")
        peer = ros_graph.spawn_python("-c", "import rclpy; ...")
        ros_graph.spin_until(lambda: received, timeout=10.0, nodes=[node])
"""

from __future__ import annotations

import ctypes
import fcntl
import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path
from typing import IO, Any, NoReturn
from collections.abc import Callable, Generator, Iterator, Sequence

import pytest

#: Domain ids handed out to tests (inclusive). 0 is the ROS default domain and is avoided.
DOMAIN_IDS: range = range(1, 102)

#: Folder of the per-domain lock files shared by every test run on this host.
LOCK_DIR: Path = Path(tempfile.gettempdir()) / "bearing_rig_sim-ros-domains"

REPO_ROOT: Path = Path(__file__).resolve().parent.parent

_used_this_session: set[int] = set()


class DomainLease:
    """An exclusive claim on one ROS domain id, held through a ``flock`` on a lock file."""

    def __init__(self, domain_id: int, handle: IO[str]) -> None:
        self.domain_id = domain_id
        self._handle = handle

    def release(self) -> None:
        """Give the domain id back (closing the file drops the lock)."""
        if not self._handle.closed:
            fcntl.flock(self._handle, fcntl.LOCK_UN)
            self._handle.close()


def lease_domain(timeout: float = 60.0) -> DomainLease:
    """Claim a free domain id from :data:`DOMAIN_IDS`, preferring ids unused in this session.

    Raises:
        RuntimeError: every id stayed claimed by other processes for ``timeout`` seconds.
    """
    if not LOCK_DIR.is_dir():
        LOCK_DIR.mkdir(parents=True, exist_ok=True)
        try:
            LOCK_DIR.chmod(0o1777)  # shared by every user's test runs, like /tmp itself
        except OSError:
            pass
    deadline = time.monotonic() + timeout
    ids = list(DOMAIN_IDS)
    while True:
        start = random.randrange(len(ids))
        ordered = ids[start:] + ids[:start]
        fresh = [i for i in ordered if i not in _used_this_session]
        for domain_id in fresh + [i for i in ordered if i in _used_this_session]:
            handle = open(LOCK_DIR / f"{domain_id}.lock", "a+", encoding="utf-8")
            try:
                fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                handle.close()
                continue
            if processes_on_domain(domain_id):  # an orphan still talks on it: not isolated
                fcntl.flock(handle, fcntl.LOCK_UN)
                handle.close()
                continue
            _used_this_session.add(domain_id)
            if len(_used_this_session) == len(ids):
                _used_this_session.clear()
                _used_this_session.add(domain_id)
            return DomainLease(domain_id, handle)
        if time.monotonic() > deadline:
            raise RuntimeError(f"no free ROS domain id in {DOMAIN_IDS} after {timeout} s (see {LOCK_DIR})")
        time.sleep(0.2)


def processes_on_domain(domain_id: int) -> dict[int, str]:
    """Live processes of this host (other than this one) whose environment sets
    ``ROS_DOMAIN_ID=domain_id``: pid -> command line. Empty where ``/proc`` cannot be read."""
    key = f"ROS_DOMAIN_ID={domain_id}".encode()
    found: dict[int, str] = {}
    try:
        entries = os.listdir("/proc")
    except OSError:
        return found
    for entry in entries:
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            with open(f"/proc/{entry}/environ", "rb") as handle:
                if key not in handle.read().split(b"\0"):
                    continue
            with open(f"/proc/{entry}/cmdline", "rb") as handle:
                command = handle.read().replace(b"\0", b" ").decode(errors="replace").strip()
        except OSError:  # gone meanwhile, or another user's
            continue
        if command:  # a zombie has an empty command line and talks on no graph
            found[int(entry)] = command
    return found


def kill_processes_on_domain(domain_id: int, timeout: float = 10.0) -> dict[int, str]:
    """SIGKILL every process :func:`processes_on_domain` finds and wait (up to ``timeout`` s)
    until none is left; returns what was killed."""
    leaked = processes_on_domain(domain_id)
    for pid in leaked:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    deadline = time.monotonic() + timeout
    while leaked and processes_on_domain(domain_id) and time.monotonic() < deadline:
        time.sleep(0.05)
    return leaked


def _prepare_child() -> None:  # runs in the child between fork and exec
    """Default SIGINT (tests send Ctrl-C to children, and a suite started in the background of
    a script would pass SIGINT on ignored), and SIGKILL when the test process dies (Linux
    ``PR_SET_PDEATHSIG``), so no child outlives a killed pytest as an orphan on a domain."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)
    except (OSError, AttributeError):
        pass


class RosGraph:
    """One test's private ROS graph: its domain id, environment and the ROS objects to clean up.

    Attributes:
        domain_id: the test's ``ROS_DOMAIN_ID``.
        env: environment for subprocesses (``os.environ`` plus the isolation variables).
    """

    def __init__(self, domain_id: int) -> None:
        self.domain_id = domain_id
        env = dict(os.environ)
        for name in ("ROS_LOCALHOST_ONLY", "ROS_STATIC_PEERS", "FASTRTPS_DEFAULT_PROFILES_FILE"):
            env.pop(name, None)
        env.update(
            ROS_DOMAIN_ID=str(domain_id),
            ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
            PYTHONUNBUFFERED="1",
        )
        self.env = env
        self._contexts: list[Any] = []
        self._nodes: list[Any] = []
        self._executors: list[Any] = []
        self._processes: list[subprocess.Popen[str]] = []

    # -- rclpy in the test process -----------------------------------------------------------
    def context(self) -> Any:
        """A new ``rclpy.Context`` initialised on this graph's domain (shut down at teardown)."""
        import rclpy

        context = rclpy.Context()
        rclpy.init(args=[], context=context, domain_id=self.domain_id)
        self._contexts.append(context)
        return context

    def node(self, name: str, context: Any = None, **kwargs: Any) -> Any:
        """A new ``rclpy.node.Node`` in ``context`` (a fresh one by default), destroyed at teardown."""
        from rclpy.node import Node

        node = Node(name, context=context if context is not None else self.context(), **kwargs)
        self._nodes.append(node)
        return node

    def executor(self, nodes: Sequence[Any]) -> Any:
        """A ``SingleThreadedExecutor`` over ``nodes`` (all in one context), shut down at teardown.

        Jazzy's ``MultiThreadedExecutor`` starves timers and subscriptions; do not use it.
        """
        from rclpy.executors import SingleThreadedExecutor

        if not nodes:
            raise ValueError("executor() needs at least one node")
        executor = SingleThreadedExecutor(context=nodes[0].context)
        for node in nodes:
            executor.add_node(node)
        self._executors.append(executor)
        return executor

    def spin_until(self, condition: Callable[[], bool], timeout: float, nodes: Sequence[Any] = (), executor: Any = None) -> bool:
        """Spin ``executor`` (or a new one over ``nodes``) until ``condition()`` or ``timeout`` s.

        Returns:
            Whether the condition became true in time.
        """
        if executor is None:
            executor = self.executor(nodes)
        deadline = time.monotonic() + timeout
        while not condition():
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                return False
            executor.spin_once(timeout_sec=min(0.05, remaining))
        return True

    def call(self, client: Any, request: Any, executor: Any, timeout: float, resend_after: float | None = None) -> Any:
        """The answer of ``client``'s service to ``request``, spinning ``executor``; None when none
        came within ``timeout`` s.

        With ``resend_after``, for a request that may be repeated without effect (a ``get_state``),
        the request is sent again every ``resend_after`` s: Fast DDS may drop the answer to a
        request sent just after discovery, before the server's reply writer has matched the
        client's reader (``service_is_ready`` only says the request side has matched).
        """
        deadline = time.monotonic() + timeout
        while True:
            future = client.call_async(request)
            wait = deadline - time.monotonic() if resend_after is None else min(resend_after, deadline - time.monotonic())
            if self.spin_until(future.done, timeout=max(wait, 0.0), executor=executor):
                return future.result()
            client.remove_pending_request(future)
            if time.monotonic() >= deadline:
                return None

    # -- other processes ---------------------------------------------------------------------
    def spawn_python(self, *args: str, cwd: str | Path | None = None) -> subprocess.Popen[str]:
        """Start ``python args...`` (this interpreter) in this graph's environment.

        stdout and stderr are pipes in text mode; the process is killed at teardown if still
        running. Use ``communicate(timeout=...)`` to read them.
        """
        process = subprocess.Popen(
            [sys.executable, *args],
            env=self.env,
            cwd=str(cwd) if cwd is not None else str(REPO_ROOT),
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=_prepare_child,
        )
        self._processes.append(process)
        return process

    # -- teardown ----------------------------------------------------------------------------
    @staticmethod
    def _report_output(process: subprocess.Popen[str], out: str, err: str) -> None:
        """Print the end of what a spawned node wrote (``communicate`` gives it again to a test
        that read it the same way): pytest shows it under the failing test's teardown output (and
        nowhere for a passing one), so a node's own log explains a failure seen only in CI."""
        text = (out + err).strip()
        if text:
            command = " ".join(str(a) for a in process.args[1:4]) if isinstance(process.args, list) else str(process.args)
            print(f"--- {command} (exit {process.returncode}), last 4000 characters ---\n{text[-4000:]}", file=sys.stderr)

    def close(self) -> None:
        """Stop processes, then shut down executors, destroy nodes, shut down contexts."""
        for process in self._processes:
            if process.poll() is None:
                process.terminate()
        for process in self._processes:
            try:
                out, err = process.communicate(timeout=5.0)
            except subprocess.TimeoutExpired:
                process.kill()
                out, err = process.communicate()
            self._report_output(process, out or "", err or "")
        leaked = kill_processes_on_domain(self.domain_id)
        if leaked:
            warnings.warn(
                f"processes left on ROS domain {self.domain_id} at teardown, killed: "
                + "; ".join(f"{pid}: {command[:200]}" for pid, command in leaked.items()),
                stacklevel=1,
            )
        for executor in self._executors:
            executor.shutdown(timeout_sec=1.0)
        for node in self._nodes:
            node.destroy_node()
        for context in self._contexts:
            context.try_shutdown()
        self._processes.clear()
        self._executors.clear()
        self._nodes.clear()
        self._contexts.clear()


@pytest.fixture
def ros_graph(monkeypatch: pytest.MonkeyPatch) -> Iterator[RosGraph]:
    """An isolated ROS graph for one test (see the module docstring)."""
    lease = lease_domain()
    graph = RosGraph(lease.domain_id)
    monkeypatch.setenv("ROS_DOMAIN_ID", str(lease.domain_id))
    monkeypatch.setenv("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    monkeypatch.delenv("ROS_LOCALHOST_ONLY", raising=False)
    monkeypatch.delenv("ROS_STATIC_PEERS", raising=False)
    try:
        yield graph
    finally:
        try:
            graph.close()
        finally:
            lease.release()


# -- rig sessions (``bearing-rig run``) ------------------------------------------------------------
def start_run(ros_graph: RosGraph, program: Path, run_dir: Path, *extra: str) -> subprocess.Popen[str]:
    """Start ``bearing-rig run PROGRAM --no-realtime`` on the test's graph, recording under
    ``run_dir/bags``; stopped at teardown whatever the test's outcome."""
    return ros_graph.spawn_python("-m", "bearing_rig_sim.cli", "run", str(program), "--no-realtime", "--bag-dir", str(run_dir / "bags"), *extra)


def the_bag(run_dir: Path) -> Path:
    """The one bag a session started by :func:`start_run` recorded."""
    (bag,) = [p for p in (run_dir / "bags").iterdir() if p.is_dir()]
    return bag


def summary_rows(text: str) -> list[list[str]]:
    """The rows of a session's summary table, each split on whitespace."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("summary"))
    rows = []
    for line in lines[start + 3 :]:
        if not line.strip():
            break
        rows.append(line.split())
    return rows


def write_foreign_metadata(bag_dir: Path, topics: Sequence[tuple[str, str, int]], files: Sequence[str]) -> None:
    """A minimal ``metadata.yaml`` (rosbag2 format version 9) as another rosbag2 writer could
    produce it, beside storage files written by the test: ``topics`` are (name, type, message
    count), ``files`` the storage files' names. Written by hand, not by the project's writer, so
    that reading it tests the reader against the format rather than against itself."""
    import yaml

    doc = {
        "rosbag2_bagfile_information": {
            "version": 9,
            "storage_identifier": "mcap",
            "duration": {"nanoseconds": 0},
            "starting_time": {"nanoseconds_since_epoch": 0},
            "message_count": sum(count for _name, _type, count in topics),
            "topics_with_message_count": [
                {"topic_metadata": {"name": name, "type": msgtype, "serialization_format": "cdr", "offered_qos_profiles": []}, "message_count": count}
                for name, msgtype, count in topics
            ],
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": list(files),
        }
    }
    (bag_dir / "metadata.yaml").write_text(yaml.safe_dump(doc), encoding="utf-8")


def bearing_section(section: str, bearing: str = "h7006c.yaml") -> dict[str, Any]:
    """One section of a shipped bearing file as plain values, read as YAML independently of the
    package's loader: a value written with its stated range (``{value, unit, range, source}``)
    is given as its ``value``."""
    import yaml

    from bearing_rig_sim.config import config_path

    raw = yaml.safe_load(config_path("bearings", bearing).read_text())[section]
    return {key: entry["value"] if isinstance(entry, dict) and "value" in entry else entry for key, entry in raw.items()}


# -- tiers: a test that cannot run for want of a tool fails in CI --------------------------------
TIERS: dict[str, str] = {
    "ros": "rclpy and the ROS 2 Jazzy wheels with bearing_rig_msgs (./bootstrap.sh setup)",
    "ros2-cli": "the stock ros2 command line and launch (../shared/ros2/setup.sh beside the clone, or a ROS 2 Jazzy install)",
    "foxglove": "the foxglove-sdk, foxglove-websocket and websockets packages (requirements.lock)",
    "foxglove-client": "Node.js 20 and npm with access to the npm registry (Foxglove's published client, test/foxglove_client)",
    "distributed": "dask distributed (requirements.lock)",
    "colcon": "colcon with its ROS extensions (requirements.lock)",
}
"""The optional parts of the suite, by name: what each needs. A test skipped because its tier's
tools are missing fails instead when ``CI`` is set, unless :data:`ALLOW_MISSING` names the tier."""

ALLOW_MISSING = "BEARING_RIG_ALLOW_MISSING"
"""Environment variable: tiers (comma-separated names of :data:`TIERS`) that may be absent in CI."""

IMPORT_TIERS: dict[str, str] = {
    "rclpy": "ros",
    "bearing_rig_msgs": "ros",
    "foxglove": "foxglove",
    "foxglove_websocket": "foxglove",
    "websockets": "foxglove",
    "distributed": "distributed",
}
"""The tier of a module a test imports with ``pytest.importorskip`` (by its top-level name)."""


def skip_missing(tier: str, reason: str) -> NoReturn:
    """Skip the running test because a tool of ``tier`` (a key of :data:`TIERS`) is missing; in
    CI that skip is a failure unless the tier is allowed (see :func:`skip_failure`)."""
    __tracebackhide__ = True  # the skip is reported at its caller's line
    if tier not in TIERS:
        raise ValueError(f"unknown tier {tier!r} (tiers: {', '.join(TIERS)})")
    pytest.skip(f"missing {tier}: {reason}")


def in_ci() -> bool:
    """Whether the suite runs in CI: ``CI`` set to anything but empty, 0, false or no."""
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")


def allowed_missing() -> set[str]:
    """The tiers :data:`ALLOW_MISSING` allows to be absent.

    Raises:
        pytest.UsageError: it names a tier that does not exist.
    """
    named = {name.strip() for name in os.environ.get(ALLOW_MISSING, "").split(",") if name.strip()}
    unknown = sorted(named - set(TIERS))
    if unknown:
        raise pytest.UsageError(f"{ALLOW_MISSING}: unknown tier(s) {', '.join(unknown)} (tiers: {', '.join(TIERS)})")
    return named


def skip_tier(reason: str) -> str | None:
    """The tier a skip's reason names (:func:`skip_missing`, or ``importorskip`` of a module of
    :data:`IMPORT_TIERS`); None for any other skip."""
    match = re.match(r"(?:Skipped: )?missing ([a-z0-9-]+): ", reason)
    if match and match.group(1) in TIERS:
        return match.group(1)
    match = re.match(r"(?:Skipped: )?could not import '([\w.]+)'", reason)
    if match:
        return IMPORT_TIERS.get(match.group(1).split(".")[0])
    return None


def skip_failure(reason: str) -> str | None:
    """The failure a skip with ``reason`` is in CI, or None where it may stand (not in CI, or its
    tier allowed by :data:`ALLOW_MISSING`). In CI a skip that names no tier fails too: no test is
    left out without saying so."""
    if not in_ci():
        return None
    tier = skip_tier(reason)
    if tier is not None and tier in allowed_missing():
        return None
    if tier is None:
        return f"skipped in CI: {reason}. CI (CI is set) runs every test; only a missing tier may be allowed ({ALLOW_MISSING}; tiers: {', '.join(TIERS)})."
    return (
        f"skipped in CI: {reason}. Tier {tier!r} needs {TIERS[tier]}: provide it (./bootstrap.sh test on a machine set up as README.md says), "
        f"or let it be absent with {ALLOW_MISSING}={tier} (comma-separated; tiers: {', '.join(TIERS)})."
    )


def _skip_reason(longrepr: Any) -> str:
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2])
    return str(longrepr)


def pytest_configure(config: pytest.Config) -> None:
    allowed_missing()  # a wrong name in the variable stops the run at once, naming it


@pytest.hookimpl(wrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo[None]) -> Generator[None, Any, Any]:
    report: Any = yield
    if report.skipped and not hasattr(report, "wasxfail"):
        failure = skip_failure(_skip_reason(report.longrepr))
        if failure is not None:
            report.outcome = "failed"
            report.longrepr = failure
    return report


@pytest.hookimpl(wrapper=True)
def pytest_make_collect_report(collector: pytest.Collector) -> Generator[None, Any, Any]:
    report: Any = yield
    if report.skipped:  # a module-level importorskip
        failure = skip_failure(_skip_reason(report.longrepr))
        if failure is not None:
            report.outcome = "failed"
            report.longrepr = failure
    return report


# -- one timeout per test, and every wait inside it bounded by what is left of it ------------------
GUARD_MARGIN_S = 20.0
"""Time a test's own waits leave before its pytest timeout, s: a hung wait then fails with the
test's own message (the wait's timeout, naming what it waited for), and the teardown (stopping
the processes it started, 10-60 s at most) runs, before pytest-timeout would kill the test."""

_running: dict[str, Any] = {}


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Generator[None, Any, Any]:
    _running.update(item=item, start=time.monotonic())
    try:
        return (yield)
    finally:
        _running.clear()


def timeout_of(item: pytest.Item) -> float:
    """A test's pytest timeout, s: its ``timeout`` marker (the one limit a long test declares),
    else ``--timeout``, else pytest.ini's. It counts set-up (module fixtures made for the test
    included), call and teardown."""
    marker = item.get_closest_marker("timeout")
    if marker is not None:
        value = marker.args[0] if marker.args else marker.kwargs["timeout"]
    else:
        value = item.config.getoption("timeout", None) or item.config.getini("timeout")
    return float(value)


def time_left(margin_s: float = GUARD_MARGIN_S) -> float:
    """Seconds the running test's waits may still take: its :func:`timeout_of` less the time it
    has run (set-up included) and ``margin_s``; at least 1 s. Every hang guard inside a test is
    this, so the test's timeout marker is the one number that bounds it. Where pytest's timeout
    is off (0), a day.

    Raises:
        RuntimeError: called outside a running test.
    """
    if "item" not in _running:
        raise RuntimeError("time_left() is for code that runs inside a test (its set-up, call or teardown)")
    limit = timeout_of(_running["item"])
    if limit <= 0.0:
        return 86400.0
    return max(1.0, limit - (time.monotonic() - _running["start"]) - margin_s)
