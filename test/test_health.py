"""The simulator's health for /diagnostics: which inputs make OK, WARN and ERROR, and for how long."""

from __future__ import annotations

from bearing_rig_sim.health import HealthLevel
from bearing_rig_sim.simulation.health import SimulatorHealth


def test_ok_when_nothing_is_wrong():
    health = SimulatorHealth(fault_hold=2.0).assess(10.0, overruns=0, load_clamped=False, min_load=1.0)
    assert (health.level, health.reasons, health.message) == (HealthLevel.OK, (), "running")


def test_a_refusal_is_an_error_for_the_hold_time_then_clears():
    h = SimulatorHealth(fault_hold=2.0)
    h.refuse("spindle command", "target_speed: must be finite, got nan", now=100.0)
    at = h.assess(101.9, 0, False, 1.0)
    assert at.level is HealthLevel.ERROR
    assert at.message == "spindle command refused: target_speed: must be finite, got nan"
    assert h.assess(102.1, 0, False, 1.0).level is HealthLevel.OK
    assert h.refused == 1


def test_a_new_refusal_restarts_the_hold_and_several_kinds_are_listed():
    h = SimulatorHealth(fault_hold=2.0)
    h.refuse("axial force", "nan", now=0.0)
    h.refuse("axial force", "nan", now=1.5)
    h.refuse("spindle command", "acceleration: must be > 0", now=1.5)
    at = h.assess(3.0, 0, False, 1.0)
    assert at.level is HealthLevel.ERROR and len(at.reasons) == 2
    assert h.assess(3.6, 0, False, 1.0).level is HealthLevel.OK


def test_a_diverged_engine_is_an_error_for_good():
    h = SimulatorHealth(fault_hold=0.0)
    h.halt("dynamics diverged (non-finite state)")
    assert h.assess(1e6, 0, False, 1.0).reasons == ("simulation stopped: dynamics diverged (non-finite state)",)


def test_overruns_warn_until_reported_and_a_raised_load_warns_while_it_lasts():
    h = SimulatorHealth(fault_hold=2.0)
    at = h.assess(0.0, overruns=3, load_clamped=False, min_load=1.0)
    assert at.level is HealthLevel.WARN and "3 overrun(s)" in at.message
    h.reported(3)
    assert h.assess(0.5, overruns=3, load_clamped=False, min_load=1.0).level is HealthLevel.OK
    assert "1 overrun(s)" in h.assess(0.6, overruns=4, load_clamped=False, min_load=1.0).message
    h.reported(4)
    clamped = h.assess(0.7, overruns=4, load_clamped=True, min_load=1.0)
    assert clamped.level is HealthLevel.WARN and "1 N applied" in clamped.message
    h.refuse("axial force", "got -3.0", now=0.7)
    assert h.assess(0.8, overruns=9, load_clamped=True, min_load=1.0).level is HealthLevel.ERROR  # error wins
