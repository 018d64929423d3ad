"""The bag commands: ``analyze`` (report, plots, CSV), ``bag info``, ``bag repair``, ``replay``'s
errors; user errors as one line with exit status 2."""

from __future__ import annotations

import csv
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib.image
import pytest

from bearing_rig_sim.cli import main
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.bags import BagWriter, open_bag
from bearing_rig_sim.offline.segments import SEGMENTS_CSV
from bearing_rig_sim.offline.series import STATUS_CSV, WINDOWS_CSV
from bearing_rig_sim.offline.report import PLOT_FILES, REPORT_FILE
from bearing_rig_sim.synthetic.traffic import RIG_TRAFFIC_TOPICS, rig_traffic
from conftest import time_left

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def record(path: Path, seconds: float, topics: tuple[str, ...] = tuple(RIG_TRAFFIC_TOPICS), **options: object) -> None:
    """Steady synthetic traffic at 1800 rpm (pulses, speeds, truth)."""
    with BagWriter(path, metadata={"program": "name: steady\nsegments: []\n"}, **options) as bag:
        for topic in topics:
            bag.add_topic(topic, *RIG_TRAFFIC_TOPICS[topic])
        for topic, time_ns, data in rig_traffic(seconds, spindle_speed=rpm_to_rad_s(1800.0)):
            if topic in topics:
                bag.write(topic, time_ns, data)


@pytest.fixture(scope="module")
def steady_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("bags") / "steady"
    record(path, 6.0, chunk_size=16 * 1024)
    return path


