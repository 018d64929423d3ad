"""One declarative model of a node's parameters (pydantic v2), from which come the validation of
its YAML file and of its ROS parameters in force, the one-line errors naming the file, the key
and the allowed range, and the description, unit and range of each parameter that the node
declares to ROS.

A settings class derives from :class:`NodeSettings` and declares each parameter once::

    class LoadControllerSettings(NodeSettings):
        NODE_NAME: ClassVar[str] = "load_controller"
        SHIPPED_FILE: ClassVar[str] = "load_controller.yaml"

        state_rate_hz: Number = param("rate of the state topic in simulated time", unit="Hz", gt=0.0, le=1000.0)

* :data:`Number`, :data:`Integer` and :data:`Flag` are the YAML value kinds (a number is finite
  and never a boolean; YAML 1.1's unsigned exponents such as ``2.0e9``, which PyYAML reads as
  strings, are numbers); :data:`ConfigFile` and :data:`OptionalConfigFile` are files that must
  exist (absolute, or relative to ``config/``); :func:`one_of` restricts a text to a few words;
* :func:`param` gives the description, the unit, the range (``gt``, ``ge``, ``lt``, ``le``),
  whether the parameter may change while the node runs, and where a limit of the rig lives
  (``rig_limit``: a dotted key of the node's rig file, such as ``loading_chain.max_setpoint_n``,
  which is then the upper bound the checks apply and the descriptor shows);
* :meth:`NodeSettings.from_mapping` (and ``from_values``, ``from_yaml``) validates a mapping and
  raises :class:`~bearing_rig_sim.config.ConfigError` for the first problem in field order, in
  the project's words (``load_controller.yaml: state_rate_hz: must be > 0.0, got 0``);
* :meth:`NodeSettings.parameter_fields` lists what the ROS descriptors are made from.

The defaults of a node live only in the shipped files under ``config/``: every parameter is
required.

The data files (bearing, lubricant and calibration files, sweep specifications) are models of
the same kinds and words: a :class:`FileSection` per mapping (unknown keys refused), a
:func:`quantity` per physical parameter (description, SI unit, the source of its plausible range,
the range, a default where the key may be left out), checks across keys in model validators
raising :func:`field_error`, and :func:`validate_mapping` / :func:`read_file` giving the one-line
error naming the file and the full dotted key. A quantity may be written with the range its file
states (:class:`StatedQuantity`). The rig file's records (:mod:`bearing_rig_sim.rig.parameters`)
and the test programs (:mod:`bearing_rig_sim.rig.program`) are built on the same kinds.
No ROS import.
"""

from __future__ import annotations

import typing
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, ClassVar, Self, TypeVar

import annotated_types
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, TypeAdapter, ValidationError, ValidationInfo, field_validator, model_validator
from pydantic_core import ErrorDetails

from bearing_rig_sim.config import (
    ConfigError,
    check_number,
    config_path,
    flag_value,
    integer_value,
    number_value,
    read_mapping,
    ros_parameters,
    shipped_rig_file,
)

__all__ = [
    "ConfigFile",
    "check_within_rig",
    "FileSection",
    "Flag",
    "Integer",
    "NodeSettings",
    "Number",
    "OptionalConfigFile",
    "ParameterField",
    "StatedQuantity",
    "Text",
    "field_error",
    "existing_config_file",
    "first_error",
    "one_of",
    "param",
    "quantity",
    "read_file",
    "resolve_config_file",
    "resolve_rig_file",
    "rig_file_value",
    "validate_mapping",
    "without_nulls",
]


Number = Annotated[float, BeforeValidator(number_value)]
"""A finite real number (an integer is taken as one; a boolean is not)."""

Integer = Annotated[int, BeforeValidator(integer_value)]
"""An integer (a boolean is not)."""

Flag = Annotated[bool, BeforeValidator(flag_value)]
"""A YAML boolean (``true`` or ``false``, nothing that merely converts to one)."""


def _text(raw: object) -> str:
    if not isinstance(raw, str) or not raw:
        raise ValueError(f"must be a non-empty string, got {raw!r}")
    return raw


