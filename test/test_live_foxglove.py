"""The Foxglove live view, read by a client of the Foxglove WebSocket protocol written here from
the protocol's specification (foxglove/ws-protocol, ``docs/spec.md``: JSON ``serverInfo`` and
``advertise``; a ``subscribe`` request; binary ``messageData`` frames: opcode 0x01, uint32
subscription id, uint64 log time, payload, little endian). The client offers the spec's
subprotocol ``foxglove.websocket.v1`` and its successor ``foxglove.sdk.v1``, which foxglove-sdk
servers choose (the messages used here are the same in both), as the Foxglove app does. The payloads are decoded with ``mcap_ros2``'s decoder from the schema text the server
advertised, as the Foxglove app does, not with the project's code. Localhost only.
"""

from __future__ import annotations

import json
import math
import signal
import struct
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

websockets_sync = pytest.importorskip("websockets.sync.client")
pytest.importorskip("foxglove")

from mcap.records import Schema  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402

from bearing_rig_sim.live.foxglove import FoxgloveLiveView  # noqa: E402
from bearing_rig_sim.bags.typestore import msg_definition_text, rig_typestore  # noqa: E402
from conftest import time_left  # noqa: E402

SUBPROTOCOLS = ["foxglove.websocket.v1", "foxglove.sdk.v1"]
MESSAGE_DATA = 0x01


class ProtocolClient:
    """A minimal Foxglove WebSocket client (see the module docstring)."""

    def __init__(self, url: str) -> None:
        # No keepalive pings: a test that stops reading for a moment must not lose the connection.
        self.ws = websockets_sync.connect(url, subprotocols=SUBPROTOCOLS, open_timeout=10, ping_interval=None, max_queue=None)
        assert self.ws.subprotocol in SUBPROTOCOLS
        self.server_info: dict[str, Any] = {}
        self.channels: dict[int, dict[str, Any]] = {}
        self.subscriptions: dict[int, int] = {}
        self.received: list[tuple[str, int, bytes]] = []
        """(topic, log time ns, payload) of every messageData frame."""
        self._decoded: dict[str, tuple[int, list[Any]]] = {}

    def pump(self, timeout: float = 0.2) -> None:
        """Read the frames that arrived, waiting up to ``timeout`` s for the first."""
        try:
            frame = self.ws.recv(timeout=timeout)
        except TimeoutError:
            return
        self._take(frame)
        for _ in range(10_000):
            try:
                frame = self.ws.recv(timeout=0)
            except TimeoutError:
                return
            self._take(frame)

    def _take(self, frame: str | bytes) -> None:
        if isinstance(frame, str):
            msg = json.loads(frame)
            if msg["op"] == "serverInfo":
                self.server_info = msg
            elif msg["op"] == "advertise":
                for channel in msg["channels"]:
                    self.channels[channel["id"]] = channel
            elif msg["op"] == "unadvertise":
                for channel_id in msg["channelIds"]:
                    self.channels.pop(channel_id, None)
        else:
            assert frame[0] == MESSAGE_DATA, frame[:1]
            subscription, log_time = struct.unpack_from("<IQ", frame, 1)
            self.received.append((self.subscriptions[subscription], log_time, bytes(frame[13:])))

    def pump_until(self, condition: Any, timeout: float, also: Any = None) -> bool:
        deadline = time.monotonic() + timeout
        while not condition():
            if time.monotonic() > deadline:
                return False
            if also is not None:
                also()
            self.pump()
        return True

    def channel(self, topic: str) -> dict[str, Any]:
        return next(c for c in self.channels.values() if c["topic"] == topic)

    def subscribe(self, *topics: str) -> None:
        subs = []
        for topic in topics:
            sub_id = len(self.subscriptions) + 1
            self.subscriptions[sub_id] = topic
            subs.append({"id": sub_id, "channelId": self.channel(topic)["id"]})
        self.ws.send(json.dumps({"op": "subscribe", "subscriptions": subs}))

    def decoded(self, topic: str) -> list[Any]:
        """The messages received on ``topic``, decoded from the advertised schema (each once)."""
        channel = self.channel(topic)
        assert channel["encoding"] == "cdr" and channel["schemaEncoding"] == "ros2msg"
        schema = Schema(id=1, name=channel["schemaName"], encoding="ros2msg", data=channel["schema"].encode())
        decoder = DecoderFactory().decoder_for("cdr", schema)
        assert decoder is not None
        done, messages = self._decoded.get(topic, (0, []))
        messages.extend(decoder(payload) for name, _t, payload in self.received[done:] if name == topic)
        self._decoded[topic] = (len(self.received), messages)
        return messages

    def close(self) -> None:
        self.ws.close()


