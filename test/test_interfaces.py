"""The interface contract is written once (bearing_rig_sim.interfaces): the docs agree with it,
the recorder records it, replay offers its QoS, and every type exists as a message definition."""

from __future__ import annotations

import ast
import importlib.util
import re
import sys
from pathlib import Path
from unittest.mock import MagicMock

import pytest

from bearing_rig_sim import interfaces
from bearing_rig_sim.bags.typestore import rig_typestore
from bearing_rig_sim.session.recorder import RECORDED_TOPICS

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("doc", ["docs/interfaces.md", "README.md"])
def test_docs_carry_the_contract_table_unchanged(doc: str) -> None:
    text = (ROOT / doc).read_text(encoding="utf-8")
    assert interfaces.markdown_table() in text, f"{doc}: regenerate with python -m bearing_rig_sim.interfaces"


def test_every_topic_and_service_name_is_unique_and_absolute() -> None:
    names = [t.name for t in interfaces.TOPICS] + [s.name for s in interfaces.SERVICES]
    assert len(names) == len(set(names))
    assert all(name.startswith("/") for name in names)


def test_every_topic_type_is_known_to_the_bag_typestore() -> None:
    store = rig_typestore()
    for topic in interfaces.TOPICS:
        assert topic.msgtype in store.fielddefs, topic.msgtype


def test_stamped_flag_matches_the_message_definition() -> None:
    store = rig_typestore()
    for topic in interfaces.TOPICS:
        _name, (_kind, first_type) = store.fielddefs[topic.msgtype][1][0]
        # the message's CDR starts with a time stamp: a std_msgs/Header, or a Time itself (Clock, a Header)
        assert topic.stamped == (first_type in ("std_msgs/msg/Header", "builtin_interfaces/msg/Time")), topic.name


def test_recorder_records_every_contract_topic() -> None:
    assert {t.name for t in RECORDED_TOPICS} == {t.name for t in interfaces.TOPICS}


def test_unknown_topic_is_named_in_the_error() -> None:
    with pytest.raises(KeyError, match="/rig/nothing"):
        interfaces.topic("/rig/nothing")
    assert interfaces.contract_qos("/rig/nothing") is None
    assert interfaces.contract_qos("/rig/cage/pulses") == "reliable_stream"
    assert interfaces.contract_qos("/rig/load/setpoint") == "transient_stream"


def test_every_qos_name_means_the_same_to_the_nodes_and_to_the_bags() -> None:
    """The contract's profile names resolve to one and the same profile for a live publisher
    (nodes.common) and for the QoS stored in a bag (bags.qos), and the table describes it."""
    from rclpy.qos import DurabilityPolicy, ReliabilityPolicy

    from bearing_rig_sim.bags.qos import QOS_PROFILES
    from bearing_rig_sim.nodes.common import CONTRACT_QOS_PROFILES

    assert set(CONTRACT_QOS_PROFILES) == set(QOS_PROFILES) == set(interfaces.QOS_DESCRIPTIONS)
    for name, live in CONTRACT_QOS_PROFILES.items():
        stored = QOS_PROFILES[name]
        assert (live.reliability == ReliabilityPolicy.RELIABLE) == (stored.reliability == "reliable"), name
        assert (live.durability == DurabilityPolicy.TRANSIENT_LOCAL) == (stored.durability == "transient_local"), name
        assert live.depth == stored.depth, name
        assert f"depth {stored.depth}" in interfaces.QOS_DESCRIPTIONS[name], name
    # The twin's high-rate streams are the ones a recorder must get whole (issue: no pulse lost in a bag).
    # The load cell's stream is among them: as sensor data a loaded host lost 7 % of it to the bag.
    streams = {t.name for t in interfaces.TOPICS if t.qos == "reliable_stream"}
    assert streams >= {"/clock", "/rig/spindle/pulses", "/rig/cage/pulses", "/rig/speeds", "/rig/truth", "/rig/bearing/axial_force", "/rig/axial_load/force"}
    # Depth 10 only for what comes on request or about once a second: a periodic stream (the
    # load controller's state, the thermocouple, the torque meter, the monitor's statuses, the
    # shadow's residuals) on it lost the odd sample to a recorder held up under load.
    shallow = {t.name for t in interfaces.TOPICS if interfaces.QOS_TABLE[t.qos].depth < 1000}
    assert shallow == {"/rig/spindle/command", "/rig/axial_load/setpoint", "/twin/calibration_estimate", "/diagnostics"}
    # The load set-points, sent ahead all at once (a load sweep's 40): a depth of 10 would drop 30;
    # transient local, so a reader whose own side matched after the writer's still gets the first.
    setpoints = interfaces.QOS_TABLE[interfaces.LOAD_SETPOINT.qos]
    assert (setpoints.reliability, setpoints.durability) == ("reliable", "transient_local") and setpoints.depth >= 40
    # No topic of the rig's own nodes is published best effort: the recorder could lose it.
    assert all(interfaces.QOS_TABLE[t.qos].reliability == "reliable" for t in interfaces.TOPICS)
    # The simulator paces on the force on the bearing: its reader is reliable, so no lost sample holds the pace.
    assert interfaces.QOS_TABLE["force_reader"].reliability == "reliable"


