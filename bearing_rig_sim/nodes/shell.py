"""What the node shells share beyond nodes/common.py: the managed-node base and parameters.

* :class:`ManagedNode`: an ``rclpy`` lifecycle node with the rig's contract, the one every node
  of the rig follows (docs/reference.md, "Managed nodes"):

  - **unconfigured** (after start): parameters declared, nothing else; nothing published;
  - **configure**: the parameters are validated by the node's ROS-free settings class and the
    core (engine, loading chain, monitor) is built, with its publishers, subscriptions and
    timers (timers stopped). A bad parameter or file fails the transition: the reason is logged
    as one ``configure failed: ...`` line, the node stays unconfigured and can be configured
    again;
  - **activate**: the timers start and inputs are taken: the streams flow;
  - **deactivate**: timers stopped, inputs ignored, publishers disabled: an inactive node
    publishes nothing (``/diagnostics`` included) after its delivery report: one ``/diagnostics``
    status named ``<node>: published`` (:data:`PUBLISHED_SUFFIX`) whose values are the messages
    each of its topics published so far (the report itself counted), so that a recorder can tell
    when it holds a node's last message and what it missed (``bearing-rig run`` does);
  - **cleanup** / **shutdown**: the core and every entity made at configure are destroyed.

  Faults of the rig (an interlock, a sensor loss, a halted engine, an overrun storm) do not
  change the lifecycle state: the node stays active and reports them on ``/diagnostics`` (and
  its status topic), as the bench's own instruments would; deciding to stop is the lifecycle
  manager's (``bearing-rig run``). An exception inside a transition is logged and fails it.

* :func:`declare_described`: each parameter of the shipped ``config/<node>.yaml`` declared with
  the file's value as default and a descriptor from :mod:`bearing_rig_sim.nodes.parameters`
  (description, unit, range, read-only), with dynamic typing (``-p rate:=2`` is not refused for
  being an integer where the file has ``2.0``).
* :func:`survives_shutdown`: a callback that publishes can be running when Ctrl-C or SIGTERM
  shuts the context down; its "context is invalid" error is swallowed then (and only then).
* :func:`refuse_unavailable_transitions`: the ``change_state`` service of a lifecycle node answers
  every request. rclpy in Jazzy raises "Transition is not registered" out of the service callback
  for a transition the current state does not offer (activate while unconfigured, an unknown id),
  and the exception ends the node's process; rclpy fixed this later. The node's own
  ``get_state`` and ``get_available_transitions`` services (reached through ``Node.services``)
  say what is offered; a request for anything else is answered ``success: false`` and logged.
* :func:`release_executor`: called from a node's ``close()``. When a callback raised out of
  ``spin``, the executor's wait-set iterator stays suspended holding every entity's handle, and
  ``Node.destroy_node`` then busy-waits for ever for those handles (rclpy in Jazzy). Shutting the
  executor down drops the iterator and releases them.
"""

from __future__ import annotations

import functools
from typing import Any, TypeVar
from collections.abc import Callable, Mapping

from lifecycle_msgs.msg import TransitionDescription
from lifecycle_msgs.srv import ChangeState, GetAvailableTransitions, GetState
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.exceptions import InvalidParameterValueException
from rclpy.lifecycle import LifecycleNode, LifecyclePublisher, LifecycleState, TransitionCallbackReturn
from rclpy.node import Node
from rclpy.subscription import Subscription
from rclpy.timer import Timer

from bearing_rig_sim.errors import RigError
from bearing_rig_sim.interfaces import DIAGNOSTICS
from bearing_rig_sim.nodes.parameters import ParameterSpec, in_force, is_standard, spec_for

F = TypeVar("F", bound=Callable[..., Any])

PUBLISHED_SUFFIX = ": published"
"""A node's delivery report is the ``/diagnostics`` status named ``<node name>`` + this."""


