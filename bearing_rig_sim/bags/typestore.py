"""The message types a rig bag may hold: ROS 2 Jazzy's plus ``bearing_rig_msgs``, built into a
rosbags type store from their ``.msg`` text (``msg_defs/msg`` in the source tree, else the
installed ``share/bearing_rig_msgs/msg``), never from the generated Python package."""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Iterable
from pathlib import Path

from rosbags.interfaces.typing import Typesdict
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from bearing_rig_sim.bags.errors import BagError

RIG_MSG_PACKAGE = "bearing_rig_msgs"

SCHEMA_SEPARATOR = "=" * 80
"""Line between a type's definition and each of its dependencies in a ``ros2msg`` schema."""


def msg_folder() -> Path:
    """Folder of the ``bearing_rig_msgs`` ``.msg`` files (see the module documentation); BagError if none."""
    local = Path(__file__).resolve().parents[2] / "msg_defs" / "msg"
    if local.is_dir():
        return local
    with contextlib.suppress(Exception):  # ament index absent or package not installed
        from ament_index_python.packages import get_package_share_directory

        if (installed := Path(get_package_share_directory(RIG_MSG_PACKAGE)) / "msg").is_dir():
            return installed
    raise BagError(f"cannot find the {RIG_MSG_PACKAGE} message definitions: neither {local} nor an installed share/{RIG_MSG_PACKAGE}/msg exists")


@functools.cache
def rig_message_texts() -> dict[str, str]:
    """``{"bearing_rig_msgs/msg/<Name>": <.msg file text>}`` for every custom message."""
    return {f"{RIG_MSG_PACKAGE}/msg/{path.stem}": path.read_text(encoding="utf-8") for path in sorted(msg_folder().glob("*.msg"))}


@functools.cache
def rig_typestore() -> Typestore:
    """ROS 2 Jazzy's types plus ``bearing_rig_msgs`` (cached and shared: read-only); BagError when a
    ``.msg`` file does not parse."""
    store = get_typestore(Stores.ROS2_JAZZY)
    types: Typesdict = {}
    for name, text in rig_message_texts().items():
        try:
            types.update(get_types_from_msg(text, name))
        except Exception as exc:  # rosbags parse errors have several classes
            raise BagError(f"{name}: cannot parse its .msg definition: {exc}") from exc
    store.register(types)
    return store


def msg_definition_text(msgtype: str, typestore: Typestore | None = None) -> str:
    """The ``ros2msg`` schema text of a type as rosbag2 stores it (its definition, then each type it
    uses after :data:`SCHEMA_SEPARATOR` and ``MSG: pkg/Name``); ``bearing_rig_msgs`` types keep
    their ``.msg`` text, comments (units) included. BagError for an unknown type."""
    store = typestore if typestore is not None else rig_typestore()
    if msgtype not in store.fielddefs:
        raise BagError(f"unknown message type {msgtype!r}: not a ROS 2 Jazzy type nor one of {RIG_MSG_PACKAGE}")
    text, _ = store.generate_msgdef(msgtype, ros_version=2)
    original = rig_message_texts().get(msgtype) if msgtype.startswith(f"{RIG_MSG_PACKAGE}/") else None
    if original is None:
        return text
    sections = text.split(SCHEMA_SEPARATOR + "\n")
    own = original if original.endswith("\n") else original + "\n"
    return (SCHEMA_SEPARATOR + "\n").join([own, *sections[1:]])


def type_hash(msgtype: str, typestore: Typestore | None = None) -> str:
    """The type's RIHS01 hash (rosidl's ``type_description_hash``); empty for an unknown type."""
    store = typestore if typestore is not None else rig_typestore()
    return store.hash_rihs01(msgtype) if msgtype in store.fielddefs else ""


def dependencies(store: Typestore, names: Iterable[str]) -> set[str]:
    """The known types among ``names`` and every type they use, recursively (as rosbags' ``gendefhash`` finds them)."""
    found: dict[str, tuple[str, str]] = {}
    for name in names:
        if name in store.fielddefs and name not in found:
            found[name] = ("", "")
            store.gendefhash(name, found, ros_version=2)
    return set(found)
