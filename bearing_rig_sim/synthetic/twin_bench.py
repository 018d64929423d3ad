"""A bench recorded from the twin itself: pulses and load-cell samples of a speed-and-load programme,
for shadow-mode round trips (no ROS).

:func:`twin_bench_run` runs :class:`~bearing_rig_sim.simulation.RigTwin` (engine, spindle drive,
fibre-optic sensors with their timing jitter) through :class:`Hold` segments, each reached by the
paper's STEP ramp, and returns what the bench's topics would carry: both pulse streams and the
load cell's force at 1 kHz with its noise (``config/rig.yaml``: 1 N standard deviation). Stamps
may be put on a bench system clock (``clock_offset_s``). With the bearing's thermal network
(``thermal=True``, the default, coupled both ways as in the rig session: with the default
``coupled`` calibration the lubricant follows the network's temperature, as in the session and the
shadow twin, ``config/shadow.yaml``) it also records the outer-ring thermocouple (10 Hz) and the
housing torque meter (100 Hz) as the simulator node emits them. :func:`departed` makes of a run a bench whose outer ring runs hotter or whose
torque is higher than the twin's from a given time. :func:`write_bench_bag` writes them as a bag with the topics shadow mode reads.

Units: s, rpm and N at this edge (the programme), SI in the events.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from bearing_rig_sim.config import read_mapping, rpm_to_rad_s
from bearing_rig_sim.dynamics import calibrations
from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.interfaces import AXIAL_LOAD_FORCE, CAGE_PULSES, HOUSING_TORQUE, OUTER_RING_TEMPERATURE, SPINDLE_PULSES
from bearing_rig_sim.instruments.fibre_optic import Pulse
from bearing_rig_sim.rig.speed_profile import SpeedProfileKind
from bearing_rig_sim.settings_model import validate_mapping
from bearing_rig_sim.simulation.drive import SpindleCommand
from bearing_rig_sim.simulation.twin import RigTwin
from bearing_rig_sim.instruments.first_order import ThermocoupleSettings
from bearing_rig_sim.instruments.registry import InstrumentSet


def shipped_thermocouple() -> ThermocoupleSettings:
    """The shipped rig file's thermocouple on ``/rig/outer_ring/temperature``."""
    return InstrumentSet.from_rig_file().on_topic(OUTER_RING_TEMPERATURE.name, ThermocoupleSettings)


@dataclass(frozen=True)
class Hold:
    """One programme segment: ramp to ``rpm`` over ``ramp_s`` (STEP), hold to ``duration_s`` in
    all, at ``axial_load_n`` throughout."""

    rpm: float
    duration_s: float
    axial_load_n: float = 100.0
    ramp_s: float = 0.5


@dataclass
class BenchRun:
    """The bench's topics, each in time order (bench clock, s).

    Attributes:
        spindle, cage: the pulses of each sensor.
        forces: load-cell samples (time, force N).
        truth_slip: the engine's true slip at the end of each hold, percent (for reference only).
        temperatures: outer-ring thermocouple readings (time, degC); empty without the network.
        torques: housing torque-meter samples (time, N m); empty without the network.
    """

    spindle: list[Pulse]
    cage: list[Pulse]
    forces: list[tuple[float, float]]
    truth_slip: list[float]
    temperatures: list[tuple[float, float]] = field(default_factory=list)
    torques: list[tuple[float, float]] = field(default_factory=list)

    def events(self) -> list[tuple[float, str, object]]:
        """Every message merged in time order: (time, ``"spindle"``/``"cage"``/``"force"``, payload)."""
        out: list[tuple[float, str, object]] = [(p.time, "spindle", p) for p in self.spindle]
        out += [(p.time, "cage", p) for p in self.cage]
        out += [(t, "force", f) for t, f in self.forces]
        out += [(t, "temperature", v) for t, v in self.temperatures]
        out += [(t, "torque", v) for t, v in self.torques]
        out.sort(key=lambda e: e[0])
        return out