def test_analyze_writes_report_plots_and_csv(steady_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "report"
    assert main(["analyze", str(steady_bag), "--out", str(out)]) == 0
    printed = capsys.readouterr()
    assert "final verdict stable" in printed.out and printed.err == ""
    text = (out / REPORT_FILE).read_text()
    assert "# Offline analysis of `steady`" in text and "Incomplete" not in text
    assert "final verdict offline: **stable**" in text and "constant-speed stretches" in text
    assert "| 1 | stretch 1 |" in text and "| `/rig/truth` |" in text
    for name in PLOT_FILES:
        data = (out / name).read_bytes()
        assert data.startswith(PNG_SIGNATURE) and f"]({name})" in text
        image = matplotlib.image.imread(out / name)
        assert image.shape[0] > 200 and image.shape[1] > 400
    with open(out / STATUS_CSV, newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) >= 60 and rows[-1]["reason"] == "end" and rows[-1]["state"] == "2"
    # the report's time origin, on the rig clock the CSV files keep: the first pulse's stamp
    with open_bag(steady_bag) as bag:
        first = min(m.message.header.stamp.sec + m.message.header.stamp.nanosec * 1e-9 for m in bag.messages(["/rig/spindle/pulses", "/rig/cage/pulses"]))
    origin = re.search(r"time below runs from the first pulse, at ([0-9.]+) s of rig time; the CSV files keep rig time", text)
    assert origin is not None and float(origin.group(1)) == pytest.approx(first, abs=1e-6)
    assert float(rows[0]["time_s"]) >= first - 1e-9
    assert float(rows[-1]["inner_ring_rpm"]) == pytest.approx(1800.0, rel=1e-6)
    assert float(rows[-1]["truth_slip_rate_pct"]) == pytest.approx(2.5)
    with open(out / WINDOWS_CSV, newline="") as stream:
        windows = list(csv.DictReader(stream))
    # 6 s of cage pulses at 702 rpm (0.0855 s a revolution); a window holds the fewest whole
    # revolutions lasting at least the monitor's min_window_s = 0.1 s, i.e. 2 (0.171 s): 35 windows.
    assert len(windows) >= 34 and all(math.isfinite(float(w["slip_rate_pct"])) for w in windows)
    with open(out / SEGMENTS_CSV, newline="") as stream:
        segments = list(csv.DictReader(stream))
    assert [s["name"] for s in segments] == ["stretch 1"] and segments[0]["final_state"] == "2"


def test_analyze_loads_no_dynamics_engine(steady_bag: Path, tmp_path: Path) -> None:
    """``bearing-rig analyze`` in its own process, as a user runs it, loads neither numba nor the
    engine (the commands that need them are not imported): numba alone costs some 100 MB, half
    of issue 36's 200 MB for an hour's analysis."""
    script = (
        "import sys\n"
        "from bearing_rig_sim import cli\n"
        "status = cli.main(sys.argv[1:])\n"
        "heavy = sorted(m for m in ('numba', 'llvmlite', 'bearing_rig_sim.dynamics', 'rclpy') if m in sys.modules)\n"
        "print('loaded:' + ''.join(' ' + m for m in heavy))\n"
        "sys.exit(status)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script, "analyze", str(steady_bag), "--out", str(tmp_path / "report")],
        capture_output=True,
        text=True,
        timeout=time_left(),
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "loaded:", done.stdout


def test_analyze_a_bag_without_sensor_topics_is_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    record(tmp_path / "speeds", 0.5, topics=("/rig/speeds", "/rig/truth"))
    assert main(["analyze", str(tmp_path / "speeds"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("bearing-rig: error: ")
    assert "/rig/spindle/pulses nor /rig/cage/pulses" in err[0]
    assert not (tmp_path / "out" / REPORT_FILE).exists()


def test_analyze_a_truncated_bag_warns_and_says_so(steady_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "steady"
    shutil.copytree(steady_bag, bag)
    mcap = bag / "steady_0.mcap"
    os.truncate(mcap, mcap.stat().st_size // 2)
    assert main(["analyze", str(bag), "--out", str(tmp_path / "out")]) == 0
    printed = capsys.readouterr()
    warnings_printed = printed.err.splitlines()
    assert warnings_printed and all(line.startswith("bearing-rig: warning: ") for line in warnings_printed)
    assert any("cut by the end of the file" in line for line in warnings_printed)
    assert "INCOMPLETE bag, partial results" in printed.out
    text = (tmp_path / "out" / REPORT_FILE).read_text()
    assert "**Incomplete results.**" in text and "cut by the end of the file" in text


def test_analyze_not_a_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", str(tmp_path / "missing")]) == 2
    assert "no such bag" in capsys.readouterr().err


def test_bag_info(steady_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["bag", "info", str(steady_bag)]) == 0
    out = capsys.readouterr().out
    assert "state:      complete" in out and "duration:   6.000 s" in out
    assert "/rig/speeds" in out and " 6000 " in out and "reliable, volatile, keep_last 5000" in out
    assert "program: 2 lines (--metadata shows them)" in out and "project_version: " in out
    assert "problems:   none" in out
    assert main(["bag", "info", "--metadata", str(steady_bag)]) == 0
    assert "    name: steady" in capsys.readouterr().out


def test_bag_info_and_repair_of_a_killed_recording(steady_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = tmp_path / "steady"
    shutil.copytree(steady_bag, bag)
    mcap = bag / "steady_0.mcap"
    os.truncate(mcap, mcap.stat().st_size * 2 // 3)  # summary and footer gone, last chunk cut
    assert main(["bag", "info", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "DAMAGED" in out and "cut by the end of the file" in out
    assert main(["bag", "repair", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "messages recovered" in out and "rebuilt" in out and (bag / "steady_0.mcap.orig").exists()
    assert main(["bag", "info", str(bag)]) == 0
    assert "state:      complete" in capsys.readouterr().out
    assert main(["bag", "repair", str(tmp_path / "nothing"), str(bag)]) == 2
    printed = capsys.readouterr()
    assert "nothing to repair" in printed.out and printed.err.startswith("bearing-rig: error: ")


def test_replay_unknown_topic_and_bad_rate(steady_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(steady_bag), "--topics", "/rig/nothing"]) == 2
    assert "no topic /rig/nothing in the bag" in capsys.readouterr().err
    assert main(["replay", str(steady_bag), "--rate", "0"]) == 2
    assert "replay: rate: must be > 0.0, got 0.0" in capsys.readouterr().err


def test_bag_info_checks_every_chunk(steady_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A chunk zeroed after the recording: the index is intact, so only reading the chunks shows
    it; bag info names the chunk and counts the messages it cost (mcap's own reader for the count)."""
    from mcap.reader import make_reader

    bag = tmp_path / "steady"
    shutil.copytree(steady_bag, bag)
    mcap = bag / "steady_0.mcap"
    with open(mcap, "rb") as stream:
        reader = make_reader(stream)
        total = reader.get_summary().statistics.message_count
        chunk = sorted(reader.get_summary().chunk_indexes, key=lambda c: c.chunk_start_offset)[1]
        in_chunk = sum(1 for _ in reader.iter_messages(starting_at=chunk.message_start_time, ending_at=chunk.message_end_time))
    with open(mcap, "r+b") as stream:
        stream.seek(chunk.chunk_start_offset + chunk.chunk_length - 32)
        stream.write(bytes(32))
    assert main(["bag", "info", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "DAMAGED" in out and f"chunk at offset {chunk.chunk_start_offset}" in out
    assert f"{in_chunk} of {total} messages" in out
    assert main(["bag", "info", "--index-only", str(bag)]) == 0
    assert "index only; chunks not checked" in capsys.readouterr().out


def test_bag_info_reports_log_time_outliers(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """One /clock recorded at 2^31 - 1 s among a second of traffic: an outlier, not 'problems: none'."""
    from bearing_rig_sim.bags import rig_typestore

    types = rig_typestore().types
    bag = tmp_path / "outlier"
    with BagWriter(bag) as writer:
        writer.add_topic("/clock", "rosgraph_msgs/msg/Clock")
        for k in range(1000):
            writer.write_message(
                "/clock", k * 1_000_000, types["rosgraph_msgs/msg/Clock"](clock=types["builtin_interfaces/msg/Time"](sec=0, nanosec=k * 1_000_000))
            )
        far = (2**31 - 1) * 1_000_000_000
        writer.write_message("/clock", far, types["rosgraph_msgs/msg/Clock"](clock=types["builtin_interfaces/msg/Time"](sec=2**31 - 1, nanosec=0)))
    assert main(["bag", "info", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "log-time outliers: 1 message(s) at 2147483647.000-2147483647.000 s" in out
    assert "the main timeline (0.000-0.999 s, 1000 messages)" in out and "DAMAGED" in out
