"""The rosbag2 bag directory ``<name>/``: ``metadata.yaml`` (format version 9: files, topics with
type, serialization format, offered QoS, RIHS01 type hash and count, time range, ``custom_data``
where the project puts its run context too) and the storage files ``<name>_0.mcap``, ``<name>_1.mcap``..."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path, PurePath
from typing import Any

import yaml
from rosbags.interfaces import Qos
from rosbags.rosbag2.metadata import dump_qos_v9, parse_qos

from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.storage import FileIndex
from bearing_rig_sim.config import ConfigError, parse_yaml

METADATA_FILE = "metadata.yaml"
RUN_METADATA_RECORD = "bearing_rig_sim"
"""Name of the MCAP metadata record holding the run context."""
BAG_VERSION = 9
ROS_DISTRO = "jazzy"


@dataclass
class TopicEntry:
    """One topic of ``metadata.yaml``: offered QoS profiles kept as stored, RIHS01 type hash
    (empty when unknown)."""

    name: str
    msgtype: str
    qos: list[Qos] = field(default_factory=list)
    type_hash: str = ""
    message_count: int = 0
    serialization_format: str = "cdr"


@dataclass
class FileEntry:
    """One storage file of ``metadata.yaml``: relative path, start (ns), duration (ns), count."""

    path: str
    start_ns: int = 0
    duration_ns: int = 0
    message_count: int = 0


@dataclass
class BagLayout:
    """The content of a ``metadata.yaml``; ``stated_message_count`` is the top-level count of one
    that was read (None when built)."""

    topics: list[TopicEntry] = field(default_factory=list)
    files: list[FileEntry] = field(default_factory=list)
    custom_data: dict[str, str] = field(default_factory=dict)
    storage_identifier: str = "mcap"
    version: int = BAG_VERSION
    ros_distro: str = ROS_DISTRO
    stated_message_count: int | None = None

    @property
    def message_count(self) -> int:
        """Messages in all files (the stated count when the files section lacks them)."""
        counted = sum(f.message_count for f in self.files)
        return counted if counted or self.stated_message_count is None else self.stated_message_count

    @property
    def start_ns(self) -> int:
        """Earliest message time (ns); 0 for an empty bag, as :attr:`end_ns`."""
        return min((f.start_ns for f in self.files if f.message_count), default=0)

    @property
    def end_ns(self) -> int:
        """Latest message time (ns)."""
        return max((f.start_ns + f.duration_ns for f in self.files if f.message_count), default=0)

    @property
    def duration_ns(self) -> int:
        """``end_ns - start_ns``."""
        return self.end_ns - self.start_ns


def _qos_dicts(profiles: list[Qos]) -> list[dict[str, Any]]:
    return dump_qos_v9(list(profiles))  # type: ignore[return-value]  # rosbags types the dump as its own str alias


def qos_yaml(profiles: list[Qos]) -> str:
    """Offered QoS profiles as the YAML text rosbag2 stores in an MCAP channel's metadata."""
    return yaml.safe_dump(_qos_dicts(profiles), sort_keys=False, default_flow_style=False).strip()


def parse_qos_profiles(value: Any, source: str) -> list[Qos]:
    """QoS profiles from ``metadata.yaml`` (v9 list, v8 YAML) or MCAP channel metadata; BagError for another value."""
    if value in (None, "", []):
        return []
    try:
        return parse_qos(value)
    except Exception as exc:  # rosbags raises KeyError/TypeError/ReaderError here
        raise BagError(f"{source}: offered_qos_profiles is not a list of QoS profiles ({exc})") from None


