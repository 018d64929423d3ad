"""The ``mounting`` section of ``config/rig.yaml``: how the test bearing sits on the spindle
(docs/model.md, "Mounting").

Four inputs of the dynamic engine (:class:`bearing_rig_sim.dynamics.Mounting`), each 0 when the
section or the key is absent (the bearing as its file describes it, alone on the spindle, the
tilts held at zero):

* ``clearance_change_m``: extra diametral clearance P_d (negative: an interference fit takes
  clearance up);
* ``misalignment_rad``: [theta_x, theta_y], the inner ring's tilts held against the outer ring
  when no moment is applied;
* ``preload_n``: a spring preload, a constant axial force added to the loading chain's;
* ``preload_displacement_m``: the rigid (position) preload of a back-to-back pair of the test
  bearing, the partner modelled at rest and axially only.

Range errors name the rig file, the dotted key (``mounting.misalignment_rad[1]``) and the range.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

from pydantic import Field

from bearing_rig_sim.config import config_path, read_mapping
from bearing_rig_sim.rig.parameters import RIG_FILE
from bearing_rig_sim.settings_model import FileSection, Number, quantity, validate_mapping

SECTION = "mounting"
"""The rig file's top-level key of this section."""

MAX_MISALIGNMENT_RAD = 0.003
"""Plausible misalignment per axis, rad (about 10 arcmin)."""

Tilt = Annotated[Number, Field(ge=-MAX_MISALIGNMENT_RAD, le=MAX_MISALIGNMENT_RAD)]
"""One tilt of the misalignment, rad."""


class MountingConfig(FileSection):
    """The rig file's ``mounting`` section (SI units; all 0 by default)."""

    clearance_change_m: Number = quantity(
        "extra diametral clearance P_d of the test bearing, m (negative: interference)",
        unit="m",
        source="ISO 5753-1 radial clearance groups of 30 mm bore ball bearings span about 1-41 um (C2 to C4); "
        "an interference fit takes up some 60-80 % of its interference, a warm inner ring some 5-10 um: "
        "30 um either way covers fits, clearance groups and thermal changes",
        ge=-30e-6,
        le=30e-6,
        default=0.0,
    )
    misalignment_rad: tuple[Tilt, Tilt] = quantity(
        "tilts [theta_x, theta_y] of the inner ring against the outer, held with no moment applied, rad",
        unit="rad",
        source="catalogues allow a single angular contact ball bearing some 2 arcmin (6e-4 rad); "
        "10 arcmin (3e-3 rad) per axis leaves room to study a faulty mounting",
        default=(0.0, 0.0),
    )
    preload_n: Number = quantity(
        "spring preload, a constant axial force added to the loading chain's, N",
        unit="N",
        source="7006 spindle bearings' light to heavy preload classes lie at some 50-600 N (catalogue preload tables); "
        "the loading chain's largest set-point, 1000 N, bounds it",
        ge=0.0,
        le=1000.0,
        default=0.0,
    )
    preload_displacement_m: Number = quantity(
        "rigid preload displacement of a back-to-back pair of the test bearing, m",
        unit="m",
        source="the H7006C pair carries about 160 N at 20 um (Hertz, balls at rest); 30 um, some 320 N, is a heavy preload of this size",
        ge=0.0,
        le=30e-6,
        default=0.0,
    )

    @classmethod
    def from_rig_file(cls, path: str | Path | None = None) -> MountingConfig:
        """The ``mounting`` section of a rig file (default: the shipped ``config/rig.yaml``);
        absent: all 0.

        Raises:
            ConfigError: naming the file, the key and its allowed range.
        """
        rig_file = path or config_path(RIG_FILE)
        stated = read_mapping(rig_file).get(SECTION)
        return cls() if stated is None else validate_mapping(cls, stated, str(rig_file), SECTION)
