"""Checks on the data handed to the analysis, and the error they raise.

Every public function of :mod:`bearing_rig_sim.analysis` passes its arrays through these checks
first, so that a bad sample (NaN, an empty series, series of different lengths, a clock that runs
backwards) is reported as an :class:`AnalysisError` naming the argument and the offending index,
not as a numpy warning or a meaningless fit.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import numpy.typing as npt

from bearing_rig_sim.errors import RigError

FloatArray = npt.NDArray[np.float64]
"""One-dimensional (or scalar-shaped) array of float64."""


class AnalysisError(RigError, ValueError):
    """Input the analysis cannot use: non-finite, empty, mismatched, out of range or unordered."""


def finite_array(name: str, values: Any, *, min_len: int = 1) -> FloatArray:
    """``values`` as a 1-D float64 array of at least ``min_len`` finite entries.

    Args:
        name: argument name used in the error message.
        values: a sequence or array of real numbers (a scalar counts as one entry).
        min_len: the fewest entries accepted.

    Raises:
        AnalysisError: not numeric, not one-dimensional, too short, or a NaN/inf entry.
    """
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise AnalysisError(f"{name}: must be real numbers ({exc})") from None
    arr = np.atleast_1d(arr)
    if arr.ndim != 1:
        raise AnalysisError(f"{name}: must be one-dimensional, got shape {arr.shape}")
    if arr.size < min_len:
        what = "empty" if arr.size == 0 else f"only {arr.size} value(s)"
        raise AnalysisError(f"{name}: needs at least {min_len} value(s), got {what}")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise AnalysisError(f"{name}: non-finite value {arr[bad[0]]} at index {bad[0]} ({bad.size} in all)")
    return arr


def same_length(**arrays: FloatArray) -> None:
    """Raise unless all keyword arrays have the same length.

    Raises:
        AnalysisError: naming every argument with its length.
    """
    lengths = {name: len(arr) for name, arr in arrays.items()}
    if len(set(lengths.values())) > 1:
        listed = ", ".join(f"{name} has {n}" for name, n in lengths.items())
        raise AnalysisError(f"lengths differ: {listed}")


def strictly_increasing(name: str, values: FloatArray) -> None:
    """Raise unless ``values`` increase strictly (time stamps, swept loads).

    Raises:
        AnalysisError: naming the first index where the value does not increase.
    """
    steps = np.diff(values)
    bad = np.flatnonzero(~(steps > 0.0))
    if bad.size:
        i = int(bad[0]) + 1
        raise AnalysisError(f"{name}: must increase strictly, but {name}[{i}] = {float(values[i])!r} <= {name}[{i - 1}] = {float(values[i - 1])!r}")


def finite_number(name: str, value: Any) -> float:
    """``value`` as a finite float.

    Raises:
        AnalysisError: not a real number, or NaN/inf.
    """
    if isinstance(value, bool):
        raise AnalysisError(f"{name}: must be a real number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise AnalysisError(f"{name}: must be a real number, got {value!r}") from None
    if not math.isfinite(x):
        raise AnalysisError(f"{name}: must be finite, got {value!r}")
    return x


def positive_int(name: str, value: Any) -> int:
    """``value`` as an integer >= 1.

    Raises:
        AnalysisError: not an integer, or < 1.
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise AnalysisError(f"{name}: must be an integer >= 1, got {value!r}")
    if value < 1:
        raise AnalysisError(f"{name}: must be an integer >= 1, got {value}")
    return int(value)
