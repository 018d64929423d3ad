"""Reading YAML configuration safely, and the project's configuration error.

Every configuration file of the project (bearing, lubricant and calibration data, rig data, test
programs, sweep specifications, node parameters) is read here (:func:`read_mapping`: no Python
objects, no aliases, bounded size and depth) and validated by its declarative model
(:mod:`bearing_rig_sim.settings_model`), so that every error a user can make is one line naming
the file, the dotted key and what was allowed::

    config/bearings/h7006c.yaml: geometry.ball_diameter_m: must be > 0.0, got -0.0063

The value kinds of those models (:func:`number_value`, :func:`integer_value`,
:func:`flag_value`) and :func:`check_number` for a value checked outside a model (a command-line
argument) are here too. Defaults live in ``config/``, not in code.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any
from collections.abc import Mapping, Sequence

import yaml

from bearing_rig_sim.errors import RigError

#: Folder holding the shipped configuration files (``config/`` at the repository root, or
#: ``share/bearing_rig_sim/config`` in an installed ROS package).
CONFIG_DIR: Path = Path(__file__).resolve().parent.parent / "config"


class ConfigError(RigError, ValueError):
    """A configuration value is missing, malformed or out of range.

    Attributes:
        source: the file (or other origin) the value came from.
        key: dotted path of the offending key (empty for the whole document).
        problem: what is wrong, including the allowed range where there is one.
    """

    def __init__(self, source: str, key: str, problem: str) -> None:
        self.source = source
        self.key = key
        self.problem = problem
        where = f"{source}: {key}" if key else source
        super().__init__(f"{where}: {problem}")


BEARING_MODELS: tuple[str, ...] = ("bench", "paper")
"""The named models of the bearing's physics, the default first: ``bench`` (the bench twin) and
``paper`` (the paper's own model); :mod:`bearing_rig_sim.dynamics.models` builds them."""


def config_path(*parts: str) -> Path:
    """Path of a shipped configuration file, e.g. ``config_path("bearings", "h7006c.yaml")``.

    Looks in the source tree first, then in the installed ROS share folder.
    """
    local = CONFIG_DIR.joinpath(*parts)
    if local.exists():
        return local
    try:
        from ament_index_python.packages import get_package_share_directory

        share = Path(get_package_share_directory("bearing_rig_sim")) / "config"
        installed = share.joinpath(*parts)
        if installed.exists():
            return installed
    except Exception:
        pass
    return local


SHIPPED_BEARING_FILE: str = "bearings/h7006c.yaml"
"""The shipped bearing file, relative to ``config/``: the bearing a command, a core or a node
uses when none is named (the node parameter files name it too, as their defaults)."""

SHIPPED_CALIBRATION_FILE: str = "calibration/h7006c_table3.yaml"
"""The shipped calibration of :data:`SHIPPED_BEARING_FILE` (the bench's Table 3 fit), relative to
``config/``."""

SHIPPED_RIG_FILE: str = "rig.yaml"
"""The shipped rig file, relative to ``config/``."""


def shipped_bearing_file() -> Path:
    """Path of the shipped bearing file (:data:`SHIPPED_BEARING_FILE`)."""
    return config_path(*SHIPPED_BEARING_FILE.split("/"))


def shipped_calibration_file() -> Path:
    """Path of the shipped calibration (:data:`SHIPPED_CALIBRATION_FILE`)."""
    return config_path(*SHIPPED_CALIBRATION_FILE.split("/"))


def shipped_rig_file() -> Path:
    """Path of the shipped rig file (:data:`SHIPPED_RIG_FILE`)."""
    return config_path(SHIPPED_RIG_FILE)


MAX_YAML_BYTES: int = 4 * 1024 * 1024
"""Largest YAML document read, bytes (the shipped files are a few kB; a bag's metadata a few
tens of kB)."""

MAX_YAML_DEPTH: int = 32
"""Deepest nesting of mappings and lists accepted (the shipped files nest 4 levels)."""


class _BoundedSafeLoader(yaml.SafeLoader):
    """PyYAML's safe loader with aliases refused and nesting bounded.

    Aliases (``*name``) are what makes a "billion laughs" document of a few hundred bytes expand
    to gigabytes; no configuration or bag metadata of this project needs them. Deep nesting
    would otherwise end in a RecursionError deep inside the constructor.
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: Any, index: Any) -> Any:
        """PyYAML's hook for each node: refuse an alias, count the depth."""
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise yaml.composer.ComposerError(None, None, "aliases (*name) are not accepted", event.start_mark)
        self._depth += 1
        try:
            if self._depth > MAX_YAML_DEPTH:
                event = self.peek_event()
                raise yaml.composer.ComposerError(None, None, f"nested deeper than {MAX_YAML_DEPTH} levels", event.start_mark)
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


def parse_yaml(text: str | bytes, source: str) -> Any:
    """Parse one YAML document safely: no Python objects, no aliases, bounded size and depth.

    Args:
        text: the document; bytes must be UTF-8.
        source: file name (or other origin) for error messages.

    Raises:
        ConfigError: one line naming ``source`` and what is wrong (not UTF-8, too large, an
            alias, too deep, not valid YAML).
    """
    if isinstance(text, bytes):
        if len(text) > MAX_YAML_BYTES:
            raise ConfigError(source, "", f"larger than {MAX_YAML_BYTES} bytes ({len(text)})")
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ConfigError(source, "", f"not UTF-8 text (byte {exc.start})") from None
    if len(text) > MAX_YAML_BYTES:
        raise ConfigError(source, "", f"larger than {MAX_YAML_BYTES} characters ({len(text)})")
    loader = _BoundedSafeLoader(text)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        at = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise ConfigError(source, "", f"not valid YAML{at}: {getattr(exc, 'problem', exc)}") from None
    except RecursionError:
        raise ConfigError(source, "", "nested too deeply") from None
    finally:
        loader.dispose()


def read_yaml_file(path: str | Path) -> Any:
    """Read and :func:`parse_yaml` a file (any top-level type).

    Raises:
        ConfigError: the file is missing or unreadable, or see :func:`parse_yaml`.
    """
    source = str(path)
    try:
        with open(path, "rb") as stream:
            raw = stream.read(MAX_YAML_BYTES + 1)
    except OSError as exc:
        raise ConfigError(source, "", f"cannot read file ({exc.strerror or exc})") from None
    return parse_yaml(raw, source)


def read_mapping(path: str | Path) -> dict[str, Any]:
    """Read a YAML file whose top level is a mapping (see :func:`parse_yaml` for the limits).

    Raises:
        ConfigError: the file is missing, unreadable, not UTF-8, not YAML, has aliases, is too
            large or too deep, or is not a mapping.
    """
    data = read_yaml_file(path)
    if not isinstance(data, dict):
        raise ConfigError(str(path), "", f"top level must be a mapping, got {type(data).__name__}")
    return data


def mapping_at(data: Mapping[str, Any], keys: Sequence[str], source: str) -> dict[str, Any]:
    """The mapping at ``keys`` inside ``data`` (read from ``source``), e.g. ``("monitor",
    "ros__parameters")``.

    Raises:
        ConfigError: a key is missing or null, or its value is not a mapping.
    """
    here: Any = data
    for depth, key in enumerate(keys):
        value = here.get(key)
        path = ".".join(keys[: depth + 1])
        if value is None:
            raise ConfigError(source, path, "missing (required)")
        if not isinstance(value, dict):
            raise ConfigError(source, path, f"must be a mapping, got {type(value).__name__}")
        here = value
    return dict(here)


def number_value(value: object) -> float:
    """A YAML value as a finite real number (an integer is one; a boolean is not).

    Raises:
        ValueError: the problem in the project's words (``must be a number, got 'fast'``).
    """
    if isinstance(value, str):
        # PyYAML follows YAML 1.1, which reads exponents without a sign ("2.0e9") as strings;
        # YAML 1.2 reads them as floats, and so do we.
        try:
            value = float(value.strip())
        except ValueError:
            raise ValueError(f"must be a number, got {value!r}") from None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"must be a number, got {value!r}")
    if not math.isfinite(value):
        raise ValueError(f"must be finite, got {value!r}")
    return float(value)


