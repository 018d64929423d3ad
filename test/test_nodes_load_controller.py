"""Load controller node in its own process on an isolated ROS graph, driven by a /clock the test
publishes in lockstep (one 1 ms tick, then wait for the force of that tick): a load step settles
within its stated time; bad set-points by topic, service and parameter are refused with a reason
and a WARN on /diagnostics while the node keeps answering; an interlock trips, refuses a reset
while its cause persists, and resets once it is gone.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any

import pytest
import yaml

rclpy = pytest.importorskip("rclpy")

from bearing_rig_msgs.msg import AxialLoadState  # noqa: E402
from bearing_rig_msgs.srv import SetAxialLoad  # noqa: E402
from builtin_interfaces.msg import Time  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus  # noqa: E402
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from rcl_interfaces.srv import SetParameters  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from rclpy.qos import QoSProfile, ReliabilityPolicy  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from std_msgs.msg import Float64  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402

from bearing_rig_sim.config import config_path  # noqa: E402
from bearing_rig_sim.load_control import settle_time_bound  # noqa: E402
from bearing_rig_sim.nodes.common import RELIABLE_QOS, from_stamp, to_stamp  # noqa: E402
from bearing_rig_sim.nodes.load_controller import DIAGNOSTIC_NAME  # noqa: E402
from bearing_rig_sim.rig.loading import LoadingChainConfig  # noqa: E402
from conftest import time_left  # noqa: E402

pytestmark = pytest.mark.ros

TICK = 0.001  # s of sim time per /clock message
RESEND = 0.5  # s of wall time without the force of a tick before the tick is sent again
DEEP = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)


class Harness:
    """The test's side of the graph: clock, set-point publisher, service clients, recorders."""

    def __init__(self, ros_graph: Any, *ros_args: str) -> None:
        self.graph = ros_graph
        self.process = ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.load_controller", "--autostart", "--ros-args", *ros_args)
        self.node = ros_graph.node("load_controller_test")
        self.executor = ros_graph.executor([self.node])
        self.time = 0.0
        self.forces: dict[int, float] = {}
        self.states: list[AxialLoadState] = []
        self.diagnostics: list[DiagnosticStatus] = []
        node = self.node
        self.clock = node.create_publisher(Clock, "/clock", RELIABLE_QOS)
        self.setpoint = node.create_publisher(Float64, "/rig/axial_load/setpoint", RELIABLE_QOS)
        node.create_subscription(WrenchStamped, "/rig/bearing/axial_force", self._on_force, DEEP)
        node.create_subscription(AxialLoadState, "/rig/axial_load/state", self.states.append, DEEP)
        node.create_subscription(DiagnosticArray, "/diagnostics", self._on_diagnostics, DEEP)
        self.set_client = node.create_client(SetAxialLoad, "/rig/axial_load/set")
        self.reset_client = node.create_client(Trigger, "/rig/axial_load/reset_fault")
        self.param_client = node.create_client(SetParameters, "/load_controller/set_parameters")
        ready = self.spin_until(
            lambda: (
                self.clock.get_subscription_count() > 0
                and self.setpoint.get_subscription_count() > 0
                and node.count_publishers("/rig/bearing/axial_force") > 0
                and node.count_publishers("/diagnostics") > 0
                and all(c.service_is_ready() for c in (self.set_client, self.reset_client, self.param_client))
            ),
        )
        assert ready, self.failure("the load controller did not come up")
        # The first clock reading starts the node's count; it is repeated until the node, active
        # and matched to this probe's subscription (slow on a busy host), answers it.
        self.tick()

    def failure(self, what: str) -> str:
        if self.process.poll() is not None:
            _, err = self.process.communicate()
            return f"{what}; it exited with {self.process.returncode}: {err[-2000:]}"
        return what

    def _on_force(self, msg: WrenchStamped) -> None:
        self.forces[round(from_stamp(msg.header.stamp) / TICK)] = msg.wrench.force.z

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        self.diagnostics.extend(s for s in msg.status if s.name == DIAGNOSTIC_NAME)

    def spin_until(self, condition: Any, timeout: float | None = None) -> bool:
        """Spin until ``condition()``, at most ``timeout`` s (default: the test's time left)."""
        return self.graph.spin_until(condition, timeout=time_left() if timeout is None else timeout, executor=self.executor)

    def tick(self) -> float:
        """One clock tick; returns the bearing force the node published for it.

        Waits for that force (the event), sending the tick again every ``RESEND`` s meanwhile: the
        node reads /clock best effort, so a tick may be lost, and a repeated stamp does not step
        it again. Only a node silent for the rest of the test's time fails the tick.
        """
        self.time += TICK
        key = round(self.time / TICK)
        deadline = time.monotonic() + time_left()
        while True:
            self.clock.publish(Clock(clock=to_stamp(self.time)))
            if self.spin_until(lambda: key in self.forces, timeout=min(RESEND, max(deadline - time.monotonic(), 0.0))):
                return self.forces[key]
            if time.monotonic() >= deadline:
                raise AssertionError(self.failure(f"no force for t = {self.time:.3f} s within the test's time"))

    def run(self, seconds: float) -> list[tuple[float, float]]:
        """Tick for ``seconds`` of sim time; (time, bearing force) per tick."""
        return [(self.time, self.tick()) for _ in range(int(round(seconds / TICK)))]

    def call(self, client: Any, request: Any) -> Any:
        future = client.call_async(request)
        assert self.spin_until(future.done), self.failure("no answer from the load controller")
        return future.result()

    def set_by_service(self, force: float) -> SetAxialLoad.Response:
        return self.call(self.set_client, SetAxialLoad.Request(axial_load=force))

    def set_by_parameter(self, value: Any) -> Any:
        parameter = Parameter("axial_load_setpoint_n", value=value).to_parameter_msg()
        return self.call(self.param_client, SetParameters.Request(parameters=[parameter])).results[0]

    def mark(self) -> int:
        """Where the diagnostics received so far end (for :meth:`wait_diagnostic`)."""
        return len(self.diagnostics)

    def wait_diagnostic(self, since: int, level: bytes, *words: str) -> DiagnosticStatus:
        """The first status after ``since`` at ``level`` whose message holds every word."""
        start = since

        def found() -> DiagnosticStatus | None:
            for status in self.diagnostics[start:]:
                if status.level == level and all(w in status.message for w in words):
                    return status
            return None

        assert self.spin_until(lambda: found() is not None), self.failure(
            f"no diagnostic at level {level!r} with {words}; got {[(s.level, s.message) for s in self.diagnostics[start:]]}"
        )
        status = found()
        assert status is not None
        return status


