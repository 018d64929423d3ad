"""The interface contract of the rig, written once: every topic and service, with its type, QoS,
rate, unit and publisher.

Nodes, the session, the recorder, replay, offline analysis and the benchmarks take topic names,
types and QoS profiles from here; ``docs/interfaces.md`` and the README's interface table are
generated from :func:`markdown_table` (a test checks that both agree with it). The same topics
are carried by the physical bench's pulse counter and load cell, so that the monitor and every
subscriber work unchanged on either.

Units on the wire are SI (rad/s, N, s); the slip rate is in percent. Message definitions live in
``msg_defs/msg/*.msg`` (package ``bearing_rig_msgs``) with every field's unit in a comment.

No ROS import: :mod:`bearing_rig_sim.nodes.common` turns a :class:`Topic`'s profile name into an
rclpy ``QoSProfile``; :mod:`bearing_rig_sim.bags.qos` into the profile stored in a bag.

Adding a topic: one :class:`Topic` constant below, added to :data:`TOPICS`; then regenerate the two
tables (``python -m bearing_rig_sim.interfaces`` rewrites them in place) and wire the publisher in its node.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

QosName = Literal["reliable", "reliable_stream", "sensor_data", "transient_local", "transient_stream"]
"""The contract's five QoS profiles (see :data:`QOS_DESCRIPTIONS`)."""
Reliability = Literal["reliable", "best_effort"]
Durability = Literal["volatile", "transient_local"]


@dataclass(frozen=True)
class QosEntry:
    """One QoS profile of the rig (keep-last history).

    Attributes:
        reliability: ``"reliable"`` or ``"best_effort"``.
        durability: ``"volatile"`` or ``"transient_local"`` (late joiners get the last messages).
        depth: history depth, messages.
        description: what it is, as the interface table says it.
    """

    reliability: Reliability
    durability: Durability
    depth: int
    description: str


QOS_TABLE: dict[str, QosEntry] = {
    # -- the contract's profiles: what the publishers offer ---------------------------------------
    "reliable": QosEntry("reliable", "volatile", 10, "reliable, volatile, depth 10"),
    "reliable_stream": QosEntry("reliable", "volatile", 5000, "reliable stream (reliable, depth 5000)"),
    "sensor_data": QosEntry("best_effort", "volatile", 100, "sensor data (best effort, depth 100)"),
    "transient_local": QosEntry("reliable", "transient_local", 10, "reliable, transient local, depth 10"),
    "transient_stream": QosEntry("reliable", "transient_local", 5000, "reliable, transient local, depth 5000"),
    # -- the rig's own readers: compatible with the profiles above, deeper ---------------------
    "pulse_reader": QosEntry("best_effort", "volatile", 10000, "the monitor's and shadow's pulse readers (best effort, depth 10000)"),
    "clock_reader": QosEntry("best_effort", "volatile", 100, "the load controller's /clock reader (best effort, depth 100)"),
    "force_reader": QosEntry("reliable", "volatile", 1000, "the simulator's axial-force reader (reliable, depth 1000)"),
}
"""Every QoS profile of the rig, by name: the one table (rclpy profiles are made from it by
:func:`bearing_rig_sim.nodes.common.qos_profile`).

``reliable_stream`` is the twin's high-rate streams: published reliably with a deep history, so
that a reader asking for reliability (the session's recorder) gets every sample even when its
process is held up for seconds, while readers asking for best effort (the monitor, the live view,
any sensor-data subscriber) are served as sensor data. The physical bench's counter may publish
the same topics as plain sensor data; every reader of the rig reads them best effort or records
whatever comes. The load cell's ``/rig/axial_load/force`` is such a stream too: as sensor data it
lost some 7 % of its samples to the recorder on a loaded host. So are the other periodic
streams (the load controller's state, the thermocouple and the torque meter, the shadow's
residuals, one per slip window): with the 10 of ``reliable`` a recorder held up for a fraction
of a second lost the odd sample (1 of 14965 torque readings in a load sweep under six busy loops)
as the writer's history let it go unacknowledged. ``reliable`` is for what comes on request or
about once a second (set-points, ``/diagnostics``, the shadow's calibration estimates).

``transient_stream``: the load set-points, sent ahead (a whole program's fixed starts at once
without real time): reliable, and transient local so that a reader whose match the writer saw
first still receives the set-points published before its own side matched (a volatile reader
starts at the writer's next sample, and an attached session lost its first set-point so);
depth 5000 keeps every set-point of any program for it. The monitor's statuses are published so
too: they come in bursts (one per closed slip window, 60 a second at 9000 rpm, and the ticks a
late pulse brings), and with the 10 of ``transient_local`` a reliable reader held up for a
fraction of a second lost some (4 of 3889 in a load sweep under six busy loops) as the writer's
history let them go unacknowledged; a late joiner receives the kept statuses in order, the
latest last.

``pulse_reader``: a reader's history drops the oldest sample once ``depth`` are waiting; at 100 a
monitor held up for a fraction of a second lost bursts of pulses; 10000 is some 20 s of pulses at
9000 rpm. ``clock_reader``: every tick of the load controller's 10 ms step period (100 ms of a
1 kHz clock), so the clock guard sees the stamps in a row it needs to confirm a restarted clock.
``force_reader``: a second of the load controller's force messages, of which the simulator applies
the latest; reliable, because the simulator paces on their stamps without real time, and a lost
last sample would hold it until its silence guard."""