def test_a_protocol_client_receives_and_decodes_rig_messages() -> None:
    store = rig_typestore()
    view = FoxgloveLiveView(0, msg_definition_text)
    client = None
    try:
        view.add_topic("/rig/slip_status", "bearing_rig_msgs/msg/SlipStatus")
        view.add_topic("/rig/speeds", "sensor_msgs/msg/JointState")
        client = ProtocolClient(view.url)
        assert client.pump_until(lambda: len(client.channels) == 2 and client.server_info, timeout=time_left())
        client.subscribe("/rig/slip_status", "/rig/speeds")

        status = store.deserialize_cdr(_slip_status_cdr(store), "bearing_rig_msgs/msg/SlipStatus")
        speeds = store.deserialize_cdr(_speeds_cdr(store), "sensor_msgs/msg/JointState")

        def send() -> None:  # until the server has taken the subscription
            view.write("/rig/slip_status", 2_500_000_000, bytes(store.serialize_cdr(status, "bearing_rig_msgs/msg/SlipStatus")))
            view.write("/rig/speeds", 2_500_000_001, bytes(store.serialize_cdr(speeds, "sensor_msgs/msg/JointState")))

        assert client.pump_until(lambda: {t for t, _, _ in client.received} == {"/rig/slip_status", "/rig/speeds"}, 10.0, also=send)
        got_status = client.decoded("/rig/slip_status")[0]
        assert (got_status.state, got_status.slip_rate, got_status.criterion) == (2, pytest.approx(3.25), "time")
        assert got_status.header.stamp.sec == 2 and got_status.header.stamp.nanosec == 500_000_000
        got_speeds = client.decoded("/rig/speeds")[0]
        assert list(got_speeds.name) == ["inner_ring", "cage"]
        assert list(got_speeds.velocity) == [pytest.approx(157.08), pytest.approx(66.1)]
        assert {t for _, t, _ in client.received} >= {2_500_000_000, 2_500_000_001}
    finally:
        if client is not None:
            client.close()
        view.close()


def _slip_status_cdr(store: Any) -> bytes:
    Time = store.types["builtin_interfaces/msg/Time"]
    Header = store.types["std_msgs/msg/Header"]
    cls = store.types["bearing_rig_msgs/msg/SlipStatus"]
    msg = cls(
        header=Header(stamp=Time(sec=2, nanosec=500_000_000), frame_id="bearing"),
        inner_ring_speed=157.08,
        cage_speed=65.0,
        theoretical_cage_speed=67.2,
        slip_rate=3.25,
        fitted_slope=-0.01,
        critical_slope=-0.03,
        state=2,
        criterion="time",
        confidence=0.9,
        window_revolutions=1,
        detail="",
        axial_load=100.0,
        kinematic_slip_rate=3.6,
        loaded_contact_angle=0.2845,
        sweep_speed=104.72,
        sweep_stable_from=300.0,
        sweep_verdict="stable from 300 N",
    )
    return bytes(store.serialize_cdr(msg, "bearing_rig_msgs/msg/SlipStatus"))


def _speeds_cdr(store: Any) -> bytes:
    Time = store.types["builtin_interfaces/msg/Time"]
    Header = store.types["std_msgs/msg/Header"]
    cls = store.types["sensor_msgs/msg/JointState"]
    msg = cls(
        header=Header(stamp=Time(sec=2, nanosec=500_000_001), frame_id=""),
        name=["inner_ring", "cage"],
        position=np.array([1.0, 0.4]),
        velocity=np.array([157.08, 66.1]),
        effort=np.array([], dtype=np.float64),
    )
    return bytes(store.serialize_cdr(msg, "sensor_msgs/msg/JointState"))


@pytest.mark.ros
@pytest.mark.slow
def test_a_live_session_serves_speeds_and_slip_status(ros_graph: Any, tmp_path: Path) -> None:
    program = tmp_path / "hold.yaml"
    program.write_text(
        "name: hold\nbearing: bearings/h7006c.yaml\nstability_criterion: time\nsegments:\n"
        "  - {name: n1500, speed_rpm: 1500, ramp_s: 0.5, axial_load_n: 100, dwell_s: 600}\n",
        encoding="utf-8",
    )
    session = ros_graph.spawn_python("-m", "bearing_rig_sim.cli", "run", str(program), "--bag-dir", str(tmp_path / "bags"), "--foxglove", "0")
    client = None
    try:
        assert session.stdout is not None
        url = ""
        for line in session.stdout:
            if line.startswith("Foxglove live view: "):
                url = line.split()[3]
                break
        assert url.startswith("ws://localhost:"), url
        client = ProtocolClient(url)
        topics = ("/rig/slip_status", "/rig/speeds")
        assert client.pump_until(lambda: {c["topic"] for c in client.channels.values()} >= set(topics), timeout=time_left()), client.channels
        client.subscribe(*topics)

        def stable_slip() -> bool:
            return any(s.state in (1, 2) and math.isfinite(s.slip_rate) for s in client.decoded("/rig/slip_status"))

        assert client.pump_until(lambda: bool(client.decoded("/rig/speeds")) and stable_slip(), timeout=time_left())
        speeds = client.decoded("/rig/speeds")[-1]
        assert list(speeds.name) == ["inner_ring", "cage"] and speeds.velocity[0] > 0.0
        status = next(s for s in client.decoded("/rig/slip_status") if math.isfinite(s.slip_rate))
        assert 0.0 < status.slip_rate < 20.0 and status.criterion == "time"
    finally:
        if client is not None:
            client.close()
        session.send_signal(signal.SIGINT)
        session.communicate(timeout=time_left())
    assert session.returncode == 130