def twin_bench_run(
    holds: list[Hold],
    *,
    calibration_file: str | Path | None = None,
    bearing_file: str | Path | None = None,
    load_noise_std_n: float = 1.0,
    clock_offset_s: float = 0.0,
    seed: int = 7,
    thermal: bool = True,
    initial_rise_k: float = 0.0,
    lubricant_feedback: bool | None = None,
) -> BenchRun:
    """Run the twin through ``holds`` (from rest at 0 s) and record its bench topics.

    Args:
        holds: the programme.
        calibration_file: the calibration of the twin playing the bench (default: the named
            default, ``coupled``: :data:`~bearing_rig_sim.dynamics.calibrations.DEFAULT_CALIBRATION`).
        bearing_file: bearing data (default: the shipped H7006C).
        load_noise_std_n: load-cell noise, N (standard deviation of each 1 kHz sample).
        clock_offset_s: added to every stamp (a bench system clock), s.
        seed: of the load-cell noise.
        thermal: couple the bearing's thermal network and record the thermocouple and the torque
            meter (the bearing file's ``thermal:`` section).
        initial_rise_k: the network's start above the bearing file's ambient, K.
        lubricant_feedback: the engine's lubricant follows the network's temperature (the
            simulator's parameter of that name; None: as the calibration was fitted, on for a
            coupled one (:func:`~bearing_rig_sim.dynamics.calibrations.is_coupled`)).
    """
    cal = calibrations.calibration_file(calibration_file if calibration_file is not None else calibrations.DEFAULT_CALIBRATION)
    feedback = calibrations.is_coupled(cal) if lubricant_feedback is None else lubricant_feedback
    start: dict[str, Any] = {"initial_axial_load": holds[0].axial_load_n} if holds else {}
    twin = RigTwin.from_files(bearing_file, cal, None, **start)
    rng = random.Random(seed)
    run = BenchRun([], [], [], [])
    coupling = twin.attach_thermal(bearing_file, initial_rise_k=initial_rise_k, feedback=feedback) if thermal else None

    def shifted(p: Pulse) -> Pulse:
        return Pulse(p.time + clock_offset_s, p.strip_id, p.strip_count, p.revolution, p.pulse_index, p.sensor_id)

    for hold in holds:
        twin.set_axial_load(hold.axial_load_n)
        twin.command_spindle(SpindleCommand(rpm_to_rad_s(hold.rpm), SpeedProfileKind.STEP, ramp_time=hold.ramp_s))
        end = twin.time + hold.duration_s
        while twin.time < end - 1e-9:
            out = twin.tick(with_truth=False)
            run.spindle.extend(shifted(p) for p in out.spindle_pulses)
            run.cage.extend(shifted(p) for p in out.cage_pulses)
            run.forces.append((out.time + clock_offset_s, hold.axial_load_n + rng.gauss(0.0, load_noise_std_n)))
            if coupling is not None:  # the rig file's thermocouple and torque meter, as the simulator publishes them
                for r in out.readings.get(OUTER_RING_TEMPERATURE.name, []):
                    run.temperatures.append((r.time + clock_offset_s, float(r.message_fields()["temperature"])))
                for r in out.readings.get(HOUSING_TORQUE.name, []):
                    run.torques.append((r.time + clock_offset_s, float(r.message_fields()["wrench.torque.z"])))
        truth = twin.truth()
        run.truth_slip.append(truth.slip_rate)
    return run


def departed(run: BenchRun, *, from_s: float, outer_ring_hotter_k: float = 0.0, torque_factor: float = 1.0) -> BenchRun:
    """The bench of ``run`` departing from the twin at bench time ``from_s`` (s): its outer ring
    ``outer_ring_hotter_k`` K hotter, seen through the thermocouple's first-order lag
    (the shipped rig file's ``time_constant_s``, :func:`shipped_thermocouple`: the reading's offset
    is dT (1 - exp(-(t - from_s) / tau))), and its friction torque ``torque_factor`` times the
    twin's (the torque meter's 10 ms lag and its 0.2 mN m noise, under 0.3 % of the torque, are
    scaled with it). Pulses and load-cell samples are those of ``run``."""
    tau = shipped_thermocouple().time_constant_s
    temperatures = [(t, v + (outer_ring_hotter_k * (1.0 - math.exp(-(t - from_s) / tau)) if t > from_s else 0.0)) for t, v in run.temperatures]
    torques = [(t, v * torque_factor if t > from_s else v) for t, v in run.torques]
    return BenchRun(list(run.spindle), list(run.cage), list(run.forces), list(run.truth_slip), temperatures, torques)


