"""Bag replay: the schedule with a fake clock (no ROS), then into an isolated ROS graph: pulse
timing, /clock, unknown types, and a monitor node reaching the recorded verdict."""

from __future__ import annotations

import math
import struct
import sys
import warnings
from pathlib import Path
from typing import Any

import pytest

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.monitoring import MonitorState
from bearing_rig_sim.bags import QOS_PROFILES, BagError, BagWarning, BagWriter, TopicInfo, open_bag, rig_typestore
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.replay.player import (
    CLOCK_TOPIC,
    ReplayOptions,
    ReplaySchedule,
    clock_message,
    message_class,
    offered_qos,
    replay_bag,
)
from bearing_rig_sim.synthetic.traffic import RIG_TRAFFIC_TOPICS, sample_message

sys.path.insert(0, str(Path(__file__).parent))
from test_offline_analysis import write_twin_bag

PULSE = "bearing_rig_msgs/msg/FibreOpticPulse"
CAGE = "/rig/cage/pulses"

OVERSHOOT = 2e-4
"""The fake clock oversleeps by this much (s), as time.sleep does."""
PUBLISH_COST = 3e-4
"""Each fake publish takes this long (s)."""


class FakeClock:
    """Monotonic time that advances only by sleeping (plus an overshoot) and by publishing."""

    def __init__(self) -> None:
        self.t = 1000.0

    def now(self) -> float:
        return self.t

    def sleep(self, seconds: float) -> None:
        assert seconds > 0.0
        self.t += seconds + OVERSHOOT


class ListSink:
    """Records (clock time, topic, bytes) of each publish; topics in ``missing`` have no type."""

    def __init__(self, clock: FakeClock, missing: tuple[str, ...] = ()) -> None:
        self.clock = clock
        self.missing = missing
        self.sent: list[tuple[float, str, bytes]] = []

    def can_publish(self, topic: str) -> bool:
        return topic not in self.missing

    def publish(self, topic: str, data: bytes) -> None:
        self.sent.append((self.clock.t, topic, data))
        self.clock.t += PUBLISH_COST


def pulse_bytes(index: int, time_ns: int) -> bytes:
    store = rig_typestore()
    message = sample_message(PULSE, index, store)
    message.header.stamp.sec, message.header.stamp.nanosec = divmod(time_ns, 10**9)
    message.pulse_index = index
    return bytes(store.serialize_cdr(message, PULSE))


def clock_ns(data: bytes) -> int:
    sec, nanosec = struct.unpack_from("<iI", data, 4)
    return sec * 10**9 + nanosec


def write_pulse_bag(path: Path, times_ns: list[int], *, with_clock: bool = False, extra: tuple[str, str] | None = None) -> None:
    """Cage pulses at ``times_ns`` (optionally /clock every 5 ms, a topic of another type)."""
    with BagWriter(path) as bag:
        bag.add_topic(CAGE, *RIG_TRAFFIC_TOPICS[CAGE])
        if with_clock:
            bag.add_topic(CLOCK_TOPIC, "rosgraph_msgs/msg/Clock", "reliable")
            for t in range(times_ns[0], times_ns[-1] + 1, 5_000_000):
                bag.write(CLOCK_TOPIC, t, clock_message(t))
        if extra is not None:
            bag.add_topic(*extra, "reliable")
            bag.write_message(extra[0], times_ns[0] + 1, sample_message(extra[1], 0))
        for index, t in enumerate(times_ns):
            bag.write(CAGE, t + 2, pulse_bytes(index, t))


# Irregular pulse times over 1.2 s, starting far from zero (bench-like stamps).
TIMES_NS = [5_000_000_000 + sum(7_000_000 + 3_000_000 * (k % 5) for k in range(i)) for i in range(120)]


@pytest.mark.parametrize("rate", [1.0, 2.0, 0.5])
def test_schedule_follows_the_log_time_without_drift(tmp_path: Path, rate: float) -> None:
    """Every message goes out at (log - first) / rate after the start (the end of the first
    /clock's publish), late by no more than one oversleep plus one publish, however many messages
    came before (absolute deadlines)."""
    write_pulse_bag(tmp_path / "bag", TIMES_NS)
    clock = FakeClock()
    sink = ListSink(clock)
    with open_bag(tmp_path / "bag") as bag:
        stats = replay_bag(bag, sink, ReplayOptions(rate=rate, topics=(CAGE,)), clock)
        first = bag.start_ns
    first_clock = sink.sent[0]
    assert first_clock[1] == CLOCK_TOPIC and clock_ns(first_clock[2]) == first
    start = first_clock[0] + PUBLISH_COST
    pulses = [(t, data) for t, topic, data in sink.sent if topic == CAGE]
    assert len(pulses) == len(TIMES_NS) and stats.published == {CAGE: len(TIMES_NS)}
    for (sent_at, _data), log_ns in zip(pulses, TIMES_NS):
        due = start + (log_ns + 2 - first) * 1e-9 / rate
        assert due - 1e-9 <= sent_at <= due + OVERSHOOT + PUBLISH_COST + 1e-9
    assert stats.max_late <= OVERSHOOT + PUBLISH_COST + 1e-9
    assert [data for _t, data in pulses] == [pulse_bytes(i, t) for i, t in enumerate(TIMES_NS)]


