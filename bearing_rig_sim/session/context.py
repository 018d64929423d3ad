"""A run's identity and the context recorded with it (no ROS).

The run id is the UTC start time and the program's name, ``20250612T093015Z-validation``; the
bag goes to ``<bag dir>/<run id>/``. The context (:func:`run_context`) travels in the bag's
metadata as string key/value pairs, so a bag says how it was made:

* ``program``, ``program_file``: the test program's text and where it was read;
* ``bearing``, ``bearing_file``: the bearing data file's text and path: the program's ``bearing``,
  which :func:`node_parameters` hands to the simulator and the monitor, so it is the bearing the
  run simulated;
* ``calibration/<file>``: every file of ``config/calibration/`` named after the bearing file
  (``h7006c_*``: the calibration the simulator applies, with its data);
* ``rig``: ``config/rig.yaml`` (loading chain, sensors);
* ``parameters/<node>``: each node's parameter file (``config/<node>.yaml``) when present;
* ``command_line``, ``run_id``, ``started_utc``, ``ros_domain_id``, ``realtime``;
* the recorder adds ``project_version``.
"""

from __future__ import annotations

import json
import re
import shlex
from datetime import datetime, UTC
from pathlib import Path
from collections.abc import Mapping, Sequence

from bearing_rig_sim.config import config_path
from bearing_rig_sim.rig.program import TestProgram

__all__ = ["NODE_PARAMETER_FILES", "check_bearing_file", "check_parameter_file", "make_run_id", "node_parameters", "parameter_arguments", "run_context"]

NODE_PARAMETER_FILES = ("simulator", "load_controller", "monitor")
"""Nodes whose ``config/<node>.yaml`` is recorded."""


def node_parameters(program: TestProgram, simulator_defaults: Mapping[str, object]) -> dict[str, dict[str, str | bool | int | float]]:
    """``-p`` overrides per node that make the nodes use the program's bearing file.

    The simulator and the monitor read their bearing file from their parameters; a program that
    names another one gets it passed to both. The shipped calibration belongs to the bearing the
    simulator's parameters name, so with another bearing the run is uncalibrated
    (``calibration_file`` empty) rather than calibrated for a different bearing.

    Args:
        program: the validated program.
        simulator_defaults: the simulator's shipped parameter values (``bearing_file`` relative
            to ``config/`` unless absolute).
    """
    shipped = Path(str(simulator_defaults.get("bearing_file", "")))
    shipped = shipped if shipped.is_absolute() else config_path(*shipped.parts)
    if shipped.resolve() == program.bearing_file.resolve():
        return {}
    bearing = str(program.bearing_file.resolve())
    return {
        "simulator": {"bearing_file": bearing, "calibration_file": ""},
        "monitor": {"bearing_file": bearing},
    }


def parameter_arguments(values: Mapping[str, str | bool | int | float]) -> list[str]:
    """``-p name:=value`` ROS arguments for ``values``, each value written so that rcl's YAML
    reading gives it back unchanged: booleans as ``true``/``false``, numbers as they are,
    strings double-quoted (an empty string, a path with ``: `` or ``#`` in it, a string that
    reads as a number or a boolean all stay strings).

    Raises:
        TypeError: a value of another type.
    """
    arguments = []
    for name, value in values.items():
        if isinstance(value, bool):
            text = "true" if value else "false"
        elif isinstance(value, (int, float)):
            text = repr(value)
        elif isinstance(value, str):
            text = json.dumps(value)  # a JSON string is a YAML double-quoted scalar
        else:
            raise TypeError(f"parameter {name}: cannot pass a {type(value).__name__} on the command line")
        arguments += ["-p", f"{name}:={text}"]
    return arguments


def check_bearing_file(program: TestProgram, program_file: str | Path) -> None:
    """Read the program's bearing file as the simulator will (every key, unit and range), so a
    file that is no bearing data is refused when the program is loaded, not by a node later.

    Raises:
        ConfigError: naming the program file, its ``bearing`` key and what is wrong.
    """
    from bearing_rig_sim.config import ConfigError
    from bearing_rig_sim.dynamics.parameters import BearingParameters  # numba: only where a run starts

    try:
        BearingParameters.from_yaml(program.bearing_file)
    except (ConfigError, ValueError) as exc:
        raise ConfigError(str(program_file), "bearing", f"not usable bearing data: {exc}") from None


def _flatten(block: Mapping[object, object], prefix: str = "") -> dict[str, object]:
    """ROS 2 parameter names of a ``ros__parameters`` block: nested mappings join with ``.``."""
    flat: dict[str, object] = {}
    for key, value in block.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            flat.update(_flatten(value, f"{name}."))
        else:
            flat[name] = value
    return flat


