"""The bearing_rig_msgs contract across processes.

Every custom message is filled with non-default values in every field, sent from one process
and compared field by field in another (both directions), and the SetAxialLoad service is
called across processes. The peer process runs this file as a script::

    python test/test_messages.py publish FibreOpticPulse    # publish SAMPLES[...] until killed
    python test/test_messages.py subscribe SlipStatus       # print the first message as JSON
    python test/test_messages.py serve                      # SetAxialLoad server, limit 1000 N

Publishers and subscribers use reliable, transient-local QoS, so a late subscriber still gets
the message and discovery time (up to a few seconds) cannot make the tests flaky; every wait
is bounded. Also checked without a graph: the installed classes match msg_defs/ (fields,
types, constants), which catches a stale build of the interfaces.
"""

from __future__ import annotations

import array
import importlib
import json
import math
import re
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from conftest import time_left

MSG_DIR = Path(__file__).resolve().parent.parent / "msg_defs"

#: Every field of every custom message, each different from its default (0, "", false), with
#: integers beyond 32 bits where the type allows, so a dropped or truncated field shows.
SAMPLES: dict[str, dict[str, Any]] = {
    "FibreOpticPulse": {
        "header": {"stamp": {"sec": 1_700_000_123, "nanosec": 987_654_321}, "frame_id": "cage_sensor_mount"},
        "sensor_id": "cage",
        "strip_id": 1,
        "strip_count": 2,
        "revolution": 2**40 + 3,
        "pulse_index": 2**41 + 7,
    },
    "SlipStatus": {
        "header": {"stamp": {"sec": 42, "nanosec": 500_000_001}, "frame_id": "rig"},
        "inner_ring_speed": 942.4777960769379,
        "cage_speed": 380.12345678901234,
        "theoretical_cage_speed": 401.9876543210987,
        "slip_rate": 5.44,
        "fitted_slope": -0.012345678901234,
        "critical_slope": -0.03,
        "state": 2,
        "criterion": "time",
        "confidence": 0.875,
        "window_revolutions": 4_000_000_000,
        "detail": "stable: slope −0.0123 %/s ≥ −0.03 %/s",
        "axial_load": 200.125,
        "kinematic_slip_rate": 0.0625,
        "loaded_contact_angle": 0.3046875,
        "sweep_speed": 104.71975511965977,
        "sweep_stable_from": 300.0,
        "sweep_verdict": "stable from 300 N (2-term Gaussian, R^2 0.9991, RMSE 0.012 %, 8 loads)",
    },
    "SimulatorTruth": {
        "header": {"stamp": {"sec": 7, "nanosec": 123_456_789}, "frame_id": "bearing"},
        "inner_ring_speed": 942.4777960769379,
        "inner_ring_acceleration": -12.5,
        "cage_speed": 398.1,
        "theoretical_cage_speed": 401.3,
        "slip_rate": 0.7974081734363285,
        "axial_load": 700.25,
        "inner_contact_load_mean": 61.03125,
        "inner_contact_load_max": 88.5,
        "outer_contact_load_mean": 60.96875,
        "outer_contact_load_max": 90.125,
        "pocket_load_max": 1.5e-3,
        "inner_contact_angle": 0.2617993877991494,
        "outer_contact_angle": 0.2530727415391778,
        "inner_ring_axial_displacement": 1.234e-5,
        "real_time_factor": 1.0625,
        "step_count": 2**35 + 11,
        "overruns": 3_000_000_000,
        "friction_torque": 0.0152,
        "power_loss": 42.75,
        "cage_whirl_radius_um": 37.5,
        "ball_azimuth": [0.0, 2.0943951023931953, 4.1887902047863905],
        "ball_orbit_speed": [398.0, 398.25, 397.875],
        "ball_spin_speed": [-3125.5, -3126.0, -3124.75],
        "ball_inner_contact_load": [139.0, 0.0, 20.125],
        "ball_outer_contact_load": [140.5, 1.5e-3, 21.0],
        "ball_inner_contact_angle": [0.28, 0.2617993877991494, 0.27],
        "ball_outer_contact_angle": [0.26, 0.2617993877991494, 0.25],
        "ball_pocket_load": [-0.5, 1.25, 0.0625],
        "cage_centre_x": -1.25e-5,
        "cage_centre_y": 3.5e-5,
    },
    "AxialLoadState": {
        "header": {"stamp": {"sec": 99, "nanosec": 1}, "frame_id": "load_cell"},
        "setpoint": 500.0,
        "load_cell_force": 499.8712,
        "bearing_force": 497.25,
        "brake_current": 1.8375,
        "brake_force": 251.5,
        "rope_tension": 251.0625,
        "clutch_state": 2,
        "fault": True,
        "fault_reason": "clutch slipping: demand 2.1 kN > holding 2.0 kN",
    },
    "ShadowResidual": {
        "header": {"stamp": {"sec": 1_700_000_004, "nanosec": 156_000_001}, "frame_id": "bearing"},
        "window_start": 1_700_000_004.0,
        "inner_ring_speed": 94.24777960769379,
        "axial_load": 100.125,
        "measured_cage_speed": 38.98,
        "predicted_cage_speed": 39.11,
        "measured_slip": 3.6684,
        "predicted_slip": 3.3304,
        "residual": 0.338,
        "band": 0.1984,
        "compared": True,
        "anomaly": True,
        "level": 2,
        "detail": "residual +0.338 pp outside its band (±0.198 pp) for 3.2 s: slip higher than predicted",
        "measured_temperature": 31.25,
        "predicted_temperature": 30.9,
        "temperature_residual": 0.35,
        "temperature_band": 1.82,
        "temperature_anomaly": True,
        "measured_torque": 0.1125,
        "predicted_torque": 0.1086,
        "torque_residual": 0.0039,
        "torque_band": 0.0326,
        "torque_anomaly": True,
    },
    "ShadowEstimate": {
        "header": {"stamp": {"sec": 1_700_000_009, "nanosec": 5}, "frame_id": "bearing"},
        "parameter": "ball_drag_scale",
        "calibrated": 3641.74,
        "value": 4733.5,
        "std": 19.8,
        "updates": 4_000_000_000,
    },
    "SpindleCommand": {
        "header": {"stamp": {"sec": 3, "nanosec": 250_000_000}, "frame_id": "spindle"},
        "target_speed": 942.4777960769379,
        "profile": 1,
        "ramp_time": 2.5,
        "acceleration": 31.41592653589793,
    },
}

