"""Quality-of-service profiles a recorded topic was offered with.

A bag stores, per topic, the QoS its publisher offered (rosbag2 ``offered_qos_profiles``), so that
a replay can offer the same again. The named profiles are the ones of the interface contract
(``docs/interfaces.md``, :data:`bearing_rig_sim.interfaces.QOS_DESCRIPTIONS`):

* ``"reliable"``: reliable, volatile, keep last 10 (commands, states, diagnostics);
* ``"reliable_stream"``: reliable, volatile, keep last 5000 (the twin's streams: ``/clock``,
  pulses, speeds, truth, the force on the bearing);
* ``"sensor_data"``: best effort, volatile, keep last 100 (load cell);
* ``"transient_local"``: reliable, transient local, keep last 10 (latched: spindle command, slip
  status).

Deadline, lifespan and liveliness lease are stored as 0 s, the middleware's "default" (none).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

from bearing_rig_sim.bags.errors import BagError

Reliability = Literal["reliable", "best_effort"]
Durability = Literal["volatile", "transient_local"]
History = Literal["keep_last", "keep_all"]


@dataclass(frozen=True)
class QosSpec:
    """The QoS a publisher offered on a topic.

    Attributes:
        reliability: ``"reliable"`` or ``"best_effort"``.
        durability: ``"volatile"`` or ``"transient_local"`` (late joiners get the last messages).
        depth: history depth (messages), >= 1 for ``keep_last``.
        history: ``"keep_last"`` or ``"keep_all"``.
    """

    reliability: Reliability = "reliable"
    durability: Durability = "volatile"
    depth: int = 10
    history: History = "keep_last"

    def __post_init__(self) -> None:
        if self.reliability not in ("reliable", "best_effort"):
            raise BagError(f"QoS reliability must be 'reliable' or 'best_effort', got {self.reliability!r}")
        if self.durability not in ("volatile", "transient_local"):
            raise BagError(f"QoS durability must be 'volatile' or 'transient_local', got {self.durability!r}")
        if self.history not in ("keep_last", "keep_all"):
            raise BagError(f"QoS history must be 'keep_last' or 'keep_all', got {self.history!r}")
        if not isinstance(self.depth, int) or self.depth < 0 or (self.history == "keep_last" and self.depth < 1):
            raise BagError(f"QoS depth must be an integer >= 1 with keep_last, got {self.depth!r}")

    def to_rosbags(self) -> Qos:
        """The same profile as a rosbags :class:`~rosbags.interfaces.Qos` (as stored in bags)."""
        zero = QosTime(0, 0)
        return Qos(
            QosHistory[self.history.upper()],
            self.depth,
            QosReliability[self.reliability.upper()],
            QosDurability[self.durability.upper()],
            zero,
            zero,
            QosLiveliness.SYSTEM_DEFAULT,
            zero,
            False,
        )

    @classmethod
    def from_rosbags(cls, qos: Qos) -> QosSpec | None:
        """The profile stored in a bag, or None when it uses values this project does not offer
        (system default, best available, unknown)."""
        try:
            return cls(
                reliability=qos.reliability.name.lower(),  # type: ignore[arg-type]  # an enum name checked by QosSpec itself
                durability=qos.durability.name.lower(),  # type: ignore[arg-type]  # an enum name checked by QosSpec itself
                depth=int(qos.depth),
                history=qos.history.name.lower(),  # type: ignore[arg-type]  # an enum name checked by QosSpec itself
            )
        except BagError:
            return None


QOS_PROFILES: dict[str, QosSpec] = {
    "reliable": QosSpec("reliable", "volatile", 10),
    "reliable_stream": QosSpec("reliable", "volatile", 5000),
    "sensor_data": QosSpec("best_effort", "volatile", 100),
    "transient_local": QosSpec("reliable", "transient_local", 10),
}
"""The named profiles of the interface contract."""


def qos_spec(qos: str | QosSpec) -> QosSpec:
    """Resolve a profile name (a key of :data:`QOS_PROFILES`) or pass a :class:`QosSpec` through.

    Raises:
        BagError: unknown profile name.
    """
    if isinstance(qos, QosSpec):
        return qos
    try:
        return QOS_PROFILES[qos]
    except (KeyError, TypeError):
        raise BagError(f"unknown QoS profile {qos!r}: use one of {', '.join(QOS_PROFILES)} or a QosSpec") from None
