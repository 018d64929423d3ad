"""Test programs: YAML sequences of segments (speed profile, axial load, end condition).

A program file (``config/programs/*.yaml``)::

    name: validation
    description: ...
    bearing: bearings/h7006c.yaml        # bearing file, relative to config/
    stability_criterion: time            # "time" or "axial_load" (abscissa of the slope criterion)
    initial_speed_rpm: 0.0               # optional; the spindle's speed before the first segment
    segments:
      - name: n900
        speed_rpm: 900                   # target inner-ring speed
        ramp_s: 1.0                      # optional: STEP ramp from the previous speed (0 = jump)
        axial_load_n: 100
        until_stable: true               # or: dwell_s: 5.0
        timeout_s: 10.0
      - name: accel_20
        speed_rpm: 1500                  # target speed ...
        acceleration_rad_s2: 20          # ... reached at this constant angular acceleration
        axial_load_n: 200
        dwell_s: 5.0

Each segment starts from the speed the previous one ended at. The end condition counts from the
end of the speed change: ``dwell_s`` holds the target speed that long; ``until_stable`` ends at
the first stable verdict of the monitor, or after ``timeout_s`` without one.

Speeds are given in rpm in the file and converted to rad/s once, at load; everything returned
is SI (rad/s, rad/s^2, s, N). A segment's speed against time (the paper's STEP drive function or a
constant acceleration) is :mod:`bearing_rig_sim.rig.speed_profile`'s.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, ClassVar

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field

from bearing_rig_sim.config import ConfigError, config_path, read_mapping, rad_s_to_rpm, rpm_to_rad_s
from bearing_rig_sim.rig.loading import LoadingChainConfig
from bearing_rig_sim.rig.parameters import RIG_FILE, ParameterRecord, bounded
from bearing_rig_sim.rig.speed_profile import SegmentSpeed, SpeedProfileKind
from bearing_rig_sim.rig.spindle import SpindleConfig
from bearing_rig_sim.settings_model import ConfigFile, Flag, Number, one_of, validate_mapping

STABILITY_CRITERIA = ("time", "axial_load")
"""Abscissas of the slope criterion (docs/paper.md section 7): slip vs time, or slip vs axial load."""


# ---------------------------------------------------------------------------------------------
# Segments and programs (the speed profile of a segment: :mod:`bearing_rig_sim.rig.speed_profile`)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Segment:
    """One segment of a test program (SI units)."""

    name: str
    """Segment name, unique in its program."""
    target_speed: float
    """Inner-ring speed to reach, rad/s."""
    profile: SpeedProfileKind
    """How the speed changes from the previous segment's end."""
    ramp_time: float
    """STEP ramp duration, s (0 = jump; 0 for constant acceleration)."""
    acceleration: float
    """Magnitude of the angular acceleration, rad/s^2 (0 for STEP)."""
    axial_load: float
    """Axial-load set-point during the segment, N."""
    dwell: float | None
    """Time held at the target speed after the ramp, s; None with ``until_stable``."""
    until_stable: bool
    """End at the first stable verdict after the ramp (or at ``timeout``)."""
    timeout: float | None
    """With ``until_stable``: longest wait after the ramp, s; None otherwise."""
    radial_load: float = 0.0
    """Radial-load set-point during the segment, N (``radial_load_n``, within the rig's limit)."""
    moment: float = 0.0
    """Moment on the inner ring across the radial load, N m (``moment_n_m``, within the rig's limit)."""
    radial_azimuth: float = 0.0
    """Direction of the radial load in the bearing's frame, rad from its x axis towards y
    (``radial_azimuth_deg``; 0: along x)."""

    @property
    def radial_components(self) -> tuple[float, float]:
        """The radial load along the bearing frame's x and y axes, N (force.x, force.y of the
        load set-point)."""
        return self.radial_load * math.cos(self.radial_azimuth), self.radial_load * math.sin(self.radial_azimuth)

    def speed_profile(self, start_time: float, start_speed: float) -> SegmentSpeed:
        """The segment's speed against time, for a start at ``start_time`` (s) from
        ``start_speed`` (rad/s)."""
        return SegmentSpeed(start_time, start_speed, self.target_speed, self.profile, self.ramp_time, self.acceleration)

    def ramp_duration(self, start_speed: float) -> float:
        """Duration of the speed change from ``start_speed`` (rad/s), s."""
        return self.speed_profile(0.0, start_speed).ramp_end

    def longest_duration(self, start_speed: float) -> float:
        """Ramp plus dwell, or ramp plus timeout for ``until_stable``, s."""
        hold = self.dwell if self.dwell is not None else self.timeout
        assert hold is not None
        return self.ramp_duration(start_speed) + hold


