"""Synthetic messages for checking recorders, readers and tools without a running rig.

* :func:`sample_message`: a message of any known type with every field filled from a seed
  (sequences of varying length, empty ones included; strings with non-ASCII characters), for
  round trips through a bag.
* :func:`message_fields`: any message object (rosbags', ``mcap_ros2``'s, rclpy's) as plain
  nested dicts and lists, so that objects from different decoders compare equal field by field.
* :func:`rig_traffic`: the serialized traffic of a steady run of the rig (speeds at 1 kHz,
  fibre-optic pulses, truth at 100 Hz), for benchmarks and long-bag tests. The speeds are
  ``sensor_msgs/JointState`` with an empty ``effort``, carrying the 8 bytes of trailing padding
  Fast-CDR gives such a message, as a raw subscription delivers it.
"""

from __future__ import annotations

import math
import random
import string
import struct
from typing import Any
from collections.abc import Iterator

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.typesys.store import Typestore

from bearing_rig_sim.interfaces import CAGE_PULSES, SPEEDS, SPINDLE_PULSES, TRUTH
from bearing_rig_sim.bags.typestore import rig_typestore

_INT_RANGES = {
    "int8": (-(2**7), 2**7 - 1),
    "uint8": (0, 2**8 - 1),
    "byte": (0, 2**7 - 1),  # rosbags packs byte and char signed, mcap_ros2 unsigned: 0..127 agree
    "char": (0, 2**7 - 1),
    "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1),
    "int32": (-(2**31), 2**31 - 1),
    "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1),
    "uint64": (0, 2**64 - 1),
}
_DTYPES = {
    "bool": np.bool_,
    "byte": np.uint8,
    "char": np.uint8,
    "int8": np.int8,
    "uint8": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}
_TEXT = string.ascii_letters + string.digits + " _-/µé°"

SPEEDS_TOPIC = SPEEDS.name
SPINDLE_PULSES_TOPIC = SPINDLE_PULSES.name
CAGE_PULSES_TOPIC = CAGE_PULSES.name
TRUTH_TOPIC = TRUTH.name

NO_BALLS: dict[str, Any] = {
    **{
        f"ball_{name}": np.zeros(0)
        for name in (
            "azimuth",
            "orbit_speed",
            "spin_speed",
            "inner_contact_load",
            "outer_contact_load",
            "inner_contact_angle",
            "outer_contact_angle",
            "pocket_load",
        )
    },
    "cage_centre_x": 0.0,
    "cage_centre_y": 0.0,
}
"""SimulatorTruth's per-ball fields for a truth without per-ball state (rosbags keyword arguments:
empty arrays and a centred cage)."""
RIG_TRAFFIC_TOPICS: dict[str, tuple[str, str]] = {t.name: (t.msgtype, t.qos) for t in (SPEEDS, SPINDLE_PULSES, CAGE_PULSES, TRUTH)}
"""Topics of :func:`rig_traffic`: name -> (type, QoS profile), from the interface contract."""

FAST_CDR_PADDING = 8
"""Trailing bytes Fast-CDR adds to a JointState with names, positions, velocities and no effort."""


def _scalar(rng: random.Random, name: str, bound: int) -> Any:
    if name == "bool":
        return rng.random() < 0.5
    if name in _INT_RANGES:
        low, high = _INT_RANGES[name]
        return rng.choice((low, high, 0, rng.randint(low, high)))
    if name == "float32":
        return float(np.float32(rng.uniform(-1e3, 1e3)))
    if name == "float64":
        return rng.choice((0.0, -0.0, 1e-300, rng.uniform(-1e6, 1e6)))
    if name == "string":
        length = rng.randint(0, bound or 12)
        return "".join(rng.choice(_TEXT) for _ in range(length))
    raise ValueError(f"no sample value for field type {name!r}")


def _value(store: Typestore, rng: random.Random, desc: tuple) -> Any:
    kind, arg = desc
    if kind == Nodetype.BASE:
        return _scalar(rng, arg[0], arg[1])
    if kind == Nodetype.NAME:
        return sample_from(store, arg, rng)
    (subkind, subarg), count = arg
    length = count if kind == Nodetype.ARRAY else rng.randint(0, min(count, 3) if count else 3)
    if subkind == Nodetype.BASE and subarg[0] in _DTYPES:
        return np.array([_scalar(rng, subarg[0], 0) for _ in range(length)], dtype=_DTYPES[subarg[0]])
    return [_value(store, rng, (subkind, subarg)) for _ in range(length)]


def sample_from(store: Typestore, msgtype: str, rng: random.Random) -> object:
    """A ``msgtype`` message (rosbags object) with every field drawn from ``rng``."""
    fields = {name: _value(store, rng, desc) for name, desc in store.fielddefs[msgtype][1]}
    return store.types[msgtype](**fields)


def sample_message(msgtype: str, seed: int = 0, typestore: Typestore | None = None) -> object:
    """A deterministic ``msgtype`` message with every field filled (see the module documentation)."""
    store = typestore if typestore is not None else rig_typestore()
    return sample_from(store, msgtype, random.Random(f"{msgtype}/{seed}"))


def message_fields(message: object, msgtype: str, typestore: Typestore | None = None) -> dict[str, Any]:
    """A message as nested dicts and lists of Python scalars, whatever decoder produced it."""
    store = typestore if typestore is not None else rig_typestore()
    return _plain(store, message, (Nodetype.NAME, msgtype))


