"""Progress line, summary table, real-time factor and the printer (no ROS): rpm and percent at the
edge, missing values shown as '-', aligned columns, refresh on a terminal, quiet.
"""

from __future__ import annotations

import io

import pytest

from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.session.progress import ProgressPrinter, ProgressSnapshot, RealTimeFactor, format_progress, format_summary
from bearing_rig_sim.session.runner import SegmentOutcome, StatusState, Verdict


def snapshot(**changes: object) -> ProgressSnapshot:
    values: dict[str, object] = dict(
        segment_number=3,
        segment_count=8,
        segment_name="n1200",
        phase="hold",
        sim_time=14.23,
        inner_ring_speed=rpm_to_rad_s(1200.04),
        cage_speed=rpm_to_rad_s(494.31),
        slip_rate=3.5123,
        slip_state=StatusState.SLIPPING,
        real_time_factor=0.984,
    )
    values.update(changes)
    return ProgressSnapshot(**values)  # type: ignore[arg-type]


def test_progress_line_shows_rpm_percent_and_state() -> None:
    line = format_progress(snapshot())
    assert line == "[3/8 n1200 hold] t=14.2 s  inner 1200.0 rpm  cage 494.3 rpm  slip 3.512 %  slipping  rtf 0.98"


def test_progress_line_before_any_data() -> None:
    line = format_progress(
        snapshot(
            segment_number=0,
            segment_name="-",
            phase="starting",
            inner_ring_speed=None,
            cage_speed=None,
            slip_rate=None,
            slip_state=None,
            real_time_factor=None,
            sim_time=0.0,
        )
    )
    assert line == "[0/8 - starting] t=0.0 s  inner -  cage -  slip -  -  rtf -"


def outcome(index: int, name: str, rpm: float, verdict: Verdict, **changes: object) -> SegmentOutcome:
    values: dict[str, object] = dict(
        index=index,
        name=name,
        target_speed=rpm_to_rad_s(rpm),
        axial_load=100.0,
        verdict=verdict,
        start_time=0.0,
        ramp_end=1.0,
        end_time=3.0,
        time_to_stable=2.314,
        measured_slip=3.2151,
        truth_slip=3.2203,
        bearing_force=99.94,
    )
    values.update(changes)
    return SegmentOutcome(**values)  # type: ignore[arg-type]


def test_summary_table_rows_and_alignment() -> None:
    table = format_summary(
        [
            outcome(0, "load_up", 0.0, Verdict.UNKNOWN, time_to_stable=None, measured_slip=None, truth_slip=None),
            outcome(1, "n0900", 900.0, Verdict.STABLE),
            outcome(2, "n1200", 1200.0, Verdict.TIMEOUT, time_to_stable=None),
        ]
    )
    lines = table.splitlines()
    assert lines[0].split() == [
        "#",
        "segment",
        "speed",
        "rpm",
        "meas",
        "rpm",
        "load",
        "N",
        "F_bearing",
        "N",
        "slip",
        "%",
        "meas",
        "slip",
        "%",
        "truth",
        "verdict",
        "t_stable",
        "s",
        "conditions",
    ]
    assert set(lines[1]) <= {"-", " "}
    assert lines[2].split() == ["1", "load_up", "0", "-", "100", "99.9", "-", "-", "unknown", "-", "ok"]
    assert lines[3].split() == ["2", "n0900", "900", "-", "100", "99.9", "3.215", "3.220", "stable", "2.31", "ok"]
    assert lines[4].split()[-3:] == ["timeout", "-", "ok"]
    # numbers right-aligned: the column ends line up
    end = lines[0].index("speed rpm") + len("speed rpm")
    assert lines[3][end - 3 : end] == "900" and lines[2][end - 1 : end] == "0"


def test_segments_whose_conditions_were_not_met_are_marked_and_explained() -> None:
    table = format_summary(
        [
            outcome(0, "n7000", 7000.0, Verdict.STABLE, measured_speed=rpm_to_rad_s(5000.0), conditions=("speed 5000 rpm measured, 7000 rpm commanded",)),
            outcome(
                1,
                "n0900",
                900.0,
                Verdict.STABLE,
                measured_speed=rpm_to_rad_s(900.0),
                bearing_force=30.0,
                conditions=("load 30.0 N on the bearing, 100 N commanded", "disturbed: a message on /rig/axial_load/setpoint not sent by this session"),
            ),
        ]
    )
    lines = table.splitlines()
    assert lines[2].split()[3] == "5000" and lines[2].split()[-1] == "speed"
    assert lines[3].split()[-1] == "load,disturbed"
    assert "conditions not met in segment 1 n7000: speed 5000 rpm measured, 7000 rpm commanded" in table
    assert "conditions not met in segment 2 n0900: load 30.0 N on the bearing, 100 N commanded; disturbed: " in table


