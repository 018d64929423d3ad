"""Input checks shared by the analysis: each bad input gives an AnalysisError naming it."""

from __future__ import annotations

import numpy as np
import pytest

from bearing_rig_sim.analysis.inputs import (
    AnalysisError,
    finite_array,
    finite_number,
    positive_int,
    same_length,
    strictly_increasing,
)
from bearing_rig_sim.errors import RigError


def test_analysis_error_is_a_user_facing_error() -> None:
    assert issubclass(AnalysisError, RigError)
    assert issubclass(AnalysisError, ValueError)


def test_finite_array_accepts_scalars_and_sequences() -> None:
    assert finite_array("x", 2.5).tolist() == [2.5]
    out = finite_array("x", [1, 2, 3])
    assert out.dtype == np.float64 and out.tolist() == [1.0, 2.0, 3.0]


@pytest.mark.parametrize(
    ("values", "min_len", "message"),
    [
        ([], 1, r"x: needs at least 1 value\(s\), got empty"),
        ([1.0], 2, r"x: needs at least 2 value\(s\), got only 1 value\(s\)"),
        ([1.0, np.inf, np.nan], 1, r"x: non-finite value inf at index 1 \(2 in all\)"),
        ([[1.0, 2.0]], 1, r"x: must be one-dimensional, got shape \(1, 2\)"),
        (["a"], 1, r"x: must be real numbers"),
    ],
)
def test_finite_array_rejects(values: object, min_len: int, message: str) -> None:
    with pytest.raises(AnalysisError, match=message):
        finite_array("x", values, min_len=min_len)


def test_same_length_names_each_argument() -> None:
    same_length(a=np.zeros(3), b=np.ones(3))
    with pytest.raises(AnalysisError, match="lengths differ: a has 3, b has 2"):
        same_length(a=np.zeros(3), b=np.ones(2))


def test_strictly_increasing_names_the_first_offender() -> None:
    strictly_increasing("t", np.array([0.0, 0.5, 2.0]))
    with pytest.raises(AnalysisError, match=r"t\[2\] = 0.5 <= t\[1\] = 0.5"):
        strictly_increasing("t", np.array([0.0, 0.5, 0.5, 0.1]))


def test_finite_number_and_positive_int() -> None:
    assert finite_number("k", np.float32(-0.5)) == -0.5
    for bad in (float("nan"), "x", None, True):
        with pytest.raises(AnalysisError, match="k: must be"):
            finite_number("k", bad)
    assert positive_int("n", np.int64(3)) == 3
    for bad in (0, -2, 1.0, True):
        with pytest.raises(AnalysisError, match="n: must be an integer >= 1"):
            positive_int("n", bad)