Text = Annotated[str, BeforeValidator(_text)]
"""A non-empty string."""


def resolve_config_file(value: str) -> Path | None:
    """A file parameter as a path: None for ``""``, as given if absolute, else under ``config/``."""
    if not value:
        return None
    path = Path(value)
    return path if path.is_absolute() else config_path(*path.parts)


def existing_config_file(raw: object, *, empty_ok: bool = False) -> Path | None:
    """A file parameter that must exist (absolute or under ``config/``); ``""`` is None where
    ``empty_ok``. Raises ValueError with the problem (a settings validator's error)."""
    if not isinstance(raw, str) or (not raw and not empty_ok):
        raise ValueError(f"must be a file name (absolute or relative to config/), got {raw!r}")
    path = resolve_config_file(raw)
    if path is not None and not path.is_file():
        raise ValueError(f"file not found: {raw!r} (looked for {path})")
    return path


def resolve_rig_file(raw: object) -> Path:
    """A rig-file parameter as an existing path: ``""`` is the shipped ``config/rig.yaml``, a
    relative name is under ``config/``. Raises ValueError with the problem."""
    if raw == "":
        return shipped_rig_file()
    path = existing_config_file(raw)
    assert path is not None  # "" handled above
    return path


def rig_file_value(rig_file: Path, key: str) -> float:
    """The number at dotted ``key`` of a rig file (a limit of the rig, such as
    ``loading_chain.max_setpoint_n``): the one place that limit is written.

    Raises:
        ConfigError: naming the rig file and the key (missing, not a number).
    """
    *sections, last = key.split(".")
    here: Any = read_mapping(rig_file)
    for depth, section in enumerate(sections):
        here = here.get(section)
        if not isinstance(here, Mapping):
            raise ConfigError(str(rig_file), ".".join(sections[: depth + 1]), "missing (required: a mapping)")
    if last not in here:
        raise ConfigError(str(rig_file), key, "missing (required)")
    return check_number(here[last], str(rig_file), key)


def check_within_rig(
    value: float,
    source: str,
    key: str,
    rig_key: str,
    *,
    rig_file: Path | None = None,
    unit_in_si: float = 1.0,
    unit: str = "",
) -> float:
    """Check that ``value`` (at ``key`` of ``source``) is at most the rig's limit at dotted
    ``rig_key`` of ``rig_file`` (default: the shipped ``config/rig.yaml``); ``unit_in_si`` is
    the value's unit in SI (``RPM_TO_RAD_S`` for a speed in rpm), ``unit`` its name in the error.

    Raises:
        ConfigError: naming ``source``, ``key``, the limit and where it is written.
    """
    rig = rig_file if rig_file is not None else shipped_rig_file()
    limit = rig_file_value(rig, rig_key) / unit_in_si
    if not value <= limit * (1.0 + 1e-12):  # a limit written in SI for a round number of rpm
        raise ConfigError(source, key, f"must be <= {limit:.10g}{unit}, the rig's limit ({rig_key} in {rig}), got {value!r}")
    return value


def _required_file(raw: object) -> Path | None:
    return existing_config_file(raw)


def _optional_file(raw: object) -> Path | None:
    return existing_config_file(raw, empty_ok=True)


ConfigFile = Annotated[Path, BeforeValidator(_required_file)]
"""A file that exists, named absolute or relative to ``config/`` (never ``""``)."""

OptionalConfigFile = Annotated[Path | None, BeforeValidator(_optional_file)]
"""As :data:`ConfigFile`, or ``""`` for none (None)."""


def one_of(allowed: Sequence[str]) -> BeforeValidator:
    """The check of a text field that takes one of a few words:
    ``model: Annotated[str, one_of(MODELS)] = param(...)``."""
    words = tuple(allowed)

    def check(raw: object) -> str:
        if raw not in words:
            raise ValueError(f"must be one of {', '.join(words)}, got {raw!r}")
        return str(raw)

    return BeforeValidator(check)