def test_a_run_up_is_said_to_count_from_its_start_at_the_speed_it_became_stable() -> None:
    """A run-up's t_stable counts from its start (paper section 4.2): the line under the table says
    so, with the speed of its stable status (127.4 rad/s = 1216.6 rpm); a step segment adds none."""
    run_up = outcome(1, "accel_20", 1500.0, Verdict.STABLE, run_up=True, stable_speed=127.4)
    table = format_summary([outcome(0, "n0900", 900.0, Verdict.STABLE), run_up])
    notes = [line for line in table.splitlines() if line.startswith("run-ups")]
    assert notes == [
        "run-ups are judged during their acceleration (the paper's section 4.2): t_stable from the run-up's start, slip at the stable status (accel_20 1217 rpm)"
    ]
    assert "run-ups" not in format_summary([outcome(0, "n0900", 900.0, Verdict.STABLE)])


def test_empty_summary_says_so() -> None:
    assert "(no segment ran)" in format_summary([])


def test_real_time_factor_over_its_window() -> None:
    rtf = RealTimeFactor(window_s=2.0)
    assert rtf.value is None
    for k in range(50):  # 0.5 s of sim per s of wall
        rtf.add(0.1 * k, 0.05 * k)
    assert rtf.value == pytest.approx(0.5)
    rtf.add(5.0, 0.0)  # clock went back: starts again
    assert rtf.value is None


def test_printer_lines_refresh_and_quiet() -> None:
    lines = io.StringIO()
    ProgressPrinter(lines, refresh=False).show("a")
    assert lines.getvalue() == "a\n"
    term = io.StringIO()
    printer = ProgressPrinter(term, refresh=True)
    printer.show("a")
    printer.show("b")
    printer.message("event")
    printer.show("c")
    printer.done()
    assert term.getvalue() == "\ra\x1b[K\rb\x1b[K\nevent\n\rc\x1b[K\n"
    quiet = io.StringIO()
    ProgressPrinter(quiet, quiet=True).show("a")
    assert quiet.getvalue() == ""


def test_the_delivery_table_names_every_shortfall_loudly() -> None:
    from bearing_rig_sim.session.progress import format_delivery

    published = {"/clock": 1000, "/rig/axial_load/force": 1000, "/rig/slip_status": 50}
    recorded = {"/clock": 1000, "/rig/axial_load/force": 930, "/rig/slip_status": 50, "/rig/spindle/pulses": 0}
    text = format_delivery(published, recorded)
    rows = {line.split()[0]: line.split()[1:] for line in text.splitlines()[1:4]}
    assert rows == {"/clock": ["1000", "1000"], "/rig/axial_load/force": ["1000", "930"], "/rig/slip_status": ["50", "50"]}
    assert "NOT ALL RECORDED: /rig/axial_load/force: 70 of 1000 published messages missing from the bag" in text
    assert "every published message recorded" not in text
    whole = format_delivery({"/clock": 3}, {"/clock": 3})
    assert whole.endswith("every published message recorded") and "NOT" not in whole


def test_a_node_without_a_delivery_report_is_named() -> None:
    from bearing_rig_sim.session.progress import format_delivery

    text = format_delivery({"/clock": 3}, {"/clock": 3, "/rig/slip_status": 7}, unreported=["monitor"])
    assert ["/rig/slip_status", "?", "7"] in [line.split() for line in text.splitlines()]
    assert "NO DELIVERY REPORT from monitor" in text and "every published message recorded" not in text


def test_topics_without_a_published_count_are_not_called_complete() -> None:
    from bearing_rig_sim.session.progress import format_delivery

    text = format_delivery({"/rig/spindle/command": 3}, {"/rig/spindle/command": 3, "/clock": 900})  # attached: nodes managed elsewhere
    assert "every published message recorded" not in text and "published counts unknown for 1 topic(s)" in text
