"""The real-time pacer's arithmetic on a fake wall clock: due chunks, overruns, resyncs, the
achieved real-time factor, and the as-fast-as-possible mode."""

from __future__ import annotations

import math

import pytest

from bearing_rig_sim.simulation.pacing import PacerError, RealTimePacer


class FakeClock:
    """A wall clock the test moves by hand (s)."""

    def __init__(self, start: float = 1000.0) -> None:
        self.now = start

    def __call__(self) -> float:
        return self.now


OPTIONS: dict[str, object] = {"loop_period": 1e-3, "realtime": True, "rate": 1.0, "overrun_margin": 5e-3, "rtf_window": 1.0, "max_batch": 50, "resync_lag": 0.5}
"""The test's own pacer: 1 ms loop, 5 ms margin, batches of 50 (the arithmetic below is worked for these)."""


def pacer(clock: FakeClock, **options: object) -> RealTimePacer:
    return RealTimePacer(1e-3, clock=clock, **(OPTIONS | options))  # type: ignore[arg-type]


def test_due_chunks_follow_the_wall_clock():
    clock = FakeClock()
    p = pacer(clock)
    p.start(2.0)
    assert p.due_chunks(2.0) == 0
    clock.now += 0.0035  # 3.5 ms later: three whole chunks are due
    assert p.due_chunks(2.0) == 3
    clock.now += 0.0006  # 4.1 ms: the simulation ran its three chunks, one more is due
    assert p.due_chunks(2.003) == 1
    assert p.due_chunks(2.004) == 0
    assert p.lag(2.004) == pytest.approx(0.0001)
    assert p.next_due_in(2.004) == pytest.approx(0.0009)
    assert p.overruns == 0


def test_rate_scales_the_simulated_time():
    clock = FakeClock()
    p = pacer(clock, rate=2.0)
    p.start(0.0)
    clock.now += 0.010
    assert p.target() == pytest.approx(0.020)
    assert p.due_chunks(0.0) == 20
    assert p.lag(0.0) == pytest.approx(0.010)  # wall seconds


def test_batches_are_capped():
    clock = FakeClock()
    p = pacer(clock, max_batch=4, overrun_margin=1.0)
    p.start(0.0)
    clock.now += 0.1
    assert p.due_chunks(0.0) == 4
    assert p.due_chunks(0.004) == 4


def test_a_call_later_than_one_period_plus_the_margin_is_an_overrun():
    clock = FakeClock()
    p = pacer(clock)  # period 1 ms, margin 5 ms
    p.start(0.0)
    clock.now += 0.0059  # 5.9 ms behind: within period + margin
    p.due_chunks(0.0)
    assert (p.overruns, p.behind) == (0, False)
    clock.now += 0.0002  # 6.1 ms behind
    p.due_chunks(0.0)
    assert (p.overruns, p.behind) == (1, True)
    p.due_chunks(0.0)  # still behind at the next call: a second overrun
    assert p.overruns == 2
    p.due_chunks(0.006)  # caught up
    assert (p.overruns, p.behind) == (2, False)


def test_a_large_debt_is_dropped_and_counted_as_a_resync():
    clock = FakeClock()
    p = pacer(clock)
    p.start(0.0)
    clock.now += 0.8  # a stall of 0.8 s > resync_lag 0.5 s
    assert p.due_chunks(0.010) == 1
    assert (p.resyncs, p.overruns) == (1, 1)
    assert p.target() == pytest.approx(0.010)  # re-anchored at the simulation's time
    clock.now += 0.002
    assert p.due_chunks(0.011) == 1


def test_as_fast_as_possible_gives_full_batches_and_no_overruns():
    clock = FakeClock()
    p = pacer(clock, realtime=False, max_batch=20)
    p.start(0.0)
    clock.now += 10.0
    assert p.due_chunks(0.0) == 20
    assert (p.overruns, p.lag(0.0), p.next_due_in(0.0)) == (0, 0.0, 0.0)


def test_real_time_factor_over_a_sliding_window():
    clock = FakeClock()
    p = pacer(clock, rtf_window=1.0)
    p.start(0.0)
    assert math.isnan(p.real_time_factor)
    sim = 0.0
    for _ in range(100):  # 1 s of wall time at twice real time
        clock.now += 0.01
        sim += 0.02
        p.record(sim)
    assert p.real_time_factor == pytest.approx(2.0)
    for _ in range(300):  # then 3 s at half real time: the window forgets the fast second
        clock.now += 0.01
        sim += 0.005
        p.record(sim)
    assert p.real_time_factor == pytest.approx(0.5, rel=0.02)


def test_bad_options_and_calls_before_start_are_refused():
    clock = FakeClock()
    for bad in ({"rate": 0.0}, {"overrun_margin": -1.0}, {"max_batch": 0}, {"rtf_window": math.nan}, {"loop_period": 0.0}):
        with pytest.raises(PacerError):
            pacer(clock, **bad)
    with pytest.raises(PacerError, match="chunk"):
        RealTimePacer(0.0, clock=clock, **OPTIONS)  # type: ignore[arg-type]
    with pytest.raises(PacerError, match="start"):
        pacer(clock).due_chunks(0.0)


