"""The rig's topics served live to the Foxglove app over the Foxglove WebSocket protocol (no ROS).

:class:`FoxgloveLiveView` is a message writer (``add_topic``, ``write``: the same protocol as the
bag writer's, :class:`~bearing_rig_sim.session.recorder.MessageWriter`), so whatever feeds the
recorder feeds the view: ``bearing-rig run --foxglove [PORT]`` tees the recorded stream to it,
``bearing-rig replay --foxglove [PORT]`` the replayed one. Each topic becomes a channel with its
``ros2msg`` schema (the type's ``.msg`` text with its dependencies, as rosbag2 stores it in MCAP),
and messages go out as the serialized CDR the publisher sent, with their log time (sim time, ns),
so the app decodes the rig's own types (``bearing_rig_msgs``) and plots them on the rig's clock.

Two servers carry the same channels, one per subprotocol of the Foxglove WebSocket protocol, both
bound to ``127.0.0.1`` only (the view is for the machine the rig runs on; an SSH tunnel takes it
further):

* ``ws://localhost:PORT``: the ``foxglove-sdk`` package's server (its own threads; ``write`` only
  queues). It speaks ``foxglove.sdk.v1`` only, what the Foxglove app and the SDK's clients offer.
* ``ws://localhost:PORT+1``: the ``foxglove-websocket`` package's server (Foxglove's reference
  Python implementation of the protocol, on an asyncio loop in a thread of its own). It speaks
  ``foxglove.websocket.v1``, the spec's subprotocol, the one foxglove_bridge, Lichtblick and the
  tools built on ``@foxglove/ws-protocol`` offer. No foxglove-sdk release accepts it (the SDK's
  handshake answers HTTP 400 to a client offering only the older name), and the messages used
  here (serverInfo, advertise, subscribe, messageData) are the same in both, so a second,
  maintained server of the same protocol is the smallest sound way to serve both kinds of client.
  Messages go to it only while a client subscribes to their channel.

Open the Foxglove app, "Open connection", "Foxglove WebSocket", ``ws://localhost:PORT``, then
import the layout ``config/foxglove/rig.json`` (docs/ros.md, "Foxglove").
"""

from __future__ import annotations

import asyncio
import threading
from typing import Any
from collections.abc import Callable

from bearing_rig_sim.bags.cdr import header_stamp_ns
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import CLOCK

__all__ = ["DEFAULT_PORT", "HOST", "SUBPROTOCOLS", "FoxgloveLiveView", "TeeWriter"]

DEFAULT_PORT = 8765
"""The Foxglove app's default WebSocket port."""

HOST = "127.0.0.1"
"""The view listens on the loopback interface only."""

SUBPROTOCOLS = ("foxglove.sdk.v1", "foxglove.websocket.v1")
"""The subprotocol of the server on ``port`` and of the one on ``port + 1``."""

START_TIMEOUT_S = 10.0
"""Longest wait for the second server to listen or to add a channel, s."""


class _WebsocketV1Server:
    """The ``foxglove-websocket`` server (subprotocol ``foxglove.websocket.v1``) on an asyncio loop
    in a daemon thread; ``add_channel`` waits for the channel id, ``send`` only schedules.

    Raises:
        RigError: the package is missing or the port cannot be bound.
    """

    def __init__(self, port: int, name: str) -> None:
        try:
            from foxglove_websocket.server import FoxgloveServer, FoxgloveServerListener
        except ImportError as exc:  # pragma: no cover - pinned in requirements.lock
            raise RigError(f"--foxglove needs the foxglove-websocket package: {exc}") from None
        self.subscribed: set[int] = set()
        """Channel ids some client subscribes to (changed on the server's loop only)."""
        subscribed = self.subscribed

        class Listener(FoxgloveServerListener):
            def on_subscribe(self, server: Any, channel_id: int) -> None:
                subscribed.add(channel_id)

            def on_unsubscribe(self, server: Any, channel_id: int) -> None:
                subscribed.discard(channel_id)

        self._loop = asyncio.new_event_loop()
        self._thread = threading.Thread(target=self._loop.run_forever, name="foxglove-websocket", daemon=True)
        self._thread.start()

        async def start() -> tuple[Any, int]:
            server = FoxgloveServer(HOST, port, name, supported_encodings=["cdr"])
            server.set_listener(Listener())
            server.start()
            opened = await server.wait_opened()
            return server, int(opened.sockets[0].getsockname()[1])

        try:
            self._server, self.port = self._call(start())
        except Exception as exc:
            self._loop.call_soon_threadsafe(self._loop.stop)
            raise RigError(f"--foxglove: cannot serve on {HOST}:{port}: {' '.join(str(exc).split()) or type(exc).__name__}") from None

    def _call(self, coroutine: Any) -> Any:
        return asyncio.run_coroutine_threadsafe(coroutine, self._loop).result(timeout=START_TIMEOUT_S)

    def add_channel(self, topic: str, msgtype: str, schema: str) -> int:
        """Advertise a channel; its id."""
        return int(
            self._call(self._server.add_channel({"topic": topic, "encoding": "cdr", "schemaName": msgtype, "schema": schema, "schemaEncoding": "ros2msg"}))
        )

    def send(self, channel_id: int, log_time_ns: int, data: bytes) -> None:
        """Queue one message for the clients subscribed to ``channel_id`` (none: dropped here)."""
        if channel_id in self.subscribed:
            asyncio.run_coroutine_threadsafe(self._server.send_message(channel_id, log_time_ns, data), self._loop)

    def close(self) -> None:
        async def stop() -> None:
            self._server.close()
            await self._server.wait_closed()

        try:
            self._call(stop())
        finally:
            self._loop.call_soon_threadsafe(self._loop.stop)
            self._thread.join(timeout=START_TIMEOUT_S)