class CountedPublisher(LifecyclePublisher):
    """A lifecycle publisher that counts the messages it published (:attr:`published`)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.published = 0
        """Messages published while enabled."""

    def publish(self, msg: Any) -> None:
        """Publish (when enabled, as :class:`LifecyclePublisher`) and count it."""
        if self.is_activated:
            self.published += 1
        super().publish(msg)


def descriptor_of(spec: ParameterSpec) -> ParameterDescriptor:
    """The ROS descriptor of a parameter: description with the unit, range, read-only."""
    description = f"{spec.description} [{spec.unit}]" if spec.unit and spec.unit != "1" else spec.description
    descriptor = ParameterDescriptor(
        name=spec.name,
        description=description,
        additional_constraints=spec.constraints(),
        read_only=spec.read_only,
        dynamic_typing=True,
    )
    if spec.numeric:
        assert spec.low is not None and spec.high is not None
        if spec.integer:
            descriptor.integer_range = [IntegerRange(from_value=int(spec.low), to_value=int(spec.high), step=0)]
        else:
            descriptor.floating_point_range = [FloatingPointRange(from_value=float(spec.low), to_value=float(spec.high), step=0.0)]
    return descriptor


def declare_described(node: Node, node_name: str, defaults: Mapping[str, Any]) -> None:
    """Declare each parameter of ``defaults`` (except those every node declares by itself,
    :func:`~bearing_rig_sim.nodes.parameters.is_standard`) with its descriptor. A parameter
    bounded by a limit of the rig file (``rig_limit``) is declared last, with the rig file in
    force (declared before it) giving its upper bound.

    Raises:
        RigError: a value given at start (``-p``, parameter file) is out of the parameter's
            range (one line naming the parameter and the range); a parameter has no spec.
    """
    names = [name for name in defaults if not is_standard(name)]
    bounded = [name for name in names if spec_for(node_name, name).rig_limit]
    for name in [*(n for n in names if n not in bounded), *bounded]:
        default = defaults[name]
        spec = spec_for(node_name, name)
        if spec.rig_limit:
            spec = in_force(node_name, parameter_values(node, defaults))[name]
        try:
            node.declare_parameter(name, default, descriptor_of(spec))
        except InvalidParameterValueException as exc:
            raise RigError(f"{node_name}: parameter {name} refused: {spec.constraints()} ({' '.join(str(exc).split())})") from None


def parameter_values(node: Node, defaults: Mapping[str, Any]) -> dict[str, Any]:
    """The values in force of the parameters named in ``defaults`` (and ``use_sim_time``)."""
    return {name: node.get_parameter(name).value for name in defaults if node.has_parameter(name)}


def survives_shutdown(method: F) -> F:
    """Decorate a node's callback method: an exception raised while the node's context is shut
    down (publishing during Ctrl-C, or the KeyboardInterrupt of that Ctrl-C, which rclpy's signal
    handler raises after shutting the context down) is dropped; any other propagates."""

    @functools.wraps(method)
    def wrapper(self: Node, *args: Any, **kwargs: Any) -> Any:
        try:
            return method(self, *args, **kwargs)
        except (Exception, KeyboardInterrupt):
            if self.context.ok():
                raise
            return None

    return wrapper  # type: ignore[return-value]  # functools.wraps loses the TypeVar's signature


def release_executor(node: Node) -> None:
    """Shut down the executor that spun ``node`` (if any) so that it lets go of the node's
    handles before ``destroy_node``; see the module docstring."""
    executor = node.executor
    if executor is not None:
        executor.shutdown(timeout_sec=0.0)


def _lifecycle_service(node: Node, name: str) -> Any:
    """The node's lifecycle service ``<node>/<name>`` (made by rclpy's ``LifecycleNode``)."""
    wanted = f"{node.get_fully_qualified_name()}/{name}"
    for service in node.services:
        if service.service_name == wanted:
            return service
    raise RigError(f"{wanted}: no such service on the node")


def offered_transitions(node: Node) -> tuple[str, list[TransitionDescription]]:
    """The lifecycle node's current state label and the transitions it offers from there."""
    get_state = _lifecycle_service(node, "get_state")
    available = _lifecycle_service(node, "get_available_transitions")
    state = get_state.callback(GetState.Request(), GetState.Response()).current_state.label
    offered = available.callback(GetAvailableTransitions.Request(), GetAvailableTransitions.Response()).available_transitions
    return state, list(offered)