class _Sent:
    """A replay sink keeping what it is given."""

    def __init__(self) -> None:
        self.sent: list[str] = []

    def can_publish(self, topic: str) -> bool:
        return True

    def publish(self, topic: str, data: bytes) -> None:
        self.sent.append(topic)


def test_a_replay_is_shown_with_its_stamps(tmp_path: Path) -> None:
    from test_replay_player import TIMES_NS, pulse_bytes, write_pulse_bag  # the replay tests' bag of cage pulses

    from bearing_rig_sim.bags import open_bag, rig_typestore
    from bearing_rig_sim.live.foxglove import LiveReplaySink
    from bearing_rig_sim.replay.player import ReplayOptions, replay_bag

    bag_path = tmp_path / "pulses"
    write_pulse_bag(bag_path, TIMES_NS, with_clock=True)
    view = FoxgloveLiveView(0, msg_definition_text)
    client = None
    try:
        with open_bag(bag_path) as bag:
            inner = _Sent()
            sink = LiveReplaySink(inner, view, {name: info.msgtype for name, info in bag.topics.items()})
            client = ProtocolClient(view.url)
            assert client.pump_until(lambda: {c["topic"] for c in client.channels.values()} == {"/clock", "/rig/cage/pulses"}, 10.0)
            client.subscribe("/rig/cage/pulses")
            assert client.pump_until(lambda: bool(client.received), 30.0, also=lambda: replay_bag(bag, sink, ReplayOptions(rate=100.0)))
        pulses = client.decoded("/rig/cage/pulses")
        # each decoded pulse is the bag's pulse of that index, field for field (the generated
        # pulses have random strings, some of them empty)
        store = rig_typestore()
        for p in pulses:
            sent = store.deserialize_cdr(pulse_bytes(p.pulse_index, TIMES_NS[p.pulse_index]), "bearing_rig_msgs/msg/FibreOpticPulse")
            assert (p.sensor_id, p.strip_id, p.revolution) == (sent.sensor_id, sent.strip_id, sent.revolution)
            assert p.header.stamp.sec * 10**9 + p.header.stamp.nanosec == TIMES_NS[p.pulse_index]
        stamps = {t for topic, t, _ in client.received if topic == "/rig/cage/pulses"}
        assert stamps <= set(TIMES_NS) and stamps  # log time = the pulse's own stamp
        assert inner.sent.count("/rig/cage/pulses") >= len(TIMES_NS)  # still published to ROS
    finally:
        if client is not None:
            client.close()
        view.close()


def test_the_shipped_layout_plots_fields_that_exist() -> None:
    """config/foxglove/rig.json: every panel of the tree is configured, and every plotted path
    names a topic of the interface contract and a field of its message type."""
    from bearing_rig_sim.config import config_path
    from bearing_rig_sim.interfaces import TOPICS

    layout = json.loads(config_path("foxglove", "rig.json").read_text(encoding="utf-8"))
    panels: list[str] = []

    def walk(node: Any) -> None:
        if isinstance(node, str):
            panels.append(node)
        else:
            walk(node["first"])
            walk(node["second"])

    walk(layout["layout"])
    assert sorted(panels) == sorted(layout["configById"])
    types = {t.name: t.msgtype for t in TOPICS}
    store = rig_typestore()
    paths = [p["value"] for config in layout["configById"].values() for p in config.get("paths", [])]
    assert paths and layout["configById"]["DiagnosticSummary!rig"]["topicToRender"] == "/diagnostics"
    for path in paths:
        topic, *fields = path.split(".")
        assert topic in types, path
        msgtype = types[topic]
        for field in fields:
            name = field.split("[")[0]
            names = [f[0] for f in store.fielddefs[msgtype][1]]
            assert name in names, (path, names)
            kind = dict(store.fielddefs[msgtype][1])[name]
            msgtype = kind[1] if kind[0].name == "NAME" else (kind[1][0][1] if kind[0].name in ("ARRAY", "SEQUENCE") and kind[1][0][0].name == "NAME" else "")
    for topic in ("/rig/speeds", "/rig/slip_status", "/rig/axial_load/state"):
        assert any(p.startswith(topic + ".") for p in paths), topic
