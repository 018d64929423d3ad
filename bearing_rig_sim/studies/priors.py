"""What the bench did not measure, as uncertain inputs of the coupled twin, and the spread they
give its predictions (model form), the calibration refitted to each.

The coupled twin (the lubricant at the temperature its own heat gives it; calibration
``coupled``) rests on three inputs nobody measured (:data:`PRIORS`, docs/thermal.md section
"Uncertain inputs"):

* ``consistency_temperature_exponent`` x of the grease's law K(T) = K_ref (eta(T)/eta_ref)^x,
  uniform on [0, 1];
* ``frame_conductance_w_k``, the housing's conduction to the bench frame, uniform on its stated
  range [0, 5] W/K (with the housing's 0.3 W/K of free convection, the housing's whole
  conductance to ambient spans 0.3-5.3 W/K);
* ``hold``: how long the bench held each Table 3 speed before its reading. The paper does not say
  (docs/paper.md sections 8-9). From the shortest hold that gives a reading (30 s per speed of a
  rising program 900, 1200, ..., 2700 rpm from a cold start; the Gaussian fits of the pulses need
  seconds) to a settled bearing (the thermal steady state): drawn as the lubricant's warm fraction
  phi = (T - T_ambient) / (T_steady - T_ambient), uniform between its value after the short
  hold and 1.

**How the spread is made.** Each input's effect on the slip is evaluated by the engine at the
ends of its range (and at the calibration's value), at the calibration's rows and at the
prediction's point, and taken piecewise linear between them. For each of a small Latin-hypercube
set of draws (:data:`DRAWS`, no engine run per draw), the calibration is refitted linearly: the
rows' slips move by r(p), the fitted log-parameters by d theta = -(J^T J)^-1 J^T r(p) (J the
rows' Jacobian of the fit, as for the load offset in :mod:`.uncertainty`), and the prediction by
the input's own effect there plus g_theta . d theta. A draw whose refitted values leave their
physical ranges is discarded: the bench data and the ranges refute it (so the exponent's
uniform prior is cut to the values the Table 3 slips allow). Refitting matters: without it the
exponent alone moves the warm slip at 2700 rpm by 3 pp (docs/model.md, "Recalibration with the
thermal model"); a twin whose inputs changed would be recalibrated on the same rows, so its
predictions between the rows move far less. The 2.5-97.5 % range of the kept draws' shifts is the
model-form spread; ``predict``'s interval adds it in quadrature to the parametric half-width on
each side (:func:`widen`).
"""

from __future__ import annotations

from bearing_rig_sim.errors import RigError

import dataclasses
import math
from dataclasses import dataclass
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from bearing_rig_sim.config import rad_s_to_rpm
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.thermal.bearing import ThermalConfig, build_network, node_heat

EXPONENT = "consistency_temperature_exponent"
FRAME = "frame_conductance_w_k"
HOLD = "hold"


@dataclass(frozen=True)
class Prior:
    """One uncertain input: its unit, range (uniform prior), the values the engine is run at,
    and its source."""

    name: str
    unit: str
    low: float
    high: float
    evaluated: tuple[float, ...]
    source: str


PRIORS: tuple[Prior, ...] = (
    Prior(
        EXPONENT,
        "1",
        0.0,
        1.0,
        (0.0, 0.25),
        "x of K(T) = K_ref (eta(T)/eta_ref)^x: 0 the thickener alone, 1 the base oil's viscosity; no flow curve of this grease against "
        "temperature found (config/lubricants/nlgi2_grease.yaml); evaluated at 0 and 0.25 and taken linear (beyond about 0.25 the "
        "refitted yield stress leaves its range: such draws are discarded)",
    ),
    Prior(
        FRAME,
        "W/K",
        0.0,
        5.0,
        (0.0, 0.5, 5.0),
        "the housing's conduction to the bench frame: the bearing file's stated range [0, 5] W/K (ASSUMPTION 0.5 W/K)",
    ),
    Prior(
        HOLD,
        "1",
        0.0,
        1.0,
        (0.0, 1.0),
        "hold of each speed: 0 = 30 s per speed of a rising 300 rpm program from a cold start, 1 = settled (thermal steady state); "
        "drawn as the lubricant's warm fraction between the two (the paper gives no hold time)",
    ),
)
"""The coupled twin's uncertain inputs (module doc)."""