QOS_DESCRIPTIONS: dict[str, str] = {
    name: QOS_TABLE[name].description for name in ("reliable", "reliable_stream", "sensor_data", "transient_local", "transient_stream")
}
"""What each profile of the contract (:data:`QosName`) is, as the interface table says it."""


@dataclass(frozen=True)
class Topic:
    """One topic of the contract.

    Attributes:
        name: the topic name, e.g. ``/rig/slip_status``.
        msgtype: the message type as ``pkg/msg/Name``.
        qos: the publisher's QoS profile (:data:`QosName`).
        rate: how often it is published, in words (sim or wall time as said).
        unit: the units of its fields.
        publisher: who publishes it (on the twin; on the bench where that differs).
        stamped: the message starts with a time stamp (``header.stamp``, or ``clock``).
        note: what the type column adds (field names), or empty.
    """

    name: str
    msgtype: str
    qos: QosName
    rate: str
    unit: str
    publisher: str
    stamped: bool = True
    note: str = ""

    @property
    def short_type(self) -> str:
        """The type as ``pkg/Name`` (the table's spelling)."""
        package, _, name = self.msgtype.split("/")
        return f"{package}/{name}"


@dataclass(frozen=True)
class Service:
    """One service of the contract.

    Attributes:
        name: the service name.
        srvtype: the service type as ``pkg/srv/Name``.
        unit: the units of its fields.
        server: who serves it, and what it does.
    """

    name: str
    srvtype: str
    unit: str
    server: str