def param(
    description: str,
    *,
    unit: str = "",
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    live: bool = False,
    rig_limit: str = "",
) -> Any:
    """One parameter of a settings class: what it is, its SI unit (``"1"`` for a pure number,
    ``""`` for text, files and flags), its allowed range, whether it may be set while the node
    runs (``live``; otherwise it is read at configure and read-only to ROS), and the dotted key
    of the node's rig file holding its upper bound (``rig_limit``; ``le`` is then the plausible
    bound of any bench, the rig file's value the one in force)."""
    return Field(description=description, gt=gt, ge=ge, lt=lt, le=le, json_schema_extra={"unit": unit, "live": live, "rig_limit": rig_limit})


def quantity(
    description: str,
    *,
    unit: str,
    source: str,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    default: Any = ...,
    calibratable: bool = False,
) -> Any:
    """One physical parameter of a data file (bearing, lubricant, calibration, sweep): what it
    is, its SI unit (``"1"`` for a pure number), where its plausible range (``gt``, ``ge``,
    ``lt``, ``le``) comes from, its default where the key may be left out, and whether a
    calibration file may set it."""
    extra: dict[str, Any] = {"unit": unit, "source": source} | ({"calibratable": True} if calibratable else {})
    return Field(default, description=description, gt=gt, ge=ge, lt=lt, le=le, json_schema_extra=extra)


@dataclass(frozen=True)
class ParameterField:
    """What a node declares to ROS about one parameter, as the settings class states it (no ROS
    here: :mod:`bearing_rig_sim.nodes.shell` makes the ``ParameterDescriptor``).

    Attributes:
        name: the parameter's name.
        description: what it is.
        unit: SI unit, ``"1"``, or ``""``.
        low, high: the allowed range (None where unbounded or not a number).
        low_exclusive, high_exclusive: the bound itself is refused.
        integer: an integer parameter.
        live: may be set while the node runs.
        rig_limit: the dotted key of the rig file holding the upper bound ("" for none).
        limit_source: where ``high`` was read ("" for the settings class itself), e.g.
            ``loading_chain.max_setpoint_n in rig.yaml``.
    """

    name: str
    description: str
    unit: str
    low: float | None
    high: float | None
    low_exclusive: bool
    high_exclusive: bool
    integer: bool
    live: bool
    rig_limit: str = ""
    limit_source: str = ""

    @property
    def numeric(self) -> bool:
        """A number with a range at both ends (what a ROS range can state)."""
        return self.low is not None and self.high is not None

    @property
    def read_only(self) -> bool:
        """Refused by ``set_parameters`` once declared (read at configure)."""
        return not self.live

    def constraints(self) -> str:
        """The descriptor's ``additional_constraints`` text: unit, range, when it applies. ROS
        ranges are inclusive; an exclusive bound is refused by the settings class at configure
        and stated here."""
        parts = []
        if self.unit:
            parts.append(f"unit: {self.unit}")
        if self.low is not None and self.high is not None:
            low = ">" if self.low_exclusive else ">="
            high = "<" if self.high_exclusive else "<="
            parts.append(f"range: {low} {self.low:g} and {high} {self.high:g}" + (f" ({self.limit_source})" if self.limit_source else ""))
        parts.append("may be set live" if self.live else "read-only: set at start (parameter file or -p), read at configure")
        return "; ".join(parts)


_BOUND_WORDS = {
    "greater_than": (">", "gt"),
    "greater_than_equal": (">=", "ge"),
    "less_than": ("<", "lt"),
    "less_than_equal": ("<=", "le"),
}


def _problem(error: ErrorDetails) -> str:
    """One validation error in the project's words."""
    kind = error["type"]
    ctx = error.get("ctx", {})
    if kind == "missing":
        return "missing (required)"
    if kind in _BOUND_WORDS:
        word, key = _BOUND_WORDS[kind]
        return f"must be {word} {ctx[key]}, got {error['input']!r}"
    if kind == "value_error":
        cause = ctx["error"]
        return cause.problem if isinstance(cause, ConfigError) else str(cause)
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        return f"must be a mapping, got {type(error['input']).__name__}"
    if kind in ("too_short", "too_long"):
        bound = f"at least {ctx['min_length']}" if kind == "too_short" else f"at most {ctx['max_length']}"
        return f"must be a list of {bound} item(s), got {error['input']!r}"
    if kind == "list_type":
        return f"must be a list, got {type(error['input']).__name__}"
    return str(error["msg"])


