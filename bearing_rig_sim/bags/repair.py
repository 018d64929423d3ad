"""Repairing a bag whose recording was killed: ``bearing-rig bag repair BAG...``, docs/bags.md."""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.layout import METADATA_FILE, BagLayout, layout_from_indexes, layout_to_dict, read_layout, write_layout
from bearing_rig_sim.bags.mcapfile import McapFormat, McapIndex, damaged_chunk_bytes, index_file
from bearing_rig_sim.bags.typestore import rig_typestore, type_hash
from bearing_rig_sim.bags.writer import DEFAULT_CHUNK_SIZE, CountingSink, register_topic, start_mcap

BACKUP_SUFFIX = ".orig"


@dataclass
class FileRepair:
    """What the repair did to one storage file: ``intact``, ``rebuilt`` (from its readable part) or
    ``removed`` (not MCAP: moved aside); ``messages_lost``: counted by the original's index and not
    recovered (0 without an index); ``bytes_lost``: damaged chunks and the end in no complete record."""

    name: str
    action: Literal["intact", "rebuilt", "removed"]
    messages_recovered: int = 0
    messages_lost: int = 0
    bytes_lost: int = 0
    backup: Path | None = None
    problems: list[str] = field(default_factory=list)


@dataclass
class RepairReport:
    """Outcome of :func:`repair_bag`."""

    path: Path
    files: list[FileRepair] = field(default_factory=list)
    metadata_rewritten: bool = False
    metadata_backup: Path | None = None

    @property
    def messages_recovered(self) -> int:
        """Messages in the bag after the repair (``messages_lost``, ``bytes_lost``: as :class:`FileRepair`'s, summed)."""
        return sum(f.messages_recovered for f in self.files)

    @property
    def bytes_lost(self) -> int:
        return sum(f.bytes_lost for f in self.files)

    @property
    def messages_lost(self) -> int:
        return sum(f.messages_lost for f in self.files)

    @property
    def changed(self) -> bool:
        """True when anything was rewritten."""
        return self.metadata_rewritten or any(f.action != "intact" for f in self.files)

    def summary(self) -> str:
        """A few lines for a person: what was done, recovered and lost."""
        if not self.changed:
            return f"{self.path}: nothing to repair ({self.messages_recovered} messages, all files finished properly)"
        lines = [f"{self.path}: {self.messages_recovered} messages recovered, {self.messages_lost} messages and {self.bytes_lost} bytes lost"]
        for f in self.files:
            kept = f"; original kept as {f.backup.name}" if f.backup else ""
            lines.append(f"  {f.name}: {f.action}, {f.messages_recovered} messages, {f.messages_lost} messages and {f.bytes_lost} bytes lost{kept}")
            lines.extend(f"    {p}" for p in f.problems)
        if self.metadata_rewritten:
            kept = f" (old one kept as {self.metadata_backup.name})" if self.metadata_backup else ""
            lines.append(f"  {METADATA_FILE}: rebuilt from the files{kept}")
        return "\n".join(lines)


def _backup_path(path: Path) -> Path:
    candidate = path.with_name(path.name + BACKUP_SUFFIX)
    number = 1
    while candidate.exists():
        candidate = path.with_name(f"{path.name}{BACKUP_SUFFIX}.{number}")
        number += 1
    return candidate


def _storage_files(bag_dir: Path, previous: BagLayout | None) -> list[Path]:
    listed = [bag_dir / f.path for f in previous.files] if previous is not None else []
    split = re.compile(r"_(\d+)\.mcap$")  # the writer's <dir>_<n>.mcap; files without come first
    found = sorted(bag_dir.glob("*.mcap"), key=lambda p: (int(m.group(1)) if (m := split.search(p.name)) else -1, p.name))
    files = [p for p in listed if p.is_file()]
    files += [p for p in found if p not in files]
    return files