CLOCK = Topic("/clock", "rosgraph_msgs/msg/Clock", "reliable_stream", "1 kHz (sim)", "s", "simulator, replay")
SPINDLE_COMMAND = Topic(
    "/rig/spindle/command",
    "bearing_rig_msgs/msg/SpindleCommand",
    "transient_local",
    "one per segment (stamp: its start)",
    "rad/s, rad/s^2, s",
    "program runner",
)
SPINDLE_PULSES = Topic(
    "/rig/spindle/pulses",
    "bearing_rig_msgs/msg/FibreOpticPulse",
    "reliable_stream",
    "strips x rev/s",
    "s",
    "simulator (bench: pulse counter)",
)
CAGE_PULSES = Topic(
    "/rig/cage/pulses",
    "bearing_rig_msgs/msg/FibreOpticPulse",
    "reliable_stream",
    "strips x rev/s",
    "s",
    "simulator (bench: pulse counter)",
)
SPEEDS = Topic(
    "/rig/speeds",
    "sensor_msgs/msg/JointState",
    "reliable_stream",
    "1 kHz",
    "rad/s (velocity), rad (position)",
    "simulator (bench: pulse counter)",
    note="names `inner_ring`, `cage`",
)
TRUTH = Topic("/rig/truth", "bearing_rig_msgs/msg/SimulatorTruth", "reliable_stream", "100 Hz", "see msg", "simulator only")
AXIAL_LOAD_SETPOINT = Topic(
    "/rig/axial_load/setpoint",
    "std_msgs/msg/Float64",
    "reliable",
    "on request",
    "N",
    "user (the manual input: in force on arrival)",
    stamped=False,
)
LOAD_SETPOINT = Topic(
    "/rig/load/setpoint",
    "geometry_msgs/msg/WrenchStamped",
    "transient_stream",
    "one per segment (stamp: its start, sent ahead)",
    "N, N m",
    "program runner, user",
    note="the whole load set-point, in force from header.stamp (0: on arrival): force.z axial, force.x/y radial "
    "(magnitude and azimuth), torque.x/y a moment; torque.z unused; up to the rig file's limits",
)
AXIAL_LOAD_STATE = Topic("/rig/axial_load/state", "bearing_rig_msgs/msg/AxialLoadState", "reliable_stream", "100 Hz (sim)", "N, A", "load controller")
AXIAL_LOAD_FORCE = Topic(
    "/rig/axial_load/force",
    "geometry_msgs/msg/WrenchStamped",
    "reliable_stream",
    "each `/clock` advance (up to 1 kHz)",
    "N",
    "load controller (bench: load cell)",
    note="force.z",
)
BEARING_AXIAL_FORCE = Topic(
    "/rig/bearing/axial_force",
    "geometry_msgs/msg/WrenchStamped",
    "reliable_stream",
    "each `/clock` advance (up to 1 kHz)",
    "N",
    "load controller -> simulator",
    note="force.z axial, force.x/y radial (magnitude and azimuth), torque.x/y a moment (frees the tilts); up to the rig file's limits",
)
SLIP_STATUS = Topic(
    "/rig/slip_status",
    "bearing_rig_msgs/msg/SlipStatus",
    "transient_stream",
    "10 Hz + each closed slip window (one per cage revolution)",
    "rad/s, %",
    "monitor",
)
TWIN_RESIDUAL = Topic(
    "/twin/residual",
    "bearing_rig_msgs/msg/ShadowResidual",
    "reliable_stream",
    "one per closed slip window",
    "rad/s, N, %",
    "shadow",
    note="measured and predicted slip, residual, band",
)
TWIN_ESTIMATE = Topic(
    "/twin/calibration_estimate",
    "bearing_rig_msgs/msg/ShadowEstimate",
    "reliable",
    "one per steady window (re-calibration on)",
    "the parameter's",
    "shadow",
)
TWIN_TEMPERATURE_RESIDUAL = Topic(
    "/twin/outer_ring/temperature_residual",
    "geometry_msgs/msg/Vector3Stamped",
    "reliable_stream",
    "one per compared slip window with a thermocouple reading",
    "K (x, y), degC (z)",
    "shadow",
    note="x the outer-ring thermocouple's residual (measured minus predicted), y its threshold (the band's half-width, "
    "config/shadow.yaml), z the twin's predicted reading",
)
TWIN_TORQUE_RESIDUAL = Topic(
    "/twin/housing/torque_residual",
    "geometry_msgs/msg/Vector3Stamped",
    "reliable_stream",
    "one per compared slip window with torque-meter samples",
    "N m",
    "shadow",
    note="x the housing torque meter's residual (measured minus predicted), y its threshold (the band's half-width, "
    "config/shadow.yaml), z the twin's predicted friction torque",
)
OUTER_RING_TEMPERATURE = Topic(
    "/rig/outer_ring/temperature",
    "sensor_msgs/msg/Temperature",
    "reliable_stream",
    "10 Hz (sim)",
    "degC (the message type's unit), variance K^2",
    "simulator (bench: outer-ring thermocouple)",
    note="temperature",
)
HOUSING_TORQUE = Topic(
    "/rig/housing/torque",
    "geometry_msgs/msg/WrenchStamped",
    "reliable_stream",
    "100 Hz (sim)",
    "N m",
    "simulator (bench: torque meter on the housing)",
    note="torque.z, the friction torque about the spindle axis",
)
SESSION_PROGRESS = Topic(
    "/rig/session/progress",
    "std_msgs/msg/Header",
    "reliable_stream",
    "each take of the recorder's queues that found a new clock (at most 50 Hz wall)",
    "s",
    "session",
    note="stamp: the latest `/clock` the session has taken and recorded; frame_id: the program's name. "
    "Without real time the simulator runs at most 2 s of sim time past it",
)
DIAGNOSTICS = Topic("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray", "reliable", "1 Hz + on change", "-", "every node")