TOPIC_PREFIX = "/test/bearing_rig_msgs/"
AXIAL_LOAD_LIMIT_N = 1000.0
PEER_LIFETIME_S = 60.0
SERVICE_RESEND_S = 5.0
"""A request unanswered this long is sent again (its response may have been lost)."""


def message_class(name: str) -> type:
    """``bearing_rig_msgs.msg.<name>``."""
    return getattr(importlib.import_module("bearing_rig_msgs.msg"), name)


def qos() -> Any:
    """Reliable, transient-local, keep last 1: a late subscriber still receives the sample."""
    from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def fill(message: Any, values: dict[str, Any]) -> Any:
    """Set ``message``'s fields from ``values`` (nested dicts for nested messages); return it."""
    for field, value in values.items():
        if isinstance(value, dict):
            fill(getattr(message, field), value)
        else:
            setattr(message, field, value)
    return message


def to_plain(message: Any) -> dict[str, Any]:
    """Every field of ``message`` as plain Python values (nested messages as dicts)."""
    out: dict[str, Any] = {}
    for field in message.get_fields_and_field_types():
        value = getattr(message, field)
        if hasattr(value, "get_fields_and_field_types"):
            value = to_plain(value)
        elif isinstance(value, array.array):
            value = value.tolist()
        out[field] = value
    return out