def test_clock_is_made_from_the_log_time_when_the_bag_has_none(tmp_path: Path) -> None:
    write_pulse_bag(tmp_path / "bag", TIMES_NS)
    clock = FakeClock()
    sink = ListSink(clock)
    with open_bag(tmp_path / "bag") as bag:
        stats = replay_bag(bag, sink, ReplayOptions(clock_hz=50.0), clock)
        first, last = bag.start_ns, bag.end_ns
    clocks = [clock_ns(data) for _t, topic, data in sink.sent if topic == CLOCK_TOPIC]
    assert clocks == list(range(first, last + 1, 20_000_000)) and stats.clock_messages == len(clocks)
    # each /clock goes out before the pulses of its time, and no pulse runs ahead of the clock
    latest = 0
    for _t, topic, data in sink.sent:
        if topic == CLOCK_TOPIC:
            latest = clock_ns(data)
        else:
            assert clock_ns(data) <= latest + 20_000_000  # a pulse's stamp leads its message too


def test_the_bags_clock_is_replayed_as_recorded(tmp_path: Path) -> None:
    write_pulse_bag(tmp_path / "bag", TIMES_NS, with_clock=True)
    clock = FakeClock()
    sink = ListSink(clock)
    with open_bag(tmp_path / "bag") as bag:
        replay_bag(bag, sink, ReplayOptions(topics=(CAGE,)), clock)
        recorded = [clock_message(t) for t in range(TIMES_NS[0], TIMES_NS[-1] + 1, 5_000_000)]
    clocks = [data for _t, topic, data in sink.sent if topic == CLOCK_TOPIC]
    assert clocks == [clock_message(TIMES_NS[0])] + recorded


def test_loop_restarts_with_a_clock_jump_back(tmp_path: Path) -> None:
    write_pulse_bag(tmp_path / "bag", TIMES_NS)
    clock = FakeClock()
    sink = ListSink(clock)
    with open_bag(tmp_path / "bag") as bag:
        stats = replay_bag(bag, sink, ReplayOptions(rate=2.0, loop=True, max_loops=3, clock_hz=10.0), clock)
        first = bag.start_ns
    assert stats.loops == 3 and stats.published == {CAGE: 3 * len(TIMES_NS)}
    clocks = [(t, clock_ns(data)) for t, topic, data in sink.sent if topic == CLOCK_TOPIC]
    jumps = [(a, b) for a, b in zip(clocks, clocks[1:]) if b[1] < a[1]]
    assert len(jumps) == 2 and all(b[1] == first for _a, b in jumps)
    per_pass = len(sink.sent) // 3
    span = (TIMES_NS[-1] - TIMES_NS[0]) * 1e-9 / 2.0
    for n in (1, 2):  # each pass keeps the timing of the first, shifted by a pass
        for (t0, topic0, data0), (t1, topic1, data1) in zip(sink.sent[:per_pass], sink.sent[n * per_pass : (n + 1) * per_pass]):
            assert (topic0, data0) == (topic1, data1)
            assert t1 - t0 == pytest.approx(n * span, abs=n * (OVERSHOOT + 2 * PUBLISH_COST) + 1e-6)


def test_start_duration_and_selection(tmp_path: Path) -> None:
    write_pulse_bag(tmp_path / "bag", TIMES_NS, extra=("/bench/setpoint", "std_msgs/msg/Float64"))
    clock = FakeClock()
    sink = ListSink(clock, missing=("/bench/setpoint",))
    with open_bag(tmp_path / "bag") as bag:
        stats = replay_bag(bag, sink, ReplayOptions(start=0.3, duration=0.5), clock)
        with pytest.raises(BagError, match=r"no topic /rig/nothing in the bag \(it has /bench/setpoint, /rig/cage/pulses\)"):
            replay_bag(bag, sink, ReplayOptions(topics=("/rig/nothing",)), clock)
        with pytest.raises(BagError, match="nothing to replay"):
            replay_bag(bag, sink, ReplayOptions(start=5.0), clock)
        first = bag.start_ns
    window = [t for t in TIMES_NS if first + 300_000_000 <= t + 2 < first + 800_000_000]
    assert stats.published == {CAGE: len(window)} and stats.skipped_topics == ["/bench/setpoint"]
    assert clock_ns(sink.sent[0][2]) == first + 300_000_000


