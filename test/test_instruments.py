"""The bench's instruments in one home: the rig file's ``sensors`` section against the contract,
its errors naming file and key, the first-order instruments against their closed form, and an
instrument added from a model class, a contract entry and a settings block alone, sampled by the
twin (no ROS).

The first-order lag's references are computed here: a step of size dx read after time h shows
x0 + dx (1 - exp(-h / tau)).
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
import yaml

from bearing_rig_sim import interfaces
from bearing_rig_sim.config import ConfigError, config_path
from bearing_rig_sim.instruments.base import InstrumentError, InstrumentSettings, Measurand, Reading, Sample
from bearing_rig_sim.instruments.fibre_optic import FibreOpticSensor, FibreOpticSettings
from bearing_rig_sim.instruments.first_order import FirstOrderLag, Thermocouple, ThermocoupleSettings, TorqueMeter
from bearing_rig_sim.instruments.registry import INSTRUMENT_MODELS, InstrumentModel, InstrumentSet
from bearing_rig_sim.interfaces import CAGE_PULSES, HOUSING_TORQUE, OUTER_RING_TEMPERATURE, SPINDLE_PULSES
from bearing_rig_sim.rig.parameters import bounded
from bearing_rig_sim.simulation.twin import RigTwin

SHIPPED = config_path("rig.yaml")


def rig_file_with(tmp_path: Path, change: Callable[[dict[str, object]], None]) -> Path:
    """A copy of the shipped rig file whose ``sensors`` section ``change`` edited."""
    data = yaml.safe_load(SHIPPED.read_text(encoding="utf-8"))
    change(data["sensors"])
    path = tmp_path / "rig.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    return path


def test_the_shipped_instruments_publish_the_contract_topics_the_simulator_always_published() -> None:
    instruments = InstrumentSet.from_rig_file()
    assert set(instruments.topics()) == {SPINDLE_PULSES.name, CAGE_PULSES.name, OUTER_RING_TEMPERATURE.name, HOUSING_TORQUE.name}
    built = instruments.build()
    for name, settings in instruments.blocks.items():
        assert interfaces.topic(settings.topic).msgtype == type(settings).MSGTYPE
        instrument = built[name]
        if isinstance(instrument, FibreOpticSensor):
            assert isinstance(settings, FibreOpticSettings)
            assert instrument.strip_count == settings.counter().strip_count == settings.strip_count
            assert instrument.jitter_std == settings.timing_jitter_std_s
    assert [instruments.blocks[b].topic for b in instruments.measuring("inner_ring_angle")] == [SPINDLE_PULSES.name]
    assert [instruments.blocks[b].topic for b in instruments.measuring("cage_angle")] == [CAGE_PULSES.name]


@pytest.mark.parametrize(
    ("block", "change", "key", "problem"),
    [
        ("spindle", {"strip_count": 0}, "sensors.spindle.strip_count", ">= 1"),
        (
            "spindle",
            {"timing_jitter_std_s": {"value": 5e-6, "unit": "s", "range": [0.0, 2e-6], "source": "x"}},
            "sensors.spindle.timing_jitter_std_s.value",
            "<= 2e-06",
        ),
        (
            "spindle",
            {"timing_jitter_std_s": {"value": 1e-6, "unit": "ms", "range": [0.0, 2e-6], "source": "x"}},
            "sensors.spindle.timing_jitter_std_s.unit",
            "'s'",
        ),
        ("cage", {"pulse_drop_probability": 1.5}, "sensors.cage.pulse_drop_probability", "< 1.0"),
        ("cage", {"strips": 3}, "sensors.cage.strips", "unknown key"),
        ("cage", {"measures": "friction_torque"}, "sensors.cage.measures", "shaft"),
        ("outer_ring_thermocouple", {"kind": "pyrometer"}, "sensors.outer_ring_thermocouple.kind", "fibre_optic"),
        ("outer_ring_thermocouple", {"topic": "/rig/outer_ring/heat"}, "sensors.outer_ring_thermocouple.topic", "not a topic of the interface contract"),
        ("outer_ring_thermocouple", {"topic": HOUSING_TORQUE.name}, "sensors.outer_ring_thermocouple.topic", "carries geometry_msgs/msg/WrenchStamped"),
        ("outer_ring_thermocouple", {"measures": "outer_ring_pressure"}, "sensors.outer_ring_thermocouple.measures", "must be one of"),
        (
            "outer_ring_thermocouple",
            {"time_constant_s": {"value": 9.0, "unit": "s", "range": [0.5, 5.0], "source": "x"}},
            "sensors.outer_ring_thermocouple.time_constant_s.value",
            "<= 5.0",
        ),
        ("housing_torque_meter", {"topic": OUTER_RING_TEMPERATURE.name, "kind": "thermocouple"}, "sensors.housing_torque_meter.noise_std_n_m", "unknown key"),
        ("housing_torque_meter", {"noise_std_n_m": -1.0}, "sensors.housing_torque_meter.noise_std_n_m", ">= 0.0"),
    ],
)
def test_a_bad_settings_block_is_refused_naming_file_and_key(tmp_path: Path, block: str, change: dict[str, object], key: str, problem: str) -> None:
    def edit(section: dict[str, object]) -> None:
        target = section[block]
        assert isinstance(target, dict)
        target.update(change)

    path = rig_file_with(tmp_path, edit)
    with pytest.raises(ConfigError) as info:
        InstrumentSet.from_rig_file(path)
    assert (info.value.source, info.value.key) == (str(path), key)
    assert problem in info.value.problem


def test_two_instruments_on_one_topic_are_refused(tmp_path: Path) -> None:
    def edit(section: dict[str, object]) -> None:
        section["second_thermocouple"] = copy.deepcopy(section["outer_ring_thermocouple"])

    path = rig_file_with(tmp_path, edit)
    with pytest.raises(ConfigError, match="already the topic of sensors.outer_ring_thermocouple") as info:
        InstrumentSet.from_rig_file(path)
    assert info.value.key == "sensors.second_thermocouple.topic"


def test_a_shaft_without_its_fibre_optic_sensor_is_refused(tmp_path: Path) -> None:
    path = rig_file_with(tmp_path, lambda section: section.pop("cage"))
    with pytest.raises(ConfigError, match="cage_angle"):
        RigTwin.from_files(rig_file=path)


class _Step:
    """A measured quantity at ``value`` at the chunk's end."""

    def __init__(self, value: float) -> None:
        self.value = value

    def at_start(self) -> float:
        return self.value

    def at_end(self) -> float:
        return self.value