def write_bench_bag(run: BenchRun, path: str | Path) -> Path:
    """Write ``run`` as a bag (MCAP) with the two pulse topics and the load-cell topic."""
    from bearing_rig_sim.bags.typestore import rig_typestore
    from bearing_rig_sim.bags.writer import BagWriter

    store = rig_typestore()
    types = store.types

    def stamp(t: float) -> Any:
        ns = int(round(t * 1e9))
        return types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)

    variance = shipped_thermocouple().noise_std_k ** 2
    with BagWriter(path, typestore=store) as writer:
        topics = [SPINDLE_PULSES, CAGE_PULSES, AXIAL_LOAD_FORCE]
        topics += [OUTER_RING_TEMPERATURE] if run.temperatures else []
        topics += [HOUSING_TORQUE] if run.torques else []
        for topic in topics:
            writer.add_topic(topic.name, topic.msgtype, topic.qos)
        for t, kind, payload in run.events():
            header = types["std_msgs/msg/Header"](stamp=stamp(t), frame_id="bench")
            if kind == "temperature":
                msg = types["sensor_msgs/msg/Temperature"](header=header, temperature=float(payload), variance=variance)  # type: ignore[arg-type]  # rosbags' message constructors are loosely typed
                writer.write_message(OUTER_RING_TEMPERATURE.name, int(round(t * 1e9)), msg)
                continue
            if kind == "torque":
                vec = types["geometry_msgs/msg/Vector3"]
                msg = types["geometry_msgs/msg/WrenchStamped"](
                    header=header,
                    wrench=types["geometry_msgs/msg/Wrench"](force=vec(x=0.0, y=0.0, z=0.0), torque=vec(x=0.0, y=0.0, z=float(payload))),  # type: ignore[arg-type]  # rosbags' message constructors are loosely typed
                )
                writer.write_message(HOUSING_TORQUE.name, int(round(t * 1e9)), msg)
                continue
            if kind == "force":
                vec = types["geometry_msgs/msg/Vector3"]
                msg = types["geometry_msgs/msg/WrenchStamped"](
                    header=header,
                    wrench=types["geometry_msgs/msg/Wrench"](force=vec(x=0.0, y=0.0, z=float(payload)), torque=vec(x=0.0, y=0.0, z=0.0)),  # type: ignore[arg-type]  # rosbags' message constructors are loosely typed
                )
                writer.write_message(AXIAL_LOAD_FORCE.name, int(round(t * 1e9)), msg)
            else:
                p = payload
                assert isinstance(p, Pulse)
                msg = types["bearing_rig_msgs/msg/FibreOpticPulse"](
                    header=header, sensor_id=kind, strip_id=p.strip_id, strip_count=p.strip_count, revolution=p.revolution, pulse_index=p.pulse_index
                )
                writer.write_message((SPINDLE_PULSES if kind == "spindle" else CAGE_PULSES).name, int(round(t * 1e9)), msg)
    return Path(path)


def scaled_calibration(source: str | Path, key: str, factor: float, dest: str | Path, *, base: float | None = None) -> Path:
    """A copy of the calibration file ``source`` with parameter ``key`` (as written under its
    ``parameters:``, e.g. ``lubricant.yield_stress_pa``) multiplied by ``factor``: a bench whose
    drag or traction has changed. A ``{value: ...}`` entry has its value scaled (its range kept:
    a value outside it is refused on loading). A key the file does not set (a parameter the
    calibration left at the bearing file's value) is added as ``base * factor``.

    Raises:
        KeyError: no such parameter in the file and no ``base``.
        ConfigError: ``source`` is not a valid calibration file (one line naming the file and the key).
    """
    import yaml

    doc = read_mapping(source)
    validate_mapping(CalibrationFile, doc, str(source))  # the raw document is rewritten, checked first
    params = doc["parameters"]
    if key not in params:
        if base is None:
            raise KeyError(f"{source}: no parameter {key!r} (it has {', '.join(params)})")
        params[key] = float(base) * factor
    elif isinstance(params[key], dict):
        params[key]["value"] = float(params[key]["value"]) * factor
    else:
        params[key] = float(params[key]) * factor
    out = Path(dest)
    out.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    return out