def refuse_unavailable_transitions(node: Node) -> None:
    """Answer every ``change_state`` request of lifecycle ``node`` (see the module docstring):
    a transition its state does not offer, by id or by label, is refused with a logged reason;
    an exception raised while a transition runs is logged and answered ``success: false``."""
    change = _lifecycle_service(node, "change_state")
    perform = change.callback
    logger = node.get_logger()

    def answer(request: ChangeState.Request, response: ChangeState.Response) -> ChangeState.Response:
        wanted = request.transition
        asked = f"{wanted.label!r}" if wanted.label else f"id {wanted.id}"
        try:
            state, offered = offered_transitions(node)
            match = [t for t in offered if (t.transition.label == wanted.label if wanted.label else t.transition.id == wanted.id)]
            if not match:
                choices = ", ".join(f"{t.transition.label} ({t.transition.id})" for t in offered) or "none"
                logger.warning(f"change_state refused: transition {asked} is not available in state {state} (available: {choices})")
                response.success = False
                return response
            result: ChangeState.Response = perform(request, response)
            return result
        except Exception as exc:
            logger.error(f"change_state {asked} failed: {one_line(exc)}")
            response.success = False
            return response

    change.callback = answer


def one_line(exc: BaseException) -> str:
    """An exception's message on one line."""
    return " ".join(str(exc).split()) or type(exc).__name__


