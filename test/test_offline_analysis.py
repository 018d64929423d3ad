"""Offline analysis of bags: the monitor's verdicts without ROS, deterministic, on damaged and
independently written bags."""

from __future__ import annotations

import math
import os
import shutil
import struct
import warnings
from dataclasses import astuple
from types import SimpleNamespace
from pathlib import Path

import numpy as np
import pytest
import yaml
from mcap_ros2.writer import Writer as McapRos2Writer

from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.monitoring import MonitorSettings, MonitorState, SlipMonitor
from bearing_rig_sim.bags import BagError, BagWarning, BagWriter, open_bag, rig_typestore
from bearing_rig_sim.offline.analysis import analyse_bag, decode_pulse
from bearing_rig_sim.offline.report import _column
from bearing_rig_sim.offline.segments import PROFILE_CONSTANT_ACCELERATION, SEGMENTS_CSV, SegmentTracker
from bearing_rig_sim.offline.series import STATUS_CSV, WINDOWS_CSV, CsvWriter, RowDecimator, SlipWindowRow, StatusRow, csv_columns
from bearing_rig_sim.synthetic.traffic import NO_BALLS, RIG_TRAFFIC_TOPICS, rig_traffic, sample_message
from bearing_rig_sim.bags.typestore import msg_folder
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.simulation import RigTwin, SpindleCommand
from conftest import write_foreign_metadata

PULSE = "bearing_rig_msgs/msg/FibreOpticPulse"
HEADER_DEPENDENCIES = (
    "=" * 80
    + "\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
    + "=" * 80
    + "\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
)


def stamp_of(t: float) -> tuple[int, int]:
    sec = math.floor(t)
    nanosec = int(round((t - sec) * 1e9))
    return (sec + 1, nanosec - 10**9) if nanosec >= 10**9 else (sec, nanosec)


def wire_pulse(pulse: Pulse) -> Pulse:
    """The pulse as a subscriber sees it: its time through a ROS stamp."""
    sec, nanosec = stamp_of(pulse.time)
    return Pulse(sec + nanosec * 1e-9, pulse.strip_id, pulse.strip_count, pulse.revolution, pulse.pulse_index, pulse.sensor_id)