TOPICS: tuple[Topic, ...] = (
    CLOCK,
    SPINDLE_COMMAND,
    SPINDLE_PULSES,
    CAGE_PULSES,
    SPEEDS,
    TRUTH,
    AXIAL_LOAD_SETPOINT,
    LOAD_SETPOINT,
    AXIAL_LOAD_STATE,
    AXIAL_LOAD_FORCE,
    BEARING_AXIAL_FORCE,
    SLIP_STATUS,
    TWIN_RESIDUAL,
    TWIN_ESTIMATE,
    TWIN_TEMPERATURE_RESIDUAL,
    TWIN_TORQUE_RESIDUAL,
    OUTER_RING_TEMPERATURE,
    HOUSING_TORQUE,
    SESSION_PROGRESS,
    DIAGNOSTICS,
)
"""Every topic of the contract, in the table's order. The session records all of them."""

PULSE_TOPICS: dict[str, Topic] = {"spindle": SPINDLE_PULSES, "cage": CAGE_PULSES}
"""The two fibre-optic pulse streams by shaft."""

AXIAL_LOAD_SET = Service("/rig/axial_load/set", "bearing_rig_msgs/srv/SetAxialLoad", "N", "load controller (server)")
AXIAL_LOAD_RESET_FAULT = Service(
    "/rig/axial_load/reset_fault",
    "std_srvs/srv/Trigger",
    "-",
    "load controller (server): clears a latched interlock once its cause is gone",
)
AXIAL_LOAD_CLUTCH = Service(
    "/rig/axial_load/clutch",
    "std_srvs/srv/SetBool",
    "-",
    "load controller (server): engage (true) / release the magnet clutch",
)

SERVICES: tuple[Service, ...] = (AXIAL_LOAD_SET, AXIAL_LOAD_RESET_FAULT, AXIAL_LOAD_CLUTCH)
"""Every service of the contract."""

_BY_NAME: dict[str, Topic] = {t.name: t for t in TOPICS}


def topic(name: str) -> Topic:
    """The contract's topic of that name.

    Raises:
        KeyError: no such topic in the contract (the message names it).
    """
    try:
        return _BY_NAME[name]
    except KeyError:
        raise KeyError(f"{name!r} is not a topic of the interface contract") from None


def contract_qos(name: str) -> QosName | None:
    """The QoS profile name the contract gives a topic, or None for a topic outside it."""
    found = _BY_NAME.get(name)
    return found.qos if found is not None else None


def markdown_table() -> str:
    """The interface table (markdown) of ``docs/interfaces.md`` and the README, services placed
    after the set-point topic as the table has always shown them."""
    rows = [
        "| topic | type | QoS | rate | unit | publisher |",
        "|---|---|---|---|---|---|",
    ]
    for t in TOPICS:
        kind = f"`{t.short_type}`" + (f" ({t.note})" if t.note else "")
        rows.append(f"| `{t.name}` | {kind} | {QOS_DESCRIPTIONS[t.qos]} | {t.rate} | {t.unit} | {t.publisher} |")
        if t is AXIAL_LOAD_SETPOINT:
            for s in SERVICES:
                rows.append(f"| `{s.name}` (service) | `{s.srvtype}` | service | on request | {s.unit} | {s.server} |")
    return "\n".join(rows) + "\n"


TABLE_DOCUMENTS = ("docs/interfaces.md", "README.md")
"""The documents, relative to the repository, that carry :func:`markdown_table`."""

_TABLE_PATTERN = r"\| topic \| type \| QoS \| rate \| unit \| publisher \|\n(?:\|.*\|\n)+"


def write_tables(root: Path) -> list[Path]:
    """Replace the interface table in each of :data:`TABLE_DOCUMENTS` under ``root`` by
    :func:`markdown_table`; returns the files that changed."""
    changed = []
    for name in TABLE_DOCUMENTS:
        path = root / name
        text = path.read_text(encoding="utf-8")
        new = re.sub(_TABLE_PATTERN, lambda _m: markdown_table(), text, count=1)
        if new != text:
            path.write_text(new, encoding="utf-8")
            changed.append(path)
    return changed


if __name__ == "__main__":  # pragma: no cover - the docs' regeneration command
    for changed_file in write_tables(Path(__file__).resolve().parent.parent):
        print(f"updated {changed_file}")