def test_a_first_order_lag_follows_a_step_by_its_time_constant_and_scatters_by_its_noise() -> None:
    lag = FirstOrderLag(2.0, 0.0, None)
    assert lag.update(20.0, 0.1) == 20.0
    assert lag.update(30.0, 2.0) == pytest.approx(20.0 + 10.0 * (1.0 - math.exp(-1.0)), rel=1e-12)
    noisy = FirstOrderLag(0.01, 2e-4, 3)
    readings = np.array([noisy.update(0.1, 0.01) for _ in range(4000)])
    assert np.mean(readings[100:]) == pytest.approx(0.1, abs=3e-5)  # 4 standard errors of 2e-4 / sqrt(3900)
    assert np.std(readings[100:]) == pytest.approx(2e-4, rel=0.1)
    with pytest.raises(InstrumentError, match="time constant"):
        FirstOrderLag(0.0, 0.0, None)


def test_the_shipped_thermocouple_and_torque_meter_read_at_their_rates_with_their_variance() -> None:
    instruments = InstrumentSet.from_rig_file()
    thermocouple = Thermocouple(instruments.on_topic(OUTER_RING_TEMPERATURE.name, ThermocoupleSettings))
    torque_meter = INSTRUMENT_MODELS["torque_meter"].build(instruments.blocks["housing_torque_meter"])
    assert isinstance(torque_meter, TorqueMeter)
    chunk, temperatures, torques = 1e-3, [], []
    for k in range(1000):  # 1 s of 1 ms chunks
        temperatures += thermocouple.observe(k * chunk, (k + 1) * chunk, _Step(40.0))
        torques += torque_meter.observe(k * chunk, (k + 1) * chunk, _Step(0.02))
    assert len(temperatures) == 10 and len(torques) == 100  # config/rig.yaml: 10 Hz and 100 Hz
    assert temperatures[0].time == pytest.approx(0.1, abs=1e-12)
    fields = temperatures[0].message_fields()
    assert fields["header.frame_id"] == "outer_ring"
    assert fields["variance"] == pytest.approx(0.05**2)  # config/rig.yaml: noise_std_k 0.05 K
    assert set(torques[0].message_fields()) == {"header.frame_id", "wrench.torque.z"}


# -- an instrument added from its three pieces ---------------------------------------------------

HOUSING_TEMPERATURE = interfaces.Topic(
    "/rig/housing/temperature", "sensor_msgs/msg/Temperature", "reliable", "20 Hz (sim)", "degC", "simulator (bench: housing Pt100)"
)
"""Piece 1: the contract entry."""