def _plain(store: Typestore, value: Any, desc: tuple) -> Any:
    kind, arg = desc
    if kind == Nodetype.BASE:
        return value.item() if isinstance(value, np.generic) else value
    if kind == Nodetype.NAME:
        return {name: _plain(store, getattr(value, name), sub) for name, sub in store.fielddefs[arg][1]}
    items = list(value) if not isinstance(value, (bytes, bytearray)) else [int(b) for b in value]
    return [_plain(store, item, arg[0]) for item in items]


def _joint_state_template(store: Typestore) -> tuple[bytearray, list[int]]:
    """Serialized speeds message with the byte offsets of sec, nanosec, 2 positions, 2 velocities."""
    sentinels = [1111111111, 2222222222, 1.25e301, 2.5e301, 3.75e301, 5.0e301]
    types = store.types
    message = types["sensor_msgs/msg/JointState"](
        header=types["std_msgs/msg/Header"](stamp=types["builtin_interfaces/msg/Time"](sec=sentinels[0], nanosec=sentinels[1]), frame_id=""),
        name=["inner_ring", "cage"],
        position=np.array(sentinels[2:4]),
        velocity=np.array(sentinels[4:6]),
        effort=np.array([], dtype=np.float64),
    )
    data = bytearray(store.serialize_cdr(message, "sensor_msgs/msg/JointState")) + bytes(FAST_CDR_PADDING)
    offsets = [data.index(struct.pack("<I", s) if i < 2 else struct.pack("<d", s)) for i, s in enumerate(sentinels)]
    return data, offsets


def rig_traffic(
    duration_s: float,
    *,
    spindle_speed: float = 2 * math.pi * 150.0,
    cage_ratio: float = 0.39,
    typestore: Typestore | None = None,
) -> Iterator[tuple[str, int, bytes]]:
    """Serialized messages of a steady run, in time order: (topic, time in ns, CDR bytes).

    Args:
        duration_s: simulated seconds (s).
        spindle_speed: inner-ring speed (rad/s); default 9000 rpm.
        cage_ratio: cage speed / inner-ring speed (1).
        typestore: types; default :func:`rig_typestore`.

    Rates: speeds 1 kHz; one pulse per revolution of spindle and cage; truth 100 Hz.
    """
    store = typestore if typestore is not None else rig_typestore()
    types = store.types
    template, offsets = _joint_state_template(store)
    cage_speed = spindle_speed * cage_ratio
    pulse_periods = {SPINDLE_PULSES_TOPIC: 2 * math.pi / spindle_speed, CAGE_PULSES_TOPIC: 2 * math.pi / cage_speed}
    next_pulse = dict.fromkeys(pulse_periods, 0.0)
    pulse_count = dict.fromkeys(pulse_periods, 0)
    steps = int(round(duration_s * 1000))
    pack_into = struct.pack_into

    def header(time_ns: int, frame: str) -> Any:
        stamp = types["builtin_interfaces/msg/Time"](sec=time_ns // 10**9, nanosec=time_ns % 10**9)
        return types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame)

    for step in range(steps):
        time_ns = step * 1_000_000
        t = step * 1e-3
        pack_into("<I", template, offsets[0], time_ns // 10**9)
        pack_into("<I", template, offsets[1], time_ns % 10**9)
        pack_into("<d", template, offsets[2], math.fmod(spindle_speed * t, 2 * math.pi))
        pack_into("<d", template, offsets[3], math.fmod(cage_speed * t, 2 * math.pi))
        pack_into("<d", template, offsets[4], spindle_speed)
        pack_into("<d", template, offsets[5], cage_speed)
        yield SPEEDS_TOPIC, time_ns, bytes(template)
        if step % 10 == 0:
            truth = types["bearing_rig_msgs/msg/SimulatorTruth"](
                header=header(time_ns, "rig"),
                inner_ring_speed=spindle_speed,
                inner_ring_acceleration=0.0,
                cage_speed=cage_speed,
                theoretical_cage_speed=spindle_speed * 0.4,
                slip_rate=(1 - cage_ratio / 0.4) * 100,
                axial_load=300.0,
                inner_contact_load_mean=25.0,
                inner_contact_load_max=26.0,
                outer_contact_load_mean=25.0,
                outer_contact_load_max=26.0,
                pocket_load_max=0.5,
                inner_contact_angle=0.26,
                outer_contact_angle=0.26,
                inner_ring_axial_displacement=1e-6,
                real_time_factor=1.0,
                step_count=step,
                overruns=0,
                friction_torque=0.01,
                power_loss=3.0,
                cage_whirl_radius_um=0.0,
                **NO_BALLS,
            )
            yield TRUTH_TOPIC, time_ns, bytes(store.serialize_cdr(truth, "bearing_rig_msgs/msg/SimulatorTruth"))
        pulses = []
        for topic, period in pulse_periods.items():
            while next_pulse[topic] < t + 1e-3:
                count = pulse_count[topic]
                pulse_ns = max(time_ns, int(round(next_pulse[topic] * 1e9)))
                pulse = types["bearing_rig_msgs/msg/FibreOpticPulse"](
                    header=header(pulse_ns, "rig"),
                    sensor_id="spindle" if topic == SPINDLE_PULSES_TOPIC else "cage",
                    strip_id=0,
                    strip_count=1,
                    revolution=count,
                    pulse_index=count,
                )
                pulses.append((pulse_ns, topic, bytes(store.serialize_cdr(pulse, "bearing_rig_msgs/msg/FibreOpticPulse"))))
                pulse_count[topic] = count + 1
                next_pulse[topic] += period
        for pulse_ns, topic, data in sorted(pulses):
            yield topic, pulse_ns, data
