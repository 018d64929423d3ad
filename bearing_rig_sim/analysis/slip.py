"""Cage slip rate from the inner-ring and cage speeds (paper Eq. 11-12; docs/paper.md section 6).

The epicyclic (pure-rolling) cage speed n_s = n_i / 2 * (1 - Dw cos(alpha) / dm) and the slip
rate S_c = (1 - n_c / n_s) * 100, in **percent**, are defined once in
:mod:`bearing_rig_sim.bearing.kinematics`; :class:`BearingKinematics` checks its geometry and
the speeds handed to it and applies them. The nominal (free) contact angle is the default; pass
the loaded angle to use it instead (:meth:`BearingKinematics.at_contact_angle`).

Speeds are SI (rad/s) and the slip rate is the one quantity kept in percent, as in the paper.

:func:`whole_revolution_slip` computes the slip as the monitor does on the bench (docs/paper.md
section 8): from the time stamps of the fibre-optic sensors' light pulses, one per reflective
strip passing, averaging over whole cage revolutions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import NamedTuple, Self, overload

import numpy as np
from pydantic import ConfigDict, model_validator
from scipy.optimize import brentq

from bearing_rig_sim.analysis.inputs import (
    AnalysisError,
    FloatArray,
    finite_array,
    positive_int,
    same_length,
    strictly_increasing,
)
from bearing_rig_sim.bearing.hertz import raceway_contacts
from bearing_rig_sim.bearing.kinematics import epicyclic_ratio, slip_pct
from bearing_rig_sim.config import ConfigError, read_mapping
from bearing_rig_sim.settings_model import FileSection, Integer, Number, quantity, validate_mapping


class _Reading(FileSection):
    """The part of a bearing file an analysis reads; the rest of the file is the engine's
    (:class:`~bearing_rig_sim.dynamics.bearing_file.BearingFile`)."""

    model_config = ConfigDict(frozen=True, extra="ignore")


class _KinematicGeometry(_Reading):
    ball_diameter_m: Number = quantity("ball diameter Dw", unit="m", source="a ball", gt=0.0)
    pitch_diameter_m: Number = quantity("pitch diameter dm (above Dw)", unit="m", source="a pitch circle", gt=0.0)
    contact_angle_deg: Number = quantity("nominal contact angle", unit="deg", source="a ball bearing (radial to thrust)", ge=0.0, lt=90.0)

    @model_validator(mode="after")
    def _pitch_above_ball(self) -> Self:
        if not self.pitch_diameter_m > self.ball_diameter_m:
            raise ConfigError("", "pitch_diameter_m", f"must exceed ball_diameter_m = {self.ball_diameter_m}, got {self.pitch_diameter_m}")
        return self


class _KinematicsReading(_Reading):
    geometry: _KinematicGeometry


class _ContactGeometry(_KinematicGeometry):
    inner_groove_curvature_ratio: Number = quantity("inner groove radius / Dw", unit="1", source="a groove wider than the ball", gt=0.5, lt=1.0)
    outer_groove_curvature_ratio: Number = quantity("outer groove radius / Dw", unit="1", source="a groove wider than the ball", gt=0.5, lt=1.0)
    ball_count: Integer = quantity("number of balls Z", unit="1", source="a count", ge=1)


class _Elastic(_Reading):
    youngs_modulus_pa: Number = quantity("Young's modulus", unit="Pa", source="a solid", gt=0.0)
    poisson_ratio: Number = quantity("Poisson ratio", unit="1", source="an isotropic solid", ge=0.0, lt=0.5)


class _ElasticMaterials(_Reading):
    ball: _Elastic
    ring: _Elastic


class _ContactReading(_Reading):
    geometry: _ContactGeometry
    materials: _ElasticMaterials


@dataclass(frozen=True)
class BearingKinematics:
    """The bearing geometry the slip rate depends on.

    Attributes:
        ball_diameter: Dw, m (> 0).
        pitch_diameter: dm, m (> Dw).
        contact_angle: alpha, rad, in [0, pi/2).

    Raises:
        AnalysisError: a value is non-finite or out of range.
    """

    ball_diameter: float
    pitch_diameter: float
    contact_angle: float

    def __post_init__(self) -> None:
        for name in ("ball_diameter", "pitch_diameter", "contact_angle"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
                raise AnalysisError(f"{name}: must be a real number, got {value!r}")
            if not math.isfinite(value):
                raise AnalysisError(f"{name}: must be finite, got {value!r}")
        if not self.ball_diameter > 0.0:
            raise AnalysisError(f"ball_diameter: must be > 0 m, got {self.ball_diameter!r}")
        if not self.pitch_diameter > self.ball_diameter:
            raise AnalysisError(f"pitch_diameter: must exceed the ball diameter {self.ball_diameter!r} m, got {self.pitch_diameter!r}")
        if not 0.0 <= self.contact_angle < 0.5 * math.pi:
            raise AnalysisError(f"contact_angle: must be in [0, pi/2) rad, got {self.contact_angle!r}")

    @classmethod
    def from_config(cls, source: str | Path) -> BearingKinematics:
        """Read ``geometry.ball_diameter_m``, ``geometry.pitch_diameter_m`` and
        ``geometry.contact_angle_deg`` (the nominal angle, degrees) from a bearing file.

        Args:
            source: the bearing file's path.

        Raises:
            ConfigError: naming the file and key of a missing or out-of-range value.
        """
        g = validate_mapping(_KinematicsReading, read_mapping(source), str(source)).geometry
        return cls(g.ball_diameter_m, g.pitch_diameter_m, math.radians(g.contact_angle_deg))

    def at_contact_angle(self, contact_angle: float) -> BearingKinematics:
        """The same bearing at another contact angle (rad), e.g. the loaded one."""
        return replace(self, contact_angle=contact_angle)

    def epicyclic_ratio(self) -> float:
        """n_s / n_i = (1 - Dw cos(alpha) / dm) / 2, dimensionless (0.4283 for H7006C at 15 deg)."""
        return epicyclic_ratio(self.ball_diameter, self.pitch_diameter, self.contact_angle)

    @overload
    def cage_speed_epicyclic(self, inner_ring_speed: float) -> float: ...
    @overload
    def cage_speed_epicyclic(self, inner_ring_speed: FloatArray) -> FloatArray: ...
    def cage_speed_epicyclic(self, inner_ring_speed: float | FloatArray) -> float | FloatArray:
        """Pure-rolling cage speed (rad/s) for an inner-ring speed (rad/s); Eq. 12.

        Any finite speed is accepted (the relation is linear; zero gives zero).

        Raises:
            AnalysisError: a non-finite or empty input.
        """
        speed, scalar = _speeds("inner_ring_speed", inner_ring_speed)
        out = self.epicyclic_ratio() * speed
        return float(out[0]) if scalar else out

    @overload
    def slip_rate(self, cage_speed: float, inner_ring_speed: float) -> float: ...  # type: ignore[overload-overlap]  # a float pair is never an array
    @overload
    def slip_rate(self, cage_speed: FloatArray | float, inner_ring_speed: FloatArray | float) -> FloatArray: ...
    def slip_rate(self, cage_speed: float | FloatArray, inner_ring_speed: float | FloatArray) -> float | FloatArray:
        """Cage slip rate in **percent**, (1 - n_c / n_s) * 100; Eq. 11.

        Args:
            cage_speed: n_c, rad/s; any finite value (0 gives 100 %, a backwards-turning cage
                more than 100 %).
            inner_ring_speed: n_i, rad/s; must be > 0. The slip rate is undefined at rest, and
                this function raises rather than return NaN, so that a stopped or reversed
                spindle is reported where it happens instead of poisoning a fit downstream.
                Callers sampling a run-up filter out the samples below a speed of their choice.

        Either argument may be a scalar and the other an array; two arrays must have the same
        length. Returns a float when both are scalars.

        Raises:
            AnalysisError: non-finite or empty input, mismatched lengths, or an inner-ring
                speed <= 0 (the message gives the first offending index).
        """
        cage, cage_scalar = _speeds("cage_speed", cage_speed)
        inner, inner_scalar = _speeds("inner_ring_speed", inner_ring_speed)
        if not cage_scalar and not inner_scalar:
            same_length(cage_speed=cage, inner_ring_speed=inner)
        bad = np.flatnonzero(~(inner > 0.0))
        if bad.size:
            raise AnalysisError(f"inner_ring_speed: must be > 0 rad/s for a slip rate, got {float(inner[bad[0]])!r} at index {bad[0]}")
        out = slip_pct(cage, inner, self.epicyclic_ratio())
        return float(out[0]) if cage_scalar and inner_scalar else out


def _speeds(name: str, value: float | FloatArray) -> tuple[FloatArray, bool]:
    """A speed argument as a checked 1-D array, and whether it was a scalar."""
    scalar = np.ndim(value) == 0
    return finite_array(name, value), scalar


def epicyclic_cage_speed(inner_ring_speed: float | FloatArray, ball_diameter: float, pitch_diameter: float, contact_angle: float) -> float | FloatArray:
    """Pure-rolling cage speed n_s (rad/s); paper Eq. 12.

    Args:
        inner_ring_speed: n_i, rad/s (scalar or 1-D array, any finite value).
        ball_diameter: Dw, m.
        pitch_diameter: dm, m.
        contact_angle: alpha, rad.

    Raises:
        AnalysisError: bad geometry or non-finite speed.
    """
    return BearingKinematics(ball_diameter, pitch_diameter, contact_angle).cage_speed_epicyclic(inner_ring_speed)


def slip_rate(
    cage_speed: float | FloatArray,
    inner_ring_speed: float | FloatArray,
    ball_diameter: float,
    pitch_diameter: float,
    contact_angle: float,
) -> float | FloatArray:
    """Cage slip rate S_c in **percent**; paper Eq. 11. See :meth:`BearingKinematics.slip_rate`.

    Args:
        cage_speed: n_c, rad/s.
        inner_ring_speed: n_i, rad/s, > 0 (zero or negative raises).
        ball_diameter: Dw, m.
        pitch_diameter: dm, m.
        contact_angle: alpha, rad.

    Raises:
        AnalysisError: bad geometry, non-finite speeds, mismatched lengths, n_i <= 0.
    """
    return BearingKinematics(ball_diameter, pitch_diameter, contact_angle).slip_rate(cage_speed, inner_ring_speed)


class WindowedSlip(NamedTuple):
    """Slip over consecutive windows of whole cage revolutions (one row per window)."""

    end_time: FloatArray
    """Time stamp of the cage pulse closing each window, s."""
    cage_speed: FloatArray
    """Mean cage speed over the window, rad/s."""
    inner_ring_speed: FloatArray
    """Mean spindle (inner-ring) speed over the same interval, rad/s."""
    slip_pct: FloatArray
    """Slip rate from the two mean speeds, percent."""


def whole_revolution_slip(
    cage_pulse_times: FloatArray,
    cage_strips: int,
    spindle_pulse_times: FloatArray,
    spindle_strips: int,
    kinematics: BearingKinematics,
    *,
    revolutions: int = 1,
) -> WindowedSlip:
    """Slip rate over windows of whole cage revolutions, from pulse time stamps.

    The cage pulses are cut into consecutive, non-overlapping windows of ``revolutions`` whole
    cage revolutions (``revolutions * cage_strips`` pulse intervals), which start and end on a
    pulse. The mean cage speed of a window is 2 pi ``revolutions`` / duration, exact whatever the
    spacing of the strips on the cage. The spindle's revolution count is interpolated linearly in
    its pulse index at the window's two ends (this assumes its strips are evenly spaced; for a
    single strip that is no assumption) and the mean inner-ring speed is its difference over the
    same duration. Speeds that are constant over a window are recovered exactly.

    Windows not fully covered by spindle pulses are dropped; if no window is complete the four
    arrays are empty (a monitor that has just started).

    Args:
        cage_pulse_times: time stamps of the cage sensor's pulses, s, strictly increasing.
        cage_strips: reflective strips on the cage (pulses per cage revolution), >= 1.
        spindle_pulse_times: time stamps of the spindle sensor's pulses, s, strictly increasing.
        spindle_strips: reflective strips on the spindle, >= 1.
        kinematics: the bearing's geometry.
        revolutions: whole cage revolutions per window, >= 1.

    Raises:
        AnalysisError: fewer than two pulses of either sensor, non-finite or non-increasing time
            stamps, strip or revolution counts that are not integers >= 1.
    """
    cage_t = finite_array("cage_pulse_times", cage_pulse_times, min_len=2)
    spindle_t = finite_array("spindle_pulse_times", spindle_pulse_times, min_len=2)
    strictly_increasing("cage_pulse_times", cage_t)
    strictly_increasing("spindle_pulse_times", spindle_t)
    per_window = positive_int("revolutions", revolutions) * positive_int("cage_strips", cage_strips)
    spindle_per_rev = positive_int("spindle_strips", spindle_strips)

    end_idx = np.arange(per_window, cage_t.size, per_window)
    t0, t1 = cage_t[end_idx - per_window], cage_t[end_idx]
    covered = (t0 >= spindle_t[0]) & (t1 <= spindle_t[-1])
    t0, t1 = t0[covered], t1[covered]
    duration = t1 - t0
    spindle_revs = np.arange(spindle_t.size, dtype=np.float64) / spindle_per_rev
    turned = np.interp(t1, spindle_t, spindle_revs) - np.interp(t0, spindle_t, spindle_revs)
    cage_speed = 2.0 * math.pi * revolutions / duration
    inner_speed = 2.0 * math.pi * turned / duration
    slip = kinematics.slip_rate(cage_speed, inner_speed) if t1.size else np.empty(0)
    return WindowedSlip(t1, cage_speed, inner_speed, np.asarray(slip, dtype=np.float64))


@dataclass(frozen=True)
class ThrustContact:
    """The contact angle of a ball bearing under a pure axial load, from Harris's thrust
    equilibrium (Harris and Kotzalas, *Rolling Bearing Analysis*, Eq. for a thrust-loaded angular
    contact bearing; physics-targets.md)::

        sin(a) (cos(a0) / cos(a) - 1)^1.5 = F_a / (Z K_n (B Dw)^1.5)

    with a0 the free (nominal) angle, B = f_i + f_o - 1 the total curvature, K_n the combined
    load-deflection constant of the two raceway contacts (1/K_n^(2/3) = 1/K_i^(2/3) + 1/K_o^(2/3),
    elliptical Hertz contacts at the free angle; no centrifugal force, so it holds at the rig's
    speeds as long as the ball's centrifugal force is small against its contact load).

    Attributes:
        ball_count: Z (>= 1).
        free_angle: a0, rad.
        total_curvature: B, 1 (> 0).
        ball_diameter: Dw, m.
        combined_constant: K_n, N/m^1.5.
    """

    ball_count: int
    free_angle: float
    total_curvature: float
    ball_diameter: float
    combined_constant: float

    @classmethod
    def from_config(cls, source: str | Path) -> ThrustContact:
        """From a bearing file: ``geometry`` (ball diameter, pitch diameter, ball count, nominal
        angle, groove curvature ratios) and ``materials`` (ring and ball moduli, Poisson ratios).

        Raises:
            ConfigError: naming the file and key of a missing or out-of-range value.
        """
        doc = validate_mapping(_ContactReading, read_mapping(source), str(source))
        g, ball, ring = doc.geometry, doc.materials.ball, doc.materials.ring
        dw, fi, fo = g.ball_diameter_m, g.inner_groove_curvature_ratio, g.outer_groove_curvature_ratio
        a0 = math.radians(g.contact_angle_deg)
        z = g.ball_count
        inner, outer = raceway_contacts(
            dw, g.pitch_diameter_m, a0, fi, fo, ball.youngs_modulus_pa, ball.poisson_ratio, ring.youngs_modulus_pa, ring.poisson_ratio
        )
        k_n = (inner.stiffness ** (-2.0 / 3.0) + outer.stiffness ** (-2.0 / 3.0)) ** -1.5
        return cls(z, a0, fi + fo - 1.0, dw, k_n)

    def loaded_contact_angle(self, axial_load: float) -> float:
        """The contact angle (rad) under the axial load ``axial_load`` (N); the free angle at or
        below zero load, NaN for a non-finite load."""
        if not math.isfinite(axial_load):
            return math.nan
        if axial_load <= 0.0:
            return self.free_angle
        rhs = axial_load / (self.ball_count * self.combined_constant * (self.total_curvature * self.ball_diameter) ** 1.5)
        cos0 = math.cos(self.free_angle)

        def balance(a: float) -> float:
            return math.sin(a) * max(cos0 / math.cos(a) - 1.0, 0.0) ** 1.5 - rhs

        return float(brentq(balance, self.free_angle, math.radians(89.9), xtol=1e-12))


def loaded_slip_rate(kinematics: BearingKinematics, thrust: ThrustContact, cage_speed: float, inner_ring_speed: float, axial_load: float) -> float:
    """The kinematic slip, %: 100 (1 - n_c / n_s(a)) against the pure-rolling cage speed at the
    contact angle a of the axial load ``axial_load`` (N, :meth:`ThrustContact.loaded_contact_angle`)
    rather than at the nominal angle; speeds in rad/s. NaN without a finite load."""
    angle = thrust.loaded_contact_angle(axial_load)
    if not math.isfinite(angle):
        return math.nan
    return slip_pct(cage_speed, inner_ring_speed, kinematics.at_contact_angle(angle).epicyclic_ratio())
