"""Parameter records of the rig models, read and range-checked from ``config/rig.yaml``.

A parameter record is a frozen dataclass whose field names are the YAML keys (units in the
name: ``resistance_ohm``, ``stiffness_n_per_m``) and whose fields carry their allowed range
(:func:`bounded`); a number declared with its unit may be written ``{value, unit, range,
source}`` as in the bearing files. The checks are those of the declarative parameter model
(:mod:`bearing_rig_sim.settings_model`): each record class gives a pydantic model of its
fields (:meth:`ParameterRecord.model`), with the same value kinds (a number is finite and never
a boolean, an integer is no float, a flag is a YAML boolean) and the same one-line errors. They
apply whether a record is read from a file (:meth:`ParameterRecord.from_mapping`, errors name
the file and the dotted key) or built in code (``__post_init__``, errors name the class and the
field). Nested records map to nested YAML mappings. Only the top-level section a record class
owns (``SECTION``) is read from the file; other top-level sections belong to other parts of the
project and are ignored.

Records stay dataclasses (not pydantic models) so that code builds them positionally and
changes them with :func:`dataclasses.replace`, which checks them again.
"""

from __future__ import annotations

import dataclasses
import functools
import typing
from pathlib import Path
from typing import Any, ClassVar, TypeVar

from pydantic import BaseModel, Field, ValidationError, create_model

from bearing_rig_sim.config import SHIPPED_RIG_FILE, ConfigError, config_path, mapping_at, read_mapping
from bearing_rig_sim.settings_model import FileSection, Flag, Integer, Number, Text, first_error, validate_mapping

R = TypeVar("R", bound="ParameterRecord")

RIG_FILE = SHIPPED_RIG_FILE
"""Name of the rig data file under ``config/``."""


def bounded(
    *,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    default: Any = dataclasses.MISSING,
    unit: str = "",
) -> Any:
    """A dataclass field of a :class:`ParameterRecord` with its allowed range.

    Integer, boolean and text fields are recognised by their annotation; the bounds apply to
    numbers and integers alike. ``default`` makes the key optional in the YAML file. A number
    with a ``unit`` (SI, ``"1"`` for a pure number) may be written in the file as
    ``{value, unit, range, source}`` (:class:`~bearing_rig_sim.settings_model.StatedQuantity`):
    its unit must be this one and its value lie in the range it states.
    """
    bounds = {"gt": gt, "ge": ge, "lt": lt, "le": le}
    return dataclasses.field(default=default, metadata={"bounds": bounds, "unit": unit})


def _is_record(kind: object) -> bool:
    return isinstance(kind, type) and issubclass(kind, ParameterRecord)


def _as_mapping(record: ParameterRecord) -> dict[str, Any]:
    """A record's values as the mapping its model validates (nested records as mappings)."""
    return {
        f.name: _as_mapping(getattr(record, f.name)) if isinstance(getattr(record, f.name), ParameterRecord) else getattr(record, f.name)
        for f in dataclasses.fields(record)  # type: ignore[arg-type]  # every ParameterRecord subclass is a dataclass
    }


class ParameterRecord:
    """Base of the parameter dataclasses: range checks on construction and YAML loading."""

    SECTION: ClassVar[str] = ""
    """Top-level section of ``config/rig.yaml`` this record is read from (top-level records)."""

    @classmethod
    @functools.cache
    def _hints(cls) -> dict[str, Any]:
        """The type of each field."""
        hints = typing.get_type_hints(cls)
        return {f.name: hints[f.name] for f in dataclasses.fields(cls)}  # type: ignore[arg-type]  # every ParameterRecord subclass is a dataclass

    @classmethod
    @functools.cache
    def model(cls) -> type[BaseModel]:
        """The pydantic model of the record's fields (nested records as nested models)."""
        hints = cls._hints()
        fields: dict[str, Any] = {}
        for field in dataclasses.fields(cls):  # type: ignore[arg-type]  # every ParameterRecord subclass is a dataclass
            kind = hints[field.name]
            bounds = {k: v for k, v in field.metadata.get("bounds", {}).items() if v is not None}
            annotation: Any = kind.model() if _is_record(kind) else Flag if kind is bool else Integer if kind is int else Text if kind is str else Number
            default = ... if field.default is dataclasses.MISSING else field.default
            unit = field.metadata.get("unit", "")
            stated: dict[str, Any] | None = {"unit": unit, "source": "the rig file"} if unit else None  # may be written {value, unit, range, source}
            fields[field.name] = (annotation, Field(default, json_schema_extra=stated, **bounds))
        model: type[BaseModel] = create_model(cls.__name__, __base__=FileSection, **fields)
        return model

    def __post_init__(self) -> None:
        source = type(self).__name__
        for name, kind in type(self)._hints().items():
            value = getattr(self, name)
            if _is_record(kind) and not isinstance(value, kind):
                raise ConfigError(source, name, f"must be a {kind.__name__}, got {value!r}")
        try:
            type(self).model().model_validate(_as_mapping(self))
        except ValidationError as exc:
            raise ConfigError(source, *first_error(type(self).model(), exc)) from None
        self.check_consistency(lambda key, problem: ConfigError(source, key, problem))

    def check_consistency(self, error: typing.Callable[[str, str], ConfigError]) -> None:
        """Checks across fields (e.g. a minimum below a maximum); raise ``error(key, problem)``.

        The default has none; records with such rules override this.
        """

    @classmethod
    def from_mapping(cls: type[R], data: object, source: str, key: str = "") -> R:
        """Read and validate the record from a YAML mapping read from ``source`` (at dotted
        ``key`` in it); unknown keys are refused.

        Raises:
            ConfigError: naming the file, the dotted key and the allowed range.
        """
        return cls._build(validate_mapping(cls.model(), data, source, key), source, key)

    @classmethod
    def _build(cls: type[R], checked: BaseModel, source: str, key: str) -> R:
        """The record of a validated model; a cross-field rule's error names the file and key."""
        values: dict[str, Any] = {}
        for name, kind in cls._hints().items():
            value = getattr(checked, name)
            values[name] = kind._build(value, source, f"{key}.{name}" if key else name) if _is_record(kind) else value
        try:
            return cls(**values)
        except ConfigError as exc:  # a cross-field rule: re-attribute it to the file
            raise ConfigError(source, ".".join(part for part in (key, exc.key) if part), exc.problem) from None

    @classmethod
    def from_yaml(cls: type[R], path: str | Path | None = None) -> R:
        """Read the record's own top-level section (``SECTION``) of a rig file.

        Args:
            path: the rig file; default the shipped ``config/rig.yaml``.
        """
        if not cls.SECTION:
            raise TypeError(f"{cls.__name__} is not a top-level section of {RIG_FILE}")
        path = path if path is not None else config_path(RIG_FILE)
        return cls.from_mapping(mapping_at(read_mapping(path), (cls.SECTION,), str(path)), str(path), cls.SECTION)
