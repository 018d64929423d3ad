"""What a calibration pins down: standard errors, correlations, identifiability and prediction
intervals, with the bench's load uncertainty as a nuisance parameter.

The fit (:func:`bearing_rig_sim.studies.calibration.calibrate`) finds the log-parameters theta
that minimise the slip residuals r_i = S(theta, F_i + delta) - S_i at the bench's nominal loads
F_i; the true load differs from the nominal by delta, one offset common to every row (the same
lever and load cell), delta ~ N(0, sigma_F^2). Linearised about the fit, with J_theta = dS/dtheta
and J_F = dS/dF at the rows (finite differences of the engine's steady states):

* the data's own information: C_noise = s^2 (J_theta^T J_theta)^-1, s^2 = sum r^2 / (n - p);
* what a load offset does to the fit: dtheta/ddelta = -(J_theta^T J_theta)^-1 J_theta^T J_F;
* the parameters' covariance: C = C_noise + (dtheta/ddelta)(dtheta/ddelta)^T sigma_F^2, their
  standard errors sqrt(diag C) (relative, as theta are logarithms) and correlations;
* a prediction S(theta, F + delta) at another point, with gradients g_theta and g_F there:
  var = g_theta C_noise g_theta^T + (g_theta . dtheta/ddelta + g_F)^2 sigma_F^2; the 95 %
  interval is +-1.96 sqrt(var). A load offset the fit absorbed cancels in part at the same load.

Identifiability (:func:`check_identifiable`): a fit is refused when two fitted parameters are
correlated beyond :data:`MAX_CORRELATION` in the data's own information C_noise, or when the
columns of J_theta (each scaled to unit length) have a condition number above
:data:`MAX_CONDITION`: the data then cannot tell the parameters apart, whatever their best-fit
values. The correlation of each parameter with the load offset (data alone, without its prior)
is reported: near 1 means the parameter and the true load are not separable from these rows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from collections.abc import Sequence
from typing import Any

import numpy as np

from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.settings_model import read_file
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.thermal.bearing import ThermalConfig

LOAD_SIGMA_N = 2.0
"""Standard uncertainty of the bench's axial load, N (one offset common to all rows).
ASSUMPTION: the rig file gives the load cell's noise (1 N per sample) but no accuracy; a 2 kN
S-beam cell of OIML R60 class C3 has a combined error of about 0.02-0.05 % of full scale
(0.4-1 N), and the lever's placement of the load on the bearing adds to it: 2 N (2 % at 100 N)."""
MAX_CORRELATION = 0.99
"""Largest |correlation| two fitted parameters may have in the data's own information."""
MAX_CONDITION = 1e3
"""Largest condition number of the column-scaled Jacobian of the fitted parameters."""
LOG_STEP = 0.01
"""Finite-difference step of the log-parameters (1 % of each)."""
LOAD_STEP_N = 1.0
"""Finite-difference step of the load, N."""
Z95 = 1.959963984540054
"""Two-sided 95 % point of the normal distribution."""


class IdentifiabilityError(RigError):
    """The data cannot tell the fitted parameters apart."""


@dataclass(frozen=True)
class FitUncertainty:
    """A calibration's uncertainty (see the module doc).

    Attributes:
        names: the fitted parameters.
        values: their best-fit values (their units).
        standard_errors: relative standard errors (of the logarithms), 1.
        correlation: correlation matrix of the parameters (C), 1.
        noise_correlation: the same from the data alone (C_noise), 1.
        load_correlation: each parameter's correlation with the load offset, data alone, 1.
        load_sigma_n: the load offset's standard uncertainty, N.
        residual_sigma_pct: s, the slip residuals' standard deviation, percentage points.
        dof: n - p.
        condition_number: of the column-scaled Jacobian, 1.
        noise_covariance: C_noise of the log-parameters.
        load_sensitivity: dtheta/ddelta of the log-parameters, 1/N.
        jacobian: J_theta at the rows, d slip / d log-parameter, pp (n x p; empty when not
            stored): the fit's refit to a change of its rows (:mod:`.priors`).
    """

    names: tuple[str, ...]
    values: tuple[float, ...]
    standard_errors: tuple[float, ...]
    correlation: tuple[tuple[float, ...], ...]
    noise_correlation: tuple[tuple[float, ...], ...]
    load_correlation: tuple[float, ...]
    load_sigma_n: float
    residual_sigma_pct: float
    dof: int
    condition_number: float
    noise_covariance: tuple[tuple[float, ...], ...]
    load_sensitivity: tuple[float, ...]
    jacobian: tuple[tuple[float, ...], ...] = ()

    def as_dict(self) -> dict[str, Any]:
        """For the calibration file and ``--json`` (plain floats)."""
        r = lambda x: float(f"{x:.6g}")
        return {
            "parameters": {n: {"value": r(v), "relative_standard_error": r(se)} for n, v, se in zip(self.names, self.values, self.standard_errors)},
            "correlation": [[r(c) for c in row] for row in self.correlation],
            "data_correlation": [[r(c) for c in row] for row in self.noise_correlation],
            "load_correlation": [r(c) for c in self.load_correlation],
            "load_sigma_n": r(self.load_sigma_n),
            "residual_sigma_pct": r(self.residual_sigma_pct),
            "dof": self.dof,
            "condition_number": r(self.condition_number),
            "log_noise_covariance": [[r(c) for c in row] for row in self.noise_covariance],
            "log_load_sensitivity_1_n": [r(c) for c in self.load_sensitivity],
            **({"row_jacobian_pp": [[r(c) for c in row] for row in self.jacobian]} if self.jacobian else {}),
        }

    @classmethod
    def from_dict(cls, doc: dict[str, Any]) -> FitUncertainty:
        """Back from :meth:`as_dict` (a calibration file's ``uncertainty:`` block)."""
        names = tuple(doc["parameters"])
        tup = lambda rows: tuple(tuple(float(c) for c in row) for row in rows)
        return cls(
            names=names,
            values=tuple(float(doc["parameters"][n]["value"]) for n in names),
            standard_errors=tuple(float(doc["parameters"][n]["relative_standard_error"]) for n in names),
            correlation=tup(doc["correlation"]),
            noise_correlation=tup(doc["data_correlation"]),
            load_correlation=tuple(float(c) for c in doc["load_correlation"]),
            load_sigma_n=float(doc["load_sigma_n"]),
            residual_sigma_pct=float(doc["residual_sigma_pct"]),
            dof=int(doc["dof"]),
            condition_number=float(doc["condition_number"]),
            noise_covariance=tup(doc["log_noise_covariance"]),
            load_sensitivity=tuple(float(c) for c in doc["log_load_sensitivity_1_n"]),
            jacobian=tup(doc.get("row_jacobian_pp", ())),
        )