# -- the peer process ------------------------------------------------------------------------
def _peer(mode: str, name: str | None) -> int:
    import rclpy
    from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

    rclpy.init()
    node = rclpy.create_node(f"peer_{mode}")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    received: list[Any] = []
    deadline = time.monotonic() + (math.inf if mode == "serve" else PEER_LIFETIME_S)  # a server lives until the test ends it
    try:
        if mode == "publish":
            assert name is not None
            publisher = node.create_publisher(message_class(name), TOPIC_PREFIX + name, qos())
            publisher.publish(fill(message_class(name)(), SAMPLES[name]))
        elif mode == "subscribe":
            assert name is not None
            node.create_subscription(message_class(name), TOPIC_PREFIX + name, received.append, qos())
        elif mode == "serve":
            from bearing_rig_msgs.srv import SetAxialLoad

            def handle(request: Any, response: Any) -> Any:
                load = request.axial_load
                if math.isfinite(load) and 0.0 <= load <= AXIAL_LOAD_LIMIT_N:
                    response.accepted = True
                    response.message = f"set-point {load!r} N"
                else:
                    response.accepted = False
                    response.message = f"refused {load!r} N: outside [0, {AXIAL_LOAD_LIMIT_N!r}] N"
                return response

            node.create_service(SetAxialLoad, "/test/set_axial_load", handle)
        else:
            print(f"unknown mode {mode!r}", file=sys.stderr)
            return 2
        while time.monotonic() < deadline:
            executor.spin_once(timeout_sec=0.1)
            if received:
                print(json.dumps(to_plain(received[0])), flush=True)
                return 0
        if mode == "subscribe":
            print(f"no {name} within {PEER_LIFETIME_S} s", file=sys.stderr)
            return 3
        return 0
    except (KeyboardInterrupt, ExternalShutdownException):
        return 0
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


# -- tests -----------------------------------------------------------------------------------
def _parse_definition(text: str) -> tuple[dict[str, str], dict[str, str]]:
    """Fields (name -> type) and constants (name -> literal) of a .msg definition."""
    fields: dict[str, str] = {}
    constants: dict[str, str] = {}
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = re.fullmatch(r"(\S+)\s+([A-Za-z0-9_]+)\s*=\s*(\S+)", line)
        if match:
            constants[match.group(2)] = match.group(3)
            continue
        field_type, field_name = line.split()
        fields[field_name] = field_type
    return fields, constants


#: .msg primitive names -> the names rclpy's get_fields_and_field_types() uses.
_RCLPY_TYPE = {"float64": "double", "float32": "float", "bool": "boolean", "byte": "octet", "char": "uint8"}


def _rclpy_type(definition: str) -> str:
    """rclpy's name of a .msg field type: ``float64`` -> ``double``, ``float64[]`` ->
    ``sequence<double>`` (ROS 2 IDL mapping of an unbounded sequence)."""
    if definition.endswith("[]"):
        return f"sequence<{_rclpy_type(definition[:-2])}>"
    return _RCLPY_TYPE.get(definition, definition)


def _check_class_matches(cls: type, text: str) -> None:
    fields, constants = _parse_definition(text)
    expected = {name: _rclpy_type(t) for name, t in fields.items()}
    assert cls.get_fields_and_field_types() == expected, f"{cls.__name__} differs from its definition"
    for name, literal in constants.items():
        assert getattr(cls, name) == int(literal), f"{cls.__name__}.{name}"


def test_every_definition_has_a_sample() -> None:
    names = sorted(p.stem for p in (MSG_DIR / "msg").glob("*.msg"))
    assert names == sorted(SAMPLES)


@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_installed_message_matches_its_definition(name: str) -> None:
    _check_class_matches(message_class(name), (MSG_DIR / "msg" / f"{name}.msg").read_text(encoding="utf-8"))


def test_installed_service_matches_its_definition() -> None:
    from bearing_rig_msgs.srv import SetAxialLoad

    request_text, response_text = (MSG_DIR / "srv" / "SetAxialLoad.srv").read_text(encoding="utf-8").split("---")
    _check_class_matches(SetAxialLoad.Request, request_text)
    _check_class_matches(SetAxialLoad.Response, response_text)