def _rewrite(index: McapIndex, previous: BagLayout | None, problems: list[str]) -> Path:
    """Write the readable content of a damaged file to ``<name>.repairing``; returns that path."""
    target = index.path.with_name(index.path.name + ".repairing")
    target.unlink(missing_ok=True)
    sink = CountingSink(target)
    try:
        writer = start_mcap(sink, DEFAULT_CHUNK_SIZE, index.compression, index.profile or "ros2", index.library)
        for name, values in index.metadata.items():
            writer.add_metadata(name, values)
        schema_by_name = {name: writer.register_schema(name, encoding, text.encode()) for name, (encoding, text) in index.definitions.items()}
        channel_ids = {
            old_id: writer.register_channel(channel.topic, channel.encoding, schema_by_name.get(channel.msgtype, 0), dict(channel.metadata))
            for old_id, channel in sorted(index.channels.items())
        }
        # Topics metadata.yaml declares but whose channel records were lost with the last chunk.
        present = {c.topic for c in index.channels.values()}
        store = rig_typestore()
        for topic in previous.topics if previous is not None else []:
            if topic.name not in present and topic.msgtype in store.fielddefs:
                register_topic(writer, schema_by_name, topic, store)
        for log_time, channel_id, publish_time, data in McapFormat().messages(index, problems.append):
            writer.add_message(channel_ids[channel_id], log_time, data, publish_time)
        writer.finish()  # type: ignore[no-untyped-call, unused-ignore]  # mcap leaves it unannotated (an error under --strict only)
    except BaseException:
        target.unlink(missing_ok=True)
        raise
    finally:
        sink.close()
    return target


def repair_bag(path: str | Path) -> RepairReport:
    """Make a bag whose recording was interrupted readable by every tool again (see the module
    documentation); BagError for a path that is not a directory or holds no ``.mcap`` file."""
    bag_dir = Path(path)
    if not bag_dir.is_dir():
        raise BagError(f"{bag_dir}: not a bag directory (repair works on the directory holding metadata.yaml and the .mcap files)")
    report = RepairReport(path=bag_dir)
    try:
        previous: BagLayout | None = read_layout(bag_dir)
    except BagError:
        previous = None
    files = _storage_files(bag_dir, previous)
    if not files:
        raise BagError(f"{bag_dir}: no .mcap file, nothing to repair")
    indexes: list[McapIndex] = []
    for file in files:
        try:
            index = index_file(file)
        except BagError as exc:
            backup = _backup_path(file)
            os.replace(file, backup)
            report.files.append(FileRepair(file.name, "removed", backup=backup, problems=[str(exc)]))
            continue
        chunk_bytes_lost = damaged_chunk_bytes(index) if index.indexed and not index.problems else 0
        if index.indexed and not index.problems and not chunk_bytes_lost:
            report.files.append(FileRepair(file.name, "intact", index.message_count))
            indexes.append(index)
            continue
        counted = index.message_count if index.indexed else 0
        entry = FileRepair(file.name, "rebuilt", bytes_lost=max(0, index.file_size - index.readable_bytes) + chunk_bytes_lost, problems=list(index.problems))
        rebuilt = _rewrite(index, previous, entry.problems)
        entry.backup = _backup_path(file)
        os.replace(file, entry.backup)
        os.replace(rebuilt, file)
        index = index_file(file)
        entry.messages_recovered = index.message_count
        entry.messages_lost = max(0, counted - index.message_count)
        report.files.append(entry)
        indexes.append(index)
    problems: list[str] = []
    layout = layout_from_indexes(indexes, previous, problems.append, type_hash)
    if problems and report.files:
        report.files[0].problems.extend(problems)
    if previous is None or layout_to_dict(previous) != layout_to_dict(layout):
        old = bag_dir / METADATA_FILE
        if old.exists():
            report.metadata_backup = _backup_path(old)
            os.replace(old, report.metadata_backup)
        write_layout(bag_dir, layout)
        report.metadata_rewritten = True
    return report