SHORT_HOLD_S = 30.0
"""Shortest hold of a bench speed that gives a reading, s (module doc)."""
PROGRAM_START_RPM = 900.0
"""First speed of the bench's rising program (paper Table 3)."""
PROGRAM_STEP_RPM = 300.0
"""Its steps: Table 3's seven speeds 900-2700 rpm."""
DRAWS = 64
"""Latin-hypercube draws of the inputs (each refitted linearly; no engine run per draw)."""
DRAW_SEED = 33
"""Seed of the draws (the same draws for every prediction)."""
Z95 = 1.959963984540054


def running_time(rpm: float, hold_s: float = SHORT_HOLD_S) -> float:
    """The bench's running time from a cold start before its reading at ``rpm``: one hold per
    speed of the rising program up to this one (the earlier speeds' heat taken as this one's: it
    warms the bearing a little faster than the slower speeds would), s."""
    k = max(0, round((rpm - PROGRAM_START_RPM) / PROGRAM_STEP_RPM))
    return (k + 1) * hold_s


@dataclass(frozen=True)
class PointEffects:
    """The nominal coupled steady state at a point and each input's slip there at its
    evaluated values (pp, piecewise linear between them).

    Attributes:
        slip_pct: the nominal slip, %.
        lubricant_temperature_c: the nominal steady lubricant temperature, degC.
        effects: prior name -> slip minus the nominal slip at each of its evaluated values, pp.
        short_hold_temperature_c: the lubricant's temperature after the short hold, degC.
    """

    slip_pct: float
    lubricant_temperature_c: float
    effects: dict[str, tuple[float, ...]]
    short_hold_temperature_c: float


def point_effects(params: BearingParameters, cfg: ThermalConfig, inner_ring_speed: float, axial_load: float) -> PointEffects:
    """Each prior's effect on the coupled steady slip at one point (module doc). ``params``
    carry the calibration (the exponent at its calibrated value, the reference of the
    effects). Costs about eight engine steady states: the frame's ends take the engine's heat
    from the nominal search's, linear in the lubricant's temperature, and one engine solution
    at the temperature found."""
    from bearing_rig_sim.studies.calibration import with_values
    from bearing_rig_sim.thermal.coupling import HeatAtTemperature, thermal_steady_state

    heat = HeatAtTemperature(params, inner_ring_speed, axial_load)
    nominal = thermal_steady_state(params, cfg, inner_ring_speed, axial_load, heat=heat)
    s0 = nominal.point.slip_pct
    t_ss = nominal.temperatures["lubricant"]
    effects: dict[str, tuple[float, ...]] = {}
    x0 = params.lubricant.consistency_temperature_exponent if params.lubricant is not None else 0.0
    slips = []
    for x in _prior(EXPONENT).evaluated:
        if x == x0:
            slips.append(0.0)
            continue
        ts = thermal_steady_state(with_values(params, {EXPONENT: x}), cfg, inner_ring_speed, axial_load, start_c=t_ss)
        slips.append(ts.point.slip_pct - s0)
    effects[EXPONENT] = tuple(slips)
    slips = []
    for g in _prior(FRAME).evaluated:
        if g == cfg.frame_conductance:
            slips.append(0.0)
            continue
        t = _steady_temperature(heat, params, dataclasses.replace(cfg, frame_conductance=g), inner_ring_speed, axial_load)
        slips.append(heat(t)[0].slip_pct - s0)
    effects[FRAME] = tuple(slips)
    net = build_network(params, cfg, inner_ring_speed, axial_load, lubricant_temperature=t_ss, initial=cfg.ambient)
    net.step(net.heat_vector(node_heat(nominal.sources)), running_time(rad_s_to_rpm(inner_ring_speed)))
    t_short = min(net.temperature("lubricant"), t_ss)
    effects[HOLD] = (heat(t_short)[0].slip_pct - s0, 0.0)
    return PointEffects(s0, t_ss, effects, t_short)


