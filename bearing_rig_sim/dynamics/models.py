"""The named models of the bearing: which physics answers a question (no ROS import).

* ``bench`` (default): the bench twin. The shipped bearing file (``config/bearings/h7006c.yaml``:
  freshly packed grease, the rheology traction law integrated over the Hertz ellipse) with the
  Table 3 calibration (``config/calibration/h7006c_table3.yaml``).
* ``paper``: the paper's own model (``config/models/paper.yaml``): its regularised Coulomb law,
  Hunt-Crossley damping with its exponent, no lubricant, and the ball-set resistance its results
  imply, fitted to its simulated Table 3 column (``config/calibration/paper_table3.yaml``).

A model file names a bearing file, an overlay of bearing-file keys and a calibration; the merged
document is validated as a whole (:meth:`BearingParameters.from_mapping`), so a model can change
only what a bearing file may state, within its ranges.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from bearing_rig_sim.config import BEARING_MODELS, ConfigError, config_path, read_mapping, shipped_bearing_file, shipped_calibration_file
from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.dynamics.parameters import BearingParameters, overlay_calibration
from bearing_rig_sim.settings_model import read_file

MODELS: tuple[str, ...] = BEARING_MODELS
"""The named models, the default first."""
BENCH, PAPER = MODELS
DEFAULT_MODEL = BENCH

DEFAULT_BEARING = shipped_bearing_file()
"""The shipped bearing file."""
BENCH_CALIBRATION = shipped_calibration_file()
"""The bench twin's isothermal calibration (paper Table 3, bench column): the engine's parameters
without the thermal network (the coupled one is for a twin whose lubricant follows it:
:mod:`.calibrations`)."""


def model_file(name: str) -> Path:
    """The model file of ``name`` (``config/models/<name>.yaml``; the bench twin has none)."""
    if name not in MODELS:
        raise ConfigError("bearing model", "model", f"must be one of {', '.join(MODELS)}, got {name!r}")
    return config_path("models", f"{name}.yaml")


def model_parameters(name: str = DEFAULT_MODEL, *, calibrated: bool = True, calibration: str | Path | None = None) -> BearingParameters:
    """The bearing parameters of a named model.

    Args:
        name: one of :data:`MODELS`.
        calibrated: lay the model's shipped calibration over it (False: the model as its files
            state it, the starting point of ``bearing-rig calibrate --model``).
        calibration: another calibration file instead of the shipped one.

    Raises:
        ConfigError: an unknown model, or a model or calibration file that does not validate
            (naming the file, the key and the allowed range).
    """
    if name not in MODELS:
        raise ConfigError("bearing model", "model", f"must be one of {', '.join(MODELS)}, got {name!r}")
    if name == BENCH:
        cal = calibration if calibration is not None else (BENCH_CALIBRATION if calibrated else None)
        return BearingParameters.from_yaml(DEFAULT_BEARING, cal)
    path = model_file(name)
    doc = read_mapping(path)
    spec = doc.get("model")
    if not isinstance(spec, dict) or "bearing" not in spec:
        raise ConfigError(str(path), "model.bearing", "missing (required)")
    bearing = config_path("bearings", str(spec["bearing"]))
    data = _overlay(read_mapping(bearing), doc.get("overlay") or {}, path)
    source = f"{bearing} + {path}"
    if calibration is None and calibrated and spec.get("calibration"):
        calibration = config_path("calibration", str(spec["calibration"]))
    if calibration is not None:
        data = overlay_calibration(data, read_file(CalibrationFile, calibration))
        source += f" + {calibration}"
    return BearingParameters.from_mapping(data, source)


def _overlay(bearing: dict[str, Any], overlay: object, path: Path) -> dict[str, Any]:
    """The bearing document with the model's ``overlay:`` (section -> key -> value) laid over it."""
    if not isinstance(overlay, dict):
        raise ConfigError(str(path), "overlay", "must be a mapping of bearing-file sections")
    merged = {k: dict(v) if isinstance(v, dict) else v for k, v in bearing.items()}
    for section, keys in overlay.items():
        if section not in merged or not isinstance(keys, dict):
            raise ConfigError(str(path), f"overlay.{section}", "not a section of the bearing file")
        merged[section].update(keys)
    return merged