# -- StreamLead: the simulation kept within a lead of a stream that follows its clock -------------
from bearing_rig_sim.simulation.pacing import StreamLead  # noqa: E402


def test_a_stream_that_follows_the_clock_bounds_the_simulation_by_its_lead():
    lead = StreamLead("monitor status", 0.5)
    assert lead.room(10.0, 1e-3, 0.0) is None and "no monitor status" in lead.off  # nothing seen yet
    lead.observe(9.9, 10.0, 0.0)
    assert lead.room(10.0, 1e-3, 0.0) is None  # one stamp: not yet advancing
    lead.observe(10.0, 10.2, 0.1)
    # at most 10.0 + 0.5 s: from 10.2 s, 300 chunks of 1 ms and not one more
    assert lead.room(10.2, 1e-3, 0.1) == 300 and lead.off == ""
    assert lead.room(10.5, 1e-3, 0.1) == 0
    assert lead.room(10.6, 1e-3, 0.1) == 0  # never negative


def test_stamps_far_from_the_simulated_time_do_not_pace():
    lead = StreamLead("force on the bearing", 0.1, follow_s=1.0)
    lead.observe(1.0, 1.0, 0.0)
    lead.observe(1.001, 5.0, 0.0)  # 4 s behind when taken: not a stream that follows the clock
    assert lead.room(5.0, 1e-3, 0.0) is None
    assert lead.off == "force on the bearing stamped 1.001 s, more than 1 s from the simulated time 5.000 s"
    lead.observe(5.0, 5.0, 0.0)  # advancing and near the simulated time: paces from here
    lead.observe(5.0, 5.05, 0.0)  # the same stamp again: nothing new, the hold stays where it was
    assert lead.room(5.05, 1e-3, 0.0) == 50  # (5.0 + 0.1 - 5.05) / 1e-3: a repeated stamp releases nothing


def test_the_reason_a_stream_stops_pacing_is_the_latest_one():
    lead = StreamLead("session progress", 2.0, follow_s=30.0)
    lead.stop("no publisher of /rig/session/progress")
    lead.observe(1.8e9, 5.0, 0.0)  # a publisher on another clock: the reason is no longer "no publisher"
    assert lead.room(5.0, 1e-3, 0.0) is None and "stamped 1800000000.000 s" in lead.off
    lead.observe(5.0, 5.0, 0.0)
    lead.observe(5.1, 5.1, 0.0)
    assert lead.room(5.1, 1e-3, 0.0) == 2000 and lead.off == ""
    lead.observe(4.0, 5.1, 0.0)  # a restarted publisher: back by 1.1 s, within the follow window
    assert lead.room(5.1, 1e-3, 0.0) is None and lead.off == "session progress went back to 4.000 s from 5.100 s"
    lead.stop("/session left the active state (inactive)", paused=True)
    lead.observe(1.8e9, 5.1, 0.0)  # while paused, the pause is the reason that stands
    assert lead.room(5.1, 1e-3, 0.0) is None and "left the active state" in lead.off


def test_a_paused_or_silent_stream_stops_pacing_until_it_advances_again():
    lead = StreamLead("monitor status", 0.5, silent_s=10.0)
    lead.observe(1.0, 1.0, 0.0)
    lead.observe(1.1, 1.1, 0.0)
    assert lead.room(1.1, 1e-3, 5.0) == 500
    assert lead.room(1.1, 1e-3, 10.5) is None and "10 s of wall time" in lead.off  # silent
    lead.observe(1.2, 1.2, 11.0)
    lead.observe(1.3, 1.3, 11.0)
    assert lead.room(1.3, 1e-3, 11.0) == 500
    lead.stop("/monitor left the active state (inactive)", paused=True)
    lead.observe(1.4, 1.4, 11.0)
    lead.observe(1.5, 1.5, 11.0)  # queued before the deactivation
    assert lead.room(1.5, 1e-3, 11.0) is None and "left the active state" in lead.off
    lead.paused = False  # active again
    lead.observe(1.6, 1.6, 11.0)
    assert lead.room(1.6, 1e-3, 11.0) == 500


def test_an_idle_source_releases_the_simulation_and_says_why_until_it_is_busy_again():
    lead = StreamLead("monitor status", 0.5)
    lead.observe(1.0, 1.0, 0.0)
    lead.observe(1.1, 1.1, 0.0)
    assert lead.room(1.1, 1e-3, 0.0, idle="the rig at rest") is None and lead.off == "the rig at rest"
    # the stream's state is kept: busy again, the same bound as before (1.1 + 0.5 - 1.1 s in 1 ms chunks)
    assert lead.room(1.1, 1e-3, 0.0) == 500 and lead.off == ""


def test_a_stream_lead_refuses_a_lead_that_is_not_positive():
    with pytest.raises(PacerError, match="lead_s"):
        StreamLead("x", 0.0)