@dataclass(frozen=True)
class TestProgram:
    """A validated test program."""

    __test__ = False  # not a pytest test class despite its name

    name: str
    description: str
    bearing_file: Path
    """Bearing data file (resolved path)."""
    stability_criterion: str
    """``"time"`` or ``"axial_load"``."""
    initial_speed: float
    """Inner-ring speed before the first segment, rad/s."""
    segments: tuple[Segment, ...]
    source: str
    """File the program was read from."""

    def start_speeds(self) -> list[float]:
        """Speed at the start of each segment, rad/s (the previous segment's target)."""
        speeds = [self.initial_speed]
        speeds.extend(s.target_speed for s in self.segments[:-1])
        return speeds

    def longest_duration(self) -> float:
        """Simulated time of the whole program if every ``until_stable`` segment times out, s."""
        return sum(seg.longest_duration(v0) for seg, v0 in zip(self.segments, self.start_speeds()))


MAX_RAMP_S: float = 600.0
"""Longest speed change of one segment (STEP ramp, or speed change over acceleration), s: ten
minutes, far beyond the paper's 1-2 s ramps and 75 s run-ups; bounds a tiny acceleration."""
MAX_DWELL_S: float = 3600.0
"""Longest hold of one segment, s (one hour: a bag of some 2 GB at the rig's traffic)."""
MAX_TIMEOUT_S: float = 3600.0
"""Longest ``until_stable`` wait of one segment, s."""
MAX_SEGMENTS: int = 1000
"""Most segments in one program."""
STEP_PEAK_FACTOR: float = 1.5
"""Peak over mean acceleration of the STEP ramp: ``6 D (1 - D)`` is 1.5 at ``D = 1/2``."""
NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")
"""Program and segment names: letters, digits, ``_ . -``; at most 64 characters (they name
bag directories and CSV rows)."""


@dataclass(frozen=True)
class CombinedLoadingLimits(ParameterRecord):
    """The ``combined_loading`` section of ``config/rig.yaml``: what a radial loader accepts
    (absent: a loading chain that pulls only axially)."""

    SECTION: ClassVar[str] = "combined_loading"

    max_radial_setpoint_n: float = bounded(ge=0.0, default=0.0)
    """Largest radial-load set-point, N."""
    max_moment_setpoint_n_m: float = bounded(ge=0.0, default=0.0)
    """Largest moment set-point, N m."""