def _model_at(model: type[BaseModel], path: Sequence[int | str]) -> type[BaseModel] | None:
    """The nested model at ``path`` inside ``model`` (None if the path leads elsewhere)."""
    for part in path:
        info = model.model_fields.get(str(part))
        nested = info.annotation if info is not None else None
        for arg in typing.get_args(nested):  # a list of nested models
            nested = arg
        if not (isinstance(nested, type) and issubclass(nested, BaseModel)):
            return None
        model = nested
    return model


def first_error(model: type[BaseModel], exc: ValidationError) -> tuple[str, str]:
    """The first error of validating ``model`` in the project's words: the dotted key inside the
    validated mapping and the problem with its allowed range (``("brake.resistance_ohm", "must
    be > 0.0, got -2.0")``). A :class:`~bearing_rig_sim.config.ConfigError` raised by a nested
    check keeps its own key below the nested mapping's."""
    errors = exc.errors()
    error = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])  # a misspelt key first
    loc = [f"[{part}]" if isinstance(part, int) else part for part in error["loc"]]
    problem = _problem(error)
    if error["type"] == "extra_forbidden":
        owner = _model_at(model, [part for part in error["loc"][:-1] if not isinstance(part, int)])
        allowed = ", ".join(sorted(info.alias or name for name, info in owner.model_fields.items())) if owner is not None else ""
        problem = f"unknown key; allowed keys: {allowed}"
    cause = error.get("ctx", {}).get("error")
    if isinstance(cause, ConfigError):
        loc, problem = [*loc, cause.key] if cause.key else loc, cause.problem
    return ".".join(loc).replace(".[", "["), problem


M = TypeVar("M", bound=BaseModel)


def field_error(key: str, problem: str) -> ConfigError:
    """The error a check across fields raises inside a model's validator: ``key`` relative to
    the model's mapping; :func:`validate_mapping` names the file and the full dotted key."""
    return ConfigError("", key, problem)


def without_nulls(data: Any) -> Any:
    """A YAML ``null`` is an absent key (its default, or "missing"), also in mappings in lists."""
    if isinstance(data, Mapping):
        return {k: without_nulls(v) for k, v in data.items() if v is not None}
    if isinstance(data, list):
        return [without_nulls(v) for v in data]
    return data