def write_twin_bag(
    path: Path,
    seconds: float,
    *,
    start_rpm: float = 1200.0,
    step_at: float | None = 1.5,
    step_rpm: float = 1800.0,
    record_status: bool = False,
    command_ahead_s: float = 0.0,
) -> list[tuple[str, Pulse]]:
    """A bag of the twin at 100 N: ``start_rpm``, then a 0.5 s STEP ramp to ``step_rpm`` at
    ``step_at`` (None: no step); pulses, speeds (1 kHz), truth (100 Hz), the spindle commands,
    and with ``record_status`` the slip status a monitor node would have published (a
    SlipMonitor fed live: on every change after a window, and every 0.1 s of rig time). With
    ``command_ahead_s`` the step's command is sent (and recorded) that long before its stamp, as
    the session sends a dwell segment's successor. Returns the pulses in bag order, as received
    (times through stamps)."""
    store = rig_typestore()
    types = store.types
    twin = RigTwin.from_files(initial_speed=rpm_to_rad_s(start_rpm), initial_axial_load=100.0)
    settings = MonitorSettings.from_yaml()
    live = SlipMonitor(settings.kinematics(), settings)
    last_state: list[object] = [None]

    def header(t: float) -> object:
        sec, nanosec = stamp_of(t)
        return types["std_msgs/msg/Header"](stamp=types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), frame_id="rig")

    def command(t: float, speed: float, ramp: float) -> object:
        return types["bearing_rig_msgs/msg/SpindleCommand"](header=header(t), target_speed=speed, profile=0, ramp_time=ramp, acceleration=0.0)

    def publish_status(bag: BagWriter, now: float) -> None:
        status = live.status()
        last_state[0] = status.state
        message = types["bearing_rig_msgs/msg/SlipStatus"](header=header(status.time if status.time is not None else now), **status.message_fields())
        bag.write_message("/rig/slip_status", int(round(now * 1e9)), message)

    sent: list[tuple[str, Pulse]] = []
    segments = [{"name": f"n{start_rpm:.0f}"}] + ([{"name": f"n{step_rpm:.0f}"}] if step_at is not None else [])
    program = yaml.safe_dump({"name": "twin test", "segments": segments})
    with BagWriter(path, chunk_size=64 * 1024, metadata={"program": program}) as bag:
        for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
            bag.add_topic(topic, msgtype, qos)
        bag.add_topic("/rig/spindle/command", "bearing_rig_msgs/msg/SpindleCommand", "transient_local")
        if record_status:
            bag.add_topic("/rig/slip_status", "bearing_rig_msgs/msg/SlipStatus", "transient_local")
        bag.write_message("/rig/spindle/command", 0, command(0.0, rpm_to_rad_s(start_rpm), 0.0))
        stepped = step_at is None
        while twin.time < seconds:
            if not stepped and twin.time >= step_at - command_ahead_s:
                at = twin.time + command_ahead_s
                twin.command_spindle(SpindleCommand(rpm_to_rad_s(step_rpm), ramp_time=0.5, time=at if command_ahead_s else None))
                bag.write_message("/rig/spindle/command", int(round(twin.time * 1e9)), command(at, rpm_to_rad_s(step_rpm), 0.5))
                stepped = True
            out = twin.tick()
            pulses = sorted([("spindle", p) for p in out.spindle_pulses] + [("cage", p) for p in out.cage_pulses], key=lambda sp: sp[1].time)
            for shaft, pulse in pulses:
                received = wire_pulse(pulse)
                message = types[PULSE](
                    header=header(pulse.time),
                    sensor_id=shaft,
                    strip_id=pulse.strip_id,
                    strip_count=pulse.strip_count,
                    revolution=pulse.revolution,
                    pulse_index=pulse.pulse_index,
                )
                bag.write_message(f"/rig/{shaft}/pulses", int(round(received.time * 1e9)), message)
                sent.append((shaft, received))
                if record_status and live.add_pulse(shaft, received) and live.status().state != last_state[0]:
                    publish_status(bag, received.time)
            now = int(round(out.time * 1e9))
            measured = out.measured
            speeds = types["sensor_msgs/msg/JointState"](
                header=header(out.time),
                name=["inner_ring", "cage"],
                position=np.array([measured.inner_ring_angle, measured.cage_angle]),
                velocity=np.array([measured.inner_ring_speed, measured.cage_speed]),
                effort=np.array([], dtype=float),
            )
            bag.write_message("/rig/speeds", now, speeds)
            if round(out.time * 1000) % 10 == 0:
                truth = out.truth
                values = {
                    f: getattr(truth, f)
                    for f in (
                        "inner_ring_speed",
                        "inner_ring_acceleration",
                        "cage_speed",
                        "theoretical_cage_speed",
                        "slip_rate",
                        "axial_load",
                        "inner_contact_load_mean",
                        "inner_contact_load_max",
                        "outer_contact_load_mean",
                        "outer_contact_load_max",
                        "pocket_load_max",
                        "inner_contact_angle",
                        "outer_contact_angle",
                        "inner_ring_axial_displacement",
                        "friction_torque",
                        "power_loss",
                    )
                }
                message = types["bearing_rig_msgs/msg/SimulatorTruth"](
                    header=header(out.time),
                    **values,
                    real_time_factor=1.0,
                    step_count=truth.step_count,
                    overruns=0,
                    cage_whirl_radius_um=truth.cage_whirl_radius * 1e6,
                    **NO_BALLS,
                )
                bag.write_message("/rig/truth", now, message)
            if record_status and round(out.time * 1000) % 100 == 0:
                live.check(out.time)
                publish_status(bag, out.time)
    return sent


@pytest.fixture(scope="module")
def twin_bag(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[tuple[str, Pulse]]]:
    path = tmp_path_factory.mktemp("twin") / "twin"
    return path, write_twin_bag(path, 5.0)


def direct_monitor(pulses: list[tuple[str, Pulse]]) -> tuple[list[SlipWindowRow], list[tuple[float, int, str]], SlipMonitor]:
    """SlipMonitor fed the pulses directly, no bag: its windows and its state changes (time,
    state, and "tick" or "window" for a check or a closed window), with checks every status
    period on the pulse clock from the first pulse, as the node's timer runs them."""
    settings = MonitorSettings.from_yaml()
    monitor = SlipMonitor(settings.kinematics(), settings)
    period = 1.0 / settings.status_rate_hz
    windows, changes = [], []
    state = None
    origin, tick = pulses[0][1].time, 0

    def note(t: float, kind: str) -> None:
        nonlocal state
        new = monitor.status().state
        if state is not None and new != state:
            changes.append((t, int(new), kind))
        state = new

    for shaft, pulse in pulses:
        while (t := origin + tick * period) <= pulse.time:
            monitor.check(t)
            note(t, "tick")
            tick += 1
        if monitor.add_pulse(shaft, pulse):
            w = monitor.latest_window
            windows.append(SlipWindowRow(w.start_time, w.end_time, w.inner_ring_speed, w.cage_speed, w.slip_rate))
            note(pulse.time, "window")
    monitor.check(pulses[-1][1].time)
    return windows, changes, monitor


