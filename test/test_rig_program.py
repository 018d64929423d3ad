"""Test programs: the STEP drive function's laws (end values, monotonicity, zero end slopes, C1
continuity; the paper's typo form shown wrong), constant acceleration, the shipped programs, and
errors naming file and key for malformed programs.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.rig.program import RigLimits, load_program
from bearing_rig_sim.rig.speed_profile import SegmentSpeed, SpeedProfileKind, step_ramp, step_ramp_rate

RPM = 2.0 * math.pi / 60.0


# -- STEP -------------------------------------------------------------------------------------
@pytest.mark.parametrize("x0, x1", [(0.0, 94.2), (282.7, 94.2), (10.0, 10.0)])
def test_step_end_values_and_monotonicity(x0: float, x1: float) -> None:
    t0, t1 = 2.0, 3.5
    assert step_ramp(t0, t0, x0, t1, x1) == x0
    assert step_ramp(t1, t0, x0, t1, x1) == x1
    assert step_ramp(t0 - 1.0, t0, x0, t1, x1) == x0
    assert step_ramp(t1 + 1.0, t0, x0, t1, x1) == x1
    values = np.array([step_ramp(t, t0, x0, t1, x1) for t in np.linspace(t0 - 0.5, t1 + 0.5, 2001)])
    steps = np.diff(values) * math.copysign(1.0, x1 - x0)
    assert np.all(steps >= 0.0)
    assert values.min() >= min(x0, x1) and values.max() <= max(x0, x1)
    assert step_ramp((t0 + t1) / 2, t0, x0, t1, x1) == pytest.approx((x0 + x1) / 2)  # point symmetry


def test_step_zero_slope_at_both_ends_and_c1_continuity() -> None:
    t0, x0, t1, x1 = 1.0, 50.0, 3.0, 250.0
    args = (t0, x0, t1, x1)
    eps = 1e-6
    # slope -> 0 at both ends, from inside (6 A D (1 - D) / T with D ~ eps / T)
    assert abs(step_ramp_rate(t0 + eps, *args)) <= 6.0 * (x1 - x0) * eps / (t1 - t0) ** 2 * 1.01
    assert abs(step_ramp_rate(t1 - eps, *args)) <= 6.0 * (x1 - x0) * eps / (t1 - t0) ** 2 * 1.01
    assert step_ramp_rate(t0 - eps, *args) == 0.0 and step_ramp_rate(t1 + eps, *args) == 0.0
    # the largest slope is 1.5 A / T, at the middle
    assert step_ramp_rate(2.0, *args) == pytest.approx(1.5 * (x1 - x0) / (t1 - t0))
    # the rate is the derivative everywhere, joints included (central differences)
    h = 1e-5
    for t in np.concatenate([np.linspace(t0 - 0.2, t1 + 0.2, 97), [t0, t1]]):
        numeric = (step_ramp(t + h, *args) - step_ramp(t - h, *args)) / (2 * h)
        assert numeric == pytest.approx(step_ramp_rate(t, *args), abs=1e-3)
    # C1 at the joints: the one-sided difference quotients differ by at most 3 A h / T^2 (the
    # cubic's curvature), so both tend to the same slope 0; a kink would leave a constant gap
    for joint in (t0, t1):
        for step in (1e-3, 1e-4, 1e-5):
            left = (step_ramp(joint, *args) - step_ramp(joint - step, *args)) / step
            right = (step_ramp(joint + step, *args) - step_ramp(joint, *args)) / step
            assert abs(left - right) <= 3.0 * (x1 - x0) * step / (t1 - t0) ** 2 * 1.01 + 1e-9


def test_papers_printed_step_fraction_is_wrong() -> None:
    # The paper prints D = (t - t0)/(t - t1): it diverges at t1 and gives x0 + 5 A mid-ramp.
    def printed(t: float, t0: float, x0: float, t1: float, x1: float) -> float:
        d = (t - t0) / (t - t1)
        return x0 + (x1 - x0) * d * d * (3.0 - 2.0 * d)

    t0, x0, t1, x1 = 0.0, 0.0, 1.0, 100.0
    assert printed(0.5, t0, x0, t1, x1) == pytest.approx(x0 + 5.0 * (x1 - x0))
    near_end = t1 - 1e-6
    assert abs(printed(near_end, t0, x0, t1, x1) - x1) > 1e6  # does not reach x1 at t1
    assert step_ramp(near_end, t0, x0, t1, x1) == pytest.approx(x1, abs=1e-6)
    assert step_ramp(0.5, t0, x0, t1, x1) == pytest.approx(50.0)


def test_step_jump_and_bad_arguments() -> None:
    assert step_ramp(0.99, 1.0, 0.0, 1.0, 5.0) == 0.0
    assert step_ramp(1.0, 1.0, 0.0, 1.0, 5.0) == 5.0  # zero-length ramp: a jump at t0
    with pytest.raises(ValueError, match="t1"):
        step_ramp(0.5, 1.0, 0.0, 0.0, 5.0)
    with pytest.raises(ValueError, match="finite"):
        step_ramp(math.nan, 0.0, 0.0, 1.0, 5.0)


# -- segment speed --------------------------------------------------------------------------
@pytest.mark.parametrize("start, target, alpha", [(0.0, 1500 * RPM, 20.0), (0.0, 1500 * RPM, 80.0), (300.0, 100.0, 40.0)])
def test_constant_acceleration_reaches_target_at_delta_omega_over_alpha(start: float, target: float, alpha: float) -> None:
    t_start = 3.0
    profile = SegmentSpeed(t_start, start, target, SpeedProfileKind.CONSTANT_ACCELERATION, acceleration=alpha)
    duration = abs(target - start) / alpha
    sign = math.copysign(1.0, target - start)
    assert profile.ramp_end == pytest.approx(t_start + duration)
    assert profile.at(t_start + duration)[0] == pytest.approx(target, abs=1e-9)
    speed, accel = profile.at(t_start + 0.5 * duration)
    assert speed == pytest.approx((start + target) / 2) and accel == sign * alpha
    assert abs(profile.at(t_start + 0.999 * duration)[0] - target) > 0.0
    assert profile.at(t_start + 2 * duration) == (target, 0.0)
    assert profile.at(t_start - 1.0) == (start, 0.0)


def test_step_segment_speed_and_acceleration() -> None:
    profile = SegmentSpeed(10.0, 94.2, 125.7, SpeedProfileKind.STEP, ramp_time=1.0)
    assert profile.ramp_end == 11.0
    for t in (10.0, 10.25, 10.5, 10.9, 11.0, 12.0):
        speed, accel = profile.at(t)
        assert speed == step_ramp(t, 10.0, 94.2, 11.0, 125.7)
        assert accel == step_ramp_rate(t, 10.0, 94.2, 11.0, 125.7)


def test_profile_kind_message_codes() -> None:
    # SpindleCommand.msg: PROFILE_STEP=0, PROFILE_CONSTANT_ACCELERATION=1
    assert SpeedProfileKind.STEP.message_code == 0
    assert SpeedProfileKind.CONSTANT_ACCELERATION.message_code == 1


# -- shipped programs ----------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["validation", "load_sweep", "acceleration"])
def test_shipped_programs_load(name: str) -> None:
    program = load_program(config_path("programs", f"{name}.yaml"))  # against the shipped rig
    assert program.name == name and program.bearing_file.is_file() and program.segments


def test_validation_program_matches_the_papers_table_3_conditions() -> None:
    program = load_program(config_path("programs", "validation.yaml"))
    speeds = [s.target_speed for s in program.segments if s.target_speed > 0]
    np.testing.assert_allclose(speeds, [n * RPM for n in range(900, 2701, 300)])
    assert {s.axial_load for s in program.segments} == {100.0}
    assert all(s.profile is SpeedProfileKind.STEP for s in program.segments)
    assert program.longest_duration() < 100.0  # well under 2 minutes even if every segment times out


def test_load_sweep_and_acceleration_programs_cover_the_papers_ranges() -> None:
    sweep = load_program(config_path("programs", "load_sweep.yaml"))
    assert sweep.stability_criterion == "axial_load"
    assert {round(s.target_speed / RPM) for s in sweep.segments} == {0, 1000, 3000, 5000, 7000, 9000}
    loads = [s.axial_load for s in sweep.segments]
    assert min(loads) == 50.0 and max(loads) == 700.0
    # every speed is run up from rest under the full load and left at rest under it (the
    # program's comment: no run-up under a light load, no skid hysteresis in the points)
    starts = sweep.start_speeds()
    for k, seg in enumerate(sweep.segments):
        if seg.target_speed > 0.0 and starts[k] != seg.target_speed:
            assert starts[k] == 0.0 and seg.axial_load == 700.0, seg.name
        if seg.target_speed == 0.0:
            assert seg.axial_load == 700.0, seg.name
    accel = load_program(config_path("programs", "acceleration.yaml"))
    ramps = [s for s in accel.segments if s.profile is SpeedProfileKind.CONSTANT_ACCELERATION]
    assert [s.acceleration for s in ramps] == [20.0, 40.0, 60.0, 80.0]
    assert {s.axial_load for s in accel.segments} == {200.0}
    starts = dict(zip([s.name for s in accel.segments], accel.start_speeds()))
    assert all(starts[s.name] == 0.0 for s in ramps)  # each run from rest


# -- malformed programs ------------------------------------------------------------------------
GOOD = """
name: probe
description: a small program
bearing: bearings/h7006c.yaml
stability_criterion: time
segments:
  - {name: a, speed_rpm: 900, ramp_s: 1.0, axial_load_n: 100, dwell_s: 2.0}
  - {name: b, speed_rpm: 1500, acceleration_rad_s2: 40, axial_load_n: 100, until_stable: true, timeout_s: 5}
