"""``bearing-rig run`` end to end: the three nodes as processes on the test's isolated domain, a
shortened validation program without real time, recorded into tmp_path. It runs to the end with a
stable verdict and a bag that both readers decode; SIGINT in the middle leaves a complete,
readable bag, the summary so far and exit status 130; a node killed in the middle is named, with
the bag finalised and exit status 1; a hostile /clock (far future, negative) during a session is
refused and reported, the load controller lives on, the bag's timeline stays whole; a session
without real time loses no pulse, and its bag (read with the mcap library) holds every message
the nodes published, every stamp on the simulated time, the monitor's statuses to the clock's end.

No test here waits for a duration and then expects the session to have got somewhere: each
waits for the line that says the session got there (a segment's start, its hold phase), and the
programs hold that segment for far longer than the test needs to act, so the signal lands where
the assertion expects it on any machine, however loaded.
"""

from __future__ import annotations

import os
import json
import re
import signal
import subprocess
import time
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("rclpy")

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.highlevel import AnyReader

from bearing_rig_sim.bags import open_bag, rig_typestore
from conftest import start_run, summary_rows, the_bag, time_left
from bearing_rig_sim.config import config_path

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SHORT_PROGRAM = """
name: short_validation
description: two speeds of the validation program, short holds
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 100, dwell_s: 0.3}
  - {name: n0900, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 100, until_stable: true, timeout_s: 8.0}
  - {name: n1500, speed_rpm: 1500, ramp_s: 1.0, axial_load_n: 100, until_stable: true, timeout_s: 8.0}
"""

LONG_HOLD_PROGRAM = """
name: long_hold
description: load up, then 900 rpm held for ten minutes of sim time (a session to stop midway)
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 100, dwell_s: 0.3}
  - {name: n0900, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 100, dwell_s: 600.0}
  - {name: n1500, speed_rpm: 1500, ramp_s: 1.0, axial_load_n: 100, dwell_s: 1.0}
"""

SENSOR_TOPICS = ("/rig/speeds", "/rig/spindle/pulses", "/rig/cage/pulses", "/rig/slip_status")

VERDICT, CONDITIONS = 8, 10
"""Columns of a summary row split on whitespace: # segment speed meas load F_bearing slip slip
verdict t_stable conditions."""


def start_session(ros_graph: Any, tmp_path: Path, *extra: str, program_text: str = SHORT_PROGRAM) -> subprocess.Popen[str]:
    program = tmp_path / "program.yaml"
    program.write_text(program_text, encoding="utf-8")
    return start_run(ros_graph, program, tmp_path, *extra)