def test_write_tables_replaces_a_stale_table(tmp_path: Path) -> None:
    stale = "# t\n\n| topic | type | QoS | rate | unit | publisher |\n|---|---|---|---|---|---|\n| `/old` | x | y | z | - | - |\n\nafter\n"
    for name in interfaces.TABLE_DOCUMENTS:
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(stale, encoding="utf-8")
    changed = interfaces.write_tables(tmp_path)
    assert len(changed) == len(interfaces.TABLE_DOCUMENTS)
    text = (tmp_path / "README.md").read_text(encoding="utf-8")
    assert "/old" not in text and interfaces.markdown_table() in text and text.endswith("\nafter\n")
    assert interfaces.write_tables(tmp_path) == []


def test_every_topic_type_resolves_to_its_generated_class() -> None:
    """The session records with the class named by the table's ``pkg/msg/Name`` (no second,
    hand-written list): each resolves to the generated class of that package and name."""
    from bearing_rig_sim.session.node import MESSAGE_TYPES, message_class

    for t in interfaces.TOPICS:
        package, _, name = t.msgtype.split("/")
        cls = MESSAGE_TYPES[t.msgtype]
        assert cls.__name__ == name and cls.__module__.startswith(f"{package}.msg"), t.name
    with pytest.raises(AttributeError):
        message_class("std_msgs/msg/NoSuchMessage")


LAUNCH_MODULES = (
    "launch",
    "launch.actions",
    "launch.conditions",
    "launch.event_handlers",
    "launch.events",
    "launch.events.process",
    "launch.launch_context",
    "launch.substitutions",
    "launch_ros",
    "launch_ros.actions",
    "launch_ros.event_handlers",
    "launch_ros.events",
    "launch_ros.events.lifecycle",
)
"""What launch/rig.launch.py imports from ROS 2's launch packages (not on PyPI): stood in for by
mocks that record each action the file makes."""


