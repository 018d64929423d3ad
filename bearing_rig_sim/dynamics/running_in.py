"""The grease's running-in: the bearing's state as a function of its running time (SI; no ROS
import).

A freshly packed grease bearing starts with its swept volume full (``fill_fraction`` 1: the balls
and cage plough through grease, the churning phase); running pushes the grease aside into the dead
spaces and onto the shoulders and cage (channelling), until only what lies on the track is
sheared (the channelled end state, a fill of 0.02-0.1 of the swept volume). The friction torque
and the temperature are high while the grease churns and fall to a steady level within hours
(SKF super-precision catalogue, "Running-in of grease lubricated bearings"; Lugt, Tribology
Transactions 52, 2009, 470-480; Chatra, Osara and Lugt, Tribology International 2023, 108375).

The law here is first order in running time t (s):

    fill(t) = f_end + (f_0 - f_end) exp(-t / tau),

f_0 the bearing's fill at t = 0 (the bench calibration's state: config/calibration/
h7006c_table3.yaml over the packed grease, fill 1), f_end and tau from the ``running_in:``
section of the lubricant file (config/lubricants/nlgi2_grease.yaml; each value with its unit,
source and plausible range there). The fill multiplies the grease's drag on the balls and its
shear in the cage land (:func:`~.parameters.derive`); the grease's rheology (yield stress,
consistency, flow index) is held. Running time is in seconds here; hours only at the command
line (``bearing-rig predict --running-hours H``). docs/model.md, section "Running in".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bearing_rig_sim.dynamics.bearing_file import LubricantFile, RunningIn
from bearing_rig_sim.dynamics.lubrication import Lubricant
from bearing_rig_sim.dynamics.parameters import BearingParameters
from bearing_rig_sim.settings_model import read_file

SECONDS_PER_HOUR = 3600.0
"""Seconds in an hour (running time at the command line is in hours)."""


class RunningInError(ValueError):
    """A running-in request the bearing cannot answer (no grease, no ``running_in:`` section, a
    negative running time)."""


@dataclass(frozen=True)
class RunningInLaw:
    """The first-order running-in law of a grease.

    Attributes:
        time_constant: tau of the fill's exponential approach to its channelled value, s.
        channelled_fill_fraction: f_end, the share of the swept volume still holding grease once
            channelled, 1.
        source: the lubricant file it was read from.
    """

    time_constant: float
    channelled_fill_fraction: float
    source: str = "<memory>"

    @classmethod
    def from_section(cls, section: RunningIn, source: str) -> RunningInLaw:
        """The law of a validated ``running_in:`` section."""
        return cls(section.time_constant_s, section.channelled_fill_fraction, source)

    @classmethod
    def of(cls, lubricant: Lubricant | None) -> RunningInLaw:
        """The law the lubricant's file states (its ``running_in:`` section).

        Raises:
            RunningInError: no lubricant file, not a grease, or no ``running_in:`` section.
        """
        if lubricant is None or lubricant.kind != "grease":
            raise RunningInError("running-in needs a grease lubricant file (lubricant.file of kind grease)")
        doc = read_file(LubricantFile, lubricant.source)
        if doc.running_in is None:
            raise RunningInError(f"{lubricant.source}: running_in: missing (the grease's running-in law)")
        return cls.from_section(doc.running_in, lubricant.source)

    def fill_fraction(self, running_time: float, initial_fill: float) -> float:
        """fill(t) = f_0 - (f_0 - f_end)(1 - exp(-t / tau)) for ``running_time`` t (s) from
        ``initial_fill`` f_0 (1); exactly f_0 at t = 0, never below f_end, and never rising
        (an initial fill already below f_end is kept).

        Raises:
            RunningInError: a negative or non-finite running time.
        """
        if not math.isfinite(running_time) or running_time < 0.0:
            raise RunningInError(f"running time must be >= 0 s, got {running_time!r}")
        drop = max(initial_fill - self.channelled_fill_fraction, 0.0)
        return initial_fill - drop * -math.expm1(-running_time / self.time_constant)


def at_running_time(params: BearingParameters, running_time: float, law: RunningInLaw | None = None) -> BearingParameters:
    """The bearing after ``running_time`` (s) of running from the state ``params`` describes
    (t = 0: the calibrated, packed grease): its lubricant's fill by ``law`` (default: the
    lubricant file's ``running_in:`` section). At t = 0 the parameters are returned unchanged.

    Raises:
        RunningInError: see :meth:`RunningInLaw.of` and :meth:`RunningInLaw.fill_fraction`.
    """
    law = law or RunningInLaw.of(params.lubricant)
    lubricant = params.lubricant
    if lubricant is None:  # RunningInLaw.of refuses it; a law given without a lubricant too
        raise RunningInError("running-in needs a grease lubricant file (lubricant.file of kind grease)")
    fill = law.fill_fraction(running_time, lubricant.fill_fraction)
    if fill == lubricant.fill_fraction:
        return params
    return params.with_lubricant(fill_fraction=fill)