@dataclass(frozen=True)
class RigLimits:
    """What the rig a program runs on accepts (SI units)."""

    max_speed_rad_s: float
    """Highest inner-ring speed of the spindle drive, rad/s (``spindle.max_speed_rad_s``)."""
    max_acceleration_rad_s2: float
    """Highest angular acceleration of the drive, rad/s^2 (``spindle.max_acceleration_rad_s2``)."""
    max_axial_load_n: float
    """Largest axial-load set-point of the loading chain, N (``loading_chain.max_setpoint_n``)."""
    source: str = RIG_FILE
    """The rig file the limits come from (for messages)."""
    max_radial_load_n: float = 0.0
    """Largest radial-load set-point, N (``combined_loading.max_radial_setpoint_n``; absent: 0,
    a loading chain that pulls only axially)."""
    max_moment_n_m: float = 0.0
    """Largest moment set-point, N m (``combined_loading.max_moment_setpoint_n_m``; absent: 0)."""

    @classmethod
    def from_rig_file(cls, path: str | Path | None = None) -> RigLimits:
        """The limits of a rig file (default: the shipped ``config/rig.yaml``).

        Raises:
            ConfigError: the rig file's ``spindle`` or ``loading_chain`` section is invalid.
        """
        spindle = SpindleConfig.from_yaml(path)
        chain = LoadingChainConfig.from_yaml(path)
        name = Path(path).name if path is not None else RIG_FILE
        rig_file = path or config_path(RIG_FILE)
        stated = read_mapping(rig_file).get("combined_loading")
        combined = CombinedLoadingLimits.from_mapping(stated, str(rig_file), "combined_loading") if stated is not None else CombinedLoadingLimits()
        return cls(
            spindle.max_speed_rad_s,
            spindle.max_acceleration_rad_s2,
            chain.max_setpoint_n,
            name,
            combined.max_radial_setpoint_n,
            combined.max_moment_setpoint_n_m,
        )


def _name(value: object) -> str:
    if not isinstance(value, str) or not value:
        raise ValueError(f"must be a non-empty string, got {value!r}")
    if not NAME_PATTERN.fullmatch(value):
        raise ValueError(f"must be 1-64 letters, digits, '_', '.' or '-' (starting with a letter or digit), got {value!r}")
    return value


def _segment_list(value: object) -> object:
    if not isinstance(value, list) or not value:
        raise ValueError("must be a non-empty list of mappings")
    if len(value) > MAX_SEGMENTS:
        raise ValueError(f"at most {MAX_SEGMENTS} segments, got {len(value)}")
    return value


def _text(value: object) -> str:
    if not isinstance(value, str):
        raise ValueError(f"must be a string, got {value!r}")
    return value.strip()


Name = Annotated[str, BeforeValidator(_name)]
"""A program or segment name (:data:`NAME_PATTERN`)."""

_FILE = ConfigDict(frozen=True, extra="forbid")


class SegmentFile(BaseModel):
    """A segment as its program file states it (rpm at this edge); the rules that need the rig
    or the segment before it are :func:`load_program`'s. Optional keys whose presence matters
    (``ramp_s`` against ``acceleration_rad_s2``, ``dwell_s`` against ``until_stable``) are read
    from ``model_fields_set``."""

    model_config = _FILE

    name: Name = Field(description="segment name, unique in its program")
    speed_rpm: Number = Field(ge=0.0, description="target inner-ring speed, rpm")
    ramp_s: Number = Field(0.0, ge=0.0, le=MAX_RAMP_S, description="STEP ramp from the previous speed, s (0 = jump)")
    acceleration_rad_s2: Number = Field(0.0, gt=0.0, description="constant angular acceleration to the target, rad/s^2")
    axial_load_n: Number = Field(ge=0.0, description="axial-load set-point, N")
    dwell_s: Number = Field(0.0, gt=0.0, le=MAX_DWELL_S, description="hold at the target speed, s")
    until_stable: Flag = Field(False, description="end at the first stable verdict (with timeout_s)")
    timeout_s: Number = Field(0.0, gt=0.0, le=MAX_TIMEOUT_S, description="longest wait for a stable verdict, s")
    radial_load_n: Number = Field(0.0, ge=0.0, description="radial-load set-point, N")
    moment_n_m: Number = Field(0.0, description="moment set-point across the radial load, N m")
    radial_azimuth_deg: Number = Field(0.0, ge=-360.0, le=360.0, description="direction of the radial load from the bearing frame's x axis towards y, deg")