def check_parameter_file(path: Path) -> None:
    """Check a ``--params-file`` against the session's nodes before any starts: every block is
    for one of them (by name, ``/ns/name``, or a wildcard ``/**``), every parameter is one the
    node declares (rclpy silently drops the others: a misspelt name would change nothing), and
    each node's values, laid over its shipped ones, pass its settings check (types, units,
    ranges), as they will at configure. The parameters every ROS 2 node declares by itself
    (``use_sim_time``, ``start_type_description_service``, ``qos_overrides.*``; what ``ros2 param
    dump`` writes besides the node's own) are not the rig's to check: the node takes them.

    Raises:
        ConfigError: naming the file, the block and key, and what is wrong (with the names a
            misspelt one may have meant).
    """
    import difflib

    from bearing_rig_sim.config import ConfigError, read_yaml_file
    from bearing_rig_sim.nodes.parameters import NODE_PARAMETERS, NODE_SETTINGS, is_standard

    source = str(path)
    data = read_yaml_file(path)
    if not isinstance(data, dict):
        raise ConfigError(source, "", f"a ROS 2 parameter file maps node names to blocks; its top level is a {type(data).__name__}")
    nodes = list(NODE_PARAMETER_FILES)
    given: dict[str, dict[str, object]] = {name: {} for name in nodes}
    for key, block in data.items():
        last = str(key).rstrip("/").rsplit("/", 1)[-1]
        wildcard = last in ("*", "**")
        if not wildcard and last not in nodes:
            near = difflib.get_close_matches(last, nodes, n=1)
            raise ConfigError(
                source, str(key), f"no node of a session has this name (its nodes: {', '.join(nodes)}" + (f"; did you mean {near[0]}?)" if near else ")")
            )
        params = block.get("ros__parameters") if isinstance(block, dict) else None
        if not isinstance(params, dict):
            raise ConfigError(source, str(key), "must be a mapping with a ros__parameters mapping")
        targets = nodes if wildcard else [last]
        for name, value in _flatten(params).items():
            if is_standard(name):  # every ROS 2 node has it (``ros2 param dump`` writes it): the node takes it
                continue
            known = [n for n in targets if name in NODE_PARAMETERS[n] or name == "use_sim_time"]
            if not known:
                names = sorted({p for n in targets for p in NODE_PARAMETERS[n]})
                near = difflib.get_close_matches(name, names, n=1)
                raise ConfigError(
                    source,
                    f"{key}.ros__parameters.{name}",
                    f"{' '.join(targets)} {'has' if len(targets) == 1 else 'have'} no such parameter"
                    + (f"; did you mean {near[0]}?" if near else f" (see config/{targets[0]}.yaml)"),
                )
            for n in known:
                given[n][name] = value
    for node, values in given.items():
        if values:
            settings = NODE_SETTINGS[node]
            settings.from_values({**settings.shipped_parameters(), **values}, f"{source}: {node}.ros__parameters")


def make_run_id(program_name: str, start: datetime) -> str:
    """``<UTC start, basic ISO 8601>-<program name>``, with characters other than letters, digits,
    ``-``, ``_`` and ``.`` in the name replaced by ``_``.

    Raises:
        ValueError: ``start`` has no time zone.
    """
    if start.tzinfo is None:
        raise ValueError("make_run_id: the start time needs a time zone")
    name = re.sub(r"[^A-Za-z0-9._-]", "_", program_name) or "program"
    return f"{start.astimezone(UTC):%Y%m%dT%H%M%SZ}-{name}"


def _text(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        return f"<unreadable: {exc}>"


def run_context(
    program: TestProgram,
    *,
    run_id: str,
    start: datetime,
    command_line: Sequence[str],
    extra: Mapping[str, str] | None = None,
) -> dict[str, str]:
    """The run context of the module documentation, as string key/value pairs."""
    program_file = Path(program.source)
    context = {
        "run_id": run_id,
        "started_utc": start.astimezone(UTC).isoformat(),
        "command_line": shlex.join(command_line),
        "program_file": str(program_file),
        "program": _text(program_file),
        "bearing_file": str(program.bearing_file),
        "bearing": _text(program.bearing_file),
        "rig": _text(config_path("rig.yaml")),
    }
    calibration = config_path("calibration")
    if calibration.is_dir() and not (extra or {}).get("calibration") == "none":
        for path in sorted(calibration.glob(f"{program.bearing_file.stem}_*")):
            if path.is_file():
                context[f"calibration/{path.name}"] = _text(path)
    for node in NODE_PARAMETER_FILES:
        path = config_path(f"{node}.yaml")
        if path.is_file():
            context[f"parameters/{node}"] = _text(path)
    context.update(extra or {})
    return context