def _correlation(cov: np.ndarray) -> np.ndarray:
    d = np.sqrt(np.clip(np.diag(cov), 1e-300, None))
    return np.asarray(cov / np.outer(d, d))


def linear_uncertainty(j_theta: np.ndarray, j_load: np.ndarray, residuals: np.ndarray, load_sigma: float) -> dict[str, Any]:
    """The module doc's linearised quantities from the Jacobians at the fit.

    Args:
        j_theta: dS/dtheta at the rows, n x p.
        j_load: dS/dF at the rows, n.
        residuals: model minus bench slip at the fit, n.
        load_sigma: the load offset's standard uncertainty.

    Returns:
        ``noise_cov``, ``dtheta_dload``, ``cov``, ``s`` (residual sigma), ``dof``, ``condition``,
        ``load_correlation`` (each parameter with the load offset, data alone).
    """
    j = np.asarray(j_theta, dtype=float)
    n, p = j.shape
    dof = n - p
    if dof < 1:
        raise IdentifiabilityError(f"{n} rows cannot give the uncertainty of {p} parameters (need at least {p + 1})")
    s2 = float(np.sum(np.asarray(residuals) ** 2)) / dof
    info_inv = np.linalg.pinv(j.T @ j)
    noise_cov = s2 * info_inv
    dtheta = -info_inv @ j.T @ np.asarray(j_load, dtype=float)
    cov = noise_cov + np.outer(dtheta, dtheta) * load_sigma**2
    scaled = j / np.linalg.norm(j, axis=0)
    condition = float(np.linalg.cond(scaled))
    aug = np.column_stack([j, j_load])
    aug_cov = np.linalg.pinv(aug.T @ aug)
    load_corr = _correlation(aug_cov)[-1, :-1]
    return {"noise_cov": noise_cov, "dtheta_dload": dtheta, "cov": cov, "s": math.sqrt(s2), "dof": dof, "condition": condition, "load_correlation": load_corr}


def check_identifiable(names: Sequence[str], noise_correlation: np.ndarray, condition: float) -> None:
    """Refuse a fit the data cannot resolve (module doc's rule), naming the parameters."""
    p = len(names)
    for a in range(p):
        for b in range(a + 1, p):
            c = float(noise_correlation[a, b])
            if abs(c) > MAX_CORRELATION:
                raise IdentifiabilityError(
                    f"{names[a]} and {names[b]} are not identifiable from these rows: correlation {c:+.4f} beyond +-{MAX_CORRELATION} "
                    "(fit one of them, or add rows that separate them: other loads or speeds)"
                )
    if condition > MAX_CONDITION:
        raise IdentifiabilityError(
            f"{', '.join(names)}: the scaled Jacobian's condition number {condition:.3g} exceeds {MAX_CONDITION:g}; not identifiable from these rows"
        )


def _slips(params: BearingParameters, points: Sequence[tuple[float, float]], thermal: ThermalConfig | None = None) -> np.ndarray:
    from bearing_rig_sim.studies.calibration import steady_states

    return np.array([s.slip_pct for s in steady_states(params, points, thermal=thermal)])  # on the Dask cluster when one is set