class FileSection(BaseModel):
    """Base of a data file's model (a file or one of its mappings): frozen, an unknown key is
    refused (a misspelt optional key would otherwise leave its default in force silently).

    A physical parameter (a :func:`quantity`) is written either as a number or as a
    :class:`StatedQuantity` ``{value, unit, range: [low, high], source}``: then its unit must be
    the parameter's and its value must lie in the range the file states (besides the model's
    plausible range)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    @field_validator("*", mode="before")
    @classmethod
    def _stated_quantity(cls, raw: object, info: ValidationInfo) -> object:
        extra = cls.model_fields[info.field_name].json_schema_extra if info.field_name else None
        if not isinstance(raw, Mapping) or not isinstance(extra, dict) or "source" not in extra:
            return raw
        stated = validate_mapping(StatedQuantity, raw, "")
        if stated.unit != extra["unit"]:
            raise field_error("unit", f"must be {extra['unit']!r}, the unit of this key, got {stated.unit!r}")
        return stated.value


class StatedQuantity(FileSection):
    """A value with its unit, the plausible range its file states and where both come from (a
    calibrated value, or a bearing or lubricant datum written with its range)."""

    value: Number = Field(description="the value, in the unit")
    unit: Text = Field(description="its SI unit")
    range: Annotated[list[Number], Field(min_length=2, max_length=2)] = Field(description="[low, high], the plausible interval")
    source: Text = Field(description="where the value and the range come from")

    @model_validator(mode="after")
    def _value_in_range(self) -> Self:
        check_number(self.value, "", "value", ge=self.range[0], le=self.range[1])
        return self


def validate_mapping(model: type[M], data: object, source: str, key: str = "") -> M:
    """Validate a mapping read from ``source`` (at dotted ``key`` inside it) against ``model``;
    a ``null`` counts as absent.

    Raises:
        ConfigError: the first problem in field order (a misspelt key first), naming the source,
            the full dotted key and the allowed range.
    """
    if not isinstance(data, Mapping):
        raise ConfigError(source, key, f"must be a mapping, got {type(data).__name__}")
    try:
        return model.model_validate(without_nulls(data))
    except ValidationError as exc:
        where, problem = first_error(model, exc)
        raise ConfigError(source, ".".join(part for part in (key, where) if part).replace(".[", "["), problem) from None


def read_file(model: type[M], path: str | Path) -> M:
    """Read a YAML file (:func:`~bearing_rig_sim.config.read_mapping`) and validate it against
    ``model`` (:func:`validate_mapping`).

    Raises:
        ConfigError: naming the file, the dotted key and the allowed range.
    """
    return validate_mapping(model, read_mapping(path), str(path))


class NodeSettings(BaseModel):
    """Base of a node's settings: a frozen model whose fields are its parameters (see the module
    documentation). Set ``NODE_NAME`` (the node's name, its block in a parameter file) and
    ``SHIPPED_FILE`` (under ``config/``, the only place the defaults live); ``OTHER_KEYS`` are
    keys a parameter file may hold that are not the node's own (by default rclpy's
    ``use_sim_time``, which every node has), to be checked by :meth:`check_other_keys`."""

    model_config = ConfigDict(frozen=True, extra="forbid", arbitrary_types_allowed=True)

    NODE_NAME: ClassVar[str]
    SHIPPED_FILE: ClassVar[str]
    OTHER_KEYS: ClassVar[tuple[str, ...]] = ("use_sim_time",)
    RIG_FILE_PARAMETER: ClassVar[str] = "rig_file"
    """The parameter naming the rig file whose limits bound the ``rig_limit`` parameters."""

    @model_validator(mode="after")
    def _within_the_rig(self) -> Self:
        """A parameter with a ``rig_limit`` is at most the rig file's value."""
        for name, key in self.rig_limits().items():
            check_within_rig(getattr(self, name), "", name, key, rig_file=getattr(self, self.RIG_FILE_PARAMETER))
        return self

    @classmethod
    def rig_limits(cls) -> dict[str, str]:
        """Parameter -> the dotted key of the rig file holding its upper bound."""
        out = {}
        for name, info in cls.model_fields.items():
            extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
            if extra.get("rig_limit"):
                out[name] = str(extra["rig_limit"])
        return out

    @classmethod
    def check_other_keys(cls, values: Mapping[str, Any]) -> None:
        """Check the values of :attr:`OTHER_KEYS` in ``values`` (none by default); raise
        :func:`field_error`."""

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any], source: str, key: str = "") -> Self:
        """Validate the parameters in ``values`` (read from ``source``, at dotted ``key`` in it):
        every parameter required, no unknown key.

        Raises:
            ConfigError: the first problem, naming the source, the key and the allowed range.
        """
        allowed = [*cls.model_fields, *cls.OTHER_KEYS]
        try:
            for name in values:
                if name not in allowed:
                    raise field_error(str(name), f"unknown key; allowed keys: {', '.join(sorted(allowed))}")
            cls.check_other_keys(values)
        except ConfigError as exc:
            raise ConfigError(source, ".".join(part for part in (key, exc.key) if part), exc.problem) from None
        own = {k: v for k, v in values.items() if k in cls.model_fields}
        return validate_mapping(cls, own, source, key)

    @classmethod
    def from_values(cls, values: Mapping[str, Any], source: str | None = None) -> Self:
        """Validate a flat mapping of parameter values (the node's ROS parameters in force).

        Raises:
            ConfigError: naming the key and the allowed range.
        """
        return cls.from_mapping(values, source or f"{cls.NODE_NAME} parameters")

    @classmethod
    def _parameter_block(cls, path: str | Path) -> dict[str, Any]:
        """The ``<node>: ros__parameters:`` mapping of a parameter file."""
        return ros_parameters(read_mapping(path), cls.NODE_NAME, str(path))

    @classmethod
    def from_yaml(cls, path: str | Path | None = None) -> Self:
        """Read ``<node>: ros__parameters:`` of a parameter file (default: the shipped one).

        Raises:
            ConfigError: naming the file and the key.
        """
        path = path or config_path(cls.SHIPPED_FILE)
        return cls.from_mapping(cls._parameter_block(path), str(path), f"{cls.NODE_NAME}.ros__parameters")

    @classmethod
    def shipped_parameters(cls) -> dict[str, Any]:
        """The raw values of the shipped file (the node's declared defaults), checked valid.

        Raises:
            ConfigError: the shipped file is missing or malformed.
        """
        path = config_path(cls.SHIPPED_FILE)
        values = cls._parameter_block(path)
        cls.from_mapping(values, str(path), f"{cls.NODE_NAME}.ros__parameters")  # the defaults themselves must be valid
        return dict(values)

    def replace(self, **changes: Any) -> Self:
        """A copy with some values changed, not validated again (for tests and for a value the
        caller has checked, such as a criterion read from a recording)."""
        return self.model_copy(update=changes)

    @classmethod
    def check_value(cls, name: str, value: object) -> str:
        """Why ``value`` is refused for parameter ``name`` by its own field checks ("" when it
        is accepted): a live parameter vetted before the node is configured. Checks across
        fields (validators naming other parameters) are not run.

        Raises:
            KeyError: ``name`` is not a parameter of this class.
        """
        info = cls.model_fields[name]
        adapter: TypeAdapter[Any] = TypeAdapter(Annotated[(info.annotation, *info.metadata)])  # type: ignore[arg-type]  # an Annotated built from the field's parts at run time
        try:
            adapter.validate_python(value)
        except ValidationError as exc:
            return f"{name}: {_problem(exc.errors()[0])}"
        return ""

    @classmethod
    def parameter_fields(cls, values: Mapping[str, Any] | None = None) -> list[ParameterField]:
        """Every parameter as the node declares it to ROS, in field order. With the ``values``
        in force (the rig file's parameter among them), a parameter with a ``rig_limit`` has that
        rig file's value as its upper bound; without, or where the rig file cannot be read (the
        node reports that at configure), the settings class's plausible bound."""
        limits: dict[str, tuple[float, str]] = {}
        if values is not None and cls.RIG_FILE_PARAMETER in values:
            try:
                rig = resolve_rig_file(values[cls.RIG_FILE_PARAMETER])
                limits = {name: (rig_file_value(rig, key), f"{key} in {rig.name}") for name, key in cls.rig_limits().items()}
            except (ConfigError, ValueError):
                limits = {}
        out = []
        for name, info in cls.model_fields.items():
            bounds: dict[str, float] = {}
            for item in info.metadata:
                for key in ("gt", "ge", "lt", "le"):
                    if isinstance(item, getattr(annotated_types, key.capitalize())):
                        bounds[key] = float(getattr(item, key))
            extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
            low = bounds.get("gt", bounds.get("ge"))
            high = bounds.get("lt", bounds.get("le"))
            limit, limit_source = limits.get(name, (None, ""))
            if limit is not None and (high is None or limit <= high):
                high = limit
                bounds.pop("lt", None)
            else:
                limit_source = ""
            out.append(
                ParameterField(
                    name=name,
                    description=info.description or "",
                    unit=str(extra.get("unit", "")),
                    low=low,
                    high=high,
                    low_exclusive="gt" in bounds,
                    high_exclusive="lt" in bounds,
                    integer=info.annotation is int,
                    live=bool(extra.get("live", False)),
                    rig_limit=str(extra.get("rig_limit", "")),
                    limit_source=limit_source,
                )
            )
        return out
