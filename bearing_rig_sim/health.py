"""The health vocabulary every node core reports on ``/diagnostics``: one level enum and one
value type, shared by the simulator, the load controller and the monitor.

Each core assesses its own health (the simulator's rules: :class:`~bearing_rig_sim.simulation.health.
SimulatorHealth`; the load controller's: ``AxialLoadOperation.health``) and returns a
:class:`Health`; the node shells map :class:`HealthLevel` one to one onto
``diagnostic_msgs/DiagnosticStatus`` levels.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class HealthLevel(IntEnum):
    """Levels of ``diagnostic_msgs/DiagnosticStatus`` (OK 0, WARN 1, ERROR 2)."""

    OK = 0
    WARN = 1
    ERROR = 2


@dataclass(frozen=True)
class Health:
    """A level and the reasons for it (empty when OK)."""

    level: HealthLevel
    reasons: tuple[str, ...]
    """Why the level is what it is, or, at OK, what the component is doing (may be empty)."""

    @property
    def message(self) -> str:
        """One line for the diagnostics' message."""
        return "; ".join(self.reasons) if self.reasons else "running"
