"""The QoS a recorded topic was offered with (rosbag2 ``offered_qos_profiles``), so that a replay
offers it again. The named profiles are the contract's (:data:`bearing_rig_sim.interfaces.QOS_TABLE`);
deadline, lifespan and liveliness lease are stored as 0 s, the middleware's default (none)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, get_args

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime

from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.interfaces import QOS_TABLE, Durability, QosName, Reliability

History = Literal["keep_last", "keep_all"]


@dataclass(frozen=True)
class QosSpec:
    """The QoS a publisher offered on a topic (depth >= 1 with ``keep_last``); BagError for a value
    outside the literals."""

    reliability: Reliability = "reliable"
    durability: Durability = "volatile"
    depth: int = 10
    history: History = "keep_last"

    def __post_init__(self) -> None:
        for name, allowed in (("reliability", Reliability), ("durability", Durability), ("history", History)):
            if getattr(self, name) not in get_args(allowed):
                raise BagError(f"QoS {name} must be {' or '.join(map(repr, get_args(allowed)))}, got {getattr(self, name)!r}")
        if not isinstance(self.depth, int) or self.depth < 0 or (self.history == "keep_last" and self.depth < 1):
            raise BagError(f"QoS depth must be an integer >= 1 with keep_last, got {self.depth!r}")

    def to_rosbags(self) -> Qos:
        """The same profile as a rosbags :class:`~rosbags.interfaces.Qos` (as stored in bags)."""
        zero = QosTime(0, 0)
        history, reliability, durability = QosHistory[self.history.upper()], QosReliability[self.reliability.upper()], QosDurability[self.durability.upper()]
        return Qos(history, self.depth, reliability, durability, zero, zero, QosLiveliness.SYSTEM_DEFAULT, zero, False)

    @classmethod
    def from_rosbags(cls, qos: Qos) -> QosSpec | None:
        """The profile stored in a bag; None for values this project does not offer (system default...)."""
        names = (qos.reliability.name.lower(), qos.durability.name.lower(), int(qos.depth), qos.history.name.lower())
        try:
            return cls(*names)  # type: ignore[arg-type]  # enum names, checked by QosSpec itself
        except BagError:
            return None


QOS_PROFILES: dict[str, QosSpec] = {name: QosSpec(QOS_TABLE[name].reliability, QOS_TABLE[name].durability, QOS_TABLE[name].depth) for name in get_args(QosName)}
"""The contract's named profiles, as stored in a bag."""


def qos_spec(qos: str | QosSpec) -> QosSpec:
    """The profile of a name of :data:`QOS_PROFILES` (BagError for another), or a :class:`QosSpec` as is."""
    if isinstance(qos, QosSpec):
        return qos
    try:
        return QOS_PROFILES[qos]
    except (KeyError, TypeError):
        raise BagError(f"unknown QoS profile {qos!r}: use one of {', '.join(QOS_PROFILES)} or a QosSpec") from None