class FoxgloveLiveView:
    """Foxglove WebSocket servers carrying the topics written to them (see the module docstring).

    Args:
        port: TCP port on 127.0.0.1 of the ``foxglove.sdk.v1`` server (0: any free port;
            :attr:`port` tells which); the ``foxglove.websocket.v1`` server takes ``port + 1``
            (any free one with 0; :attr:`websocket_v1_port`).
        schema_text: the ``ros2msg`` schema text of a type ``pkg/msg/Name``.
        name: the server's name shown by the app.

    Raises:
        RigError: foxglove-sdk is not installed, or the port cannot be bound.
    """

    def __init__(self, port: int, schema_text: Callable[[str], str], name: str = "bearing-rig") -> None:
        try:
            import foxglove
        except ImportError as exc:  # pragma: no cover - pinned in requirements.lock
            raise RigError(f"--foxglove needs the foxglove-sdk package: {exc}") from None
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
            raise RigError(f"--foxglove: the port must be a whole number 0-65535, got {port!r}")
        self._foxglove = foxglove
        self._schema_text = schema_text
        self._context = foxglove.Context()
        self._channels: dict[str, Any] = {}
        if port == 65535:
            raise RigError("--foxglove: the port must leave port + 1 for the second server (at most 65534)")
        try:
            self._server = foxglove.start_server(name=name, host=HOST, port=port, context=self._context)
        except Exception as exc:
            raise RigError(f"--foxglove: cannot serve on {HOST}:{port}: {' '.join(str(exc).split())}") from None
        try:
            self._v1 = _WebsocketV1Server(port + 1 if port else 0, name)
        except RigError:
            self._server.stop()
            raise
        self._v1_channels: dict[str, int] = {}

    @property
    def port(self) -> int:
        """The TCP port the server listens on."""
        return int(self._server.port)

    @property
    def websocket_v1_port(self) -> int:
        """The TCP port of the ``foxglove.websocket.v1`` server."""
        return self._v1.port

    @property
    def url(self) -> str:
        """What to type into the app's "Open connection" dialog."""
        return f"ws://localhost:{self.port}"

    @property
    def urls(self) -> str:
        """Both servers, for a user: each URL with its subprotocol."""
        return f"{self.url} ({SUBPROTOCOLS[0]}), ws://localhost:{self.websocket_v1_port} ({SUBPROTOCOLS[1]})"

    def add_topic(self, name: str, msgtype: str, qos: str = "") -> None:
        """Advertise ``name`` of type ``pkg/msg/Name`` with its ``ros2msg`` schema."""
        if name in self._channels:
            return
        text = self._schema_text(msgtype)
        schema = self._foxglove.Schema(name=msgtype, encoding="ros2msg", data=text.encode("utf-8"))
        self._channels[name] = self._foxglove.Channel(name, schema=schema, message_encoding="cdr", context=self._context)
        self._v1_channels[name] = self._v1.add_channel(name, msgtype, text)

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None:
        """Send one serialized message to the subscribed clients (dropped when none is)."""
        channel = self._channels.get(topic)
        if channel is not None:
            payload = bytes(data)
            channel.log(payload, log_time=int(log_time_ns))
            self._v1.send(self._v1_channels[topic], int(log_time_ns), payload)

    def close(self) -> None:
        """Stop the server (clients see the connection close)."""
        for channel in self._channels.values():
            channel.close()
        self._channels.clear()
        self._v1_channels.clear()
        try:
            self._v1.close()
        finally:
            self._server.stop()


class TeeWriter:
    """A message writer writing to a main writer and to a live view (see
    :class:`~bearing_rig_sim.session.recorder.MessageWriter`); a failure of the view never loses
    a recorded message."""

    def __init__(self, main: Any, view: FoxgloveLiveView) -> None:
        self.main = main
        self.view: FoxgloveLiveView | None = view
        self.view_error = ""
        """Why the view stopped being fed ("" while it is)."""

    def add_topic(self, name: str, msgtype: str, qos: str) -> None:
        self.main.add_topic(name, msgtype, qos)
        self._to_view(lambda view: view.add_topic(name, msgtype, qos))

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None:
        self.main.write(topic, log_time_ns, data)
        self._to_view(lambda view: view.write(topic, log_time_ns, data))

    def _to_view(self, action: Callable[[FoxgloveLiveView], None]) -> None:
        if self.view is None:
            return
        try:
            action(self.view)
        except Exception as exc:
            self.view_error = " ".join(str(exc).split()) or type(exc).__name__
            self.view = None


class LiveReplaySink:
    """A replay sink (:class:`~bearing_rig_sim.replay.player.ReplaySink`) that also shows what it
    publishes in a live view: ``bearing-rig replay --foxglove``. Each message goes to the view
    with its own stamp as log time (the one the recording used), a message without a stamp (a
    set-point) with the latest ``/clock``'s.

    Args:
        inner: the sink that publishes (the ROS one).
        view: the live view.
        msgtypes: ``pkg/msg/Name`` of each topic that may be published.
    """

    def __init__(self, inner: Any, view: FoxgloveLiveView, msgtypes: dict[str, str]) -> None:
        self.inner = inner
        self.view = view
        self._clock_ns = 0
        for name, msgtype in msgtypes.items():
            view.add_topic(name, msgtype)

    def can_publish(self, topic: str) -> bool:
        return bool(self.inner.can_publish(topic))

    def publish(self, topic: str, data: bytes) -> None:
        self.inner.publish(topic, data)
        stamp = header_stamp_ns(data)
        if topic == CLOCK.name and stamp is not None:
            self._clock_ns = stamp
        self.view.write(topic, stamp if stamp else self._clock_ns, data)