MAX_STEADY_LUBRICANT_C = 400.0
"""Highest lubricant temperature searched for a steady state, degC: above the flash points of
spindle greases' base oils (about 200-250 degC), so a point beyond it has no useful steady state."""


class ThermalRunawayError(RigError):
    """No steady lubricant temperature below :data:`MAX_STEADY_LUBRICANT_C` for a prior's draw."""


def _prior(name: str) -> Prior:
    return next(p for p in PRIORS if p.name == name)


def _steady_temperature(heat: Any, params: BearingParameters, cfg: ThermalConfig, inner_ring_speed: float, axial_load: float) -> float:
    """The lubricant's steady temperature with other thermal data, the engine's heat taken
    linear in the lubricant's temperature through the two cached solutions nearest to it
    (extrapolated beyond them), degC."""
    from scipy.optimize import brentq

    known = sorted(heat.cache)
    net = build_network(params, cfg, inner_ring_speed, axial_load, lubricant_temperature=known[-1])
    q = {t: net.heat_vector(node_heat(heat.cache[t][1])) for t in known}
    lub = list(net.names).index("lubricant")

    def g(t: float) -> float:
        a, b = sorted(known, key=lambda k: abs(k - t))[:2]
        w = (t - a) / (b - a) if b != a else 0.0
        return float(net.steady(np.maximum(q[a] + w * (q[b] - q[a]), 0.0))[lub]) - t

    hot = MAX_STEADY_LUBRICANT_C
    if g(hot) > 0.0:
        raise ThermalRunawayError(
            f"no steady lubricant temperature below {hot:g} degC at {rad_s_to_rpm(inner_ring_speed):.0f} rpm / {axial_load:g} N "
            f"with the frame conductance {cfg.frame_conductance:g} W/K: the bearing's heat outgrows what the housing carries"
        )
    return float(brentq(g, cfg.ambient, hot, xtol=0.01))


def draws(count: int = DRAWS, seed: int = DRAW_SEED) -> list[dict[str, float]]:
    """The Latin-hypercube draws of the inputs over their uniform priors (:data:`PRIORS`)."""
    from scipy.stats import qmc

    unit = qmc.LatinHypercube(d=len(PRIORS), seed=seed).random(count)
    return [{p.name: p.low + u * (p.high - p.low) for p, u in zip(PRIORS, row)} for row in unit]


def shift(effects: Mapping[str, Sequence[float]], draw: Mapping[str, float]) -> float:
    """The slip change (pp) of a draw at a point whose effects are ``effects`` (each input's
    piecewise-linear effect, summed)."""
    total = 0.0
    for p in PRIORS:
        xs, ys, v = p.evaluated, effects[p.name], draw[p.name]
        if v > xs[-1]:  # linear beyond the last evaluated value (the exponent's 0.25)
            total += float(ys[-1] + (ys[-1] - ys[-2]) * (v - xs[-1]) / (xs[-1] - xs[-2]))
        else:
            total += float(np.interp(v, xs, ys))
    return total