def exact(values: object) -> bytes:
    """Bit pattern of a row: NaN-safe equality of floats."""
    return repr([struct.pack("<d", v) if isinstance(v, float) else v for v in values]).encode()


def test_pulse_decoder_agrees_with_the_general_decoder() -> None:
    store = rig_typestore()
    for seed in range(40):
        message = sample_message(PULSE, seed, store)
        data = bytes(store.serialize_cdr(message, PULSE))
        pulse = decode_pulse(data)
        stamp = message.header.stamp
        assert pulse == Pulse(
            stamp.sec + stamp.nanosec * 1e-9, message.strip_id, message.strip_count, message.revolution, message.pulse_index, message.sensor_id
        )
        with pytest.raises(BagError, match="malformed"):
            decode_pulse(data[: len(data) - 3])
    big_endian = bytes(store.serialize_cdr(sample_message(PULSE, 1, store), PULSE, little_endian=False))
    with pytest.raises(BagError, match="not little-endian"):
        decode_pulse(big_endian)


def test_offline_verdicts_are_the_monitors(twin_bag: tuple[Path, list[tuple[str, Pulse]]], tmp_path: Path) -> None:
    path, pulses = twin_bag
    windows, changes, monitor = direct_monitor(pulses)
    rows: list[StatusRow] = []
    got_windows: list[SlipWindowRow] = []
    with warnings.catch_warnings():
        warnings.simplefilter("error", BagWarning)
        result = analyse_bag(path, csv_dir=tmp_path, on_row=rows.append, on_window=got_windows.append)
    assert result.complete and not result.problems
    assert result.pulses == {"spindle": sum(s == "spindle" for s, _p in pulses), "cage": sum(s == "cage" for s, _p in pulses)}
    assert [exact(astuple(w)) for w in got_windows] == [exact(astuple(w)) for w in windows]
    assert len(windows) > 30  # two-revolution windows at 1800 rpm (min_window_s 0.1 s)
    # the same state changes at the same instants, from the same kind of event (a check on the
    # status-rate ticks, where refits run, or a closed window); the clean run has no fault
    offline_changes = [(r.time, r.state, r.reason) for a, r in zip(rows, rows[1:]) if r.state != a.state]
    assert offline_changes == changes and changes
    assert sum(r.reason == "window" for r in rows) == len(windows)  # a status per closed window, as the node
    final = monitor.status()
    assert result.final_status is not None and result.final_status.state == final.state == MonitorState.STABLE
    assert result.final_status.slip_rate == final.slip_rate
    # ticks at the monitor's status rate, on the pulse clock
    ticks = [r.time for r in rows if r.reason == "tick"]
    assert ticks[0] == pulses[0][1].time and ticks[1] - ticks[0] == pytest.approx(0.1, abs=1e-9)
    assert len(ticks) == math.floor((pulses[-1][1].time - pulses[0][1].time) / 0.1) + 1
    # context sampled at the rows: truth and the counter's speeds
    last = rows[-1]
    assert last.truth_slip_rate == pytest.approx(last.slip_rate, abs=0.1)
    assert last.counter_inner_ring_speed == pytest.approx(rpm_to_rad_s(1800.0), rel=1e-3)
    # program segments from the commands, named after the program
    assert result.segment_source == "program"
    assert [s.name for s in result.segments] == ["n1200", "n1800"]
    second = result.segments[1]
    assert second.ramp_end == pytest.approx(second.start_time + 0.5)
    assert second.inner_ring_speed == pytest.approx(rpm_to_rad_s(1800.0), rel=2e-3)
    assert second.final_state == MonitorState.STABLE and second.time_to_stable is not None
    assert second.axial_load == pytest.approx(100.0)
    # CSV files hold every row and window
    assert sorted(p.name for p in result.csv_files) == sorted([STATUS_CSV, WINDOWS_CSV, SEGMENTS_CSV])
    assert len((tmp_path / STATUS_CSV).read_text().splitlines()) == len(rows) + 1 == result.status_rows + 1
    assert len((tmp_path / WINDOWS_CSV).read_text().splitlines()) == len(windows) + 1