def integer_value(value: object) -> int:
    """A YAML value as an integer (a boolean or a float is not one).

    Raises:
        ValueError: the problem in the project's words.
    """
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"must be an integer, got {value!r}")
    return value


def flag_value(value: object) -> bool:
    """A YAML boolean (``true`` or ``false``, nothing that merely converts to one).

    Raises:
        ValueError: the problem in the project's words.
    """
    if not isinstance(value, bool):
        raise ValueError(f"must be true or false, got {value!r}")
    return value


def check_number(
    value: Any,
    source: str,
    key: str,
    *,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
) -> float:
    """Check that ``value`` is a finite real number inside the bounds; return it as float.

    Raises:
        ConfigError: naming ``source``, ``key`` and the allowed range.
    """
    try:
        x = number_value(value)
    except ValueError as exc:
        raise ConfigError(source, key, str(exc)) from None
    if gt is not None and not x > gt:
        raise ConfigError(source, key, f"must be > {gt}, got {value!r}")
    if ge is not None and not x >= ge:
        raise ConfigError(source, key, f"must be >= {ge}, got {value!r}")
    if lt is not None and not x < lt:
        raise ConfigError(source, key, f"must be < {lt}, got {value!r}")
    if le is not None and not x <= le:
        raise ConfigError(source, key, f"must be <= {le}, got {value!r}")
    return x


def ros_parameters(doc: Mapping[str, Any], node_name: str, source: str) -> dict[str, Any]:
    """The ``node_name: ros__parameters:`` block of a ROS 2 parameter file read from ``source``.

    Raises:
        ConfigError: the block is missing or not a mapping.
    """
    return mapping_at(doc, (node_name, "ros__parameters"), source)


RPM_TO_RAD_S: float = 2.0 * math.pi / 60.0
"""Conversion factor from rev/min to rad/s (exact)."""


def rpm_to_rad_s(rpm: float) -> float:
    """Convert a speed in rev/min to rad/s (edges of the program only)."""
    return rpm * RPM_TO_RAD_S


def rad_s_to_rpm(omega: float) -> float:
    """Convert a speed in rad/s to rev/min (edges of the program only)."""
    return omega / RPM_TO_RAD_S