"""


def test_good_probe_program_loads_in_si_units(tmp_path: Path) -> None:
    path = tmp_path / "probe.yaml"
    path.write_text(GOOD)
    program = load_program(path)
    a, b = program.segments
    assert a.target_speed == pytest.approx(900 * RPM) and a.ramp_time == 1.0 and a.dwell == 2.0
    assert b.profile is SpeedProfileKind.CONSTANT_ACCELERATION and b.until_stable and b.timeout == 5.0
    assert program.longest_duration() == pytest.approx(1.0 + 2.0 + (600 * RPM) / 40.0 + 5.0)


@pytest.mark.parametrize(
    "old, new, key, problem",
    [
        ("axial_load_n: 100, dwell_s", "dwell_s", "segments[0].axial_load_n", "missing"),
        ("axial_load_n: 100, dwell_s", "axial_load_n: -5, dwell_s", "segments[0].axial_load_n", ">= 0"),
        ("speed_rpm: 900, ramp_s", "speed_rps: 15, ramp_s", "segments[0].speed_rps", "unknown key"),
        ("speed_rpm: 900, ramp_s", "ramp_s", "segments[0].speed_rpm", "missing"),
        ("speed_rpm: 900", "speed_rpm: .nan", "segments[0].speed_rpm", "finite"),
        ("ramp_s: 1.0", "ramp_s: 1.0, acceleration_rad_s2: 5", "segments[0].acceleration_rad_s2", "not both"),
        ("acceleration_rad_s2: 40", "acceleration_rad_s2: 0", "segments[1].acceleration_rad_s2", "> 0"),
        ("dwell_s: 2.0}", "dwell_s: 2.0, until_stable: true, timeout_s: 3}", "segments[0].dwell_s", "not both"),
        (", timeout_s: 5", "", "segments[1].timeout_s", "missing"),
        (", dwell_s: 2.0", "", "segments[0].dwell_s", "missing"),
        ("name: b,", "name: a,", "segments[1].name", "duplicate"),
        ("stability_criterion: time", "stability_criterion: speed", "stability_criterion", "one of"),
        ("bearings/h7006c.yaml", "bearings/nope.yaml", "bearing", "not found"),
        ("name: probe", "name: probe\nauthor: me", "author", "unknown key"),
        # programs checked against the rig they run on, and bounded
        # 600 rpm (62.8 rad/s) at 1e-300 rad/s^2 would take 6e301 s
        ("acceleration_rad_s2: 40", "acceleration_rad_s2: 1.0e-300", "segments[1].acceleration_rad_s2", "more than the 600 s allowed"),
        ("acceleration_rad_s2: 40", "acceleration_rad_s2: 5000", "segments[1].acceleration_rad_s2", "above the rig's limit of 1000 rad/s^2"),
        # 900 rpm = 94.25 rad/s in 0.1 s: peak 1.5 * 94.25 / 0.1 = 1414 rad/s^2 > 1000
        ("ramp_s: 1.0", "ramp_s: 0.1", "segments[0].ramp_s", "peak acceleration of 1414 rad/s^2"),
        ("ramp_s: 1.0", "ramp_s: 0.0", "segments[0].ramp_s", "give ramp_s > 0"),
        ("ramp_s: 1.0", "ramp_s: 1.0e9", "segments[0].ramp_s", "<= 600"),
        ("dwell_s: 2.0", "dwell_s: 1.0e9", "segments[0].dwell_s", "<= 3600"),
        ("timeout_s: 5", "timeout_s: 1.0e9", "segments[1].timeout_s", "<= 3600"),
        ("name: a,", "name: 'a/../../x',", "segments[0].name", "letters, digits"),
        ("name: probe", "name: ''", "name", "non-empty"),
    ],
)
def test_malformed_programs_name_file_and_key(tmp_path: Path, old: str, new: str, key: str, problem: str) -> None:
    assert old in GOOD
    path = tmp_path / "bad.yaml"
    path.write_text(GOOD.replace(old, new, 1))
    with pytest.raises(ConfigError) as info:
        load_program(path)
    assert info.value.source == str(path)
    assert info.value.key == key
    assert problem in info.value.problem


def test_rig_limits_and_yaml_syntax_errors(tmp_path: Path) -> None:
    path = tmp_path / "probe.yaml"
    path.write_text(GOOD)
    with pytest.raises(ConfigError) as info:
        load_program(path, RigLimits(2000 * RPM, 1000.0, 50.0, "small.yaml"))
    assert info.value.key == "segments[0].axial_load_n"
    assert info.value.problem == "segment 'a': 100 N is above the rig's limit of 50 N (loading_chain.max_setpoint_n in small.yaml)"
    with pytest.raises(ConfigError) as info:
        load_program(path, RigLimits(1000 * RPM, 1000.0, 1000.0, "small.yaml"))
    assert info.value.key == "segments[1].speed_rpm"
    assert "segment 'b': 1500 rpm is above the rig's limit of 1000 rpm (spindle.max_speed_rad_s in small.yaml)" == info.value.problem
    path.write_text(GOOD + "  - {name: c, speed_rpm: [\n")
    with pytest.raises(ConfigError, match="not valid YAML") as info:
        load_program(path)
    assert info.value.source == str(path)


# -- programs checked against the rig they run on ------------------------------------------------
SHIPPED_RIG = RigLimits.from_rig_file()


def test_shipped_rig_limits_come_from_rig_yaml() -> None:
    # config/rig.yaml: a 10 000 rpm spindle (the paper's load sweep reaches 9000 rpm), 1000 rad/s^2,
    # the loading chain's 1000 N largest set-point.
    assert SHIPPED_RIG.max_speed_rad_s == pytest.approx(10000 * 2 * math.pi / 60)
    assert SHIPPED_RIG.max_acceleration_rad_s2 == 1000.0
    assert SHIPPED_RIG.max_axial_load_n == 1000.0


def test_a_9000_rpm_program_is_refused_on_a_6000_rpm_rig_naming_the_segment() -> None:
    six_thousand = RigLimits(6000 * 2 * math.pi / 60, 1000.0, 1000.0, "rig.yaml")
    with pytest.raises(ConfigError) as info:
        load_program(config_path("programs", "load_sweep.yaml"), six_thousand)
    # the first segment above 6000 rpm is the 28th (index 27; 9 segments per speed with its
    # stop), n7000_f700
    assert info.value.key == "segments[27].speed_rpm"
    assert "segment 'n7000_f700': 7000 rpm is above the rig's limit of 6000 rpm" in info.value.problem


def test_the_shortest_allowed_step_ramp_is_accepted(tmp_path: Path) -> None:
    # 0 -> 900 rpm: peak 1.5 * 94.25 / T <= 1000 rad/s^2 for T >= 0.1414 s
    path = tmp_path / "fast.yaml"
    path.write_text(GOOD.replace("ramp_s: 1.0", "ramp_s: 0.142", 1))
    assert load_program(path).segments[0].ramp_time == 0.142


def test_program_file_errors_are_the_parameter_models_wording(tmp_path: Path) -> None:
    """The program file is checked by the declarative parameter model (ProgramFile, SegmentFile):
    the same one-line errors as every node's settings, with list places as ``segments[i]``."""
    path = tmp_path / "bad.yaml"
    cases = {
        "  - {name: a,": ("  - 5\n  - {name: a,", "segments[0]: must be a mapping, got int"),
        "speed_rpm: 900, ramp_s": (
            "speed_rpm: 900, sped: 1, ramp_s",
            "segments[0].sped: unknown key; allowed keys: acceleration_rad_s2, "
            "axial_load_n, dwell_s, moment_n_m, name, radial_azimuth_deg, radial_load_n, ramp_s, speed_rpm, timeout_s, until_stable",
        ),
        "axial_load_n: 100, dwell_s": ("axial_load_n: -5, dwell_s", "segments[0].axial_load_n: must be >= 0.0, got -5.0"),
        "until_stable: true": ("until_stable: 1", "segments[1].until_stable: must be true or false, got 1"),
    }
    for old, (new, message) in cases.items():
        assert old in GOOD
        path.write_text(GOOD.replace(old, new, 1))
        with pytest.raises(ConfigError) as info:
            load_program(path)
        assert str(info.value) == f"{path}: {message}"
    path.write_text(GOOD.replace("ramp_s: 1.0, axial_load_n: 100", "ramp_s: 1.0, radial_load_n: null, axial_load_n: 100", 1))
    assert load_program(path).segments[0].radial_load == 0.0  # a null is an absent optional key
    path.write_text(GOOD.split("segments:")[0] + "segments: []\n")
    with pytest.raises(ConfigError, match=r"bad.yaml: segments: must be a non-empty list of mappings"):
        load_program(path)


def test_the_rig_files_combined_loading_limits_are_a_checked_record(tmp_path: Path) -> None:
    rig = tmp_path / "rig.yaml"
    text = config_path("rig.yaml").read_text(encoding="utf-8")
    assert "  max_radial_setpoint_n: 0.0\n" in text
    rig.write_text(text.replace("  max_radial_setpoint_n: 0.0\n", "  max_radial_setpoint_n: 250.0\n"), encoding="utf-8")
    assert RigLimits.from_rig_file(rig).max_radial_load_n == 250.0
    rig.write_text(text.replace("  max_radial_setpoint_n: 0.0\n", "  max_radial_setpoint_n: -1.0\n"), encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        RigLimits.from_rig_file(rig)
    assert str(info.value) == f"{rig}: combined_loading.max_radial_setpoint_n: must be >= 0.0, got -1.0"