@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_sample_sets_every_field_to_a_non_default(name: str) -> None:
    cls = message_class(name)
    sample = SAMPLES[name]
    assert set(sample) == set(cls.get_fields_and_field_types())
    default = to_plain(cls())
    filled = to_plain(fill(cls(), sample))
    assert filled == sample
    for field in sample:
        assert filled[field] != default[field], f"{name}.{field} equals its default"


def _peer_output(process: Any, timeout: float) -> tuple[int, str, str]:
    try:
        out, err = process.communicate(timeout=timeout)
    except Exception:
        process.kill()
        out, err = process.communicate()
        pytest.fail(f"peer did not finish in {timeout} s; stderr:\n{err}")
    return process.returncode, out, err


@pytest.mark.ros
@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_message_from_another_process_arrives_intact(ros_graph: Any, name: str) -> None:
    peer = ros_graph.spawn_python(__file__, "publish", name)
    node = ros_graph.node("receiver")
    received: list[Any] = []
    node.create_subscription(message_class(name), TOPIC_PREFIX + name, received.append, qos())
    if not ros_graph.spin_until(lambda: bool(received) or peer.poll() is not None, timeout=time_left(), nodes=[node]):
        peer.terminate()
        pytest.fail(f"no {name} from the publisher process within the test's guard; its stderr:\n{peer.communicate()[1]}")
    if not received:
        pytest.fail(f"publisher process exited with {peer.returncode}: {peer.communicate()[1]}")
    assert type(received[0]).__name__ == name
    assert to_plain(received[0]) == SAMPLES[name]


@pytest.mark.ros
@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_message_to_another_process_arrives_intact(ros_graph: Any, name: str) -> None:
    node = ros_graph.node("sender")
    publisher = node.create_publisher(message_class(name), TOPIC_PREFIX + name, qos())
    publisher.publish(fill(message_class(name)(), SAMPLES[name]))
    peer = ros_graph.spawn_python(__file__, "subscribe", name)
    status, out, err = _peer_output(peer, timeout=time_left())
    assert status == 0, f"subscriber process failed ({status}): {err}"
    assert json.loads(out.strip().splitlines()[-1]) == SAMPLES[name]


@pytest.mark.ros
def test_set_axial_load_service_across_processes(ros_graph: Any) -> None:
    from bearing_rig_msgs.srv import SetAxialLoad

    peer = ros_graph.spawn_python(__file__, "serve")
    node = ros_graph.node("operator")
    client = node.create_client(SetAxialLoad, "/test/set_axial_load")
    executor = ros_graph.executor([node])
    assert ros_graph.spin_until(lambda: client.service_is_ready() or peer.poll() is not None, timeout=time_left(), executor=executor), (
        "SetAxialLoad server not discovered within the test's guard"
    )
    assert peer.poll() is None, f"server process exited: {peer.communicate()[1]}"

    def call(load: float) -> Any:
        # The graph shows the service ready before the server's response writer has matched this
        # client's response reader, and a response sent before that match is lost (CI saw one):
        # ask again until one comes. The answer depends on the request alone, so a repeated
        # request gets the same one. The guard only ends a hang.
        guard = time.monotonic() + time_left()
        while peer.poll() is None and time.monotonic() < guard:
            future = client.call_async(SetAxialLoad.Request(axial_load=load))
            if ros_graph.spin_until(future.done, timeout=SERVICE_RESEND_S, executor=executor):  # not a hang guard: the resend period
                return future.result()
            client.remove_pending_request(future)
        raise AssertionError(f"no response for {load} N ({'server running' if peer.poll() is None else 'server exited'})")

    accepted = call(687.125)
    assert accepted.accepted is True
    assert accepted.message == "set-point 687.125 N"
    refused = call(1000.5)
    assert refused.accepted is False
    assert refused.message == "refused 1000.5 N: outside [0, 1000.0] N"


if __name__ == "__main__":
    sys.exit(_peer(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else None))
