"""The derived series of the offline analysis: status rows and slip windows, their decimation
for plots, and their CSV files.

A :class:`StatusRow` is one status the monitor would publish, with what the other topics said at
that moment; a :class:`SlipWindowRow` one slip window. CSV files are written row by row as the
analysis streams (:class:`CsvWriter`): floats exactly (``repr``, so two runs compare byte for
byte), the unit in each column's name, speeds in rpm.

Units inside: s, rad/s, N; slip in percent, slopes in percent per second.
"""

from __future__ import annotations

import csv
import math
import operator
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from bearing_rig_sim.config import RPM_TO_RAD_S
from bearing_rig_sim.bags.errors import BagError
from bearing_rig_sim import picklable

STATUS_CSV = "status_rows.csv"
WINDOWS_CSV = "slip_windows.csv"

_NAN = math.nan
_RAD_S_TO_RPM = 1.0 / RPM_TO_RAD_S
_AS_THEY_ARE = frozenset((float, int, bool, str, type(None)))
"""Value types the csv module writes as :class:`CsvWriter` means them (a float as its ``repr``,
None as an empty field): a row of these alone is handed over as it is."""


@dataclass(frozen=True)
class StatusRow:
    """One status the monitor would publish, with what the other topics said at that moment.

    ``time`` is the rig time of the emission (a tick, a closed window, the end), s; the monitor's
    fields are :class:`~bearing_rig_sim.monitoring.MonitorStatus`'s (``window_end`` its ``time``);
    the context fields are the latest message of their topic (NaN / -1 when absent).
    Speeds rad/s, slip %, slope %/s, forces N.
    """

    time: float
    reason: str
    """``"tick"`` (a check at the status rate), ``"window"`` (a slip window closed) or ``"end"``."""
    state: int
    window_end: float
    inner_ring_speed: float
    cage_speed: float
    theoretical_cage_speed: float
    slip_rate: float
    fitted_slope: float
    confidence: float
    windows: int
    detail: str
    counter_inner_ring_speed: float = _NAN
    counter_cage_speed: float = _NAN
    truth_inner_ring_speed: float = _NAN
    truth_cage_speed: float = _NAN
    truth_slip_rate: float = _NAN
    window_start: float = _NAN
    """Start of the latest slip window (its first cage pulse), s."""
    recorded_state: int = -1
    recorded_slip_rate: float = _NAN
    axial_load_setpoint: float = _NAN
    load_cell_force: float = _NAN
    bearing_force: float = _NAN
    truth_axial_load: float = _NAN
    kinematic_slip_rate: float = _NAN
    """The monitor's kinematic slip, at the contact angle of the measured load, %."""
    loaded_contact_angle: float = _NAN
    """That contact angle, rad."""
    outer_ring_temperature: float = _NAN
    """The outer-ring thermocouple, degC."""
    housing_torque: float = _NAN
    """The housing torque meter, N m."""

    @property
    def axial_load(self) -> float:
        """The best axial-load figure at hand: bearing force, else load cell, truth, set-point; N."""
        for value in (self.bearing_force, self.load_cell_force, self.truth_axial_load, self.axial_load_setpoint):
            if math.isfinite(value):
                return value
        return _NAN


@dataclass(frozen=True)
class SlipWindowRow:
    """One slip window of the monitor: cage pulses ``start_time`` .. ``end_time`` (s), mean speeds
    (rad/s), slip (%; NaN below the monitor's minimum speed)."""

    start_time: float
    end_time: float
    inner_ring_speed: float
    cage_speed: float
    slip_rate: float


class RowDecimator:
    """Keeps every ``stride``-th row, doubling the stride (and halving what is kept) whenever
    more than ``capacity`` are held: an even spread over any length, in bounded memory."""

    def __init__(self, capacity: int) -> None:
        if capacity < 2:
            raise BagError(f"max_points must be >= 2, got {capacity}")
        self.capacity = capacity
        self.rows: list[Any] = []
        self.stride = 1
        self.offered = 0
        self.last: Any = None

    def offer(self, row: Any) -> None:
        """Take one row (kept or not)."""
        if self.offered % self.stride == 0:
            self.rows.append(row)
            if len(self.rows) > self.capacity:
                del self.rows[1::2]
                self.stride *= 2
        self.offered += 1
        self.last = row

    def result(self) -> list[Any]:
        """The rows kept, the latest offered included."""
        if self.last is not None and (not self.rows or self.rows[-1] is not self.last):
            return [*self.rows, self.last]
        return list(self.rows)


class CsvWriter:
    """Rows of a dataclass to a CSV file (the module documentation's conventions); columns as
    made by :func:`csv_columns`."""

    def __init__(self, path: Path, columns: list[tuple[str, str, float]]) -> None:
        self.path = path
        self.columns = columns
        self._file = open(path, "w", encoding="utf-8", newline="")
        self._writer = csv.writer(self._file)
        self._writer.writerow([name for name, _attr, _scale in columns])
        self._values = operator.attrgetter(*(attr for _name, attr, _scale in columns)) if len(columns) > 1 else None
        self._scales = [None if scale == 1.0 else scale for _name, _attr, scale in columns]
        self._scaled = [(k, scale) for k, scale in enumerate(self._scales) if scale is not None]

    def write(self, row: Any) -> None:
        """Append one row."""
        values = list(self._values(row)) if self._values is not None else [getattr(row, attr) for _name, attr, _scale in self.columns]
        if not set(map(type, values)) <= _AS_THEY_ARE:
            self._writer.writerow(
                [
                    (repr(float(value)) if scale is None else repr(float(value) * scale)) if isinstance(value, float) else "" if value is None else value
                    for value, scale in zip(values, self._scales)
                ]
            )
            return
        for k, scale in self._scaled:
            value = values[k]
            if type(value) is float:
                values[k] = value * scale
        self._writer.writerow(values)  # the csv module writes a float as its repr and None as ""

    def close(self) -> None:
        """Close the file."""
        self._file.close()


def csv_column(name: str) -> tuple[str, str, float]:
    """(column name with its unit, attribute, scale): speeds in rpm, the rest as they are."""
    if name.endswith("_speed"):
        return name.removesuffix("_speed") + "_rpm", name, _RAD_S_TO_RPM
    for suffixes, unit in (
        (("time", "_end", "time_to_stable"), "_s"),
        (("slip_rate",), "_pct"),
        (("fitted_slope",), "_pct_per_s"),
        (("force", "axial_load", "setpoint"), "_n"),
    ):
        if name.endswith(suffixes):
            return name + unit, name, 1.0
    return name, name, 1.0


def csv_columns(cls: type) -> list[tuple[str, str, float]]:
    """The CSV columns of a dataclass, one per field (see :func:`csv_column`)."""
    return [csv_column(f.name) for f in fields(cls)]


picklable.by_fields(StatusRow, SlipWindowRow)
