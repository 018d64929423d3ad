"""The simulator's health for /diagnostics: OK, WARN (overruns, raised load), ERROR (refused input,
diverged engine), with the reasons.

* ERROR while the engine has diverged (for good: the twin cannot continue), and for
  ``fault_hold`` seconds after the latest refused spindle command or axial force (so that a reader
  at 1 Hz sees a refusal even when valid messages follow at once).
* WARN while the loop has overrun since the previous report, or while the axial force asked
  for is below the engine's minimum and has been raised to it.
* OK otherwise.

Times are the wall clock's (s), given by the caller.
"""

from __future__ import annotations

from collections.abc import Iterable

from bearing_rig_sim.health import Health, HealthLevel

__all__ = ["STOPPED_KEY", "Health", "HealthLevel", "SimulatorHealth", "stopped_reason"]

STOPPED_KEY = "simulation_stopped"
"""Key of the simulator's diagnostic values that says why the simulation stopped for good
(a diverged engine); empty while it runs. A session ends on it (exit status 1)."""


def stopped_reason(values: Iterable[tuple[str, str]]) -> str:
    """Why the simulation stopped, from a diagnostic status's (key, value) pairs; "" if it runs."""
    return next((value for key, value in values if key == STOPPED_KEY and value), "")


class SimulatorHealth:
    """Tracks refusals, divergence and overruns (see the module docstring).

    Args:
        fault_hold: how long a refusal keeps the level at ERROR, s (>= 0).
    """

    def __init__(self, fault_hold: float) -> None:
        self.fault_hold = float(fault_hold)
        self._refusals: dict[str, tuple[float, str]] = {}
        self.halted = ""
        """Why the simulation stopped for good (empty while it runs)."""
        self.refused = 0
        """Inputs refused since the start (1)."""
        self._reported_overruns = 0
        self.reader_stalls = 0
        """Times (without real time) the loop stopped waiting for a reliable reader that
        acknowledged nothing for the give-up time, and went on without it."""
        self._stalled = ""
        self._reported_stalls = 0

    def refuse(self, kind: str, reason: str, now: float) -> None:
        """Note a refused input of ``kind`` (e.g. "spindle command", "axial force") at ``now``."""
        self._refusals[kind] = (now, f"{kind} refused: {reason}")
        self.refused += 1

    def halt(self, reason: str) -> None:
        """Note that the simulation stopped for good (diverged engine)."""
        self.halted = reason

    def reader_stalled(self, what: str) -> None:
        """Note that the loop went on without the acknowledgement of a reliable reader (``what``
        names the topics still unacknowledged and for how long)."""
        self.reader_stalls += 1
        self._stalled = what

    def assess(self, now: float, overruns: int, load_clamped: bool, min_load: float) -> Health:
        """The health at ``now`` given the loop's overrun count so far and the load flag.

        Overruns counted since the latest :meth:`reported` make WARN.
        """
        errors = [f"simulation stopped: {self.halted}"] if self.halted else []
        for kind, (when, reason) in list(self._refusals.items()):
            if now - when > self.fault_hold:
                del self._refusals[kind]
            else:
                errors.append(reason)
        if errors:
            return Health(HealthLevel.ERROR, tuple(errors))
        warnings = []
        new = overruns - self._reported_overruns
        if new > 0:
            warnings.append(f"{new} overrun(s): the loop fell behind the wall clock")
        if self.reader_stalls > self._reported_stalls:
            warnings.append(f"went on without a reliable reader: {self._stalled}")
        if load_clamped:
            warnings.append(f"axial force below the engine's minimum; {min_load:g} N applied")
        if warnings:
            return Health(HealthLevel.WARN, tuple(warnings))
        return Health(HealthLevel.OK, ())

    def reported(self, overruns: int) -> None:
        """The periodic report went out with this overrun count: later ones are new."""
        self._reported_overruns = overruns
        self._reported_stalls = self.reader_stalls
