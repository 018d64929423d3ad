"""Slip rate (paper Eq. 11-12) and slip from fibre-optic pulse trains.

Expected values are written out here from the definitions, not taken from the module:
n_s / n_i = (1 - Dw cos(alpha) / dm) / 2 and S = (1 - n_c / n_s) * 100.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bearing_rig_sim.analysis import AnalysisError
from bearing_rig_sim.analysis.slip import (
    BearingKinematics,
    epicyclic_cage_speed,
    slip_rate,
    whole_revolution_slip,
)
from bearing_rig_sim.config import ConfigError

DW, DM, ALPHA = 6.3e-3, 42.45e-3, math.radians(15.0)
H7006C = BearingKinematics(DW, DM, ALPHA)


def ratio(dw: float, dm: float, alpha: float) -> float:
    return 0.5 * (1.0 - dw * math.cos(alpha) / dm)


# -- Eq. 12 ----------------------------------------------------------------------------------------
def test_h7006c_epicyclic_ratio_is_the_digest_value() -> None:
    # docs/paper.md section 6: n_s = 0.4283 n_i at the nominal angle (4 significant digits)
    assert H7006C.epicyclic_ratio() == pytest.approx(0.4283, abs=5e-5)


def test_epicyclic_ratio_limits() -> None:
    # a vanishing ball rolls like a point: the cage turns at half the inner-ring speed
    assert BearingKinematics(1e-12, DM, ALPHA).epicyclic_ratio() == pytest.approx(0.5, abs=1e-9)
    # the ratio grows with the contact angle (cos falls), towards 1/2 at 90 deg
    angles = np.radians([0.0, 15.0, 25.0, 40.0, 89.0])
    ratios = [H7006C.at_contact_angle(float(a)).epicyclic_ratio() for a in angles]
    assert np.all(np.diff(ratios) > 0.0)
    assert ratios[0] == pytest.approx(0.5 * (1.0 - DW / DM), rel=1e-12)


def test_epicyclic_cage_speed_scalar_and_array() -> None:
    inner = np.array([0.0, 10.0, 94.25, -5.0])
    expected = inner * ratio(DW, DM, ALPHA)
    np.testing.assert_allclose(epicyclic_cage_speed(inner, DW, DM, ALPHA), expected, rtol=1e-14)
    out = epicyclic_cage_speed(100.0, DW, DM, ALPHA)
    assert isinstance(out, float) and out == pytest.approx(100.0 * ratio(DW, DM, ALPHA), rel=1e-14)
    np.testing.assert_allclose(H7006C.cage_speed_epicyclic(inner), expected, rtol=1e-14)


# -- Eq. 11 ----------------------------------------------------------------------------------------
def test_slip_rate_known_values() -> None:
    inner = 2.0 * math.pi * 1500.0 / 60.0
    ns = ratio(DW, DM, ALPHA) * inner
    assert slip_rate(ns, inner, DW, DM, ALPHA) == pytest.approx(0.0, abs=1e-12)
    assert slip_rate(0.0, inner, DW, DM, ALPHA) == pytest.approx(100.0, abs=1e-12)
    assert slip_rate(0.9 * ns, inner, DW, DM, ALPHA) == pytest.approx(10.0, abs=1e-10)
    assert slip_rate(-0.5 * ns, inner, DW, DM, ALPHA) == pytest.approx(150.0, abs=1e-10)
    # a cage faster than pure rolling gives negative slip
    assert slip_rate(1.05 * ns, inner, DW, DM, ALPHA) == pytest.approx(-5.0, abs=1e-10)


def test_slip_rate_arrays_and_broadcast() -> None:
    inner = np.array([50.0, 100.0, 200.0])
    cage = ratio(DW, DM, ALPHA) * inner * np.array([0.97, 0.95, 0.9])
    np.testing.assert_allclose(H7006C.slip_rate(cage, inner), [3.0, 5.0, 10.0], atol=1e-10)
    scalar_inner = H7006C.slip_rate(cage, 100.0)
    assert isinstance(scalar_inner, np.ndarray) and scalar_inner.shape == (3,)
    assert isinstance(H7006C.slip_rate(40.0, 100.0), float)


def test_slip_rate_at_zero_inner_speed_is_an_error() -> None:
    with pytest.raises(AnalysisError, match=r"inner_ring_speed.*> 0.*index 1"):
        H7006C.slip_rate(np.array([1.0, 0.0]), np.array([10.0, 0.0]))
    with pytest.raises(AnalysisError, match="inner_ring_speed"):
        slip_rate(1.0, -3.0, DW, DM, ALPHA)


@pytest.mark.parametrize(
    ("cage", "inner", "message"),
    [
        (np.array([1.0, np.nan]), np.array([2.0, 2.0]), r"cage_speed: non-finite value nan at index 1"),
        (np.array([1.0]), np.array([np.inf]), r"inner_ring_speed: non-finite"),
        (np.array([1.0, 2.0]), np.array([2.0, 2.0, 2.0]), r"lengths differ: cage_speed has 2, inner_ring_speed has 3"),
        (np.array([]), np.array([]), r"cage_speed: needs at least 1 value\(s\), got empty"),
        ("fast", 2.0, r"cage_speed: must be real numbers"),
    ],
)
def test_slip_rate_bad_input(cage: object, inner: object, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        H7006C.slip_rate(cage, inner)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((-1e-3, DM, ALPHA), "ball_diameter: must be > 0"),
        ((DW, DW, ALPHA), "pitch_diameter: must exceed"),
        ((DW, DM, math.pi / 2), r"contact_angle: must be in \[0, pi/2\)"),
        ((DW, DM, -0.1), "contact_angle"),
        ((DW, math.nan, ALPHA), "pitch_diameter: must be finite"),
        ((DW, DM, "15"), "contact_angle: must be a real number"),
    ],
)
def test_bad_geometry(args: tuple, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        BearingKinematics(*args)


# -- from a bearing file ---------------------------------------------------------------------------
def write_bearing(tmp_path, geometry: str):  # type: ignore[no-untyped-def]
    path = tmp_path / "bearing.yaml"
    path.write_text("bearing:\n  name: test\ngeometry:\n" + geometry, encoding="utf-8")
    return path


def test_from_config_reads_si_and_degrees(tmp_path) -> None:  # type: ignore[no-untyped-def]
    path = write_bearing(tmp_path, "  ball_diameter_m: 0.0063\n  pitch_diameter_m: 0.04245\n  contact_angle_deg: 15.0\n")
    kin = BearingKinematics.from_config(path)
    assert kin == BearingKinematics(0.0063, 0.04245, math.radians(15.0))
    assert BearingKinematics.from_config(str(path)).epicyclic_ratio() == pytest.approx(0.4283, abs=5e-5)


@pytest.mark.parametrize(
    ("geometry", "key", "problem"),
    [
        ("  pitch_diameter_m: 0.04245\n  contact_angle_deg: 15.0\n", "geometry.ball_diameter_m", "missing"),
        ("  ball_diameter_m: 0.0063\n  pitch_diameter_m: 0.04245\n  contact_angle_deg: 95\n", "geometry.contact_angle_deg", "< 90"),
        ("  ball_diameter_m: 0.05\n  pitch_diameter_m: 0.04245\n  contact_angle_deg: 15\n", "geometry.pitch_diameter_m", "must exceed"),
        ("  ball_diameter_m: -1\n  pitch_diameter_m: 0.04245\n  contact_angle_deg: 15\n", "geometry.ball_diameter_m", "> 0"),
    ],
)
def test_from_config_errors_name_file_and_key(tmp_path, geometry: str, key: str, problem: str) -> None:  # type: ignore[no-untyped-def]
    path = write_bearing(tmp_path, geometry)
    with pytest.raises(ConfigError) as info:
        BearingKinematics.from_config(path)
    assert info.value.source == str(path)
    assert info.value.key == key
    assert problem in info.value.problem


# -- slip from pulse trains ------------------------------------------------------------------------
def pulse_times(speed_before: float, speed_after: float, t_step: float, strips: list[float], phase: float, t_end: float) -> np.ndarray:
    """Times at which strips at angular positions ``strips`` (fractions of a turn) pass the sensor,
    for a shaft turning at speed_before (rad/s) until t_step and speed_after from then on."""
    turns_at_step = speed_before * t_step / (2.0 * math.pi)
    turns_end = turns_at_step + speed_after * (t_end - t_step) / (2.0 * math.pi)
    times = []
    for m in range(int(turns_end) + 2):
        for f in strips:
            turns = m + f - phase
            if turns < 0.0:
                continue
            if turns <= turns_at_step:
                t = turns * 2.0 * math.pi / speed_before
            else:
                t = t_step + (turns - turns_at_step) * 2.0 * math.pi / speed_after
            if t <= t_end:
                times.append(t)
    return np.sort(np.array(times))


def expected_slip(cage: float, inner: float) -> float:
    return (1.0 - cage / (ratio(DW, DM, ALPHA) * inner)) * 100.0


@pytest.mark.parametrize(
    ("cage_strips", "spindle_strips", "revolutions"),
    [([0.0], [0.0], 1), ([0.0, 0.31, 0.64], [0.0, 0.5], 1), ([0.1], [0.0, 0.25, 0.5, 0.75], 3)],
)
def test_whole_revolution_slip_constant_speeds_exact(cage_strips: list[float], spindle_strips: list[float], revolutions: int) -> None:
    inner = 2.0 * math.pi * 1500.0 / 60.0
    cage = 0.96 * ratio(DW, DM, ALPHA) * inner  # 4 % slip
    # cage strips unevenly placed: whole revolutions make their spacing irrelevant
    cage_t = pulse_times(cage, cage, 0.0, cage_strips, 0.37, 2.0)
    spindle_t = pulse_times(inner, inner, 0.0, spindle_strips, 0.11, 2.05)
    out = whole_revolution_slip(cage_t, len(cage_strips), spindle_t, len(spindle_strips), H7006C, revolutions=revolutions)
    cage_revs = cage * 2.0 / (2.0 * math.pi)
    assert out.slip_pct.size >= int(cage_revs / revolutions) - 2
    np.testing.assert_allclose(out.slip_pct, expected_slip(cage, inner), atol=1e-9)
    np.testing.assert_allclose(out.cage_speed, cage, rtol=1e-11)
    np.testing.assert_allclose(out.inner_ring_speed, inner, rtol=1e-11)
    # window ends are cage pulses, one window per `revolutions` turns
    np.testing.assert_allclose(np.diff(out.end_time), revolutions * 2.0 * math.pi / cage, rtol=1e-9)
    assert np.all(np.isin(out.end_time, cage_t))


def test_whole_revolution_slip_follows_a_step() -> None:
    t_step = 1.0
    inner1, inner2 = 100.0, 150.0
    r = ratio(DW, DM, ALPHA)
    cage1, cage2 = 0.95 * r * inner1, 0.98 * r * inner2  # 5 % then 2 %
    cage_t = pulse_times(cage1, cage2, t_step, [0.0], 0.2, 2.0)
    spindle_t = pulse_times(inner1, inner2, t_step, [0.0, 0.5], 0.0, 2.1)
    out = whole_revolution_slip(cage_t, 1, spindle_t, 2, H7006C)
    start = out.end_time - 2.0 * math.pi / out.cage_speed
    before, after = out.end_time <= t_step, start >= t_step
    straddle = ~before & ~after
    assert before.sum() >= 5 and after.sum() >= 5 and straddle.sum() == 1
    np.testing.assert_allclose(out.slip_pct[before], 5.0, atol=1e-9)
    np.testing.assert_allclose(out.slip_pct[after], 2.0, atol=1e-9)
    # the window across the step mixes the two: its slip lies between them
    assert 2.0 < out.slip_pct[straddle][0] < 5.0


def test_whole_revolution_slip_needs_spindle_coverage() -> None:
    inner, cage = 100.0, 40.0
    cage_t = pulse_times(cage, cage, 0.0, [0.0], 0.0, 3.0)
    spindle_t = pulse_times(inner, inner, 0.0, [0.0], 0.0, 1.0)
    out = whole_revolution_slip(cage_t, 1, spindle_t, 1, H7006C)
    assert out.end_time.size > 0 and np.all(out.end_time <= spindle_t[-1])
    # not one whole cage revolution yet: empty arrays, not an error
    empty = whole_revolution_slip(np.array([0.0, 0.01]), 3, spindle_t, 1, H7006C)
    assert empty.slip_pct.size == 0 and empty.end_time.size == 0


@pytest.mark.parametrize(
    ("cage_t", "cage_strips", "spindle_t", "spindle_strips", "message"),
    [
        ([0.0, 0.2, 0.1], 1, [0.0, 0.1, 0.2], 1, r"cage_pulse_times: must increase strictly.*\[2\]"),
        ([0.0, 0.1], 1, [0.0, 0.0], 1, r"spindle_pulse_times: must increase strictly"),
        ([0.0], 1, [0.0, 0.1], 1, r"cage_pulse_times: needs at least 2"),
        ([0.0, 0.1], 0, [0.0, 0.1], 1, r"cage_strips: must be an integer >= 1"),
        ([0.0, 0.1], 1, [0.0, 0.1], 1.5, r"spindle_strips: must be an integer >= 1"),
        ([0.0, np.nan], 1, [0.0, 0.1], 1, r"cage_pulse_times: non-finite"),
    ],
)
def test_whole_revolution_slip_bad_input(cage_t: list, cage_strips: object, spindle_t: list, spindle_strips: object, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        whole_revolution_slip(np.array(cage_t), cage_strips, np.array(spindle_t), spindle_strips, H7006C)  # type: ignore[arg-type]


# -- the loaded contact angle (Harris's thrust equilibrium) ------------------------------------
def _hamrock_brewe_stiffness(rx: float, ry: float, e_prime: float) -> float:
    """K of Q = K delta^1.5 from Hamrock and Brewe's approximations (J. Lubr. Technol. 105:171,
    1983): k = 1.0339 (Ry/Rx)^0.636, E = 1.0003 + 0.5968 Rx/Ry, F = 1.5277 + 0.6023 ln(Ry/Rx),
    delta = F (9/(2 E R) (Q/(pi k E'))^2)^(1/3) with 1/R = 1/Rx + 1/Ry."""
    k = 1.0339 * (ry / rx) ** 0.636
    e_int = 1.0003 + 0.5968 * rx / ry
    f_int = 1.5277 + 0.6023 * math.log(ry / rx)
    r = 1.0 / (1.0 / rx + 1.0 / ry)
    coef = f_int * (9.0 / (2.0 * e_int * r) / (math.pi * k * e_prime) ** 2) ** (1.0 / 3.0)  # delta = coef Q^(2/3)
    return coef**-1.5


def _hand_loaded_angle(axial_load: float) -> float:
    """H7006C (config/bearings/h7006c.yaml: Dw 6.3 mm, dm 42.45 mm, Z 16, a0 15 deg, f_i 0.52,
    f_o 0.53, steel E 208 GPa, nu 0.3), solved by bisection, degrees."""
    dw, dm, z, a0, fi, fo = 6.3e-3, 42.45e-3, 16, math.radians(15.0), 0.52, 0.53
    e_prime = 208e9 / (1.0 - 0.3**2)
    gamma = dw * math.cos(a0) / dm
    k_i = _hamrock_brewe_stiffness(0.5 * dw * (1.0 - gamma), fi * dw / (2.0 * fi - 1.0), e_prime)
    k_o = _hamrock_brewe_stiffness(0.5 * dw * (1.0 + gamma), fo * dw / (2.0 * fo - 1.0), e_prime)
    k_n = (k_i ** (-2.0 / 3.0) + k_o ** (-2.0 / 3.0)) ** -1.5
    rhs = axial_load / (z * k_n * ((fi + fo - 1.0) * dw) ** 1.5)
    lo, hi = a0, math.radians(60.0)
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if math.sin(mid) * (math.cos(a0) / math.cos(mid) - 1.0) ** 1.5 > rhs:
            hi = mid
        else:
            lo = mid
    return math.degrees(0.5 * (lo + hi))


def test_loaded_contact_angle_against_a_hand_calculation() -> None:
    """The issue's figures for the shipped bearing, 16.3 deg at 100 N and 18.9 deg at 700 N,
    recomputed here with Hamrock-Brewe's approximate Hertz constants (within 0.05 deg of them),
    and the module's elliptic-integral solution within 0.05 deg of the hand calculation."""
    from bearing_rig_sim.analysis.slip import ThrustContact
    from bearing_rig_sim.config import config_path

    thrust = ThrustContact.from_config(config_path("bearings", "h7006c.yaml"))
    assert _hand_loaded_angle(100.0) == pytest.approx(16.3, abs=0.05)
    assert _hand_loaded_angle(700.0) == pytest.approx(18.9, abs=0.06)
    for load in (50.0, 100.0, 200.0, 400.0, 700.0):
        assert math.degrees(thrust.loaded_contact_angle(load)) == pytest.approx(_hand_loaded_angle(load), abs=0.05)
    assert thrust.loaded_contact_angle(0.0) == pytest.approx(math.radians(15.0))
    assert math.isnan(thrust.loaded_contact_angle(math.nan))