def launch_processes(monkeypatch: pytest.MonkeyPatch) -> list[list[object]]:
    """The command lines of the processes ``generate_launch_description`` makes, from the launch
    file itself run against recording stand-ins of the launch packages."""
    for name in LAUNCH_MODULES:
        monkeypatch.setitem(sys.modules, name, MagicMock(name=name))
    spec = importlib.util.spec_from_file_location("rig_launch", ROOT / "launch" / "rig.launch.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.generate_launch_description()
    execute = sys.modules["launch.actions"].ExecuteProcess
    return [list(call.kwargs["cmd"]) for call in execute.call_args_list]


def test_the_launch_file_records_every_contract_topic(monkeypatch: pytest.MonkeyPatch) -> None:
    """``rig.launch.py record:=true`` runs ``ros2 bag record`` on the contract's topics, all of
    them and nothing else (a session records the same: test_recorder_records_every_contract_topic)."""
    (record,) = [cmd for cmd in launch_processes(monkeypatch) if cmd[:3] == ["ros2", "bag", "record"]]
    recorded = [arg for arg in record if isinstance(arg, str) and arg.startswith("/")]
    assert recorded == [t.name for t in interfaces.TOPICS]


TOPIC_NAME = re.compile(r"(?<![\w./-])(/(?:rig|twin)(?:/[a-z][a-z_]*)+|/clock\b|/diagnostics\b)")
"""A topic or service name of the rig written in text: ``/rig/...``, ``/twin/...``, ``/clock``,
``/diagnostics`` (a bare namespace such as ``/twin/*`` is not a name)."""

WRITTEN_IN = ("README.md", "docs/*.md", "config/**/*.yaml", "config/**/*.json", "launch/*.py", "bearing_rig_sim/**/*.py")
"""Where the rig's topics are documented or named (the tests are not: they name wrong ones on purpose)."""


def test_every_topic_the_docs_config_and_code_name_is_in_the_contract() -> None:
    """A topic a document, a configuration comment or the code names exists: a contract topic or
    service (config/shadow.yaml once documented a /twin/status that nothing published)."""
    known = {t.name for t in interfaces.TOPICS} | {s.name for s in interfaces.SERVICES}
    unknown = set()
    for pattern in WRITTEN_IN:
        for path in sorted(ROOT.glob(pattern)):
            for match in TOPIC_NAME.finditer(path.read_text(encoding="utf-8")):
                if match.group(1) not in known:
                    unknown.add(f"{path.relative_to(ROOT)}: {match.group(1)}")
    assert not unknown, sorted(unknown)


def test_the_topic_name_pattern_finds_a_stale_name() -> None:
    """The scan above can fail: it finds a topic name in a YAML comment, and not a namespace."""
    found = TOPIC_NAME.findall("    status_rate_hz: 10.0   # /twin/status, wall clock; the /twin/* topics; a/rig/x path\n")
    assert found == ["/twin/status"]


def publisher_calls(path: Path) -> list[ast.Call]:
    """The calls in ``path`` that make a publisher (``self.publisher(...)``, a ManagedNode's, or
    rclpy's ``create_publisher(...)``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [
        node
        for node in ast.walk(tree)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in ("publisher", "create_publisher") and len(node.args) >= 3
    ]


def test_every_publisher_of_the_rig_takes_its_topics_contract_profile() -> None:
    """A publisher made with a profile of its own (the load controller's state on the shallow
    ``reliable`` profile while the table said ``reliable_stream``) publishes what the contract
    does not say: its writer kept 10 samples and a recorder held up under load lost 72 of 2050.
    Each publisher of the rig's nodes and session is made as ``publisher(Type, TOPIC.name,
    qos_profile(TOPIC))``, the topic and its profile named by the same contract entry."""
    paths = sorted((ROOT / "bearing_rig_sim" / "nodes").glob("*.py")) + [ROOT / "bearing_rig_sim" / "session" / "node.py"]
    calls = [(path, call) for path in paths for call in publisher_calls(path)]
    assert len(calls) >= 15, [ast.unparse(c) for _, c in calls]  # every node's, not none found
    for path, call in calls:
        topic, qos = call.args[1], call.args[2]
        where = f"{path.name}: {ast.unparse(call)}"
        if "topic" in [ast.unparse(a) for a in call.args]:  # ManagedNode.publisher itself, passing its arguments on
            continue
        assert isinstance(topic, ast.Attribute) and topic.attr == "name", where
        assert isinstance(qos, ast.Call) and ast.unparse(qos.func) == "qos_profile" and len(qos.args) == 1, where
        assert ast.unparse(qos.args[0]) == ast.unparse(topic.value), where
