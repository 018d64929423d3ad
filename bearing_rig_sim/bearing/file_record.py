"""The engine's records of the bearing, each field declared once with the bearing-file key it is
read from (no ROS import).

A record (:class:`~bearing_rig_sim.dynamics.parameters.BearingParameters`,
:class:`~bearing_rig_sim.thermal.bearing.ThermalConfig`) is a frozen dataclass made by
:func:`file_record`; a field read from the file is declared with :func:`file_field`, which names
its dotted key in the validated file (``geometry.ball_diameter_m``) and, where the file's unit is
not the engine's SI one, the conversion::

    @file_record
    class Example:
        ball_diameter: float = file_field("geometry.ball_diameter_m")
        contact_angle: float = file_field("geometry.contact_angle_deg", convert=math.radians)
        source: str = "<memory>"

:func:`file_values` reads every such field of a validated file; the few fields that are not a
plain copy (values derived from a lubricant file, a default in place of an absent section) are
passed to it explicitly by the record's constructor. :func:`file_keys` lists the
correspondence (what a calibration file may set is derived from it).
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from typing import Any, TypeVar, dataclass_transform

FILE_KEY = "file_key"
"""Metadata entry of a field read from the file: its dotted key."""
CONVERT = "convert"
"""Metadata entry of a field read from the file: the conversion to SI (None: the value as is)."""

T = TypeVar("T")


def file_field(key: str, *, convert: Callable[[Any], Any] | None = None) -> Any:
    """A record field read from the validated file at the dotted ``key`` (section and key as the
    file writes them), through ``convert`` (e.g. :func:`math.radians` for a key in degrees)."""
    return dataclasses.field(metadata={FILE_KEY: key, CONVERT: convert})


@dataclass_transform(frozen_default=True, field_specifiers=(file_field, dataclasses.field))
def file_record(cls: type[T]) -> type[T]:
    """Make ``cls`` a frozen dataclass whose :func:`file_field` fields name their file keys."""
    return dataclasses.dataclass(frozen=True)(cls)


def file_keys(record: type) -> dict[str, str]:
    """Field name -> dotted file key, for every :func:`file_field` field of ``record``, in field
    order."""
    return {f.name: f.metadata[FILE_KEY] for f in dataclasses.fields(record) if FILE_KEY in f.metadata}


def file_values(record: type, doc: object, **explicit: Any) -> dict[str, Any]:
    """The keyword arguments of ``record`` from the validated file ``doc``: each :func:`file_field`
    field's value at its key, converted, and the ``explicit`` values (fields that are not a plain
    copy of a key, or whose key is replaced by a derived value) taking precedence."""
    values = {}
    for f in dataclasses.fields(record):
        if FILE_KEY in f.metadata and f.name not in explicit:
            value = functools.reduce(getattr, f.metadata[FILE_KEY].split("."), doc)
            convert = f.metadata[CONVERT]
            values[f.name] = value if convert is None else convert(value)
    return values | explicit