def _shifted(params: BearingParameters, names: Sequence[str], values: Sequence[float], k: int) -> BearingParameters:
    from bearing_rig_sim.studies.calibration import with_values

    return with_values(params, {n: (v * math.exp(LOG_STEP) if i == k else v) for i, (n, v) in enumerate(zip(names, values))})


def fit_uncertainty(
    params: BearingParameters,
    points: Sequence[tuple[float, float, float]],
    names: Sequence[str],
    values: Sequence[float],
    *,
    load_sigma_n: float = LOAD_SIGMA_N,
    thermal: ThermalConfig | None = None,
) -> FitUncertainty:
    """The uncertainty of a fit: ``params`` carry the best-fit ``values`` of ``names``; ``points``
    are the bench rows (inner-ring speed rad/s, nominal load N, slip %). Costs (p + 2) n steady
    states (with ``thermal``, coupled thermal steady states: the Jacobians then include the
    temperature each change of a parameter or the load brings)."""
    rows = [(w, f) for w, f, _ in points]
    base = _slips(params, rows, thermal)
    j_theta = np.column_stack([(_slips(_shifted(params, names, values, k), rows, thermal) - base) / LOG_STEP for k in range(len(names))])
    j_load = (_slips(params, [(w, f + LOAD_STEP_N) for w, f in rows], thermal) - base) / LOAD_STEP_N
    residuals = base - np.array([s for _, _, s in points])
    lin = linear_uncertainty(j_theta, j_load, residuals, load_sigma_n)
    tup = lambda m: tuple(tuple(float(c) for c in row) for row in m)
    return FitUncertainty(
        names=tuple(names),
        values=tuple(float(v) for v in values),
        standard_errors=tuple(float(x) for x in np.sqrt(np.diag(lin["cov"]))),
        correlation=tup(_correlation(lin["cov"])),
        noise_correlation=tup(_correlation(lin["noise_cov"])),
        load_correlation=tuple(float(c) for c in lin["load_correlation"]),
        load_sigma_n=float(load_sigma_n),
        residual_sigma_pct=float(lin["s"]),
        dof=int(lin["dof"]),
        condition_number=float(lin["condition"]),
        noise_covariance=tup(lin["noise_cov"]),
        load_sensitivity=tuple(float(c) for c in lin["dtheta_dload"]),
        jacobian=tup(j_theta),
    )


def read_uncertainty(calibration_file: str | Path) -> FitUncertainty | None:
    """The ``uncertainty:`` block of a calibration file, or None."""
    block = read_file(CalibrationFile, calibration_file).uncertainty
    return FitUncertainty.from_dict(block) if block is not None else None


def slip_gradients(
    params: BearingParameters, unc: FitUncertainty, inner_ring_speed: float, axial_load: float, slip_pct: float, thermal: ThermalConfig | None = None
) -> tuple[np.ndarray, float]:
    """The prediction's gradients at one point: d slip / d log-parameter (pp) and d slip / d load
    (pp/N), finite differences of the steady states (with ``thermal``, the coupled ones)."""
    from bearing_rig_sim.studies.calibration import current_value

    rows = [(inner_ring_speed, axial_load)]
    here = [current_value(params, n) for n in unc.names]  # the calibration's, or moved to a temperature
    g_theta = np.array([(_slips(_shifted(params, unc.names, here, k), rows, thermal)[0] - slip_pct) / LOG_STEP for k in range(len(unc.names))])
    g_load = (_slips(params, [(inner_ring_speed, axial_load + LOAD_STEP_N)], thermal)[0] - slip_pct) / LOAD_STEP_N
    return g_theta, float(g_load)


def parametric_sd(unc: FitUncertainty, g_theta: np.ndarray, g_load: float) -> float:
    """Standard deviation of a prediction from the parameter and load uncertainty (module doc)."""
    cov = np.array(unc.noise_covariance)
    through_fit = float(g_theta @ np.array(unc.load_sensitivity)) + g_load
    var = float(g_theta @ cov @ g_theta) + (through_fit * unc.load_sigma_n) ** 2
    return math.sqrt(max(var, 0.0))


def slip_interval(
    params: BearingParameters, unc: FitUncertainty, inner_ring_speed: float, axial_load: float, slip_pct: float, thermal: ThermalConfig | None = None
) -> tuple[float, float, float]:
    """95 % interval of the predicted slip at one point from the parameter and load uncertainty:
    (low, high, standard deviation), %. ``params`` carry the calibration's values (or those
    values moved to another lubricant temperature); ``slip_pct`` is their slip there. With
    ``thermal`` the gradients are those of the coupled thermal steady state (``params`` then
    carry the calibration's values at its reference temperature)."""
    g_theta, g_load = slip_gradients(params, unc, inner_ring_speed, axial_load, slip_pct, thermal)
    sd = parametric_sd(unc, g_theta, g_load)
    return slip_pct - Z95 * sd, slip_pct + Z95 * sd, sd
