"""Parameter records of the rig models, read and range-checked from ``config/rig.yaml``.

A parameter record is a frozen dataclass whose field names are the YAML keys (units in the
name: ``resistance_ohm``, ``stiffness_n_per_m``) and whose fields carry their allowed range
(:func:`bounded`). The same ranges are checked whether a record is read from a file
(:meth:`ParameterRecord.from_section`, errors name the file and the dotted key) or built in code
(``__post_init__``, errors name the class and the field). Nested records map to nested YAML
mappings. Only the top-level section a record class owns (``SECTION``) is read from the file;
other top-level sections belong to other parts of the project and are ignored.
"""

from __future__ import annotations

import dataclasses
import typing
from pathlib import Path
from typing import Any, ClassVar, TypeVar

from bearing_rig_sim.config import ConfigError, Section, check_number, config_path, load_yaml

R = TypeVar("R", bound="ParameterRecord")

RIG_FILE = "rig.yaml"
"""Name of the rig data file under ``config/``."""


def bounded(
    *,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    default: Any = dataclasses.MISSING,
) -> Any:
    """A dataclass field of a :class:`ParameterRecord` with its allowed range.

    Integer and boolean fields are recognised by their annotation; the bounds apply to numbers
    and integers alike. ``default`` makes the key optional in the YAML file.
    """
    bounds = {"gt": gt, "ge": ge, "lt": lt, "le": le}
    return dataclasses.field(default=default, metadata={"bounds": bounds})


def _bounds(field: dataclasses.Field[Any]) -> dict[str, float | None]:
    return dict(field.metadata.get("bounds", {}))


def _check_integer(value: Any, source: str, key: str, bounds: dict[str, float | None]) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(source, key, f"must be an integer, got {value!r}")
    check_number(value, source, key, **bounds)
    return value


class ParameterRecord:
    """Base of the parameter dataclasses: range checks on construction and YAML loading."""

    SECTION: ClassVar[str] = ""
    """Top-level section of ``config/rig.yaml`` this record is read from (top-level records)."""

    def __post_init__(self) -> None:
        hints = typing.get_type_hints(type(self))
        source = type(self).__name__
        for field in dataclasses.fields(self):  # type: ignore[arg-type]  # every ParameterRecord subclass is a dataclass
            value = getattr(self, field.name)
            kind = hints[field.name]
            if isinstance(kind, type) and issubclass(kind, ParameterRecord):
                if not isinstance(value, kind):
                    raise ConfigError(source, field.name, f"must be a {kind.__name__}, got {value!r}")
            elif kind is bool:
                if not isinstance(value, bool):
                    raise ConfigError(source, field.name, f"must be true or false, got {value!r}")
            elif kind is int:
                _check_integer(value, source, field.name, _bounds(field))
            else:
                check_number(value, source, field.name, **_bounds(field))
        self.check_consistency(lambda key, problem: ConfigError(source, key, problem))

    def check_consistency(self, error: typing.Callable[[str, str], ConfigError]) -> None:
        """Checks across fields (e.g. a minimum below a maximum); raise ``error(key, problem)``.

        The default has none; records with such rules override this.
        """

    @classmethod
    def from_section(cls: type[R], section: Section) -> R:
        """Read and validate the record from a YAML mapping; unknown keys are refused.

        Raises:
            ConfigError: naming the file, the dotted key and the allowed range.
        """
        hints = typing.get_type_hints(cls)
        fields = dataclasses.fields(cls)  # type: ignore[arg-type]  # every ParameterRecord subclass is a dataclass
        section.reject_unknown([f.name for f in fields])
        values: dict[str, Any] = {}
        for field in fields:
            kind = hints[field.name]
            optional = {"default": field.default} if field.default is not dataclasses.MISSING else {}
            key = section.key_path(field.name)
            if isinstance(kind, type) and issubclass(kind, ParameterRecord):
                values[field.name] = kind.from_section(section.section(field.name))
            elif kind is bool:
                values[field.name] = section.boolean(field.name, **optional)
            elif kind is int:
                integer = section.integer(field.name, **optional)
                values[field.name] = _check_integer(integer, section.source, key, _bounds(field))
            else:
                values[field.name] = section.number(field.name, **_bounds(field), **optional)
        try:
            return cls(**values)
        except ConfigError as exc:  # a cross-field rule: re-attribute it to the file
            raise section.error(exc.key, exc.problem) from None

    @classmethod
    def from_yaml(cls: type[R], path: str | Path | None = None) -> R:
        """Read the record's own top-level section (``SECTION``) of a rig file.

        Args:
            path: the rig file; default the shipped ``config/rig.yaml``.
        """
        if not cls.SECTION:
            raise TypeError(f"{cls.__name__} is not a top-level section of {RIG_FILE}")
        doc = load_yaml(path if path is not None else config_path(RIG_FILE))
        return cls.from_section(doc.section(cls.SECTION))

