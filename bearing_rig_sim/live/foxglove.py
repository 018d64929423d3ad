"""The rig's topics served live to the Foxglove app over the Foxglove WebSocket protocol (no ROS).

:class:`FoxgloveLiveView` is a message writer (``add_topic``, ``write``: the same protocol as the
bag writer's, :class:`~bearing_rig_sim.session.recorder.MessageWriter`), so whatever feeds the
recorder feeds the view: ``bearing-rig run --foxglove [PORT]`` tees the recorded stream to it,
``bearing-rig replay --foxglove [PORT]`` the replayed one. Each topic becomes a channel with its
``ros2msg`` schema (the type's ``.msg`` text with its dependencies, as rosbag2 stores it in MCAP),
and messages go out as the serialized CDR the publisher sent, with their log time (sim time, ns),
so the app decodes the rig's own types (``bearing_rig_msgs``) and plots them on the rig's clock.

The server is the ``foxglove-sdk`` package's (its own threads; ``write`` only queues), bound to
``127.0.0.1`` only: the view is for the machine the rig runs on (an SSH tunnel takes it further).
Open the Foxglove app, "Open connection", "Foxglove WebSocket", ``ws://localhost:PORT``, then
import the layout ``config/foxglove/rig.json`` (docs/guide.md, "Live view in Foxglove").
"""

from __future__ import annotations

from typing import Any
from collections.abc import Callable

from bearing_rig_sim.bags.cdr import header_stamp_ns
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import CLOCK

__all__ = ["DEFAULT_PORT", "HOST", "FoxgloveLiveView", "TeeWriter"]

DEFAULT_PORT = 8765
"""The Foxglove app's default WebSocket port."""

HOST = "127.0.0.1"
"""The view listens on the loopback interface only."""


class FoxgloveLiveView:
    """A Foxglove WebSocket server carrying the topics written to it.

    Args:
        port: TCP port on 127.0.0.1 (0: any free port; :attr:`port` tells which).
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
        try:
            self._server = foxglove.start_server(name=name, host=HOST, port=port, context=self._context)
        except Exception as exc:
            raise RigError(f"--foxglove: cannot serve on {HOST}:{port}: {' '.join(str(exc).split())}") from None

    @property
    def port(self) -> int:
        """The TCP port the server listens on."""
        return int(self._server.port)

    @property
    def url(self) -> str:
        """What to type into the app's "Open connection" dialog."""
        return f"ws://localhost:{self.port}"

    def add_topic(self, name: str, msgtype: str, qos: str = "") -> None:
        """Advertise ``name`` of type ``pkg/msg/Name`` with its ``ros2msg`` schema."""
        if name in self._channels:
            return
        schema = self._foxglove.Schema(name=msgtype, encoding="ros2msg", data=self._schema_text(msgtype).encode("utf-8"))
        self._channels[name] = self._foxglove.Channel(name, schema=schema, message_encoding="cdr", context=self._context)

    def write(self, topic: str, log_time_ns: int, data: bytes) -> None:
        """Send one serialized message to the subscribed clients (dropped when none is)."""
        channel = self._channels.get(topic)
        if channel is not None:
            channel.log(bytes(data), log_time=int(log_time_ns))

    def close(self) -> None:
        """Stop the server (clients see the connection close)."""
        for channel in self._channels.values():
            channel.close()
        self._channels.clear()
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