@pytest.mark.parametrize(
    ("options", "problem"),
    [({"rate": 0.0}, "rate"), ({"rate": float("nan")}, "rate"), ({"start": -1.0}, "start"), ({"duration": 0.0}, "duration"), ({"clock_hz": 0.0}, "clock_hz")],
)
def test_bad_options_are_refused(options: dict, problem: str) -> None:
    with pytest.raises(ConfigError, match=f"replay: {problem}: must be"):
        ReplayOptions(**options)
    if "rate" in options:
        with pytest.raises(ConfigError, match="replay: rate: must be"):
            ReplaySchedule(options["rate"], FakeClock())


def test_message_classes_and_qos() -> None:
    assert message_class("bearing_rig_msgs/msg/FibreOpticPulse").__name__ == "FibreOpticPulse"
    assert message_class("sensor_msgs/msg/JointState").__module__.startswith("sensor_msgs.msg")
    assert message_class("bench_msgs/msg/Secret") is None and message_class("std_msgs/msg/Nothing") is None
    assert message_class("not a type") is None
    best_effort = QOS_PROFILES["sensor_data"]
    assert offered_qos("/rig/slip_status", TopicInfo("/rig/slip_status", PULSE, 1, None, "", True)).durability == "transient_local"
    assert offered_qos("/rig/slip_status", TopicInfo("/rig/slip_status", PULSE, 1, best_effort, "", True)) == best_effort
    assert offered_qos("/bench/anything", None).reliability == "reliable"


# ---------------------------------------------------------------------------------------------
# Into a ROS graph
# ---------------------------------------------------------------------------------------------
CLOCKS_APART_S = 1e-3
"""The middleware stamps a sample (its ``source_timestamp``) on the system clock, the player keeps
its schedule on the monotonic one. Over the replays here (2.4 s at most) the two part by the
system clock's slewing only, at most 500 ppm on Linux (adjtimex(2): the kernel's frequency
offset is limited to +-500 ppm), 1.2 ms at most; a wrong rate or a schedule started late is off
by hundreds of milliseconds."""
ATTEMPTS = 3
"""Replays tried at most for the one the test can measure: the first /clock reaches the test's
reader (its match, like the pulses', is discovery's business; the replay waits for the pulses' only)."""


@pytest.mark.ros
@pytest.mark.parametrize("rate", [0.5, 2.0])
def test_no_replayed_pulse_leaves_before_its_time(ros_graph, tmp_path: Path, rate: float) -> None:
    """Through the middleware, on the real clocks: each pulse is published (its source timestamp)
    no sooner than its offset in the bag divided by the rate after the replay's first /clock, and
    all arrive, in order, with their stamps. Rate 0.5 fails if the rate is ignored or inverted
    (the pulses would leave early). How late they leave depends on the host's load and is
    measured by ``bearing-rig bench replay``; that no lateness accumulates (absolute deadlines)
    is the schedule's test above, on a fake clock."""
    from bearing_rig_msgs.msg import FibreOpticPulse
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from rosgraph_msgs.msg import Clock

    from conftest import time_left

    write_pulse_bag(tmp_path / "bag", TIMES_NS)
    first_ns = TIMES_NS[0] + 2  # the bag's first log time: the replay's first /clock
    node = ros_graph.node("listener")
    pulses: list[tuple[float, int]] = []
    clocks: list[tuple[float, int]] = []

    def on_pulse(message: FibreOpticPulse, info: dict) -> None:
        pulses.append((info["source_timestamp"] * 1e-9, message.header.stamp.sec * 10**9 + message.header.stamp.nanosec))

    def on_clock(message: Clock, info: dict) -> None:
        clocks.append((info["source_timestamp"] * 1e-9, message.clock.sec * 10**9 + message.clock.nanosec))

    deep = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
    node.create_subscription(FibreOpticPulse, CAGE, on_pulse, QoSProfile(depth=len(TIMES_NS), reliability=ReliabilityPolicy.BEST_EFFORT))
    node.create_subscription(Clock, CLOCK_TOPIC, on_clock, deep)
    executor = ros_graph.executor([node])
    missed = []
    for _attempt in range(ATTEMPTS):
        pulses.clear()
        clocks.clear()
        process = ros_graph.spawn_python(
            "-m", "bearing_rig_sim.cli", "replay", str(tmp_path / "bag"), "--rate", str(rate), "--wait-for-subscribers", "--delay", "20"
        )
        ros_graph.spin_until(lambda: len(pulses) == len(TIMES_NS) or process.poll() is not None, timeout=time_left(), executor=executor)  # noqa: B023 - waited on at once
        ros_graph.spin_until(lambda: len(pulses) == len(TIMES_NS), timeout=time_left(), executor=executor)  # the last ones in flight
        out, err = process.communicate(timeout=time_left())
        assert process.returncode == 0, err
        assert "1 pass(es)" in out
        assert [stamp for _sent, stamp in pulses] == TIMES_NS, "pulses lost or out of order"
        start = [sent for sent, value in clocks if value == first_ns]
        if not start:
            missed.append(f"first /clock not received ({len(clocks)} /clock messages, from {clocks[0][1] if clocks else None} ns)")
            continue
        early = [
            (index, round((start[0] + (stamp - TIMES_NS[0]) * 1e-9 / rate - sent) * 1e3, 3))
            for index, (sent, stamp) in enumerate(pulses)
            if sent < start[0] + (stamp - TIMES_NS[0]) * 1e-9 / rate - CLOCKS_APART_S
        ]
        assert not early, f"pulses published before their time (index, ms early): {early[:10]}"
        return
    pytest.fail(f"no replay measurable in {ATTEMPTS}: {'; '.join(missed)}")