def layout_to_dict(layout: BagLayout) -> dict[str, Any]:
    """The ``metadata.yaml`` document of a layout."""
    topics = [
        {
            "topic_metadata": {"name": t.name, "type": t.msgtype, "serialization_format": t.serialization_format,
                               "offered_qos_profiles": _qos_dicts(t.qos), "type_description_hash": t.type_hash},
            "message_count": t.message_count,
        }
        for t in layout.topics
    ]  # fmt: skip
    files = [
        {"path": f.path, "starting_time": {"nanoseconds_since_epoch": f.start_ns}, "duration": {"nanoseconds": f.duration_ns}, "message_count": f.message_count}
        for f in layout.files
    ]
    return {
        "rosbag2_bagfile_information": {
            "version": layout.version,
            "storage_identifier": layout.storage_identifier,
            "duration": {"nanoseconds": layout.duration_ns},
            "starting_time": {"nanoseconds_since_epoch": layout.start_ns},
            "message_count": layout.message_count,
            "topics_with_message_count": topics,
            "compression_format": "",
            "compression_mode": "",
            "relative_file_paths": [f.path for f in layout.files],
            "files": files,
            "custom_data": dict(layout.custom_data) or None,
            "ros_distro": layout.ros_distro,
        }
    }


def write_layout(bag_dir: Path, layout: BagLayout) -> None:
    """Write ``metadata.yaml`` atomically (a reader never sees a half-written file)."""
    target = bag_dir / METADATA_FILE
    tmp = target.with_name(METADATA_FILE + ".tmp")
    tmp.write_text(yaml.safe_dump(layout_to_dict(layout), sort_keys=False, default_flow_style=False), encoding="utf-8")
    os.replace(tmp, target)


def _get(mapping: Any, key: str, source: str, kind: type | tuple[type, ...], where: str) -> Any:
    if not isinstance(mapping, dict) or key not in mapping:
        raise BagError(f"{source}: key {where}{key} is missing")
    value = mapping[key]
    if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
        raise BagError(f"{source}: key {where}{key} has the wrong type ({type(value).__name__})")
    return value


def read_layout(bag_dir: Path) -> BagLayout:
    """Parse ``<bag_dir>/metadata.yaml``; BagError when missing, not YAML, without keys a reader needs,
    or for rosbag2 file or message compression."""
    path = bag_dir / METADATA_FILE
    source = str(path)
    try:
        text = path.read_bytes()
    except FileNotFoundError:
        hint = f" (if a recording was interrupted, `bearing-rig bag repair {bag_dir}` rebuilds it from the .mcap files)"
        raise BagError(f"{bag_dir}: no {METADATA_FILE}, so not a rosbag2 bag directory{hint if any(bag_dir.glob('*.mcap')) else ''}") from None
    except OSError as exc:
        raise BagError(f"{source}: cannot read ({exc})") from None
    try:
        doc = parse_yaml(text, source)
    except ConfigError as exc:
        raise BagError(f"{exc} (corrupt metadata; `bearing-rig bag repair {bag_dir}` rebuilds it)") from None
    info = _get(doc, "rosbag2_bagfile_information", source, dict, "")
    where = "rosbag2_bagfile_information."
    version = _get(info, "version", source, int, where)
    storage = _get(info, "storage_identifier", source, str, where)
    mode = str(info.get("compression_mode") or "").lower()
    if mode not in ("", "none"):
        raise BagError(
            f"{source}: rosbag2 {mode}-level compression is not supported (record with MCAP chunk compression instead, or decompress with `ros2 bag convert`)"
        )
    paths = _get(info, "relative_file_paths", source, list, where)
    file_info = {PurePath(str(f.get("path", ""))).name: f for f in info.get("files") or [] if isinstance(f, dict)}

    def ns(entry: dict[str, Any], key: str, unit: str) -> int:
        return int((entry.get(key) or {}).get(unit, 0) or 0)

    files = []
    for name in (PurePath(str(raw)).name for raw in paths):
        entry = file_info.get(name, {})
        start, duration = ns(entry, "starting_time", "nanoseconds_since_epoch"), ns(entry, "duration", "nanoseconds")
        files.append(FileEntry(name, start, duration, int(entry.get("message_count", 0) or 0)))
    topics = []
    for index, item in enumerate(_get(info, "topics_with_message_count", source, list, where)):
        at = f"{where}topics_with_message_count[{index}]."
        meta = _get(item, "topic_metadata", source, dict, at)
        name = _get(meta, "name", source, str, at + "topic_metadata.")
        msgtype = _get(meta, "type", source, str, at + "topic_metadata.")
        qos = parse_qos_profiles(meta.get("offered_qos_profiles"), f"{source}: topic {name}")
        count = int(item.get("message_count", 0) or 0)
        topics.append(TopicEntry(name, msgtype, qos, str(meta.get("type_description_hash") or ""), count, str(meta.get("serialization_format") or "cdr")))
    custom = info.get("custom_data") or {}
    return BagLayout(
        topics,
        files,
        {str(k): str(v) for k, v in custom.items()} if isinstance(custom, dict) else {},
        storage_identifier=storage,
        version=version,
        ros_distro=str(info.get("ros_distro") or ""),
        stated_message_count=int(info.get("message_count") or 0),
    )


