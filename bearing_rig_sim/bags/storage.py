"""The storage seam of the bag code: what reading and repairing a bag need from one storage file,
whatever its format.

A rosbag2 bag is a directory with ``metadata.yaml`` (:mod:`.layout`) and storage files whose format
``metadata.yaml`` names (``storage_identifier``). Everything above this module (the reader, repair,
``bag info``, offline analysis) talks to a :class:`StorageFormat`; only the format's own module
knows its records. One format is implemented: MCAP (:mod:`.mcapfile`), the rosbag2 default since
Iron and the format Foxglove opens.

Adding a storage format: a module with an ``index`` (file -> :class:`~.mcapfile.FileIndex`:
channels, schemas, message groups with their time ranges, statistics, problems), a ``messages``
iterator in log-time order and a ``check`` of every message group; an object with those three
methods and its ``identifier`` and ``suffix`` registered in :data:`STORAGE_FORMATS`. The writer
(:mod:`.writer`) writes MCAP.
"""

from __future__ import annotations

from pathlib import Path
from typing import Protocol
from collections.abc import Callable, Iterable, Iterator

from bearing_rig_sim.bags import mcapfile
from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim.bags.mcapfile import FileIndex

ProblemSink = Callable[[str], None]
"""Receives a one-line description of each problem met while reading."""


class StorageFormat(Protocol):
    """One storage file format of rosbag2 bags."""

    identifier: str
    """``storage_identifier`` in ``metadata.yaml`` (``"mcap"``)."""
    suffix: str
    """File name suffix of its storage files (``".mcap"``)."""

    def index(self, path: Path) -> FileIndex:
        """What the file holds, from its own index or by scanning it; damage goes into
        ``problems``. Raises :class:`~.errors.BagError` when the file is not of this format."""
        ...

    def messages(
        self,
        index: FileIndex,
        channel_ids: Iterable[int] | None = None,
        start_ns: int | None = None,
        stop_ns: int | None = None,
        report: ProblemSink = ...,
    ) -> Iterator[tuple[int, int, int, bytes]]:
        """Messages as (log_time_ns, channel_id, publish_time_ns, data) in log-time order,
        streamed; damaged groups reported through ``report`` and skipped."""
        ...

    def check(self, index: FileIndex) -> list[str]:
        """Read and verify every message group (checksums, decompression): a line per damaged one;
        the bytes of the damaged groups are left in ``index.damaged_bytes``."""
        ...


class McapFormat:
    """MCAP storage files (https://mcap.dev/spec), read by :mod:`.mcapfile`."""

    identifier = "mcap"
    suffix = ".mcap"

    def index(self, path: Path) -> FileIndex:
        """See :func:`.mcapfile.index_file`."""
        return mcapfile.index_file(path)

    def messages(
        self,
        index: FileIndex,
        channel_ids: Iterable[int] | None = None,
        start_ns: int | None = None,
        stop_ns: int | None = None,
        report: ProblemSink = lambda _msg: None,
    ) -> Iterator[tuple[int, int, int, bytes]]:
        """See :func:`.mcapfile.iter_file_messages`."""
        return mcapfile.iter_file_messages(index, channel_ids, start_ns, stop_ns, report)

    def check(self, index: FileIndex) -> list[str]:
        """See :func:`.mcapfile.check_chunks`."""
        return mcapfile.check_chunks(index)


STORAGE_FORMATS: dict[str, StorageFormat] = {"mcap": McapFormat()}
"""The storage formats this project reads, by ``storage_identifier``."""


def storage_format(identifier: str) -> StorageFormat:
    """The format of a ``storage_identifier``.

    Raises:
        BagError: a format this project does not read (the message lists those it does).
    """
    try:
        return STORAGE_FORMATS[identifier]
    except KeyError:
        known = ", ".join(sorted(STORAGE_FORMATS))
        raise BagError(f"storage {identifier!r} is not supported (this project reads: {known})") from None


def storage_for_file(path: Path) -> StorageFormat:
    """The format of a storage file, by its suffix; MCAP when the suffix names none."""
    for fmt in STORAGE_FORMATS.values():
        if path.name.endswith(fmt.suffix):
            return fmt
    return STORAGE_FORMATS["mcap"]
