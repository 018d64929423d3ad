"""Validated YAML configuration.

Every configuration file of the project (bearing data, rig data, test programs, node
parameters) is read through :class:`Section`, so that every error a user can make names the
file, the dotted key and what was allowed::

    config/bearings/h7006c.yaml: geometry.ball_diameter_m: must be > 0, got -0.0063

Defaults live in ``config/``, not in code: a missing key is an error unless the caller gives
an explicit default.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any
from collections.abc import Iterator, Sequence

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


def load_yaml(path: str | Path) -> Section:
    """Read a YAML file whose top level is a mapping (see :func:`parse_yaml` for the limits).

    Raises:
        ConfigError: the file is missing, unreadable, not UTF-8, not YAML, has aliases, is too
            large or too deep, or is not a mapping.
    """
    data = read_yaml_file(path)
    if not isinstance(data, dict):
        raise ConfigError(str(path), "", f"top level must be a mapping, got {type(data).__name__}")
    return Section(data, str(path))


_MISSING = object()


class Section:
    """A mapping read from a configuration source, with typed, range-checked accessors.

    Args:
        data: the mapping.
        source: file name (or other origin) used in error messages.
        prefix: dotted path of this mapping inside the source.
    """

    def __init__(self, data: dict[str, Any], source: str, prefix: str = "") -> None:
        self.data = data
        self.source = source
        self.prefix = prefix

    # -- helpers -----------------------------------------------------------------------------
    def key_path(self, key: str) -> str:
        """Dotted path of ``key`` inside the source."""
        return f"{self.prefix}.{key}" if self.prefix else key

    def error(self, key: str, problem: str) -> ConfigError:
        """A :class:`ConfigError` for ``key`` of this section."""
        return ConfigError(self.source, self.key_path(key), problem)

    def _get(self, key: str, default: Any) -> Any:
        if key in self.data and self.data[key] is not None:
            return self.data[key]
        if default is _MISSING:
            raise self.error(key, "missing (required)")
        return default

    def __contains__(self, key: str) -> bool:
        return key in self.data

    def keys(self) -> Iterator[str]:
        """Keys of the mapping."""
        return iter(self.data.keys())

    def reject_unknown(self, allowed: Sequence[str]) -> None:
        """Raise on keys not in ``allowed`` (catches misspelt keys)."""
        for key in self.data:
            if key not in allowed:
                raise self.error(str(key), f"unknown key; allowed keys: {', '.join(sorted(allowed))}")

    # -- accessors ---------------------------------------------------------------------------
    def section(self, key: str, default: Any = _MISSING) -> Section:
        """A nested mapping as a :class:`Section`."""
        value = self._get(key, default)
        if not isinstance(value, dict):
            raise self.error(key, f"must be a mapping, got {type(value).__name__}")
        return Section(value, self.source, self.key_path(key))

    def number(
        self,
        key: str,
        *,
        gt: float | None = None,
        ge: float | None = None,
        lt: float | None = None,
        le: float | None = None,
        default: Any = _MISSING,
    ) -> float:
        """A finite real number within the given bounds (``gt`` means strictly greater, ...)."""
        value = self._get(key, default)
        return check_number(value, self.source, self.key_path(key), gt=gt, ge=ge, lt=lt, le=le)

    def integer(self, key: str, *, ge: int | None = None, le: int | None = None, default: Any = _MISSING) -> int:
        """An integer within ``[ge, le]``."""
        value = self._get(key, default)
        try:
            value = integer_value(value)
        except ValueError as exc:
            raise self.error(key, str(exc)) from None
        if ge is not None and value < ge:
            raise self.error(key, f"must be >= {ge}, got {value}")
        if le is not None and value > le:
            raise self.error(key, f"must be <= {le}, got {value}")
        return value

    def boolean(self, key: str, default: Any = _MISSING) -> bool:
        """A YAML boolean."""
        value = self._get(key, default)
        try:
            return flag_value(value)
        except ValueError as exc:
            raise self.error(key, str(exc)) from None

    def string(self, key: str, default: Any = _MISSING) -> str:
        """A non-empty string."""
        value = self._get(key, default)
        if not isinstance(value, str) or not value:
            raise self.error(key, f"must be a non-empty string, got {value!r}")
        return value

    def choice(self, key: str, allowed: Sequence[str], default: Any = _MISSING) -> str:
        """A string out of ``allowed``."""
        value = self._get(key, default)
        if value not in allowed:
            raise self.error(key, f"must be one of {', '.join(map(str, allowed))}, got {value!r}")
        return str(value)

    def number_list(self, key: str, *, gt: float | None = None, ge: float | None = None, min_len: int = 1, default: Any = _MISSING) -> list[float]:
        """A list of finite numbers, each within the bounds."""
        value = self._get(key, default)
        if not isinstance(value, list) or len(value) < min_len:
            raise self.error(key, f"must be a list of at least {min_len} number(s), got {value!r}")
        path = self.key_path(key)
        return [check_number(v, self.source, f"{path}[{i}]", gt=gt, ge=ge) for i, v in enumerate(value)]

    def sections(self, key: str) -> list[Section]:
        """A list of mappings, each as a :class:`Section` (``key[i]`` in error paths)."""
        value = self._get(key, _MISSING)
        if not isinstance(value, list) or not value:
            raise self.error(key, "must be a non-empty list of mappings")
        out = []
        for i, item in enumerate(value):
            if not isinstance(item, dict):
                raise ConfigError(self.source, f"{self.key_path(key)}[{i}]", "must be a mapping")
            out.append(Section(item, self.source, f"{self.key_path(key)}[{i}]"))
        return out


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


def ros_parameters(doc: Section, node_name: str) -> Section:
    """The ``node_name: ros__parameters:`` block of a ROS 2 parameter file."""
    return doc.section(node_name).section("ros__parameters")


RPM_TO_RAD_S: float = 2.0 * math.pi / 60.0
"""Conversion factor from rev/min to rad/s (exact)."""


def rpm_to_rad_s(rpm: float) -> float:
    """Convert a speed in rev/min to rad/s (edges of the program only)."""
    return rpm * RPM_TO_RAD_S


def rad_s_to_rpm(omega: float) -> float:
    """Convert a speed in rad/s to rev/min (edges of the program only)."""
    return omega / RPM_TO_RAD_S