class ManagedNode(LifecycleNode):
    """A lifecycle node following the rig's contract (see the module docstring).

    Subclasses implement :meth:`configure` (build the core with :meth:`publisher`,
    :meth:`subscription` and :meth:`timer`), and may extend :meth:`activate`,
    :meth:`deactivate` and :meth:`cleanup`.
    """

    def __init__(self, node_name: str, **node_options: Any) -> None:
        super().__init__(node_name, **node_options)
        refuse_unavailable_transitions(self)
        self.active = False
        """True between activate and deactivate: inputs are taken, timers run."""
        self.configure_error = ""
        """Why the last configure failed ("" when it did not)."""
        self._publishers_made: list[LifecyclePublisher] = []
        self._subscriptions_made: list[Subscription] = []
        self._timers_made: list[Timer] = []

    # -- what subclasses implement ----------------------------------------------------------------
    def configure(self) -> None:
        """Validate the parameters and build the core and its entities.

        Raises:
            RigError: a parameter or a file it names is malformed (fails the transition).
        """
        raise NotImplementedError

    def activate(self) -> None:
        """Start the streams (the timers made at configure are started by the base)."""

    def deactivate(self) -> None:
        """Stop the streams (the timers are stopped by the base)."""

    def cleanup(self) -> None:
        """Drop the core (the entities made at configure are destroyed by the base)."""

    def delivery_stamp(self) -> Any:
        """The stamp (``builtin_interfaces/Time``) of the delivery report: the node's own rig
        time, as its other messages are stamped (the base: 0, the simulation clock's origin)."""
        from builtin_interfaces.msg import Time

        return Time()

    # -- entities made at configure ----------------------------------------------------------------
    def publisher(self, msg_type: Any, topic: str, qos: Any, **kwargs: Any) -> LifecyclePublisher:
        """A lifecycle publisher (publishes only while active), destroyed at cleanup."""
        pub = Node.create_publisher(self, msg_type, topic, qos, **kwargs, publisher_class=CountedPublisher)
        assert isinstance(pub, CountedPublisher)
        self._managed_entities.add(pub)  # as create_lifecycle_publisher, with the counting class
        self._publishers_made.append(pub)
        return pub

    def published(self) -> dict[str, int]:
        """Messages published so far per topic by the publishers made at configure."""
        counts: dict[str, int] = {}
        for pub in self._publishers_made:
            if isinstance(pub, CountedPublisher):
                counts[pub.topic_name] = counts.get(pub.topic_name, 0) + pub.published
        return counts

    def _report_published(self) -> None:
        """The delivery report (see the module docstring), on this node's ``/diagnostics``
        publisher, stamped with the stamp of its last diagnostics (the node's own time)."""
        from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue

        pub = next((p for p in self._publishers_made if p.topic_name == DIAGNOSTICS.name and isinstance(p, CountedPublisher)), None)
        if pub is None or not pub.is_activated:
            return
        counts = self.published()
        counts[DIAGNOSTICS.name] = counts.get(DIAGNOSTICS.name, 0) + 1  # this report
        name = self.get_name()
        status = DiagnosticStatus(
            level=DiagnosticStatus.OK,
            name=name + PUBLISHED_SUFFIX,
            message=f"{sum(counts.values())} messages published",
            hardware_id=name,
            values=[KeyValue(key=topic, value=str(n)) for topic, n in sorted(counts.items())],
        )
        array = DiagnosticArray(status=[status])
        array.header.stamp = self.delivery_stamp()
        pub.publish(array)

    def subscription(self, msg_type: Any, topic: str, callback: Callable[[Any], None], qos: Any, **kwargs: Any) -> Subscription:
        """A subscription whose callback runs only while active, destroyed at cleanup."""

        def gated(msg: Any) -> None:
            if self.active:
                callback(msg)

        sub = self.create_subscription(msg_type, topic, gated, qos, **kwargs)
        self._subscriptions_made.append(sub)
        return sub

    def timer(self, period_s: float, callback: Callable[[], None], **kwargs: Any) -> Timer:
        """A timer, stopped until activate and again at deactivate, destroyed at cleanup."""
        made = self.create_timer(period_s, callback, **kwargs)
        made.cancel()
        self._timers_made.append(made)
        return made

    def _destroy_entities(self) -> None:
        for made in self._timers_made:
            made.cancel()
            self.destroy_timer(made)
        for sub in self._subscriptions_made:
            self.destroy_subscription(sub)
        for pub in self._publishers_made:
            self.destroy_lifecycle_publisher(pub)
        self._timers_made, self._subscriptions_made, self._publishers_made = [], [], []

    # -- transitions ---------------------------------------------------------------------------------
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        try:
            self.configure()
        except Exception as exc:
            self.configure_error = one_line(exc)
            self.get_logger().error(f"configure failed: {self.configure_error}")
            self._destroy_entities()
            self._safe_cleanup()
            return TransitionCallbackReturn.FAILURE
        self.configure_error = ""
        self.get_logger().info("configured")
        return super().on_configure(state)

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        result = super().on_activate(state)  # enables the lifecycle publishers
        if result != TransitionCallbackReturn.SUCCESS:
            return result
        try:
            self.active = True
            self.activate()
            for made in self._timers_made:
                made.reset()
        except Exception as exc:
            self.active = False
            self.get_logger().error(f"activate failed: {one_line(exc)}")
            return TransitionCallbackReturn.FAILURE
        self.get_logger().info("active")
        return TransitionCallbackReturn.SUCCESS

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        for made in self._timers_made:
            made.cancel()
        try:
            self.deactivate()
        except Exception as exc:
            self.get_logger().error(f"deactivate: {one_line(exc)}")
        try:
            self._report_published()
        except Exception as exc:
            self.get_logger().error(f"delivery report: {one_line(exc)}")
        self.get_logger().info("inactive")
        return super().on_deactivate(state)

    def on_cleanup(self, state: LifecycleState) -> TransitionCallbackReturn:
        self._destroy_entities()
        self._safe_cleanup()
        self.get_logger().info("cleaned up")
        return super().on_cleanup(state)

    def on_shutdown(self, state: LifecycleState) -> TransitionCallbackReturn:
        if self.active:
            self.on_deactivate(state)
        self._destroy_entities()
        self._safe_cleanup()
        return TransitionCallbackReturn.SUCCESS

    def on_error(self, state: LifecycleState) -> TransitionCallbackReturn:
        self.active = False
        self._destroy_entities()
        self._safe_cleanup()
        return TransitionCallbackReturn.SUCCESS

    def _safe_cleanup(self) -> None:
        try:
            self.cleanup()
        except Exception as exc:
            self.get_logger().error(f"cleanup: {one_line(exc)}")

    def close(self) -> None:
        """Before ``destroy_node``: let the executor release the node's handles."""
        release_executor(self)