@pytest.mark.ros
def test_unknown_type_is_warned_and_skipped(ros_graph) -> None:
    from bearing_rig_sim.replay.player import RosReplaySink

    topics = {
        CAGE: TopicInfo(CAGE, PULSE, 1, None, "", True),
        "/bench/secret": TopicInfo("/bench/secret", "bench_msgs/msg/Secret", 1, None, "", False),
    }
    with pytest.warns(BagWarning, match=r"topic /bench/secret: type bench_msgs/msg/Secret is not installed"):
        sink = RosReplaySink(topics)
    with sink:
        assert sink.can_publish(CAGE) and sink.can_publish(CLOCK_TOPIC) and not sink.can_publish("/bench/secret")


@pytest.mark.ros
def test_monitor_on_a_replay_reaches_the_recorded_verdict(ros_graph, tmp_path: Path) -> None:
    """The monitor node (its console script, on use_sim_time: the replay's /clock) fed a replay
    of the pulse topics ends with the verdict the bag recorded, which the offline analysis also
    gives. Waited for is the event that carries it, a status stamped at the recorded last
    window's end (the same pulses close the same windows); on the replay's clock, which stops
    with it, no sensor loss follows, however late the monitor comes."""
    from bearing_rig_msgs.msg import SlipStatus
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy

    from conftest import time_left

    bag = tmp_path / "twin"
    write_twin_bag(bag, 4.0, start_rpm=1800.0, step_at=None, record_status=True)
    with open_bag(bag) as reader:
        recorded = [(m.message.header.stamp.sec + m.message.header.stamp.nanosec * 1e-9, m.message.state) for m in reader.messages(["/rig/slip_status"])]
    last_stamp, last_state = recorded[-1]
    assert last_state == MonitorState.STABLE
    with warnings.catch_warnings():
        warnings.simplefilter("error", BagWarning)
        offline = analyse_bag(bag)
    assert offline.final_status is not None and offline.final_status.state == last_state

    node = ros_graph.node("observer")
    statuses: list[tuple[float, int]] = []  # (stamp, state)
    qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    node.create_subscription(SlipStatus, "/rig/slip_status", lambda m: statuses.append((m.header.stamp.sec + m.header.stamp.nanosec * 1e-9, m.state)), qos)
    executor = ros_graph.executor([node])
    monitor = ros_graph.spawn_python(
        "-c", "import sys; from bearing_rig_sim.nodes.monitor import main; sys.exit(main(['monitor', '--autostart', '--ros-args', '-p', 'use_sim_time:=true']))"
    )
    assert ros_graph.spin_until(lambda: bool(statuses), timeout=time_left(), executor=executor), "the monitor node did not come up"
    replay = ros_graph.spawn_python(
        "-m", "bearing_rig_sim.cli", "replay", str(bag), "--topics", "/rig/spindle/pulses", "/rig/cage/pulses", "--wait-for-subscribers", "--delay", "20"
    )
    ros_graph.spin_until(lambda: replay.poll() is not None, timeout=time_left(), executor=executor)
    assert replay.returncode == 0, replay.communicate()[1]

    def final() -> list[tuple[float, int]]:
        return [(stamp, state) for stamp, state in statuses if stamp >= last_stamp - 1e-6]

    assert ros_graph.spin_until(lambda: bool(final()), timeout=time_left(), executor=executor), (
        f"no status stamped at the last window's end {last_stamp:.6f} s; the last: {statuses[-3:]}"
    )
    stamp, state = final()[0]
    assert abs(stamp - last_stamp) <= 1e-6 and state == last_state, (final(), recorded[-3:])
    assert all(state != MonitorState.FAULT for _stamp, state in statuses), statuses
    assert monitor.poll() is None


