"""What every bench instrument is: its settings block, what it is shown of the rig each chunk, and
what it gives back.

An instrument is read from one block of the rig file's ``sensors`` section. Every block names
its ``kind`` (a class registered in :mod:`bearing_rig_sim.instruments.registry`), the contract
``topic`` it is published on (:mod:`bearing_rig_sim.interfaces`) and the rig quantity it
``measures`` (a name the twin offers: :data:`SHAFT_ANGLES`, ``friction_torque``, or
``<node>_temperature`` for a node of the bearing's thermal network); the rest of the block is
the model's own parameters, each a number with its unit, plausible range and source.

Each chunk the twin calls :meth:`Instrument.observe` with the chunk's start and end times and a
:class:`Measurand` giving the measured quantity at either end; the instrument returns its
readings (none, one, or many, as a pulse sensor's strip passages). A reading is a
:class:`Reading`: its time and the message fields it sets (dotted paths into the contract
topic's message type, ``header.frame_id`` included), so that a ROS shell publishes any
instrument without knowing it.

No ROS import.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar, Protocol

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import topic as contract_topic
from bearing_rig_sim.rig.parameters import ParameterRecord

SHAFT_ANGLES = ("inner_ring_angle", "cage_angle")
"""The shaft angles the twin shows its instruments, rad (unwrapped)."""

TEMPERATURE_SUFFIX = "_temperature"
"""A measurand ``<node>_temperature`` is that node's temperature in the bearing's thermal
network, degC (available once the network is attached)."""

MEASURANDS = (*SHAFT_ANGLES, "friction_torque")
"""The quantities the twin shows its instruments besides the temperatures: the shaft angles
(rad) and the bearing's friction torque (N m, the engine's, about the spindle axis)."""

FieldValue = float | int | str
"""A message field's value."""


class InstrumentError(RigError):
    """An instrument used outside what it can do (a measurand it cannot take, bad input)."""


class Measurand(Protocol):
    """The measured quantity over one chunk, read only when the instrument needs it."""

    def at_start(self) -> float:
        """Its value at the chunk's start."""
        ...

    def at_end(self) -> float:
        """Its value at the chunk's end."""
        ...


class Reading(Protocol):
    """One reading of an instrument, as its message carries it."""

    @property
    def time(self) -> float:
        """When the reading was taken on the rig clock, s (the message's ``header.stamp``)."""
        ...

    def message_fields(self) -> Mapping[str, FieldValue]:
        """Dotted field path in the topic's message type -> value (``header.frame_id``
        included; the stamp is :attr:`time`)."""
        ...


@dataclass(frozen=True)
class Sample:
    """A sampled instrument's reading: its time and the message fields it sets."""

    time: float
    """Time of the reading on the rig clock, s."""
    fields: Mapping[str, FieldValue]
    """Dotted field path -> value."""

    def message_fields(self) -> Mapping[str, FieldValue]:
        """The message fields (see :class:`Reading`)."""
        return self.fields


def is_measurand(name: str) -> bool:
    """Whether the twin can show an instrument ``name`` (a temperature once its thermal network
    is attached)."""
    return name in MEASURANDS or (name.endswith(TEMPERATURE_SUFFIX) and len(name) > len(TEMPERATURE_SUFFIX))


@dataclass(frozen=True)
class InstrumentSettings(ParameterRecord):
    """The keys every instrument's settings block has; a model's settings record adds its own."""

    kind: str
    """The instrument model's registered name (:data:`bearing_rig_sim.instruments.registry.INSTRUMENT_MODELS`)."""
    topic: str
    """The contract topic its readings are published on."""
    measures: str
    """The rig quantity it measures (see the module documentation)."""

    MSGTYPE: ClassVar[str] = ""
    """The message type the model's readings fill (the contract topic must carry it)."""

    def check_consistency(self, error: Callable[[str, str], ConfigError]) -> None:
        """The topic is the contract's and carries the model's message type; the measurand is
        one the twin offers."""
        try:
            entry = contract_topic(self.topic)
        except KeyError:
            raise error("topic", f"{self.topic!r} is not a topic of the interface contract (bearing_rig_sim/interfaces.py)") from None
        if self.MSGTYPE and entry.msgtype != self.MSGTYPE:
            raise error("topic", f"{self.topic} carries {entry.msgtype}; the {self.kind} model gives {self.MSGTYPE}")
        if not is_measurand(self.measures):
            raise error("measures", f"must be one of {', '.join(MEASURANDS)} or <node>{TEMPERATURE_SUFFIX}, got {self.measures!r}")


class Instrument(Protocol):
    """A bench instrument model (see the module documentation)."""

    @property
    def settings(self) -> InstrumentSettings:
        """Its settings block."""
        ...

    def observe(self, t0: float, t1: float, measurand: Measurand) -> Sequence[Reading]:
        """The readings the instrument gives over the chunk (t0, t1], in time order."""
        ...

    def reset(self) -> None:
        """Start afresh (after a clock jump)."""
        ...
