"""Parameter records: the same range checks from code and from YAML, with errors naming the
class and field, or the file and dotted key; nested records, optional keys, unknown keys."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar
from collections.abc import Callable

import pytest

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.rig.parameters import ParameterRecord, bounded


@dataclass(frozen=True)
class Spring(ParameterRecord):
    stiffness_n_per_m: float = bounded(gt=0.0)
    preload_n: float = bounded(ge=0.0, default=0.0)


@dataclass(frozen=True)
class Stage(ParameterRecord):
    SECTION: ClassVar[str] = "stage"

    turns: int = bounded(ge=1, le=10)
    enabled: bool
    low_m: float = bounded()
    high_m: float = bounded()
    spring: Spring

    def check_consistency(self, error: Callable[[str, str], ConfigError]) -> None:
        if self.high_m <= self.low_m:
            raise error("high_m", f"must be > low_m ({self.low_m}), got {self.high_m}")


def rig_file(text: str, tmp_path: Path) -> Path:
    path = tmp_path / "rig.yaml"
    path.write_text(text)
    return path


GOOD = """
other_owner: {x: 1}
stage:
  turns: 3
  enabled: true
  low_m: -0.001
  high_m: 0.002
  spring: {stiffness_n_per_m: 2.0e5}
"""


def test_reads_nested_record_with_optional_default(tmp_path: Path) -> None:
    stage = Stage.from_mapping({"turns": 3, "enabled": True, "low_m": -0.001, "high_m": 0.002, "spring": {"stiffness_n_per_m": 2.0e5}}, "code")
    assert stage == Stage(turns=3, enabled=True, low_m=-0.001, high_m=0.002, spring=Spring(2.0e5, 0.0))
    assert Stage.from_yaml(rig_file(GOOD, tmp_path)) == stage  # only its own top-level section is read


@pytest.mark.parametrize(
    "old, new, key, problem",
    [
        ("stiffness_n_per_m: 2.0e5", "stiffness_n_per_m: 0", "stage.spring.stiffness_n_per_m", "> 0"),
        ("turns: 3", "turns: 3.0", "stage.turns", "integer"),
        ("turns: 3", "turns: 11", "stage.turns", "<= 10"),
        ("enabled: true", "enabled: 1", "stage.enabled", "true or false"),
        ("high_m: 0.002", "high_m: -0.002", "stage.high_m", "> low_m"),
        ("  low_m: -0.001\n", "", "stage.low_m", "missing"),
        ("  turns: 3\n", "  turns: 3\n  turn: 4\n", "stage.turn", "unknown key"),
        ("spring: {stiffness_n_per_m: 2.0e5}", "spring: 5", "stage.spring", "mapping"),
    ],
)
def test_yaml_errors_name_file_and_key(tmp_path: Path, old: str, new: str, key: str, problem: str) -> None:
    assert old in GOOD
    path = rig_file(GOOD.replace(old, new), tmp_path)
    with pytest.raises(ConfigError) as info:
        Stage.from_yaml(path)
    assert info.value.source == str(tmp_path / "rig.yaml")
    assert info.value.key == key
    assert problem in info.value.problem


def test_code_construction_is_checked_too() -> None:
    with pytest.raises(ConfigError) as info:
        Spring(stiffness_n_per_m=float("nan"))
    assert info.value.source == "Spring" and info.value.key == "stiffness_n_per_m"
    with pytest.raises(ConfigError, match="high_m"):
        Stage(turns=1, enabled=False, low_m=0.0, high_m=0.0, spring=Spring(1.0))
    with pytest.raises(ConfigError, match="Spring"):
        Stage(turns=1, enabled=False, low_m=0.0, high_m=1.0, spring=5.0)  # type: ignore[arg-type]


def test_record_without_section_cannot_be_read_from_a_file(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match="top-level"):
        Spring.from_yaml(tmp_path / "rig.yaml")


def test_errors_are_the_parameter_models_one_line_wording(tmp_path: Path) -> None:
    """The same words as every node's settings (bearing_rig_sim.settings_model): the range with
    the value, the allowed keys of the nested mapping, a null taken as absent."""
    cases = {
        "stiffness_n_per_m: 2.0e5": ("stiffness_n_per_m: 0", "stage.spring.stiffness_n_per_m: must be > 0.0, got 0.0"),
        "spring: {stiffness_n_per_m: 2.0e5}": (
            "spring: {stiffness_n_per_m: 2.0e5, stifness: 1}",
            "stage.spring.stifness: unknown key; allowed keys: preload_n, stiffness_n_per_m",
        ),
        "low_m: -0.001": ("low_m: null", "stage.low_m: missing (required)"),
        "turns: 3": ("turns: '3'", "stage.turns: must be an integer, got '3'"),
    }
    for old, (new, message) in cases.items():
        path = rig_file(GOOD.replace(old, new), tmp_path)
        with pytest.raises(ConfigError) as info:
            Stage.from_yaml(path)
        assert str(info.value) == f"{tmp_path / 'rig.yaml'}: {message}"
    with pytest.raises(ConfigError) as info:
        Spring(stiffness_n_per_m=1.0, preload_n=-1.0)
    assert str(info.value) == "Spring: preload_n: must be >= 0.0, got -1.0"
    assert Spring(2.0, 1.0) == Spring(stiffness_n_per_m=2.0, preload_n=1.0)  # still a dataclass