def test_load_step_settles_within_the_stated_time(ros_graph: Any) -> None:
    config = LoadingChainConfig.from_yaml()
    target = 500.0
    bound = settle_time_bound(config, 0.0, target)
    assert bound < 0.25  # the chain's stated settle time for this step (see settle_time_bound)
    rig = Harness(ros_graph)
    mark = rig.mark()
    rig.setpoint.publish(Float64(data=target))
    rig.wait_diagnostic(mark, DiagnosticStatus.OK, f"set-point {target:g} N")
    start = rig.time
    states_before = len(rig.states)
    samples = rig.run(0.6)
    outside = [t for t, f in samples if abs(f - target) > 0.02 * target]
    settle = (outside[-1] - start) if outside else 0.0
    assert settle <= bound, f"settled in {settle:.3f} s > stated {bound:.3f} s"
    assert max(f for _, f in samples) < 1.02 * target  # no overshoot out of the band
    states = rig.states[states_before:]
    assert 59 <= len(states) <= 61  # 100 Hz of sim time over 0.6 s
    assert states[-1].setpoint == target and not states[-1].fault
    assert states[-1].bearing_force == pytest.approx(target, rel=0.02)


BAD_VALUES = [(math.nan, "finite"), (-5.0, ">= 0"), (5000.0, "<= 1000"), (20_000.0, "<= 1000")]
CHAIN_LIMIT_N = float(yaml.safe_load(config_path("rig.yaml").read_text(encoding="utf-8"))["loading_chain"]["max_setpoint_n"])
"""The set-point parameter's declared upper bound: the loading chain's limit in config/rig.yaml."""


def test_bad_setpoints_are_refused_by_every_route_and_the_node_answers(ros_graph: Any) -> None:
    rig = Harness(ros_graph)
    assert rig.set_by_service(100.0).accepted
    rig.run(0.01)
    for value, reason in BAD_VALUES:
        mark = rig.mark()
        rig.setpoint.publish(Float64(data=value))
        status = rig.wait_diagnostic(mark, DiagnosticStatus.WARN, "by topic refused", reason)
        assert "keeping 100 N" in status.message
        mark = rig.mark()
        assert rig.set_by_service(100.0).accepted  # clears the WARN
        rig.wait_diagnostic(mark, DiagnosticStatus.OK)

        mark = rig.mark()
        reply = rig.set_by_service(value)
        assert not reply.accepted and reason in reply.message
        rig.wait_diagnostic(mark, DiagnosticStatus.WARN, "by service refused", reason)
        assert rig.set_by_service(100.0).accepted

        mark = rig.mark()
        result = rig.set_by_parameter(value)
        assert not result.successful
        if 0.0 <= value <= CHAIN_LIMIT_N:  # inside the parameter's declared range: the chain refuses it
            assert reason in result.reason
            rig.wait_diagnostic(mark, DiagnosticStatus.WARN, "by parameter refused", reason)
        else:  # outside the declared range (the descriptor's bound is the chain's limit): ROS refuses it
            assert "out of range" in result.reason and f"Max: {CHAIN_LIMIT_N}" in result.reason, result.reason
        assert rig.set_by_service(100.0).accepted
    result = rig.set_by_parameter("a lot")
    assert not result.successful and "must be a number" in result.reason
    # still answering, still holding the last accepted set-point, stepping on the clock
    assert rig.set_by_parameter(250).successful  # an integer is a valid number of newtons
    states_before = len(rig.states)
    rig.run(0.5)
    assert rig.states[-1].setpoint == 250.0 and len(rig.states) > states_before
    assert rig.states[-1].bearing_force == pytest.approx(250.0, rel=0.02)
    assert rig.process.poll() is None


