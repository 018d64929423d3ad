"""analyze with the bench's thermocouple and torque meter: their latest readings ride on the
status rows and are drawn in thermal.png."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bearing_rig_sim.bags import BagWriter, rig_typestore
from bearing_rig_sim.config import rpm_to_rad_s
from bearing_rig_sim.monitoring import MonitorSettings
from bearing_rig_sim.offline.analysis import analyse_bag
from bearing_rig_sim.offline.report import write_report

PULSE = "bearing_rig_msgs/msg/FibreOpticPulse"


def test_temperature_and_torque_reach_the_rows_and_the_plot(tmp_path: Path) -> None:
    """1500 rpm with 3 % slip for 8 s; the thermocouple rises 22 -> 30 degC linearly (10 Hz), the
    torque meter reads 0.1 N m (100 Hz): each row carries the latest reading before it."""
    types = rig_typestore().types

    def header(t: float) -> object:
        sec = int(t)
        return types["std_msgs/msg/Header"](stamp=types["builtin_interfaces/msg/Time"](sec=sec, nanosec=int(round((t - sec) * 1e9))), frame_id="rig")

    ratio = MonitorSettings.from_yaml().kinematics().epicyclic_ratio() * 0.97
    inner = rpm_to_rad_s(1500.0)
    events: list[tuple[float, str, object]] = []
    for shaft, speed in (("spindle", inner), ("cage", inner * ratio)):
        period = 2 * math.pi / speed
        for k in range(int(8.0 / period)):
            t = 0.001 + k * period
            events.append((t, f"/rig/{shaft}/pulses", types[PULSE](header=header(t), sensor_id=shaft, strip_id=0, strip_count=1, revolution=k, pulse_index=k)))
    temperature = {}
    for k in range(80):
        t = 0.1 * k + 0.05
        temperature[t] = 22.0 + t
        events.append((t, "/rig/outer_ring/temperature", types["sensor_msgs/msg/Temperature"](header=header(t), temperature=temperature[t], variance=0.0025)))
    vec = types["geometry_msgs/msg/Vector3"]
    for k in range(800):
        t = 0.01 * k + 0.005
        wrench = types["geometry_msgs/msg/Wrench"](force=vec(x=0.0, y=0.0, z=0.0), torque=vec(x=0.0, y=0.0, z=0.1))
        events.append((t, "/rig/housing/torque", types["geometry_msgs/msg/WrenchStamped"](header=header(t), wrench=wrench)))
    events.sort(key=lambda e: e[0])
    path = tmp_path / "bag"
    with BagWriter(path) as bag:
        bag.add_topic("/rig/spindle/pulses", PULSE, "reliable_stream")
        bag.add_topic("/rig/cage/pulses", PULSE, "reliable_stream")
        bag.add_topic("/rig/outer_ring/temperature", "sensor_msgs/msg/Temperature", "reliable")
        bag.add_topic("/rig/housing/torque", "geometry_msgs/msg/WrenchStamped", "reliable")
        for t, topic, message in events:
            bag.write_message(topic, int(round(t * 1e9)), message)
    result = analyse_bag(path)
    rows = [r for r in result.rows if math.isfinite(r.outer_ring_temperature)]
    assert len(rows) > 10
    times = np.array(sorted(temperature))
    for r in rows:
        latest = times[times <= r.time + 1e-9]
        assert r.outer_ring_temperature == pytest.approx(temperature[float(latest[-1])], abs=1e-9)
        assert r.housing_torque == pytest.approx(0.1)
    files = write_report(result, tmp_path / "out")
    assert (tmp_path / "out" / "thermal.png") in files.plots