@dataclass(frozen=True)
class ResistanceThermometerSettings(InstrumentSettings):
    """Piece 2a: the model's settings record."""

    MSGTYPE: ClassVar[str] = "sensor_msgs/msg/Temperature"

    frame_id: str
    rate_hz: float = bounded(gt=0.0, le=1000.0, unit="Hz")
    time_constant_s: float = bounded(gt=0.0, le=60.0, unit="s")
    offset_k: float = bounded(ge=-1.0, le=1.0, unit="K")


class ResistanceThermometer:
    """Piece 2b: the model, a noise-free Pt100 with a fixed offset within its tolerance class."""

    def __init__(self, settings: ResistanceThermometerSettings) -> None:
        self.settings = settings
        self.lag = FirstOrderLag(settings.time_constant_s, 0.0, None)
        self._last: float | None = None

    def reset(self) -> None:
        self._last = None

    def observe(self, t0: float, t1: float, measurand: Measurand) -> list[Reading]:
        self._last = t0 if self._last is None else self._last
        if t1 - self._last < (1.0 - 1e-9) / self.settings.rate_hz:
            return []
        h, self._last = t1 - self._last, t1
        value = self.lag.update(measurand.at_end(), h) + self.settings.offset_k
        return [Sample(t1, {"header.frame_id": self.settings.frame_id, "temperature": value})]


HOUSING_PT100 = {
    "kind": "resistance_thermometer",
    "topic": HOUSING_TEMPERATURE.name,
    "measures": "housing_temperature",
    "frame_id": "housing",
    "rate_hz": {"value": 20.0, "unit": "Hz", "range": [1.0, 100.0], "source": "test"},
    "time_constant_s": {"value": 1e-3, "unit": "s", "range": [1e-4, 10.0], "source": "test"},
    "offset_k": {"value": 0.15, "unit": "K", "range": [-0.15, 0.15], "source": "IEC 60751 class A at 0 degC: +-0.15 K"},
}
"""Piece 3: the settings block."""


def test_an_instrument_added_from_a_model_a_contract_entry_and_a_settings_block_is_sampled(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Over 1 s of a warming bearing the Pt100 gives 20 readings 0.05 s apart, each the housing
    node's temperature plus its offset (its 1 ms time constant is 1/50 of the reading period, so
    the lag leaves exp(-50) of a step: nothing); the shipped instruments go on as before."""
    monkeypatch.setitem(interfaces._BY_NAME, HOUSING_TEMPERATURE.name, HOUSING_TEMPERATURE)
    monkeypatch.setattr(interfaces, "TOPICS", (*interfaces.TOPICS, HOUSING_TEMPERATURE))
    monkeypatch.setitem(INSTRUMENT_MODELS, "resistance_thermometer", InstrumentModel(ResistanceThermometerSettings, ResistanceThermometer))
    path = rig_file_with(tmp_path, lambda section: section.update(housing_pt100=HOUSING_PT100))
    twin = RigTwin.from_files(rig_file=path, initial_speed=3000 * math.pi / 30)
    thermal = twin.attach_thermal(initial_rise_k=5.0)
    readings, truth, others = [], [], 0
    for _ in range(1000):
        out = twin.tick(with_truth=False)
        new = out.readings.get(HOUSING_TEMPERATURE.name, [])
        readings += new
        truth += [thermal.temperature("housing")] * len(new)
        others += len(out.readings[OUTER_RING_TEMPERATURE.name])
    assert len(readings) == 20 and others == 10
    assert np.diff([r.time for r in readings]) == pytest.approx([0.05] * 19, abs=1e-9)
    for reading, housing in zip(readings, truth):
        fields = reading.message_fields()
        assert fields["header.frame_id"] == "housing"
        assert fields["temperature"] == pytest.approx(housing + 0.15, abs=1e-9)
    assert truth[0] - truth[-1] > 1e5 * 1e-9  # the housing, started 5 K above ambient, cools: the readings follow it


def test_an_instrument_on_a_node_the_thermal_network_lacks_is_refused_naming_its_block(tmp_path: Path) -> None:
    def edit(section: dict[str, object]) -> None:
        block = section["outer_ring_thermocouple"]
        assert isinstance(block, dict)
        block["measures"] = "spindle_motor_temperature"

    path = rig_file_with(tmp_path, edit)
    twin = RigTwin.from_files(rig_file=path)
    with pytest.raises(ConfigError, match="no node 'spindle_motor'") as info:
        twin.attach_thermal()
    assert (info.value.source, info.value.key) == (str(path), "sensors.outer_ring_thermocouple.measures")
