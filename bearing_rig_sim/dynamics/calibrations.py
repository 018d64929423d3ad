"""The bench twin's named calibrations (no ROS import): the second choice under the bench model
(:mod:`.models`), by name or by file.

* ``coupled`` (default): the grease's values fitted with every Table 3 row at the coupled
  thermal steady state (the lubricant at the temperature its own heat gives it), the grease's
  temperature law set to what the data allow (``config/calibration/h7006c_coupled.yaml``). The
  twin runs with the lubricant following the thermal network.
* ``isothermal``: the grease's values fitted with the lubricant held at the bearing file's
  35 degC (``config/calibration/h7006c_table3.yaml``). The twin holds its lubricant there.

Which one is the default, and why: docs/thermal.md, "Named calibrations".
"""

from __future__ import annotations

from pathlib import Path

from bearing_rig_sim.config import SHIPPED_CALIBRATION_FILE, ConfigError, config_path
from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.settings_model import read_file

COUPLED = "coupled"
ISOTHERMAL = "isothermal"
NAMED: dict[str, str] = {COUPLED: "h7006c_coupled.yaml", ISOTHERMAL: Path(SHIPPED_CALIBRATION_FILE).name}
"""Named calibration -> its file under ``config/calibration/``."""
DEFAULT_CALIBRATION = COUPLED
"""The bench twin's default calibration."""


def calibration_file(name_or_path: str | Path) -> Path:
    """A named calibration's file (:data:`NAMED`), or the path given.

    Raises:
        ConfigError: neither a name of :data:`NAMED` nor an existing file.
    """
    text = str(name_or_path)
    if text in NAMED:
        return config_path("calibration", NAMED[text])
    path = Path(text)
    if not path.is_file():
        raise ConfigError("calibration", "calibration", f"must be one of {', '.join(NAMED)} or a calibration file, got {text!r} (no such file)")
    return path


def named_as_config_path(value: object) -> object:
    """A calibration's name (:data:`NAMED`) as its file relative to ``config/``; any other value
    as given (a settings file's ``calibration_file``, validated as a file afterwards)."""
    return f"calibration/{NAMED[value]}" if isinstance(value, str) and value in NAMED else value


def is_coupled(path: str | Path) -> bool:
    """Whether a calibration file was fitted through the coupled thermal steady states (its
    ``calibration.thermal``): the twin then runs with the lubricant following its temperature."""
    return bool(read_file(CalibrationFile, path).calibration.thermal)
