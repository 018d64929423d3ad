"""The storage seam: formats found by identifier and by file name, unknown ones refused by name,
and a bag read through the seam gives back what the writer put in."""

from __future__ import annotations

from pathlib import Path

import pytest

from bearing_rig_sim.bags import BagError, BagWriter, open_bag
from bearing_rig_sim.bags.storage import STORAGE_FORMATS, storage_for_file, storage_format


def test_mcap_is_found_by_identifier_and_by_suffix() -> None:
    assert storage_format("mcap") is STORAGE_FORMATS["mcap"]
    assert storage_for_file(Path("run_0.mcap")).identifier == "mcap"


def test_unknown_storage_is_refused_naming_it_and_the_known_ones() -> None:
    with pytest.raises(BagError, match=r"'sqlite3' is not supported .*mcap"):
        storage_format("sqlite3")


def test_metadata_naming_another_storage_is_refused(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    with BagWriter(bag) as writer:
        writer.add_topic("/x", "std_msgs/msg/Float64", "reliable")
        writer.write("/x", 1, b"\x00\x01\x00\x00" + bytes(8))
    meta = bag / "metadata.yaml"
    meta.write_text(meta.read_text().replace("storage_identifier: mcap", "storage_identifier: sqlite3"))
    with pytest.raises(BagError, match="sqlite3"):
        open_bag(bag)


def test_messages_through_the_seam_round_trip(tmp_path: Path) -> None:
    bag = tmp_path / "run"
    payloads = [b"\x00\x01\x00\x00" + bytes([i]) * 8 for i in range(5)]
    with BagWriter(bag) as writer:
        writer.add_topic("/x", "std_msgs/msg/Float64", "reliable")
        for i, data in enumerate(payloads):
            writer.write("/x", 1000 + i, data)
    fmt = storage_for_file(next(bag.glob("*.mcap")))
    index = fmt.index(next(bag.glob("*.mcap")))
    assert fmt.check(index) == []
    read = [(t, d) for t, _c, _p, d in fmt.messages(index)]
    assert read == [(1000 + i, d) for i, d in enumerate(payloads)]
    with open_bag(bag) as reader:
        assert reader.topics["/x"].message_count == 5