def test_a_command_recorded_ahead_of_its_stamp_starts_its_segment_at_the_stamp(twin_bag: tuple[Path, list[tuple[str, Pulse]]], tmp_path: Path) -> None:
    """The session sends a dwell segment's successor up to seconds ahead, and records it when sent:
    analyze starts the segment where the command takes effect, its stamp, not where it was
    recorded, so the segments are those of a bag with the command recorded at its stamp."""
    path = tmp_path / "ahead"
    write_twin_bag(path, 5.0, command_ahead_s=1.0)
    on_time, ahead = analyse_bag(twin_bag[0]).segments, analyse_bag(path).segments
    assert [s.name for s in ahead] == ["n1200", "n1800"]
    assert ahead[1].start_time == pytest.approx(1.5, abs=1e-3)  # the stamp, not 0.5 s (recorded)
    for a, b in zip(ahead, on_time):
        assert (a.start_time, a.ramp_end, a.end_time, a.final_state) == pytest.approx((b.start_time, b.ramp_end, b.end_time, b.final_state), abs=1e-3)
        assert (a.time_to_stable is None) == (b.time_to_stable is None)
        if a.time_to_stable is not None:
            assert a.time_to_stable == pytest.approx(b.time_to_stable, abs=0.01)


def test_two_runs_are_identical(twin_bag: tuple[Path, list[tuple[str, Pulse]]], tmp_path: Path) -> None:
    path, _pulses = twin_bag
    runs = []
    for name in ("a", "b"):
        rows: list[StatusRow] = []
        result = analyse_bag(path, csv_dir=tmp_path / name, on_row=rows.append)
        runs.append(([exact(astuple(r)) for r in rows], [exact(astuple(s)) for s in result.segments], result.transitions))
    assert runs[0] == runs[1]
    for name in (STATUS_CSV, WINDOWS_CSV, SEGMENTS_CSV):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


def test_rows_are_decimated_evenly_in_bounded_memory() -> None:
    decimator = RowDecimator(100)
    for index in range(10_000):
        decimator.offer(index)
    kept = decimator.result()
    assert len(kept) <= 101 and kept[0] == 0 and kept[-1] == 9_999
    steps = {b - a for a, b in zip(kept[:-2], kept[1:-1])}
    assert steps == {decimator.stride}


def test_csv_rows_write_floats_exactly_speeds_in_rpm(tmp_path: Path) -> None:
    """Each float as its repr (read back, the same float), None as an empty field, an int as it
    is, speeds in rpm (1 rad/s = 30 / pi rpm); a numpy float as the Python float it equals (numpy
    2 gives its repr as ``np.float64(...)``, which no CSV reader takes for a number)."""
    columns = csv_columns(SlipWindowRow)
    assert [name for name, _attr, _scale in columns] == ["start_time_s", "end_time_s", "inner_ring_rpm", "cage_rpm", "slip_rate_pct"]
    writer = CsvWriter(tmp_path / "w.csv", columns)
    rows = (
        SlipWindowRow(0.1, 0.30000000000000004, math.pi, 2.0, math.nan),
        # any object with the columns' attributes: SlipWindowRow's fields are floats (and refuse
        # None where its module runs compiled)
        SimpleNamespace(start_time=1.0, end_time=2.0, inner_ring_speed=3, cage_speed=1.0, slip_rate=None),
        SlipWindowRow(np.float64(0.1), 0.2, np.float64(math.pi), 2.0, np.float64(1.5)),
    )
    for row in rows:
        writer.write(row)
    writer.close()
    header, first, second, third = (tmp_path / "w.csv").read_text().splitlines()
    assert third.split(",") == ["0.1", "0.2", first.split(",")[2], first.split(",")[3], "1.5"]
    cells = first.split(",")
    assert cells[:2] == ["0.1", "0.30000000000000004"] and cells[4] == "nan"
    assert float(cells[2]) == pytest.approx(30.0, rel=1e-15) and float(cells[3]) == pytest.approx(60.0 / math.pi, rel=1e-15)
    assert second.split(",")[2:] == ["3", repr(float(second.split(",")[3])), ""] and float(second.split(",")[3]) == pytest.approx(30.0 / math.pi, rel=1e-15)


