"""The instrument models by name, and the rig file's ``sensors`` section read into them.

:data:`INSTRUMENT_MODELS` maps the ``kind`` a settings block names to its settings record and
the class built from it. :class:`InstrumentSet` reads the section (one block per instrument,
errors naming the file and the dotted key) and builds the instruments, which the twin samples
every chunk and the simulator publishes on the topic each block names.

Adding an instrument: a model class with its settings record (listed here), a topic in the
contract (:mod:`bearing_rig_sim.interfaces`) and a block in the rig file (docs/reference.md,
"Adding an instrument").
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from bearing_rig_sim.config import ConfigError, config_path, mapping_at, read_mapping
from bearing_rig_sim.instruments.base import Instrument, InstrumentSettings
from bearing_rig_sim.instruments.fibre_optic import FibreOpticSensor, FibreOpticSettings
from bearing_rig_sim.instruments.first_order import Thermocouple, ThermocoupleSettings, TorqueMeter, TorqueMeterSettings
from bearing_rig_sim.rig.parameters import RIG_FILE

S = TypeVar("S", bound=InstrumentSettings)

SECTION = "sensors"
"""The rig file's section holding one block per instrument."""


@dataclass(frozen=True)
class InstrumentModel:
    """A registered instrument model: its settings record and how an instrument is built."""

    settings: type[InstrumentSettings]
    """The record a settings block of this model is read into."""
    build: Callable[[Any], Instrument]
    """The instrument of a settings record (the class itself, or its ``from_settings``)."""


INSTRUMENT_MODELS: dict[str, InstrumentModel] = {
    "fibre_optic": InstrumentModel(FibreOpticSettings, FibreOpticSensor.from_settings),
    "thermocouple": InstrumentModel(ThermocoupleSettings, Thermocouple),
    "torque_meter": InstrumentModel(TorqueMeterSettings, TorqueMeter),
}
"""The instrument models a settings block may name (its ``kind`` key)."""


@dataclass(frozen=True)
class InstrumentSet:
    """The bench's instruments as the rig file's ``sensors`` section gives them.

    Attributes:
        blocks: block name -> its settings record, in the file's order.
        source: where they were read (named in errors found later, e.g. a thermal node that
            the bearing's network lacks).
    """

    blocks: Mapping[str, InstrumentSettings]
    source: str = RIG_FILE

    def __post_init__(self) -> None:
        seen: dict[str, str] = {}
        for name, settings in self.blocks.items():
            if settings.topic in seen:
                raise ConfigError(self.source, f"{SECTION}.{name}.topic", f"{settings.topic} is already the topic of {SECTION}.{seen[settings.topic]}")
            seen[settings.topic] = name

    @classmethod
    def from_mapping(cls, data: object, source: str) -> InstrumentSet:
        """Read the ``sensors`` section (``data``, read from ``source``); a block's ``kind`` is
        one of :data:`INSTRUMENT_MODELS`.

        Raises:
            ConfigError: naming the file, the dotted key and what is allowed.
        """
        known = INSTRUMENT_MODELS
        if not isinstance(data, Mapping) or not data:
            raise ConfigError(source, SECTION, f"must be a mapping of instrument blocks, got {data!r}")
        blocks: dict[str, InstrumentSettings] = {}
        for name, block in data.items():
            key = f"{SECTION}.{name}"
            if not isinstance(block, Mapping):
                raise ConfigError(source, key, f"must be a mapping (an instrument's settings), got {type(block).__name__}")
            model = known.get(block.get("kind"))  # type: ignore[arg-type]  # a missing or odd key is refused just below
            if model is None:
                raise ConfigError(source, f"{key}.kind", f"must be one of {', '.join(known)}, got {block.get('kind')!r}")
            blocks[str(name)] = model.settings.from_mapping(block, source, key)
        return cls(blocks, source)

    @classmethod
    def from_rig_file(cls, path: str | Path | None = None) -> InstrumentSet:
        """Read the ``sensors`` section of a rig file (default: the shipped ``config/rig.yaml``).

        Raises:
            ConfigError: naming the file, the dotted key and what is allowed.
        """
        path = path if path is not None else config_path(RIG_FILE)
        return cls.from_mapping(mapping_at(read_mapping(path), (SECTION,), str(path)), str(path))

    def build(self) -> dict[str, Instrument]:
        """A fresh instrument per block (block name -> instrument), in the file's order."""
        return {name: INSTRUMENT_MODELS[s.kind].build(s) for name, s in self.blocks.items()}

    def measuring(self, measurand: str) -> list[str]:
        """The blocks whose instrument measures ``measurand``."""
        return [name for name, s in self.blocks.items() if s.measures == measurand]

    def on_topic(self, topic: str, kind: type[S]) -> S:
        """The settings of the instrument published on ``topic``, a ``kind`` record (e.g.
        :class:`~bearing_rig_sim.instruments.first_order.ThermocoupleSettings`).

        Raises:
            ConfigError: no instrument of that kind is published there (naming the file).
        """
        for settings in self.blocks.values():
            if settings.topic == topic and isinstance(settings, kind):
                return settings
        raise ConfigError(self.source, SECTION, f"no instrument with {kind.__name__} is published on {topic}")

    def topics(self) -> list[str]:
        """The topic of each block, in the file's order."""
        return [s.topic for s in self.blocks.values()]
