"""The bag benchmark keeps its analysis bags in ``--workdir`` and analyses a kept one again only
when it is complete and of the length asked for."""

from __future__ import annotations

from pathlib import Path

from bearing_rig_sim.benchmarks.bags import _kept_rig_bag, _record_rig_bag


def test_a_kept_analysis_bag_is_reused_only_when_complete_and_of_the_same_length(tmp_path: Path) -> None:
    folder = tmp_path / "rig-0.05min"
    _write_s, count, size = _record_rig_bag(folder, 0.05)
    assert count > 1000  # 3 s of the rig's traffic: 1 kHz speeds alone
    assert _kept_rig_bag(folder, 0.05) == (0.0, count, size)
    assert _kept_rig_bag(folder, 0.1) is None  # another length
    (folder / "metadata.yaml").unlink()  # as an interrupted recording leaves it
    assert _kept_rig_bag(folder, 0.05) is None
    assert _record_rig_bag(folder, 0.05)[1:] == (count, size)  # recorded afresh over the remains
    assert _kept_rig_bag(tmp_path / "none", 0.05) is None