@dataclass(frozen=True)
class ModelForm:
    """The calibration's side of the spread (stored in its ``uncertainty.model_form`` block).

    Attributes:
        row_effects: prior name -> per row, the slip change at each evaluated value, pp.
        absorption: (J^T J)^-1 J^T of the fit's log-parameters, p x n.
        names: the fitted parameters; values: their calibrated values.
    """

    row_effects: dict[str, tuple[tuple[float, ...], ...]]
    absorption: tuple[tuple[float, ...], ...]
    names: tuple[str, ...]
    values: tuple[float, ...]

    def as_dict(self) -> dict[str, Any]:
        """For the calibration file (plain floats)."""
        r = lambda x: float(f"{x:.6g}")
        return {
            "priors": [{"name": p.name, "unit": p.unit, "range": [p.low, p.high], "evaluated": list(p.evaluated), "source": p.source} for p in PRIORS],
            "draws": DRAWS,
            "seed": DRAW_SEED,
            "row_effects_pp": {k: [[r(c) for c in row] for row in v] for k, v in self.row_effects.items()},
            "absorption": [[r(c) for c in row] for row in self.absorption],
            "names": list(self.names),
            "values": [r(v) for v in self.values],
        }

    @classmethod
    def from_dict(cls, doc: Mapping[str, Any]) -> ModelForm:
        """Back from :meth:`as_dict`."""
        return cls(
            row_effects={k: tuple(tuple(float(c) for c in row) for row in v) for k, v in doc["row_effects_pp"].items()},
            absorption=tuple(tuple(float(c) for c in row) for row in doc["absorption"]),
            names=tuple(doc["names"]),
            values=tuple(float(v) for v in doc["values"]),
        )


def model_form(params: BearingParameters, cfg: ThermalConfig, rows: Sequence[tuple[float, float]], names: Sequence[str], jacobian: np.ndarray) -> ModelForm:
    """The calibration's side: each input's effect at the rows (inner-ring speed rad/s, load N)
    and the fit's absorption matrix from its Jacobian (n x p, d slip / d log-parameter of
    ``names``)."""
    from bearing_rig_sim.studies.calibration import current_value

    per_row = [point_effects(params, cfg, w, f) for w, f in rows]
    j = np.asarray(jacobian, dtype=float)
    absorption = np.linalg.pinv(j.T @ j) @ j.T
    return ModelForm(
        {p.name: tuple(e.effects[p.name] for e in per_row) for p in PRIORS},
        tuple(tuple(float(c) for c in row) for row in absorption),
        tuple(names),
        tuple(current_value(params, n) for n in names),
    )


def spread(point: Mapping[str, Sequence[float]], form: ModelForm, g_theta: Sequence[float] | np.ndarray, count: int = DRAWS) -> tuple[float, float, int]:
    """The 2.5 and 97.5 % points of the prediction's shift over the kept draws, pp, and how many
    were kept (module doc: each draw refitted linearly, refuted draws discarded)."""
    from bearing_rig_sim.studies.calibration import PHYSICAL_RANGES

    a = np.array(form.absorption)
    g = np.asarray(g_theta, dtype=float)
    shifts = []
    n_rows = a.shape[1]
    for d in draws(count):
        r = np.array([shift({k: v[i] for k, v in form.row_effects.items()}, d) for i in range(n_rows)])
        dtheta = -a @ r
        refitted = {n: v * math.exp(t) for n, v, t in zip(form.names, form.values, dtheta)}
        if any(not PHYSICAL_RANGES[n].low <= v <= PHYSICAL_RANGES[n].high for n, v in refitted.items() if n in PHYSICAL_RANGES):
            continue
        shifts.append(shift(point, d) + float(g @ dtheta))
    if not shifts:
        return 0.0, 0.0, 0
    lo, hi = np.percentile(shifts, [2.5, 97.5])
    return float(lo), float(hi), len(shifts)


def widen(slip_pct: float, parametric_sd: float, low_shift: float, high_shift: float) -> tuple[float, float]:
    """The interval: on each side, the parametric 95 % half-width (1.96 sd) and the model-form
    shift to that side, in quadrature (independent sources)."""
    hw = Z95 * parametric_sd
    return slip_pct - math.hypot(hw, max(0.0, -low_shift)), slip_pct + math.hypot(hw, max(0.0, high_shift))
