"""Validation of a simulation clock read from outside (``/clock``): no ROS in here.

Any node on the graph can publish ``/clock``. One message stamped far in the future would
otherwise move every follower's time there for good (a session waits for it, a bag's timeline
jumps, a replay would wait as long); one stamped before 1970 makes rclpy raise in the middle of
a node's spin. A :class:`ClockGuard` sits between the topic and whatever follows it:

* a negative stamp is refused;
* a stamp that moves the clock back, or forward by more than ``max_step_ns`` from the last
  accepted one, is refused, unless ``confirmations`` stamps in a row continue the new timeline
  without such a jump (a restarted simulator, whose clock starts again from 0): then the jump is
  accepted, and reported as a jump;
* everything else is accepted.

Refusals are counted and described in one line each, for the caller to report (a log line, a
fault on ``/diagnostics``, a note in the session's summary); none of them raises.
"""

from __future__ import annotations

from dataclasses import dataclass

from bearing_rig_sim.interfaces import CLOCK

__all__ = ["DEFAULT_CONFIRMATIONS", "DEFAULT_MAX_STEP_NS", "ClockGuard", "ClockVerdict"]

DEFAULT_MAX_STEP_NS: int = 10_000_000_000
"""Largest forward step between two accepted stamps, ns: 10 s. The simulator publishes one
``/clock`` per 1 ms chunk; a replay one per recorded ``/clock``; only a gap in the publisher of
more than 10 s of sim time exceeds it, and that is confirmed after a few stamps anyway."""

DEFAULT_CONFIRMATIONS: int = 20
"""Stamps in a row that must continue a new timeline before a jump is accepted: 20 ms of a
simulator's clock, far more than a stray publisher sends by accident."""


@dataclass(frozen=True)
class ClockVerdict:
    """What the guard made of one stamp."""

    accepted: bool
    """Follow this stamp."""
    note: str = ""
    """One line for the log when the stamp was refused, or accepted as a confirmed jump; empty
    for an ordinary accepted stamp."""


class ClockGuard:
    """Checks each stamp of a clock against the ones accepted before (see the module docs).

    Args:
        max_step_ns: largest forward step accepted without confirmation, ns (> 0).
        confirmations: stamps in a row that confirm a jump (>= 1).
        name: what the clock is, for the notes (e.g. ``"/clock"``).

    Raises:
        ValueError: an argument out of range.
    """

    def __init__(self, *, max_step_ns: int = DEFAULT_MAX_STEP_NS, confirmations: int = DEFAULT_CONFIRMATIONS, name: str = CLOCK.name) -> None:
        if isinstance(max_step_ns, bool) or not isinstance(max_step_ns, int) or max_step_ns <= 0:
            raise ValueError(f"max_step_ns: must be a positive integer, got {max_step_ns!r}")
        if isinstance(confirmations, bool) or not isinstance(confirmations, int) or confirmations < 1:
            raise ValueError(f"confirmations: must be an integer >= 1, got {confirmations!r}")
        self.max_step_ns = max_step_ns
        self.confirmations = confirmations
        self.name = name
        self.last_ns: int | None = None
        """The last accepted stamp, ns; None before the first."""
        self.refused = 0
        """Stamps refused so far."""
        self.jumps = 0
        """Jumps accepted after confirmation so far."""
        self._candidate_ns: int | None = None
        self._candidate_count = 0

    def _continues(self, previous: int | None, stamp_ns: int) -> bool:
        return previous is not None and 0 <= stamp_ns - previous <= self.max_step_ns

    def check(self, stamp_ns: int) -> ClockVerdict:
        """Accept or refuse one stamp (ns); the guard's state follows the accepted ones."""
        if stamp_ns < 0:
            self.refused += 1
            return ClockVerdict(False, f"{self.name}: refused a negative stamp ({stamp_ns * 1e-9:.9g} s)")
        if self.last_ns is None or self._continues(self.last_ns, stamp_ns):
            self.last_ns = stamp_ns
            self._candidate_ns, self._candidate_count = None, 0
            return ClockVerdict(True)
        if self._continues(self._candidate_ns, stamp_ns):
            self._candidate_count += 1
        else:
            self._candidate_count = 1
        self._candidate_ns = stamp_ns
        if self._candidate_count >= self.confirmations:
            previous = self.last_ns
            self.last_ns = stamp_ns
            self._candidate_ns, self._candidate_count = None, 0
            self.jumps += 1
            return ClockVerdict(
                True,
                f"{self.name}: jumped from {previous * 1e-9:.9g} s to {stamp_ns * 1e-9:.9g} s (confirmed by {self.confirmations} stamps in a row)",
            )
        self.refused += 1
        direction = "back" if stamp_ns < self.last_ns else "ahead"
        return ClockVerdict(
            False,
            f"{self.name}: refused a stamp of {stamp_ns * 1e-9:.9g} s, {abs(stamp_ns - self.last_ns) * 1e-9:.9g} s "
            f"{direction} of the last accepted {self.last_ns * 1e-9:.9g} s",
        )