@pytest.mark.ros
def test_ctrl_c_stops_a_looping_replay_cleanly(ros_graph, tmp_path: Path) -> None:
    import signal

    from bearing_rig_msgs.msg import FibreOpticPulse
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    write_pulse_bag(tmp_path / "bag", TIMES_NS)
    node = ros_graph.node("listener")
    received: list[int] = []
    node.create_subscription(FibreOpticPulse, CAGE, lambda m: received.append(m.pulse_index), QoSProfile(depth=200, reliability=ReliabilityPolicy.BEST_EFFORT))
    process = ros_graph.spawn_python(
        "-m", "bearing_rig_sim.cli", "replay", str(tmp_path / "bag"), "--loop", "--rate", "4", "--wait-for-subscribers", "--delay", "20"
    )
    from conftest import time_left

    executor = ros_graph.executor([node])

    def second_pass() -> bool:  # an index lower than the one before: the bag began again (best effort may drop any one pulse)
        return any(later < earlier for earlier, later in zip(received, received[1:]))

    assert ros_graph.spin_until(second_pass, timeout=time_left(), executor=executor), f"received {len(received)} pulses"
    process.send_signal(signal.SIGINT)
    out, err = process.communicate(timeout=time_left())  # the test's guard bounds a hang; how soon it exits is no part of the contract
    assert process.returncode == 130, err
    assert "replay interrupted" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "msgtype",
    [
        "venv.__main__/msg/X",  # the audit's bag: importing it ran the venv module
        "this/msg/Zen",  # a valid package name, but not an interface package: never imported
        "json/msg/Decoder",
        "os/msg/System",
        "../evil/msg/X",
        "std_msgs/msg/string",  # not a message type name
    ],
)
def test_crafted_type_names_are_not_imported(msgtype: str) -> None:
    import sys

    top = msgtype.split("/")[0].split(".")[0]
    was_loaded = {name for name in sys.modules if name == top or name.startswith(f"{top}.")}
    assert message_class(msgtype) is None
    now_loaded = {name for name in sys.modules if name == top or name.startswith(f"{top}.")}
    assert now_loaded == was_loaded  # nothing of it was imported


def test_interface_packages_are_told_apart_without_importing_them() -> None:
    from bearing_rig_sim.replay.player import is_interface_package

    assert is_interface_package("std_msgs") and is_interface_package("bearing_rig_msgs")
    assert not is_interface_package("this") and not is_interface_package("rclpy")
    assert not is_interface_package("venv.__main__") and not is_interface_package("")


@pytest.mark.ros
def test_the_replay_benchmark_measures_every_pulse_and_none_early() -> None:
    """``bearing-rig bench replay`` (its own processes and domain): every pulse of its bag is
    measured, and none left before its time (the contract above, to the clocks' parting)."""
    import argparse

    from bearing_rig_sim.benchmarks import replay as bench_replay

    (row,) = bench_replay.run(argparse.Namespace(rate=[2.0], seconds=1.0, rpm=2700.0, repeats=1))
    assert row["received"] == row["published"] > 200  # 2700 rpm, 4 strips, two shafts: ~ 250 pulses in 1 s
    assert row["early_ms"] <= CLOCKS_APART_S * 1e3
    assert all(math.isfinite(row[k]) for k in ("late_p50_ms", "late_max_ms", "transit_p99_ms"))


@pytest.mark.parametrize(("option", "value"), [("rate", [0.0]), ("rate", [2.0, float("nan")]), ("seconds", -1.0), ("rpm", float("inf")), ("repeats", 0)])
def test_the_replay_benchmark_names_a_bad_option(option: str, value: Any) -> None:
    import argparse

    from bearing_rig_sim.benchmarks import replay as bench_replay
    from bearing_rig_sim.errors import RigError

    args = argparse.Namespace(**{"rate": [1.0], "seconds": 1.0, "rpm": 2700.0, "repeats": 1, option: value})
    with pytest.raises(RigError, match=f"bench replay: --{option} must be"):
        next(iter(bench_replay.run(args)))
