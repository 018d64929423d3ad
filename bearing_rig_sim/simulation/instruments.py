"""The bench's instruments on the twin: each shown the quantity it measures, every chunk.

:class:`TwinInstruments` builds the instruments of the rig file's ``sensors`` section
(:class:`~bearing_rig_sim.instruments.registry.InstrumentSet`) and, after each chunk, shows
each one its measurand (the shaft angles at both ends of the chunk, the engine's friction
torque, a thermal node's temperature once the network is attached) and collects its readings
by contract topic, which the simulator publishes without knowing the instruments. The two
fibre-optic sensors watching the inner ring and the cage also feed the bench's pulse counters,
from which the twin's measured speeds come.

Units: s, rad, N m, degC.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import partial

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.instruments.base import TEMPERATURE_SUFFIX, Instrument, InstrumentError, Reading
from bearing_rig_sim.instruments.fibre_optic import FibreOpticSensor, Pulse, PulseCounter
from bearing_rig_sim.instruments.registry import SECTION, InstrumentSet
from bearing_rig_sim.thermal.coupling import ThermalCoupling


class _Span:
    """A measurand known at both ends of the chunk (a shaft angle)."""

    __slots__ = ("start", "end")

    def __init__(self) -> None:
        self.start = 0.0
        self.end = 0.0

    def at_start(self) -> float:
        return self.start

    def at_end(self) -> float:
        return self.end


class _AtEnd:
    """A measurand read at the chunk's end only, when the instrument asks for it."""

    __slots__ = ("what", "read")

    def __init__(self, what: str, read: Callable[[], float]) -> None:
        self.what = what
        self.read = read

    def at_start(self) -> float:
        raise InstrumentError(f"{self.what} is shown to instruments at the chunk's end only")

    def at_end(self) -> float:
        return self.read()


class TwinInstruments:
    """The instruments of a ``sensors`` section, sampled chunk by chunk.

    Args:
        instruments: the section; it must have one fibre-optic sensor measuring
            ``inner_ring_angle`` and one measuring ``cage_angle`` (the bench's speeds).

    Raises:
        ConfigError: a shaft without its fibre-optic sensor, naming the rig file.
    """

    def __init__(self, instruments: InstrumentSet) -> None:
        self.set = instruments
        self.by_block: dict[str, Instrument] = instruments.build()
        """Block name -> instrument."""
        self.spindle_sensor = self._shaft_sensor("inner_ring_angle")
        """The fibre-optic sensor on the spindle (the inner ring's angle)."""
        self.cage_sensor = self._shaft_sensor("cage_angle")
        """The fibre-optic sensor on the cage."""
        self.spindle_counter: PulseCounter = self.spindle_sensor.settings.counter()
        self.cage_counter: PulseCounter = self.cage_sensor.settings.counter()
        self._others = [(name, i) for name, i in self.by_block.items() if i is not self.spindle_sensor and i is not self.cage_sensor]
        self._spindle_angle, self._cage_angle = _Span(), _Span()

    def _shaft_sensor(self, measurand: str) -> FibreOpticSensor:
        blocks = self.set.measuring(measurand)
        sensors = [self.by_block[b] for b in blocks]
        if len(sensors) != 1 or not isinstance(sensors[0], FibreOpticSensor):
            raise ConfigError(self.set.source, SECTION, f"needs one fibre-optic sensor measuring {measurand} (the bench's speeds), found {blocks or 'none'}")
        return sensors[0]

    def check_thermal(self, thermal: ThermalCoupling) -> None:
        """Every temperature an instrument measures is a node of ``thermal``'s network.

        Raises:
            ConfigError: naming the rig file, the block's ``measures`` and the network's nodes.
        """
        nodes = thermal.network.names
        for name, settings in self.set.blocks.items():
            if settings.measures.endswith(TEMPERATURE_SUFFIX) and settings.measures.removesuffix(TEMPERATURE_SUFFIX) not in nodes:
                raise ConfigError(
                    self.set.source,
                    f"{SECTION}.{name}.measures",
                    f"the bearing's thermal network has no node {settings.measures.removesuffix(TEMPERATURE_SUFFIX)!r}; nodes: {', '.join(nodes)}",
                )

    def observe(
        self,
        t0: float,
        t1: float,
        shafts_before: tuple[float, float],
        shafts_after: tuple[float, float],
        friction_torque: Callable[[], float],
        thermal: ThermalCoupling | None,
    ) -> tuple[list[Pulse], list[Pulse], dict[str, Sequence[Reading]]]:
        """Show every instrument the chunk (t0, t1]: the inner-ring and cage angles at its two
        ends (rad), the friction torque (N m, read only if an instrument is due) and, once
        attached, the thermal network's temperatures (degC). The pulses feed the counters.

        Returns:
            The spindle's and the cage's pulses, and every instrument's readings by topic
            (pulses included; an instrument whose temperature has no network yet gives none).
        """
        self._spindle_angle.start, self._cage_angle.start = shafts_before
        self._spindle_angle.end, self._cage_angle.end = shafts_after
        spindle = self.spindle_sensor.observe(t0, t1, self._spindle_angle)
        cage = self.cage_sensor.observe(t0, t1, self._cage_angle)
        for pulse in spindle:
            self.spindle_counter.add(pulse)
        for pulse in cage:
            self.cage_counter.add(pulse)
        readings: dict[str, Sequence[Reading]] = {self.spindle_sensor.settings.topic: spindle, self.cage_sensor.settings.topic: cage}
        for _name, instrument in self._others:
            settings = instrument.settings
            measures = settings.measures
            if measures == "inner_ring_angle":
                readings[settings.topic] = instrument.observe(t0, t1, self._spindle_angle)
            elif measures == "cage_angle":
                readings[settings.topic] = instrument.observe(t0, t1, self._cage_angle)
            elif measures == "friction_torque":
                readings[settings.topic] = instrument.observe(t0, t1, _AtEnd(measures, friction_torque))
            elif thermal is not None:  # a temperature (checked against the network on attaching it)
                node = measures.removesuffix(TEMPERATURE_SUFFIX)
                readings[settings.topic] = instrument.observe(t0, t1, _AtEnd(measures, partial(thermal.temperature, node)))
        return spindle, cage, readings