class ProgramFile(BaseModel):
    """A test program as its file states it (see the module documentation)."""

    model_config = _FILE

    name: Name = Field(description="program name")
    description: Annotated[str, BeforeValidator(_text)] = Field("", description="what the program is for")
    bearing: ConfigFile = Field(description="bearing data file, relative to config/ unless absolute")
    stability_criterion: Annotated[str, one_of(STABILITY_CRITERIA)] = Field(description="abscissa of the slope criterion")
    initial_speed_rpm: Number = Field(0.0, ge=0.0, description="the spindle's speed before the first segment, rpm")
    segments: Annotated[list[SegmentFile], BeforeValidator(_segment_list)] = Field(description="the segments, in order")


PROGRAMS_DIR = ("programs",)
"""Where the shipped test programs are, under ``config/``."""


def shipped_programs() -> list[str]:
    """The names of the shipped test programs (``config/programs/<name>.yaml``), sorted."""
    folder = config_path(*PROGRAMS_DIR)
    return sorted(f.stem for f in folder.glob("*.yaml")) if folder.is_dir() else []


def program_file(name: str | Path) -> Path:
    """The file a program argument names: an existing file as given, else a shipped program by
    its name (``acceleration`` or ``acceleration.yaml`` for ``config/programs/acceleration.yaml``).

    Raises:
        ConfigError: neither, naming the argument and listing the shipped programs.
    """
    path = Path(name)
    if path.is_file():
        return path
    if len(path.parts) == 1 and path.suffix in ("", ".yaml"):
        shipped = config_path(*PROGRAMS_DIR, f"{path.stem}.yaml")
        if shipped.is_file():
            return shipped
    raise ConfigError(
        str(name), "", f"no such program file, nor a shipped program of that name (shipped: {', '.join(shipped_programs()) or 'none'}; run by name or by path)"
    )


def load_program(path: str | Path, rig: RigLimits | None = None) -> TestProgram:
    """Read and validate a test program against the rig it will run on.

    Args:
        path: the program's YAML file.
        rig: the rig's limits; None: the shipped ``config/rig.yaml``.

    Raises:
        ConfigError: naming the file, the key (``segments[2].axial_load_n``), the segment and the
            limit that was exceeded.
    """
    rig = rig if rig is not None else RigLimits.from_rig_file()
    source = str(path)
    stated = validate_mapping(ProgramFile, read_mapping(path), source)
    max_rpm = rad_s_to_rpm(rig.max_speed_rad_s)
    if stated.initial_speed_rpm > max_rpm * (1.0 + 1e-12):
        raise ConfigError(
            source,
            "initial_speed_rpm",
            f"{stated.initial_speed_rpm:g} rpm is above the rig's limit of {max_rpm:g} rpm ({_limit(rig, 'spindle.max_speed_rad_s')})",
        )
    segments: list[Segment] = []
    start_speed = rpm_to_rad_s(stated.initial_speed_rpm)
    seen: set[str] = set()
    for i, seg_file in enumerate(stated.segments):
        if seg_file.name in seen:
            raise ConfigError(source, f"segments[{i}].name", f"duplicate segment name {seg_file.name!r}")
        seen.add(seg_file.name)
        seg = _segment(seg_file, source, f"segments[{i}]", rig, start_speed)
        segments.append(seg)
        start_speed = seg.target_speed
    return TestProgram(
        name=stated.name,
        description=stated.description,
        bearing_file=stated.bearing,
        stability_criterion=stated.stability_criterion,
        initial_speed=rpm_to_rad_s(stated.initial_speed_rpm),
        segments=tuple(segments),
        source=source,
    )


def _limit(rig: RigLimits, key: str) -> str:
    return f"{key} in {rig.source}"