def test_bag_without_pulse_topics_names_them(tmp_path: Path) -> None:
    path = tmp_path / "speeds_only"
    with BagWriter(path) as bag:
        bag.add_topic("/rig/speeds", *RIG_TRAFFIC_TOPICS["/rig/speeds"])
        bag.add_topic("/rig/spindle/pulses", *RIG_TRAFFIC_TOPICS["/rig/spindle/pulses"])
        for topic, time_ns, data in rig_traffic(0.2):
            if topic in ("/rig/speeds", "/rig/spindle/pulses"):
                bag.write(topic, time_ns, data)
    with pytest.raises(BagError, match=r"no fibre-optic pulse topic /rig/cage/pulses .*has: /rig/speeds, /rig/spindle/pulses"):
        analyse_bag(path)


def test_truncated_bag_gives_a_warning_and_partial_results(twin_bag: tuple[Path, list[tuple[str, Pulse]]], tmp_path: Path) -> None:
    source, pulses = twin_bag
    full = analyse_bag(source)
    path = tmp_path / "twin"
    shutil.copytree(source, path)
    mcap = path / "twin_0.mcap"
    os.truncate(mcap, mcap.stat().st_size * 6 // 10)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", BagWarning)
        result = analyse_bag(path)
    assert any("cut by the end of the file" in str(w.message) for w in caught if w.category is BagWarning)
    assert not result.complete and any("cut by the end of the file" in p for p in result.problems)
    assert 0 < result.windows < full.windows
    assert 0 < result.last_time < full.last_time
    assert sum(result.pulses.values()) < len(pulses)


def test_bag_from_an_independent_writer_without_truth(tmp_path: Path) -> None:
    """A bench bag: mcap_ros2's writer, a hand-written metadata.yaml, pulses only (4 strips),
    wall-clock stamps; steady 1500 rpm with 3 % slip: one stretch, stable."""
    bag = tmp_path / "bench"
    bag.mkdir()
    text = (msg_folder() / "FibreOpticPulse.msg").read_text() + HEADER_DEPENDENCIES
    settings = MonitorSettings.from_yaml()
    ratio = settings.kinematics().epicyclic_ratio() * 0.97
    inner = rpm_to_rad_s(1500.0)
    epoch = 1_700_000_000.0
    events = []
    for shaft, speed, phase in (("spindle", inner, 0.0), ("cage", inner * ratio, 0.3)):
        period = 2 * math.pi / speed / 4
        count = int(8.0 / period)
        events += [(epoch + phase * period + k * period, shaft, k) for k in range(count)]
    events.sort()
    with open(bag / "bench.mcap", "wb") as stream:
        writer = McapRos2Writer(stream)
        schema = writer.register_msgdef(PULSE, text)
        for t, shaft, k in events:
            sec, nanosec = stamp_of(t)
            message = {
                "header": {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": "bench"},
                "sensor_id": shaft,
                "strip_id": k % 4,
                "strip_count": 4,
                "revolution": k // 4,
                "pulse_index": k,
            }
            writer.write_message(f"/rig/{shaft}/pulses", schema, message, log_time=sec * 10**9 + nanosec)
        writer.finish()
    write_foreign_metadata(bag, [(f"/rig/{s}/pulses", PULSE, sum(e[1] == s for e in events)) for s in ("spindle", "cage")], ["bench.mcap"])
    with warnings.catch_warnings():
        warnings.simplefilter("error", BagWarning)
        result = analyse_bag(bag)
    assert result.final_status is not None and result.final_status.state == MonitorState.STABLE
    assert result.final_status.slip_rate == pytest.approx(3.0, abs=0.01)
    assert result.first_time == pytest.approx(epoch)
    assert result.segment_source == "stretches" and len(result.segments) == 1
    stretch = result.segments[0]
    assert stretch.inner_ring_speed == pytest.approx(inner, rel=1e-6)
    assert stretch.slip_rate == pytest.approx(3.0, abs=0.01)
    assert math.isnan(stretch.truth_slip_rate) and math.isnan(stretch.axial_load) and stretch.final_recorded_state == -1


def test_recorded_status_and_unusable_topics(tmp_path: Path) -> None:
    """A recorded slip status is read as a series; a context topic of another type is warned
    about and left out."""
    store = rig_typestore()
    types = store.types
    path = tmp_path / "recorded"
    with BagWriter(path) as bag:
        for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
            bag.add_topic(topic, msgtype, qos)
        bag.add_topic("/rig/slip_status", "bearing_rig_msgs/msg/SlipStatus", "transient_local")
        bag.add_topic("/rig/axial_load/force", "std_msgs/msg/Float64", "sensor_data")
        for topic, time_ns, data in rig_traffic(3.0, spindle_speed=rpm_to_rad_s(1800.0)):
            bag.write(topic, time_ns, data)
            if topic == "/rig/truth" and time_ns % 100_000_000 == 0:
                state = 1 if time_ns < 2 * 10**9 else 2
                stamp = types["builtin_interfaces/msg/Time"](sec=time_ns // 10**9, nanosec=time_ns % 10**9)
                status = sample_message("bearing_rig_msgs/msg/SlipStatus", 3, store)
                status.header.stamp, status.state, status.slip_rate = stamp, state, 1.5
                bag.write_message("/rig/slip_status", time_ns + 1, status)
                bag.write_message("/rig/axial_load/force", time_ns + 2, types["std_msgs/msg/Float64"](data=1.0))
    with pytest.warns(BagWarning, match=r"topic /rig/axial_load/force carries std_msgs/msg/Float64, not geometry_msgs/msg/WrenchStamped; not used"):
        result = analyse_bag(path)
    assert result.recorded_statuses == 30
    assert result.recorded_transitions == [(0.0, 1), (2.0, 2)]
    assert result.final_recorded_state == 2
    assert result.rows[-1].recorded_slip_rate == 1.5 and math.isnan(result.rows[-1].load_cell_force)
    assert not result.complete


def test_bag_with_pulse_topics_but_no_pulses(tmp_path: Path) -> None:
    path = tmp_path / "empty"
    with BagWriter(path) as bag:
        for topic in ("/rig/spindle/pulses", "/rig/cage/pulses"):
            bag.add_topic(topic, *RIG_TRAFFIC_TOPICS[topic])
    with pytest.warns(BagWarning, match="has no messages"):
        result = analyse_bag(path)
    assert result.windows == 0 and result.final_status is None and result.status_rows == 0
    with open_bag(path) as reader:
        assert reader.message_count == 0


def test_monitor_parameters_come_from_the_run_context(tmp_path: Path) -> None:
    """The run's recorded parameter file sets the monitor (over the shipped defaults); an
    invalid one is warned about and the shipped file used."""
    for name, rate, expected_period in (("custom", "5.0", 0.2), ("invalid", "-1.0", 0.1)):
        path = tmp_path / name
        parameters = f"monitor:\n  ros__parameters:\n    status_rate_hz: {rate}\n"
        with BagWriter(path, metadata={"parameters/monitor": parameters}) as bag:
            for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
                bag.add_topic(topic, msgtype, qos)
            for topic, time_ns, data in rig_traffic(2.0, spindle_speed=rpm_to_rad_s(1800.0)):
                bag.write(topic, time_ns, data)
        rows: list[StatusRow] = []
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", BagWarning)
            result = analyse_bag(path, on_row=rows.append)
        ticks = [r.time for r in rows if r.reason == "tick"]
        assert ticks[1] - ticks[0] == pytest.approx(expected_period)
        if name == "custom":
            assert "parameters/monitor" in result.settings_source and not caught
        else:
            assert "shipped" in result.settings_source
            assert any("status_rate_hz" in str(w.message) and "must be > 0" in str(w.message) for w in caught)


def status_row(time: float, windows: int, inner: float, state: int = 1, slip: float = 1.0) -> StatusRow:
    return StatusRow(time, "tick", state, time, inner, 0.4 * inner, 0.43 * inner, slip, 0.0, 0.99, windows, "")


def test_segments_of_a_program_and_stretches_of_a_bench_run() -> None:
    program = SegmentTracker(True, ["a", "b"])
    program.command(0.0, 100.0, 0, 1.0, 0.0, speed_now=0.0)
    for k in range(200):
        t = 0.1 * k
        if k == 100:
            program.command(10.0, 150.0, PROFILE_CONSTANT_ACCELERATION, 0.0, 25.0, speed_now=99.0)  # from 100 rad/s: 2 s
        program.row(status_row(t, k, 150.0 if t >= 12.0 else 100.0, state=2 if t >= 13.0 or 5.0 <= t < 10.0 else 1))
    a, b = program.finish()
    assert (a.name, a.ramp_end, a.time_to_stable) == ("a", 1.0, pytest.approx(4.0))
    assert (b.name, b.start_time, b.ramp_end, b.target_speed) == ("b", 10.0, 12.0, 150.0)
    # b is a run-up (constant acceleration): judged during the acceleration, its time to stable
    # counts from its start at 10.0 s (paper section 4.2); the first stable row, at 13.0 s, rests on
    # windows from 13.0 - (1 s + one cage revolution, 0.105 s at 60 rad/s) = 11.9 s on, after it
    assert b.time_to_stable == pytest.approx(3.0) and b.inner_ring_speed == pytest.approx(150.0) and b.final_state == 2
    stretches = SegmentTracker(False, [])
    speeds = [100.0] * 30 + [100.0 + 2.0 * k for k in range(1, 10)] + [120.0] * 50  # 3 s, a ramp, 5 s
    for k, inner in enumerate(speeds):
        stretches.row(status_row(0.1 * k, k + 1, inner))
    first, second = stretches.finish()
    assert [first.name, second.name] == ["stretch 1", "stretch 2"]
    assert first.inner_ring_speed == pytest.approx(100.0) and second.inner_ring_speed == pytest.approx(120.0)
    assert second.start_time == pytest.approx(3.9) and second.end_time == pytest.approx(8.8)


def test_a_program_segment_lasts_until_the_next_command() -> None:
    """A program segment spans the time from its command to the next command, status rows or
    not: the acceleration program's first segment (load_up, at rest) is commanded before the
    first pulse, so it had no status row and was reported as ending where it began. The last
    segment ends at its last status row (nothing commands its end)."""
    tracker = SegmentTracker(by_program=True, names=["load_up", "run", "stop"])
    tracker.command(0.0, 0.0, 0, 0.0, 0.0, speed_now=0.0)
    tracker.command(1.0, 100.0, 0, 0.5, 0.0, speed_now=0.0)
    for k in range(10, 30):
        tracker.row(status_row(0.1 * k, k, 100.0))  # 1.0 .. 2.9 s
    tracker.command(3.0, 0.0, 0, 0.5, 0.0, speed_now=100.0)
    for k in range(30, 40):
        tracker.row(status_row(0.1 * k, k, 0.0))  # 3.0 .. 3.9 s
    load_up, run, stop = tracker.finish()
    assert (load_up.start_time, load_up.end_time, load_up.rows) == (0.0, 1.0, 0)
    assert (run.start_time, run.end_time) == (1.0, 3.0)
    assert (stop.start_time, stop.end_time) == (3.0, pytest.approx(3.9))


def test_a_plotted_series_breaks_where_it_has_no_value() -> None:
    """A stopped rig has no slip from the sensors (NaN on its rows): the plotted line breaks there
    (matplotlib leaves a NaN's segments out) instead of joining the slips before and after the
    stop, as it did when such rows were dropped; a series with no value at all is not drawn."""
    rows = [status_row(0.1 * k, k, 100.0, slip=math.nan if 3 <= k < 6 else 1.0) for k in range(8)]
    xs, ys = _column(SimpleNamespace(rows=rows, first_time=0.1), "slip_rate", 2.0)  # type: ignore[arg-type]
    assert xs == pytest.approx([0.1 * k - 0.1 for k in range(8)])
    assert [math.isnan(y) for y in ys] == [False, False, False, True, True, True, False, False]
    assert [y for y in ys if not math.isnan(y)] == [2.0] * 5
    stopped = [status_row(0.1 * k, k, 100.0, slip=math.nan) for k in range(3)]
    assert _column(SimpleNamespace(rows=stopped, first_time=0.0), "slip_rate") == ([], [])  # type: ignore[arg-type]


def test_recorded_stamps_on_another_clock_are_placed_on_the_pulse_clock(tmp_path: Path) -> None:
    """A monitor stamps its status with its own clock before the first window (the system
    clock, about 1.7e9 s): such a stamp is placed at the log time before the first pulse, at the
    pulse clock after it."""
    store = rig_typestore()
    path = tmp_path / "stamps"
    wall = 1_700_000_000

    def status(sec: int, nanosec: int, state: int) -> object:
        message = sample_message("bearing_rig_msgs/msg/SlipStatus", 1, store)
        message.header.stamp.sec, message.header.stamp.nanosec, message.state = sec, nanosec, state
        return message

    with BagWriter(path) as bag:
        for topic, (msgtype, qos) in RIG_TRAFFIC_TOPICS.items():
            bag.add_topic(topic, msgtype, qos)
        bag.add_topic("/rig/slip_status", "bearing_rig_msgs/msg/SlipStatus", "transient_local")
        bag.write_message("/rig/slip_status", 0, status(wall, 0, 0))
        for topic, time_ns, data in rig_traffic(2.0, spindle_speed=rpm_to_rad_s(1800.0)):
            if time_ns >= 500_000_000:
                bag.write(topic, time_ns, data)
            if time_ns == 1_000_000_000 and topic == "/rig/truth":
                bag.write_message("/rig/slip_status", time_ns + 1, status(1, 0, 1))
                bag.write_message("/rig/slip_status", time_ns + 2, status(wall, 5, 2))
    result = analyse_bag(path)
    times = [t for t, _state in result.recorded_transitions]
    assert result.recorded_transitions[0] == (0.0, 0) and [s for _t, s in result.recorded_transitions] == [0, 1, 2]
    assert times[1] == 1.0 and 0.99 < times[2] <= 1.0  # the pulse clock when it arrived


def test_a_status_on_a_window_that_ended_before_the_next_segment_is_the_previous_segments() -> None:
    """Without real time the recorder runs behind the simulator: the pulse that closes a
    segment's last window can reach the bag after the next command took effect, so the offline
    row on that window is made after the switch. It is judged by its window's end, as the live
    summary judges the recorded status on the same window: found in a --no-realtime validation
    run, where the offline time to stable of two segments was empty while the recorded one was
    1.19 and 1.52 s. Here the first stable verdict comes on a window ending at 2.95 s, read after
    the next segment began at 3.0 s: the first segment's time to stable is 2.95 - 0.5 = 2.45 s
    (its evidence starts at 2.95 - (1 s + one cage revolution, 0.16 s at 40 rad/s) = 1.8 s, after
    the ramp's end at 0.5 s), offline and recorded alike, and the next segment has none."""
    stable, slipping = int(MonitorState.STABLE), int(MonitorState.SLIPPING)
    tracker = SegmentTracker(by_program=True, names=["run", "next"])
    tracker.command(0.0, 100.0, 0, 0.5, 0.0, 0.0)
    for k in range(30):
        tracker.row(status_row(0.1 * k, k, 100.0, state=slipping))
    tracker.command(3.0, 150.0, 0, 0.5, 0.0, 100.0)
    late = StatusRow(3.02, "window", stable, 2.95, 100.0, 40.0, 43.0, 1.0, 0.0, 0.99, 30, "")
    tracker.row(late)
    tracker.recorded(2.95, 40.0, stable, 0.99, 100.0)
    for k in range(5):
        tracker.row(status_row(3.1 + 0.1 * k, 31 + k, 120.0, state=slipping))
    run, following = tracker.finish()
    assert run.time_to_stable == pytest.approx(2.45) and run.recorded_time_to_stable == pytest.approx(2.45)
    assert run.final_state == stable
    assert following.time_to_stable is None and following.recorded_time_to_stable is None and following.final_state == slipping


def test_a_recorded_status_belongs_to_the_segment_its_stamp_falls_in() -> None:
    """The monitor's verdict on a stop's silence (state unknown, stamped at its rig time within
    the stop segment) can reach the bag after the next segment's command, which was sent ahead;
    it is the stop's final recorded state all the same, as the live summary judges it (by stamp),
    and not the next segment's. A status stamped before a segment's start is not that segment's."""
    tracker = SegmentTracker(by_program=True, names=["run", "stop", "again"])
    unknown, slipping, stable = int(MonitorState.UNKNOWN), int(MonitorState.SLIPPING), int(MonitorState.STABLE)
    tracker.command(0.0, 100.0, 0, 0.5, 0.0, 0.0)
    tracker.recorded(0.8, 40.0, stable, 0.9, 100.0)
    tracker.command(1.0, 0.0, 0, 0.5, 0.0, 100.0)
    tracker.recorded(1.3, 30.0, slipping, 0.0, 60.0)
    tracker.command(3.0, 100.0, 0, 0.5, 0.0, 0.0)
    tracker.recorded(2.9, 0.0, unknown, 0.0, 0.0)  # read after the command stamped 3.0
    run, stop, again = tracker.finish()
    assert (run.final_recorded_state, stop.final_recorded_state, again.final_recorded_state) == (stable, unknown, -1)