def check_bag_decodes(bag: Path) -> dict[str, int]:
    """Every message decodes with rosbags' AnyReader and with mcap + mcap_ros2; counts per topic."""
    counts: dict[str, int] = {}
    with AnyReader([bag], default_typestore=rig_typestore()) as reader:
        for connection, _time, raw in reader.messages():
            reader.deserialize(raw, connection.msgtype)
            counts[connection.topic] = counts.get(connection.topic, 0) + 1
    decoded = 0
    for path in sorted(bag.glob("*.mcap")):
        with open(path, "rb") as stream:
            for _schema, _channel, _message, _ros in make_reader(stream, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
                decoded += 1
    assert decoded == sum(counts.values())
    return counts


WARM_START_K = 13.0
"""The bearing's start above ambient (22 degC) for sessions whose segments must settle: the
bench's Table 3 slips are warm, steady values (docs/paper.md section 9), and from a cold start the
slip falls for minutes as the grease warms (docs/model.md, "Thermal coupling in the session"),
faster than the monitor's critical slope. 35 degC is the calibration's reference temperature."""


def warm_start(tmp_path: Path) -> tuple[str, str]:
    """``--params-file`` arguments starting the simulator's thermal network warm."""
    params = tmp_path / "warm.yaml"
    params.write_text(f"simulator:\n  ros__parameters:\n    initial_temperature_rise_k: {WARM_START_K}\n", encoding="utf-8")
    return "--params-file", str(params)


def test_short_validation_runs_to_a_stable_verdict_and_records_a_readable_bag(ros_graph: Any, tmp_path: Path) -> None:
    session = start_session(ros_graph, tmp_path, *warm_start(tmp_path))
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    rows = summary_rows(out)
    assert [row[1] for row in rows] == ["load_up", "n0900", "n1500"]
    assert rows[-1][VERDICT] == "stable", out[-3000:]
    assert [row[CONDITIONS] for row in rows] == ["ok", "ok", "ok"], out[-3000:]
    assert "segment 2/3 n0900" in out and "segment 3/3 n1500" in out  # event lines
    # progress lines (at least one a wall second; without real time a segment may take less)
    assert re.search(r"^\[\d/3 ", out, re.MULTILINE), out[-3000:]
    bag = the_bag(tmp_path)
    counts = check_bag_decodes(bag)
    for topic in (*SENSOR_TOPICS, "/clock", "/rig/axial_load/state", "/rig/bearing/axial_force", "/rig/truth", "/diagnostics"):
        assert counts.get(topic, 0) > 0, f"no {topic} in {counts}"
    # one stamped load set-point per segment, with its command; the manual axial input unused
    assert counts["/rig/spindle/command"] == 3 and counts["/rig/load/setpoint"] == 3
    assert counts.get("/rig/axial_load/setpoint", 0) == 0
    # an axially loaded program's set-points carry no radial load: the force on the bearing stays axial
    with open_bag(bag) as reader:
        forces = [m.message.wrench for m in reader.messages(["/rig/bearing/axial_force"])]  # type: ignore[attr-defined]
        commands = [m.message.header.stamp for m in reader.messages(["/rig/spindle/command"])]  # type: ignore[attr-defined]
        setpoints = [m.message for m in reader.messages(["/rig/load/setpoint"])]  # type: ignore[attr-defined]
    # each segment's set-point stamped with its start, as its command, but the first: sent before
    # the program's clock starts, which starts once the load controller shows it in force;
    # 100 N axial, nothing radial
    stamp = [s.header.stamp.sec + 1e-9 * s.header.stamp.nanosec for s in setpoints]
    start = [c.sec + 1e-9 * c.nanosec for c in commands]
    assert stamp[0] <= start[0] and stamp[1:] == start[1:], (stamp, start)
    assert all((s.wrench.force.z, s.wrench.force.x, s.wrench.force.y) == (100.0, 0.0, 0.0) for s in setpoints)
    assert forces and all((w.force.x, w.force.y, w.torque.x, w.torque.y) == (0.0, 0.0, 0.0, 0.0) for w in forces)
    with open_bag(bag) as reader:
        context = reader.run_metadata
        assert "n1500" in context["program"] and "loading_chain:" in context["rig"]
        assert context["ros_domain_id"] == str(ros_graph.domain_id) and context["realtime"] == "false"
    assert (bag / "logs" / "simulator.log").is_file()

    # the session managed the nodes' lifecycles: configure in order, activate in reverse order (the clock
    # starts last), deactivate in order (the clock stops first), clean up in reverse order
    nodes = ("simulator", "load_controller", "monitor")
    expected = [f"lifecycle: {n} configure: unconfigured -> inactive" for n in nodes]
    expected += [f"lifecycle: {n} activate: inactive -> active" for n in reversed(nodes)]
    expected += [f"lifecycle: {n} deactivate: active -> inactive" for n in nodes]
    expected += [f"lifecycle: {n} cleanup: inactive -> unconfigured" for n in reversed(nodes)]
    assert [line for line in out.splitlines() if line.startswith("lifecycle: ")] == expected
    logged = (bag / "logs" / "session.log").read_text(encoding="utf-8")
    assert [line.split(" ", 1)[1] for line in logged.splitlines() if " lifecycle: " in line] == expected
    # the log ends with how the session ended and the summary it printed
    assert re.search(r"^\S+ session ended, exit status 0$", logged, re.MULTILINE), logged[-3000:]
    assert summary_rows(logged) == rows, logged[-3000:]
    assert lifecycle_diagnostics(bag) == [(f"lifecycle_manager: {line.split()[1]}", line.split()[2].rstrip(":")) for line in expected]


def lifecycle_diagnostics(bag: Path) -> list[tuple[str, str]]:
    """(status name, transition) of the lifecycle statuses on /diagnostics in the bag, in order."""
    found = []
    with AnyReader([bag], default_typestore=rig_typestore()) as reader:
        connections = [c for c in reader.connections if c.topic == "/diagnostics"]
        for connection, _time, raw in reader.messages(connections=connections):
            for status in reader.deserialize(raw, connection.msgtype).status:
                if status.name.startswith("lifecycle_manager: "):
                    values = {kv.key: kv.value for kv in status.values}
                    found.append((status.name, values["transition"]))
    return found


def test_a_node_failing_to_configure_is_named_and_the_bag_finalised(ros_graph: Any, tmp_path: Path) -> None:
    # a file that exists (the settings check before start passes) but holds no bearing geometry,
    # which the monitor reads only in on_configure
    hollow = tmp_path / "hollow_bearing.yaml"
    hollow.write_text("geometry: {}\n", encoding="utf-8")
    params = tmp_path / "params.yaml"
    params.write_text(f"monitor:\n  ros__parameters:\n    bearing_file: {json.dumps(str(hollow))}\n", encoding="utf-8")
    session = start_session(ros_graph, tmp_path, "--params-file", str(params))
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 1, f"{out[-3000:]}\n{err[-3000:]}"
    assert "the monitor node failed to configure: " in err and "hollow_bearing.yaml" in err, err[-3000:]
    assert "summary (failed)" in out
    lines = [line for line in out.splitlines() if line.startswith("lifecycle: ")]
    assert lines[:2] == [
        "lifecycle: simulator configure: unconfigured -> inactive",
        "lifecycle: load_controller configure: unconfigured -> inactive",
    ]
    assert lines[2].startswith("lifecycle: monitor configure FAILED, stays unconfigured: ") and "hollow_bearing.yaml" in lines[2]
    assert lines[3:] == [
        "lifecycle: load_controller cleanup: inactive -> unconfigured",
        "lifecycle: simulator cleanup: inactive -> unconfigured",
    ]
    bag = the_bag(tmp_path)
    check_bag_decodes(bag)  # finalised: both readers read it whole
    assert ("lifecycle_manager: monitor", "configure") in lifecycle_diagnostics(bag)


def read_until(session: subprocess.Popen[str], prefix: str, seconds: float = 90.0) -> list[str]:
    """The session's output lines up to the first starting with ``prefix`` (progress prints at
    least a line a second, so the loop keeps coming back to the deadline)."""
    assert session.stdout is not None
    seen = []
    deadline = time.monotonic() + seconds
    for line in session.stdout:
        seen.append(line)
        if line.startswith(prefix) or time.monotonic() > deadline:
            break
    assert any(line.startswith(prefix) for line in seen), "".join(seen)[-3000:]
    return seen


def child_pid(parent: int, script: str) -> int:
    """The process id of ``parent``'s child running ``script``."""
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            cmdline = (stat.parent / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except (OSError, IndexError):
            continue
        if int(fields[1]) == parent and script in cmdline:
            return int(stat.parent.name)
    raise AssertionError(f"no child of {parent} runs {script}")


def test_a_program_naming_another_bearing_file_runs_on_it(ros_graph: Any, tmp_path: Path) -> None:
    """A program whose ``bearing`` is the user's own file (here a copy, in a folder whose name
    has ``: `` and ``#`` in it): the simulator simulates that file, uncalibrated, and the run
    ends normally. A bare ``-p calibration_file:=`` used to make rcl refuse the simulator's
    command line."""
    folder = tmp_path / "bearings: v2 #1"
    folder.mkdir()
    bearing = folder / "h7006c_variant.yaml"
    bearing.write_text(config_path("bearings", "h7006c.yaml").read_text(encoding="utf-8"), encoding="utf-8")
    text = SHORT_PROGRAM.replace("bearings/h7006c.yaml", json.dumps(str(bearing)))
    session = start_session(ros_graph, tmp_path, "--no-record", program_text=text)
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    assert [row[1] for row in summary_rows(out)] == ["load_up", "n0900", "n1500"]
    (run,) = [p for p in (tmp_path / "bags").iterdir() if p.is_dir()]
    log = (run / "logs" / "simulator.log").read_text(encoding="utf-8")
    assert "simulating h7006c_variant.yaml" in log, log[-2000:]


def test_sigint_mid_run_leaves_a_readable_bag_and_exit_130(ros_graph: Any, tmp_path: Path) -> None:
    """SIGINT once n0900 holds its speed (its progress line says "hold"): the ramp is over, so
    pulses were recorded; the segment holds for 600 s of sim time, so the signal lands in it."""
    session = start_session(ros_graph, tmp_path, program_text=LONG_HOLD_PROGRAM)
    seen = read_until(session, "[2/3 n0900 hold]")
    session.send_signal(signal.SIGINT)
    rest, err = session.communicate(timeout=time_left())
    out = "".join(seen) + rest
    assert session.returncode == 130, f"{out[-3000:]}\n{err[-3000:]}"
    assert "summary (interrupted)" in out and "stopped by SIGINT" in err
    rows = summary_rows(out)
    assert [row[1] for row in rows] == ["load_up", "n0900"]
    assert rows[-1][VERDICT] == "interrupted"
    counts = check_bag_decodes(the_bag(tmp_path))
    for topic in SENSOR_TOPICS[:3]:
        assert counts.get(topic, 0) > 0, f"no {topic} in {counts}"


def test_a_node_that_dies_is_named_and_the_bag_finalised(ros_graph: Any, tmp_path: Path) -> None:
    session = start_session(ros_graph, tmp_path, program_text=LONG_HOLD_PROGRAM)
    seen = read_until(session, "segment 2/3 n0900:")
    os.kill(child_pid(session.pid, "bearing-rig-monitor"), signal.SIGKILL)
    rest, err = session.communicate(timeout=time_left())
    out = "".join(seen) + rest
    assert session.returncode == 1, f"{out[-3000:]}\n{err[-3000:]}"
    assert "the monitor node stopped during the run: monitor was killed by signal SIGKILL" in err
    assert "monitor.log" in err and "summary (failed)" in out
    counts = check_bag_decodes(the_bag(tmp_path))
    assert counts.get("/rig/speeds", 0) > 0


HOSTILE_CLOCK_PROGRAM = """
name: hostile_clock
description: load up, then 900 rpm held long enough for an attack on /clock to land mid-run
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 100, dwell_s: 0.3}
  - {name: n0900, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 100, dwell_s: 20.0}
"""


def test_hostile_clock_stamps_during_a_session_are_refused_and_reported(ros_graph: Any, tmp_path: Path) -> None:
    """The audit's attacks: one /clock at 2^31 - 1 s hung a session and moved 98 % of its bag to
    2038; one before 1970 killed the load controller. Now the session ends normally (the load
    controller would be named if it died), the refusals are counted under the summary, and the
    bag's timeline holds no outlier."""
    from builtin_interfaces.msg import Time
    from rosgraph_msgs.msg import Clock

    from bearing_rig_sim.nodes.common import RELIABLE_QOS

    # The attacker exists before the session, so discovery runs during the nodes' bring-up, and
    # the program holds 900 rpm for 20 s of sim time: the session cannot end before the attack
    # has matched (made after the session, on a loaded host the match came too late: the program
    # had ended and its subscribers were gone).
    node = ros_graph.node("clock_attacker")
    clock = node.create_publisher(Clock, "/clock", RELIABLE_QOS)
    session = start_session(ros_graph, tmp_path, program_text=HOSTILE_CLOCK_PROGRAM)
    # the recorder and the load controller (at least) subscribe /clock; the recorder (reliable) matched
    assert ros_graph.spin_until(lambda: node.count_subscribers("/clock") >= 2 and clock.get_subscription_count() >= 2, timeout=time_left(), nodes=[node])
    seen = read_until(session, "segment 2/2 n0900:")
    for _ in range(3):
        clock.publish(Clock(clock=Time(sec=2**31 - 1, nanosec=0)))
        clock.publish(Clock(clock=Time(sec=-5, nanosec=0)))
    rest, err = session.communicate(timeout=time_left())
    out = "".join(seen) + rest
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    found = re.search(r"^clock: (\d+) /clock stamp\(s\) refused \(kept off the bag's timeline\)", out, re.MULTILINE)
    assert found is not None, out[-3000:]
    assert int(found.group(1)) >= 2  # at least one of each reached the recorder (reliable)
    assert "refused a negative stamp" in out and "ahead of the last accepted" in out  # event lines
    with open_bag(the_bag(tmp_path)) as bag:
        assert bag.end_ns < 100 * 1_000_000_000  # sim time of a short program, not 2038
        findings = bag.verify()  # a line per outlier stretch, unreadable message or bad chunk
        assert findings == [], findings


NO_GAP_PROGRAM = """
name: no_gap
description: 5000 rpm for some 20 s of sim time without real time
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: load_up, speed_rpm: 0, axial_load_n: 100, dwell_s: 0.3}
  - {name: n5000, speed_rpm: 5000, ramp_s: 2.0, axial_load_n: 100, dwell_s: 18.0}
"""


def test_no_pulse_is_lost_without_real_time(ros_graph: Any, tmp_path: Path) -> None:
    """Every pulse the simulator emitted is in the bag: its own pulse_index counts every pulse
    since it started (pulse_drop_probability is 0 in config/rig.yaml), so the bag's indices must
    start at 0 (the spindle is at rest until the program starts) and run without a gap to the
    last; and /clock has every 1 ms chunk from the first (the session activates the nodes once
    its recorder has matched their streams: before, the first 2-3 s of /clock were missing)."""
    from bearing_rig_sim.bags import open_bag as open_rig_bag

    session = start_session(ros_graph, tmp_path, program_text=NO_GAP_PROGRAM)
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    indices: dict[str, list[int]] = {"/rig/spindle/pulses": [], "/rig/cage/pulses": []}
    clock_ns: list[int] = []
    with open_rig_bag(the_bag(tmp_path)) as bag:
        for message in bag.messages(topics=[*indices, "/clock"]):
            if message.topic == "/clock":
                stamp = message.message.clock  # type: ignore[attr-defined]
                clock_ns.append(stamp.sec * 1_000_000_000 + stamp.nanosec)
            else:
                indices[message.topic].append(int(message.message.pulse_index))  # type: ignore[attr-defined]
    for topic, seen in indices.items():
        assert len(seen) > 500, f"{topic}: only {len(seen)} pulses"
        ordered = sorted(seen)
        assert ordered[0] == 0, f"{topic}: the first pulse in the bag is number {ordered[0]}"
        gaps = [(a, b) for a, b in zip(ordered, ordered[1:]) if b != a + 1]
        assert not gaps, f"{topic}: {len(gaps)} gaps in pulse_index, first {gaps[:5]}"
    # stamps are whole microseconds of a float clock: a step may read 0.999999 ms
    gaps = [(a, b) for a, b in zip(clock_ns, clock_ns[1:]) if round((b - a) / 1_000_000) != 1]
    assert not gaps, f"/clock: {len(gaps)} gaps, first {gaps[:5]}"
    assert clock_ns[-1] - clock_ns[0] >= 20 * 1_000_000_000
    assert clock_ns[0] == 0, f"/clock in the bag starts at {clock_ns[0] * 1e-9:.3f} s, not at the clock's origin"
    check_delivery(the_bag(tmp_path), out)


def header_stamps(bag: Path) -> dict[str, list[int]]:
    """Every stamp in the bag by topic, ns: ``clock`` of /clock, ``header.stamp`` of every other
    message that has one, decoded by the mcap library (mcap_ros2), not by this project's reader."""
    stamps: dict[str, list[int]] = {}
    for path in sorted(bag.glob("*.mcap")):
        with open(path, "rb") as stream:
            for _schema, channel, _message, ros in make_reader(stream, decoder_factories=[DecoderFactory()]).iter_decoded_messages():
                stamp = ros.clock if channel.topic == "/clock" else getattr(getattr(ros, "header", None), "stamp", None)
                if stamp is not None:
                    stamps.setdefault(channel.topic, []).append(stamp.sec * 1_000_000_000 + stamp.nanosec)
    return stamps


def check_delivery(bag: Path, out: str) -> None:
    """What issue 36 asks of a session without real time (the bag read with the mcap library):
    every stamp of every topic on the session's simulated time (between the clock's first and
    last stamps: no wall-clock stamp, 1.8e9 s, anywhere); the force, truth and speed streams
    without a gap over 0.5 s of sim time; the monitor's statuses up to within 1 s of the clock's
    end (the simulator keeps within 0.5 s of the monitor, and the session waits for its last
    status); and the summary's delivery table with every published message recorded."""
    stamps = header_stamps(bag)
    first, last = min(stamps["/clock"]), max(stamps["/clock"])
    for topic, seen in stamps.items():
        outside = [t for t in seen if not first <= t <= last]
        assert not outside, f"{topic}: {len(outside)} stamps outside the clock's {first * 1e-9:.3f}-{last * 1e-9:.3f} s, first {outside[:3]}"
    for topic in ("/rig/axial_load/force", "/rig/bearing/axial_force", "/rig/truth", "/rig/speeds"):
        ordered = sorted(stamps[topic])
        widest = max(b - a for a, b in zip(ordered, ordered[1:]))
        assert widest <= 500_000_000, f"{topic}: a gap of {widest * 1e-9:.3f} s of sim time"
    assert last - max(stamps["/rig/slip_status"]) <= 1_000_000_000, (
        f"the last status at {max(stamps['/rig/slip_status']) * 1e-9:.3f} s, the clock ends at {last * 1e-9:.3f} s"
    )
    assert "every published message recorded" in out, out[-3000:]
    table = out[out.index("delivery (messages per topic):") :]
    for topic in ("/clock", "/rig/axial_load/force", "/rig/truth", "/rig/spindle/pulses", "/rig/cage/pulses", "/rig/slip_status"):
        (row,) = [line.split() for line in table.splitlines() if line.startswith(topic + " ")]
        published, recorded = int(row[1]), int(row[2])
        assert published == recorded == len(stamps[topic]) > 0, f"{topic}: {published} published, {recorded} recorded, {len(stamps[topic])} in the bag"


SIMULATOR_NODE = ("-m", "bearing_rig_sim.nodes.simulator", "--autostart", "--no-realtime")


LOAD_CONTROLLER_NODE = ("-m", "bearing_rig_sim.nodes.load_controller", "--autostart")


def start_rig_nodes(ros_graph: Any, *simulators: tuple[str, ...], load_controller: tuple[str, ...] = LOAD_CONTROLLER_NODE) -> None:
    """Start the rig's nodes on the test's graph as a launch file would, for ``run --attach``:
    each simulator given (``python`` arguments; default: one shipped simulator without real
    time), the load controller (likewise) and the monitor. Returns once the graph has each node's
    output (a publisher of ``/rig/truth`` per simulator, of ``/rig/axial_load/state``, of
    ``/rig/slip_status``), so that a session started then finds every node running, however
    long their start took on a loaded host (the session's start-up bound is not the test's)."""
    simulators = simulators or (SIMULATOR_NODE,)
    for simulator in simulators:
        ros_graph.spawn_python(*simulator)
    ros_graph.spawn_python(*load_controller)
    ros_graph.spawn_python("-m", "bearing_rig_sim.nodes.monitor", "--autostart")
    observer = ros_graph.node("observer")
    outputs = {"/rig/truth": len(simulators), "/rig/axial_load/state": 1, "/rig/slip_status": 1}
    up = ros_graph.spin_until(lambda: all(observer.count_publishers(t) == n for t, n in outputs.items()), timeout=time_left(), nodes=[observer])
    assert up, {t: observer.count_publishers(t) for t in outputs}


def test_attached_session_runs_the_program_on_running_nodes(ros_graph: Any, tmp_path: Path) -> None:
    """What launch/rig.launch.py does: nodes brought up elsewhere, the program run by
    ``bearing-rig run --attach --no-record`` on the environment's domain."""
    start_rig_nodes(ros_graph)
    session = start_session(ros_graph, tmp_path, "--attach", "--no-record")
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    rows = summary_rows(out)
    assert [row[1] for row in rows] == ["load_up", "n0900", "n1500"]
    assert "not recorded (--no-record)" in out
    assert not any(line.startswith("lifecycle: ") for line in out.splitlines())
    (run,) = [p for p in (tmp_path / "bags").iterdir() if p.is_dir()]
    assert not list(run.glob("*.mcap")) and (run / "logs" / "session.log").is_file()
    # unrecorded, the log is the session's only record: it ends with how it ended and its summary
    logged = (run / "logs" / "session.log").read_text(encoding="utf-8")
    assert "session ended, exit status 0\n" in logged and summary_rows(logged) == rows, logged[-3000:]


SLOW_LOAD_CONTROLLER = """
import sys, time
from bearing_rig_sim.nodes import load_controller as node
HOLD_S = 2.0  # wall s: a slow bench controller, or a loaded host; some 10 s of a free-running simulator
apply, step, held = node.LoadControllerNode._on_load_setpoint, node.LoadControllerNode._on_step, []
def hold(self, msg):
    held.append((time.monotonic(), msg))
def stepping(self):
    while held and time.monotonic() - held[0][0] >= HOLD_S:
        apply(self, held.pop(0)[1])
    step(self)
node.LoadControllerNode._on_load_setpoint, node.LoadControllerNode._on_step = hold, stepping
sys.exit(node.main(["load_controller", "--autostart"]))
"""


def test_an_attached_session_starts_its_program_once_the_first_load_is_in_force(ros_graph: Any, tmp_path: Path) -> None:
    """Attached to nodes running without real time, the simulator runs ahead of the session (6
    times the wall clock with no recorder to pace it), so the first set-point reaches the load
    controller seconds of sim time after the session sent it; here the load controller holds
    each set-point 2 s of wall time besides. The program starts once the load controller shows
    the first segment's set-point in force: the 0.3 s load-up, then the 900 rpm segment, run
    loaded, every segment's conditions ok. Started at once instead, the load-up ended and the
    900 rpm segment began on an unloaded bearing (exit 3, "load off", as CI once saw without the
    hold)."""
    start_rig_nodes(ros_graph, load_controller=("-c", SLOW_LOAD_CONTROLLER))
    session = start_session(ros_graph, tmp_path, "--attach", "--no-record")
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    rows = summary_rows(out)
    assert [row[1] for row in rows] == ["load_up", "n0900", "n1500"]
    assert [row[CONDITIONS] for row in rows] == ["ok"] * 3, out[-3000:]


BEST_EFFORT_PULSE_SIMULATOR = """
import sys
import bearing_rig_sim.nodes.common as common
from bearing_rig_sim.interfaces import CAGE_PULSES, SPINDLE_PULSES
contract = common.qos_profile
def bench_like(topic):  # a bench's counter driver: pulses as plain sensor data
    return common.SENSOR_QOS if topic in (SPINDLE_PULSES, CAGE_PULSES) else contract(topic)
common.qos_profile = bench_like
from bearing_rig_sim.nodes.simulator import main
sys.exit(main(["simulator", "--autostart", "--no-realtime"]))
"""


def test_an_attached_session_records_pulses_a_bench_publishes_best_effort(ros_graph: Any, tmp_path: Path) -> None:
    """Attached to nodes whose pulse writers offer only best effort (as a bench's counter
    driver may), the recorder reads those topics best effort and records them; a reliable
    reader is incompatible with such a writer and recorded nothing.

    The recorder adapts at the first look at the graph that shows such a writer, and the
    program starts once the adapted reader has matched it. The graph names the writer's node
    when that node's participant data has come, which can be later than the writer itself (a
    loaded host, a lost discovery sample repaired at the next heartbeat) or, for a plain DDS
    writer, never: so the adaptation's line names the simulator, or says its node is not named
    yet and, if the name comes during the session, a second line names it."""
    from bearing_rig_sim.session.node import UNNAMED_PUBLISHER

    start_rig_nodes(ros_graph, ("-c", BEST_EFFORT_PULSE_SIMULATOR))
    session = start_session(ros_graph, tmp_path, "--attach")
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 0, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    for topic in ("/rig/spindle/pulses", "/rig/cage/pulses"):
        adapted = f"recording {topic} best effort: {{}} publishes it best effort (a reliable reader receives nothing from such a writer)"
        named_later = f"recording {topic} best effort: /simulator publishes it best effort"
        lines = [line for line in out.splitlines() if line.startswith(f"recording {topic} ")]
        assert lines in ([adapted.format("/simulator")], [adapted.format(UNNAMED_PUBLISHER)], [adapted.format(UNNAMED_PUBLISHER), named_later]), out[-3000:]
    counts = check_bag_decodes(the_bag(tmp_path))
    assert counts.get("/rig/spindle/pulses", 0) > 0 and counts.get("/rig/cage/pulses", 0) > 0, counts
    assert "recording /rig/speeds best effort" not in out  # the contract's reliable streams stay reliable


def test_a_best_effort_writer_the_graph_has_not_named_yet_is_read_at_once_and_named_later(
    ros_graph: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The graph can list a writer before it names the writer's node (its participant data not
    come yet; meanwhile the rmw's placeholder, UNKNOWN_NODE_NAME), for as long as discovery
    takes. The recorder reads the topic best effort at the first look all the same (a reader
    left reliable would record nothing meanwhile), saying the node is not named yet, matches
    the writer and records its samples; once the graph names the node, a line names it, once.
    The graph's naming is held back here by a stand-in for the session's graph lookup."""
    from bearing_rig_msgs.msg import FibreOpticPulse
    from rclpy.qos import ReliabilityPolicy

    from bearing_rig_sim.bags import BagWriter
    from bearing_rig_sim.interfaces import CAGE_PULSES
    from bearing_rig_sim.nodes.common import SENSOR_QOS, UNKNOWN_NODE_NAME
    from bearing_rig_sim.rig.program import load_program
    from bearing_rig_sim.session.node import UNNAMED_PUBLISHER, SessionNode
    from bearing_rig_sim.session.recorder import SessionRecorder
    from bearing_rig_sim.session.runner import ProgramRunner

    program = tmp_path / "program.yaml"
    program.write_text(SHORT_PROGRAM, encoding="utf-8")
    context = ros_graph.context()
    counter = ros_graph.node("counter", context=context)
    pulses = counter.create_publisher(FibreOpticPulse, CAGE_PULSES.name, SENSOR_QOS)
    with BagWriter(tmp_path / "bag") as bag:
        recorder = SessionRecorder(bag)
        session = SessionNode(recorder, ProgramRunner(load_program(program)), context=context, name="naming_session")
        executor = ros_graph.executor([session, counter])
        graph_lookup = session.publisher_names
        named = False

        def held_back(topic: str, reliability: ReliabilityPolicy | None = None) -> list[str]:
            found = graph_lookup(topic, reliability)
            return found if named else [f"_NODE_NAMESPACE_UNKNOWN_/{UNKNOWN_NODE_NAME}" if name == "/counter" else name for name in found]

        monkeypatch.setattr(session, "publisher_names", held_back)
        try:
            assert ros_graph.spin_until(lambda: session.count_publishers(CAGE_PULSES.name) == 1, 60.0, executor=executor)
            adapted = f"recording {CAGE_PULSES.name} best effort: {UNNAMED_PUBLISHER} publishes it best effort (a reliable reader receives nothing from such a writer)"
            assert session.adapt_to_publishers() == [adapted]
            assert ros_graph.spin_until(lambda: not session.unmatched_streams(published_only=True), 60.0, executor=executor)

            def recorded() -> bool:
                pulses.publish(FibreOpticPulse(sensor_id="cage"))
                session.drain()
                return recorder.counts.get(CAGE_PULSES.name, 0) > 0

            assert ros_graph.spin_until(recorded, 60.0, executor=executor), "nothing recorded from the unnamed writer"
            assert session.adapt_to_publishers() == []  # still unnamed: nothing new to say
            assert ros_graph.spin_until(lambda: graph_lookup(CAGE_PULSES.name) == ["/counter"], 60.0, executor=executor)
            named = True
            assert session.adapt_to_publishers() == [f"recording {CAGE_PULSES.name} best effort: /counter publishes it best effort"]
            assert session.adapt_to_publishers() == []
        finally:
            session.close()
            session.destroy_node()


def test_an_attached_session_refuses_a_graph_with_two_simulators(ros_graph: Any, tmp_path: Path) -> None:
    """Two simulators on one domain (a stray twin beside the one meant, or a twin beside the
    bench) would interleave two sim times and two bearings in one summary: the session ends,
    exit 1, naming the topic and the two publishers (each by its name, or as not named yet when
    the session saw its writer before the graph had its node's name). The program holds 900 rpm
    for ten minutes of sim time: only the second simulator, not the program's end, can end this
    session within the test's guard."""
    from bearing_rig_sim.session.node import UNNAMED_PUBLISHER

    start_rig_nodes(ros_graph, SIMULATOR_NODE, SIMULATOR_NODE)
    session = start_session(ros_graph, tmp_path, "--attach", "--no-record", program_text=LONG_HOLD_PROGRAM)
    out, err = session.communicate(timeout=time_left())
    assert session.returncode == 1, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    found = re.search(rf"more than one rig on ROS domain {ros_graph.domain_id}: 2 nodes publish /rig/truth \(([^)]*)\);", out + err)
    assert found is not None, f"{out[-3000:]}\n{err[-3000:]}"
    assert set(found.group(1).split(", ")) <= {"/simulator", UNNAMED_PUBLISHER}, found.group(0)


def test_a_set_point_from_outside_marks_the_segment_and_the_exit_status(ros_graph: Any, tmp_path: Path) -> None:
    """The audit's case: a set-point from another node during a segment (30 N against the
    program's 100 N) gave "stable" and exit 0. Now the segment is marked and the run exits 3."""
    from std_msgs.msg import Float64

    from bearing_rig_sim.nodes.common import RELIABLE_QOS

    # n0900 held for 20 s of sim time rather than until stable: the set-point lands inside it
    # however fast the run goes, even with the test process held up for seconds on a loaded host.
    program = SHORT_PROGRAM.replace("until_stable: true, timeout_s: 8.0}", "dwell_s: 20.0}", 1)
    session = start_session(ros_graph, tmp_path, program_text=program)
    node = ros_graph.node("meddler")
    setpoint = node.create_publisher(Float64, "/rig/axial_load/setpoint", RELIABLE_QOS)
    # Matched with the load controller and the session's recorder before the segment starts, so
    # that the set-point goes out the moment it does.
    assert ros_graph.spin_until(lambda: setpoint.get_subscription_count() >= 2, timeout=time_left(), nodes=[node])
    seen = read_until(session, "segment 2/3 n0900:")
    setpoint.publish(Float64(data=30.0))
    rest, err = session.communicate(timeout=time_left())
    out = "".join(seen) + rest
    assert session.returncode == 3, f"exit {session.returncode}\n{out[-3000:]}\n{err[-3000:]}"
    assert "summary (conditions not met)" in out and "conditions not met in" in err
    rows = {row[1]: row for row in summary_rows(out)}
    assert "disturbed" in rows["n0900"][CONDITIONS], out[-3000:]
    assert "conditions not met in segment 2 n0900:" in out


def test_the_sessions_progress_is_each_new_clock_it_took(ros_graph: Any, tmp_path: Path) -> None:
    """``/rig/session/progress`` carries the latest ``/clock`` the session has taken, once per
    new value: nothing before the first clock, nothing again while it stands, and a clock that
    went back (one the clock guard accepted as restarted) as it is, so that the simulator's
    pacing follows the restarted clock instead of waiting for the old one's time to come back.
    The session's clock is set by hand here (the recorder's take sets it in a session)."""
    from std_msgs.msg import Header

    from bearing_rig_sim.bags import BagWriter
    from bearing_rig_sim.interfaces import SESSION_PROGRESS
    from bearing_rig_sim.nodes.common import from_stamp, qos_profile
    from bearing_rig_sim.rig.program import load_program
    from bearing_rig_sim.session.node import SessionNode
    from bearing_rig_sim.session.recorder import SessionRecorder
    from bearing_rig_sim.session.runner import ProgramRunner

    program = tmp_path / "program.yaml"
    program.write_text(SHORT_PROGRAM, encoding="utf-8")
    context = ros_graph.context()
    listener = ros_graph.node("progress_listener", context=context)
    got: list[tuple[float, str]] = []
    listener.create_subscription(Header, SESSION_PROGRESS.name, lambda msg: got.append((from_stamp(msg.stamp), msg.frame_id)), qos_profile(SESSION_PROGRESS))
    with BagWriter(tmp_path / "bag") as bag:
        session = SessionNode(SessionRecorder(bag), ProgramRunner(load_program(program)), context=context, name="progress_session")
        executor = ros_graph.executor([session, listener])
        try:
            assert ros_graph.spin_until(lambda: session.count_subscribers(SESSION_PROGRESS.name) >= 2, time_left(), executor=executor)
            assert ros_graph.spin_until(lambda: session._progress.get_subscription_count() >= 2, time_left(), executor=executor)
            session.send_progress()  # no clock taken yet: nothing
            for seconds in (5.0, 5.0, 6.5, 1.25, 1.25):
                session.clock_count += 1
                session.sim_time_ns = round(seconds * 1e9)
                session.send_progress()
            assert ros_graph.spin_until(lambda: len(got) >= 3, time_left(), executor=executor), got
            name = load_program(program).name
            assert got == [(5.0, name), (6.5, name), (1.25, name)]
            assert session.sent[SESSION_PROGRESS.name] == 3
        finally:
            session.close()
            session.destroy_node()