def _segment(stated: SegmentFile, source: str, where: str, rig: RigLimits, start_speed: float) -> Segment:
    """One segment checked against the rig and the speed it starts from (``start_speed``,
    rad/s); ``where`` is its place in the file ``source`` (``segments[2]``)."""
    given = stated.model_fields_set

    def beyond(key: str, problem: str) -> ConfigError:
        return ConfigError(source, f"{where}.{key}", f"segment {stated.name!r}: {problem}")

    rpm = stated.speed_rpm
    max_rpm = rad_s_to_rpm(rig.max_speed_rad_s)
    if rpm > max_rpm * (1.0 + 1e-12):
        raise beyond("speed_rpm", f"{rpm:g} rpm is above the rig's limit of {max_rpm:g} rpm ({_limit(rig, 'spindle.max_speed_rad_s')})")
    speed = rpm_to_rad_s(rpm)
    change = abs(speed - start_speed)
    if "ramp_s" in given and "acceleration_rad_s2" in given:
        raise beyond("acceleration_rad_s2", "give either ramp_s (STEP ramp) or acceleration_rad_s2, not both")
    max_accel = rig.max_acceleration_rad_s2
    accel_limit = f"the rig's limit of {max_accel:g} rad/s^2 ({_limit(rig, 'spindle.max_acceleration_rad_s2')})"
    if "acceleration_rad_s2" in given:
        profile, ramp, accel = SpeedProfileKind.CONSTANT_ACCELERATION, 0.0, stated.acceleration_rad_s2
        if accel > max_accel:
            raise beyond("acceleration_rad_s2", f"{accel:g} rad/s^2 is above {accel_limit}")
        if change / accel > MAX_RAMP_S:
            raise beyond(
                "acceleration_rad_s2",
                f"{accel:g} rad/s^2 takes {change / accel:.3g} s for the speed change, more than the {MAX_RAMP_S:g} s allowed",
            )
    else:
        profile, ramp, accel = SpeedProfileKind.STEP, stated.ramp_s, 0.0
        if change > 0.0 and ramp == 0.0:
            raise beyond("ramp_s", f"the speed changes by {rad_s_to_rpm(change):g} rpm: give ramp_s > 0 (a jump exceeds {accel_limit})")
        if change > 0.0 and STEP_PEAK_FACTOR * change / ramp > max_accel:
            shortest = STEP_PEAK_FACTOR * change / max_accel
            raise beyond(
                "ramp_s",
                f"{ramp:g} s gives a peak acceleration of {STEP_PEAK_FACTOR * change / ramp:.4g} rad/s^2, above "
                f"{accel_limit}; the shortest ramp is {shortest:.3g} s",
            )
    load = stated.axial_load_n
    if load > rig.max_axial_load_n:
        raise beyond(
            "axial_load_n",
            f"{load:g} N is above the rig's limit of {rig.max_axial_load_n:g} N ({_limit(rig, 'loading_chain.max_setpoint_n')})",
        )
    radial = stated.radial_load_n
    if radial > rig.max_radial_load_n:
        raise beyond(
            "radial_load_n",
            f"{radial:g} N is above the rig's limit of {rig.max_radial_load_n:g} N ({_limit(rig, 'combined_loading.max_radial_setpoint_n')})",
        )
    moment = stated.moment_n_m
    if abs(moment) > rig.max_moment_n_m:
        raise beyond(
            "moment_n_m",
            f"{moment:g} N m is beyond the rig's limit of {rig.max_moment_n_m:g} N m ({_limit(rig, 'combined_loading.max_moment_setpoint_n_m')})",
        )
    until_stable = stated.until_stable
    if "until_stable" in given and not until_stable:
        raise beyond("until_stable", "must be true when given; use dwell_s for a fixed duration")
    if until_stable:
        if "dwell_s" in given:
            raise beyond("dwell_s", "give either dwell_s or until_stable, not both")
        if "timeout_s" not in given:
            raise ConfigError(source, f"{where}.timeout_s", "missing (required)")
        dwell, timeout = None, stated.timeout_s
    else:
        if "timeout_s" in given:
            raise beyond("timeout_s", "only with until_stable: true")
        if "dwell_s" not in given:
            raise beyond("dwell_s", "missing (required): give dwell_s, or until_stable: true with timeout_s")
        dwell, timeout = stated.dwell_s, None
    return Segment(stated.name, speed, profile, ramp, accel, load, dwell, until_stable, timeout, radial, moment, math.radians(stated.radial_azimuth_deg))