def layout_from_indexes(
    indexes: Sequence[FileIndex],
    previous: BagLayout | None,
    report: Callable[[str], None],
    type_hash_of: Callable[[str], str] = lambda _msgtype: "",
    accepted: list[dict[int, str]] | None = None,
) -> BagLayout:
    """The ``metadata.yaml`` content matching what the storage files hold: topics from their
    channels, completed by ``previous`` (the existing ``metadata.yaml``) for topics without
    messages or values the files lack, hashes still missing from ``type_hash_of``; a channel whose
    type contradicts the topic's is reported and left out (``accepted`` receives the topic of each
    channel kept, per file). The run context is the first :data:`RUN_METADATA_RECORD` record, else
    ``previous``'s ``custom_data``."""
    topics: dict[str, TopicEntry] = {}
    for index in indexes:
        kept: dict[int, str] = {}
        if accepted is not None:
            accepted.append(kept)
        for channel_id in sorted(index.channels):
            channel = index.channels[channel_id]
            declared = (t.msgtype for t in (previous.topics if previous is not None else []) if t.name == channel.topic)
            msgtype = channel.msgtype or next(declared, "")  # from the storage, else from metadata.yaml
            entry = topics.get(channel.topic)
            if entry is None:
                try:
                    qos = parse_qos_profiles(channel.metadata.get("offered_qos_profiles"), f"{index.path.name}: topic {channel.topic}")
                except BagError as exc:
                    report(str(exc))
                    qos = []
                entry = topics[channel.topic] = TopicEntry(channel.topic, msgtype, qos, channel.metadata.get("topic_type_hash", ""), 0, channel.encoding)
            elif msgtype and entry.msgtype and msgtype != entry.msgtype:
                report(f"{index.path.name}: topic {channel.topic} carries {msgtype} here but {entry.msgtype} before; left out")
                continue
            entry.msgtype = entry.msgtype or msgtype
            entry.message_count += index.channel_counts.get(channel_id, 0)
            kept[channel_id] = channel.topic
    if previous is not None:
        for old in previous.topics:
            entry = topics.get(old.name)
            if entry is None:
                topics[old.name] = TopicEntry(old.name, old.msgtype, list(old.qos), old.type_hash, 0, old.serialization_format)
                continue
            entry.msgtype = entry.msgtype or old.msgtype
            entry.qos = entry.qos or list(old.qos)
            if not entry.type_hash and entry.msgtype == old.msgtype:
                entry.type_hash = old.type_hash
    for entry in topics.values():
        if not entry.type_hash and entry.msgtype:
            entry.type_hash = type_hash_of(entry.msgtype)
    files = [FileEntry(i.path.name, i.start_ns, i.end_ns - i.start_ns, i.message_count) if i.message_count else FileEntry(i.path.name) for i in indexes]
    stated = dict(previous.custom_data) if previous is not None else {}
    custom = next((dict(i.metadata[RUN_METADATA_RECORD]) for i in indexes if RUN_METADATA_RECORD in i.metadata), stated)
    distro = previous.ros_distro if previous is not None and previous.ros_distro else ROS_DISTRO
    return BagLayout(topics=list(topics.values()), files=files, custom_data=custom, ros_distro=distro)