def test_interlock_trip_refused_reset_then_reset(ros_graph: Any, tmp_path: Path) -> None:
    shipped = config_path("rig.yaml").read_text(encoding="utf-8")
    assert "holding_force_n: 1500.0" in shipped
    weak = tmp_path / "rig_weak_clutch.yaml"
    weak.write_text(shipped.replace("holding_force_n: 1500.0", "holding_force_n: 300.0"), encoding="utf-8")
    rig = Harness(ros_graph, "-p", f"rig_file:={weak}")
    assert rig.set_by_service(500.0).accepted  # above what the weak magnet holds
    mark = rig.mark()
    for _ in range(1000):
        rig.tick()
        if any(s.level == DiagnosticStatus.ERROR for s in rig.diagnostics[mark:]):
            break
    status = rig.wait_diagnostic(mark, DiagnosticStatus.ERROR, "clutch slip")
    assert "300 N" in status.message

    reply = rig.call(rig.reset_client, Trigger.Request())  # 500 N would slip again
    assert not reply.success and "holding force 300 N" in reply.message
    stored = rig.set_by_service(200.0)  # accepted, but waits for the reset
    assert stored.accepted and "after reset_fault" in stored.message
    samples = rig.run(0.3)
    assert samples[-1][1] < 5.0  # brake de-energised: the load is gone, and stays gone
    assert rig.states[-1].fault and rig.states[-1].fault_reason.startswith("clutch slip")

    mark = rig.mark()
    reply = rig.call(rig.reset_client, Trigger.Request())
    assert reply.success, reply.message
    rig.wait_diagnostic(mark, DiagnosticStatus.OK)
    samples = rig.run(0.6)
    assert samples[-1][1] == pytest.approx(200.0, rel=0.02)
    assert not rig.states[-1].fault


@pytest.mark.parametrize(
    "ros_args, expected",
    [
        (["-p", "use_sim_time:=false"], "use_sim_time must be true"),
        (["-p", "rig_file:=/nonexistent/rig.yaml"], "/nonexistent/rig.yaml"),
        (["-p", "state_rate_hz:=0.0"], "state_rate_hz: must be > 0"),
        (["-p", "state_rate_hz:=5000.0"], "range: > 0 and <= 1000"),
        (["-p", "state_rate_hz:=fast"], "state_rate_hz: must be a number, got 'fast'"),
        (["--params-file", "{tmp}/broken.yaml"], "ROS arguments refused: failed to initialize rcl: Couldn't parse params file"),
    ],
)
def test_start_up_errors_are_one_line_and_exit_2(ros_graph: Any, tmp_path: Path, ros_args: list[str], expected: str) -> None:
    (tmp_path / "broken.yaml").write_text("load_controller:\n  ros__parameters:\n    state_rate_hz: [1,\n")
    ros_args = [arg.replace("{tmp}", str(tmp_path)) for arg in ros_args]
    process = ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.load_controller", "--autostart", "--ros-args", *ros_args)
    _, err = process.communicate(timeout=time_left())
    assert process.returncode == 2, err[-2000:]
    assert "load_controller: error:" in err and expected in err and "Traceback" not in err


def test_negative_and_far_future_clock_stamps_are_refused_and_the_node_lives_on(ros_graph: Any) -> None:
    """One /clock before 1970 used to end the node (rclpy's ValueError in its time source); one
    at 2^31 - 1 s moved its time to 2038. Both are refused: the node keeps stepping on the good
    clock, and nothing it publishes is stamped on the bad ones."""
    rig = Harness(ros_graph)
    rig.setpoint.publish(Float64(data=200.0))
    rig.run(0.3)
    good = rig.time
    for bad in (Clock(clock=Time(sec=-5, nanosec=0)), Clock(clock=Time(sec=2**31 - 1, nanosec=0))):
        for _ in range(3):  # the node's /clock input is best effort: send each a few times
            rig.clock.publish(bad)
    samples = rig.run(0.2)  # every tick of the good clock still gets its force
    assert rig.process.poll() is None, rig.failure("the load controller stopped")
    assert samples[-1][1] == pytest.approx(200.0, rel=0.02)
    assert max(rig.forces) == round(rig.time / TICK)  # no force stamped after the good clock
    assert min(rig.forces) > 0 and rig.time == pytest.approx(good + 0.2)


def test_clock_stamps_are_read_from_the_serialized_message() -> None:
    """The step reads /clock serialized: the stamp must be the one rclpy serialized."""
    from rclpy.serialization import serialize_message
    from rosgraph_msgs.msg import Clock

    from bearing_rig_sim.nodes.load_controller import clock_stamp

    for sec, nanosec in ((0, 1_000_000), (1_795_400_000, 999_999_999), (-5, 7), (2**31 - 1, 2**32 - 1)):
        msg = Clock()
        msg.clock.sec, msg.clock.nanosec = sec, nanosec
        assert clock_stamp(serialize_message(msg)) == (sec, nanosec)
