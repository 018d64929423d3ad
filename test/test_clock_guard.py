"""The clock guard: negative and far-jumping stamps refused, a restarted clock followed once
confirmed, nothing raised (no ROS)."""

from __future__ import annotations

import pytest

from bearing_rig_sim.clock_guard import ClockGuard

MS = 1_000_000
S = 1_000_000_000


def feed(guard: ClockGuard, stamps: list[int]) -> list[bool]:
    return [guard.check(t).accepted for t in stamps]


def test_a_steady_clock_is_accepted_including_repeats() -> None:
    guard = ClockGuard()
    assert all(feed(guard, [0, MS, 2 * MS, 2 * MS, 3 * MS]))
    assert guard.last_ns == 3 * MS and guard.refused == 0


def test_negative_stamp_is_refused_and_described() -> None:
    guard = ClockGuard()
    feed(guard, [0, MS])
    verdict = guard.check(-5 * S)
    assert not verdict.accepted
    assert verdict.note == "/clock: refused a negative stamp (-5 s)"
    assert guard.last_ns == MS and guard.refused == 1
    assert guard.check(2 * MS).accepted


def test_one_far_future_stamp_is_refused_and_the_clock_goes_on() -> None:
    # the audit's case: one stamp at 2^31 s in a 1 kHz clock
    guard = ClockGuard()
    feed(guard, [t * MS for t in range(100)])
    verdict = guard.check(2**31 * S)
    assert not verdict.accepted and "ahead of the last accepted 0.099 s" in verdict.note
    assert all(feed(guard, [t * MS for t in range(100, 200)]))
    assert guard.last_ns == 199 * MS and guard.refused == 1 and guard.jumps == 0


def test_a_single_stamp_back_is_refused() -> None:
    guard = ClockGuard()
    feed(guard, [10 * S, 10 * S + MS])
    verdict = guard.check(3 * S)
    assert not verdict.accepted and "back of the last accepted" in verdict.note
    assert guard.check(10 * S + 2 * MS).accepted


def test_a_restarted_clock_is_followed_after_the_confirmations() -> None:
    guard = ClockGuard(confirmations=5)
    feed(guard, [t * MS + 50 * S for t in range(10)])
    restart = feed(guard, [t * MS for t in range(8)])
    # the first 4 stamps of the new timeline are refused, the 5th confirms the jump
    assert restart == [False] * 4 + [True] * 4
    assert guard.jumps == 1 and guard.refused == 4 and guard.last_ns == 7 * MS


def test_an_interrupted_candidate_timeline_starts_over() -> None:
    guard = ClockGuard(confirmations=3)
    feed(guard, [0, MS])
    # two stamps far ahead, then a step far back from the candidate: the count restarts
    assert feed(guard, [100 * S, 100 * S + MS, 50 * S, 50 * S + MS]) == [False] * 4
    assert guard.check(50 * S + 2 * MS).accepted  # third in a row of the 50 s timeline


def test_the_step_limit_is_inclusive() -> None:
    guard = ClockGuard(max_step_ns=10 * S)
    assert feed(guard, [0, 10 * S, 20 * S + 1]) == [True, True, False]


@pytest.mark.parametrize("kwargs", [{"max_step_ns": 0}, {"max_step_ns": 1.5}, {"confirmations": 0}, {"confirmations": True}])
def test_bad_arguments_are_refused(kwargs: dict[str, object]) -> None:
    with pytest.raises(ValueError):
        ClockGuard(**kwargs)  # type: ignore[arg-type]
