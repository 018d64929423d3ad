"""The thermal network coupled to the dynamics: lubricant properties follow the lubricant node.

* :func:`params_at_temperature`: a bearing's parameters with its lubricant at another
  temperature: base-oil viscosity and density (Walther / ASTM D341 through the lubricant file's
  two viscosities), the grease's consistency and yield stress
  (:meth:`~bearing_rig_sim.dynamics.lubrication.Lubricant.at_temperature`) and, rebuilt, the
  rheology traction table.
* :class:`ThermalCoupling`: a running engine heats the network chunk by chunk; every
  ``interval`` seconds the network takes the engine's dissipation (term by term) and, when the
  lubricant has moved by ``retune_k``, the engine's temperature-dependent resistances (drag,
  land, EHL rolling force) are set to the new temperature. The traction table keeps the
  bearing file's temperature while running (rebuilding it takes about a second; the steady
  solutions below rebuild it).
* :func:`thermal_steady_state`: the steady operating point where the heat the engine dissipates
  at the lubricant's temperature is what the network carries away at that temperature
  (secant iteration on the lubricant temperature).
* :func:`warm_up`: the temperatures over time from ambient at constant speed and load, the
  mechanics quasi-static (they settle in milliseconds, the network in minutes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.engine import BearingDynamics
from bearing_rig_sim.dynamics.parameters import BearingParameters, derive
from bearing_rig_sim.dynamics.steady import SteadyPoint, SteadySolver
from bearing_rig_sim.dynamics.step_limit import StepLimitError
from bearing_rig_sim.thermal.bearing import HeatSources, ThermalConfig, build_network, heat_sources, node_heat
from bearing_rig_sim.thermal.network import ThermalNetwork

TEMPERATURE_DEPENDENT = (
    kn.P_DRAG_LIN, kn.P_DRAG_QUAD, kn.P_LAND_VISC, kn.P_LAND_COULOMB, kn.P_DRAG_YIELD, kn.P_DRAG_POW, kn.P_LAND_POW, kn.P_FR_IN, kn.P_FR_OUT,
)
"""Entries of the kernel parameter vector that depend on the lubricant temperature (the traction
table aside)."""


def params_at_temperature(params: BearingParameters, temperature_c: float) -> BearingParameters:
    """``params`` with the lubricant at ``temperature_c`` (degC); the bearing file's temperature
    is the reference of the grease's rheology (the calibration's values hold there)."""
    lub = params.lubricant
    if lub is None:
        return params
    warm = lub.at_temperature(temperature_c, params.lubricant_temperature)
    return params.replace(
        lubricant=warm, lubricant_temperature=float(temperature_c), oil_viscosity=warm.dynamic_viscosity(temperature_c), oil_density=warm.density(temperature_c)
    )


def resistance_vector(params: BearingParameters, temperature_c: float) -> np.ndarray:
    """The kernel parameter vector's temperature-dependent entries at ``temperature_c`` (all
    :data:`kn.P_SIZE` entries; use those of :data:`TEMPERATURE_DEPENDENT`), without building a
    traction table (under a millisecond)."""
    warm = params_at_temperature(params, temperature_c)
    vector, _ = derive(warm.replace(friction_model="ehl_traction"))
    return vector[: kn.P_SIZE]


class ThermalCoupling:
    """A running engine and the bearing's network, coupled at chunk level.

    Args:
        engine: the dynamics engine (its parameters' lubricant temperature is the reference).
        config: the bearing file's thermal data.
        interval: how often (s of simulated time) the network takes the engine's heat (> 0);
            the network's shortest time constant is seconds, so 0.1 s resolves it.
        retune_k: lubricant temperature change (K) after which the engine's resistances are
            set to the new temperature.
        initial: start temperature of every node, degC (default: ambient).
        feedback: set the engine's resistances to the lubricant's temperature (both ways); False
            leaves the engine as its parameters say and only tracks the temperatures (one way).
    """

    def __init__(
        self, engine: BearingDynamics, config: ThermalConfig, *, interval: float = 0.1, retune_k: float = 0.5, initial: float | None = None, feedback: bool = True
    ) -> None:
        if not math.isfinite(interval) or interval <= 0.0:
            raise ValueError(f"interval must be > 0 s, got {interval!r}")
        self.engine = engine
        self.config = config
        self.interval = float(interval)
        self.retune_k = float(retune_k)
        self.feedback = bool(feedback)
        self.params = engine.params
        self._operating = (max(engine.inner_ring_speed, 1.0), engine.axial_load)
        self.network = build_network(self.params, config, *self._operating, initial=initial)
        self._pending = 0.0
        self.applied_temperature = self.params.lubricant_temperature
        """The lubricant temperature the engine's resistances are set to, degC."""
        self.sources = HeatSources(0.0, 0.0, 0.0, 0.0, 0.0)
        """The latest heat split, W."""
        if self.feedback:
            self._retune(self.network.temperature("lubricant"))

    def temperature(self, node: str) -> float:
        """A node's temperature, degC."""
        return self.network.temperature(node)

    def advance(self, h: float) -> bool:
        """Account ``h`` seconds of the engine's running (call after each chunk); returns True
        when the network stepped."""
        self._pending += h
        if self._pending < self.interval - 1e-12:
            return False
        engine = self.engine
        speed, load = max(engine.inner_ring_speed, 1.0), engine.axial_load
        old_speed, old_load = self._operating
        if abs(speed - old_speed) > 0.05 * old_speed or abs(load - old_load) > 0.05 * old_load:
            rebuilt = build_network(self.params, self.config, speed, load, lubricant_temperature=self.applied_temperature)
            rebuilt.temperatures = self.network.temperatures.copy()
            rebuilt.initial_temperatures = self.network.initial_temperatures.copy()
            rebuilt.heat_in, rebuilt.heat_out, rebuilt.time = self.network.heat_in, self.network.heat_out, self.network.time
            self.network = rebuilt
            self._operating = (speed, load)
        self.sources = heat_sources(engine) if engine.inner_ring_speed > 0.0 else HeatSources(0.0, 0.0, 0.0, 0.0, 0.0)
        self.network.step(self.network.heat_vector(node_heat(self.sources)), self._pending)
        self._pending = 0.0
        t_lub = self.network.temperature("lubricant")
        if self.feedback and abs(t_lub - self.applied_temperature) >= self.retune_k:
            self._retune(t_lub)
        return True

    def _retune(self, temperature_c: float) -> None:
        v = resistance_vector(self.params, temperature_c)
        for i in TEMPERATURE_DEPENDENT:
            self.engine.vector[i] = v[i]
        self.applied_temperature = float(temperature_c)


@dataclass(frozen=True)
class ThermalSteadyState:
    """The coupled steady state at one operating point.

    Attributes:
        point: the engine's steady state at the lubricant's steady temperature.
        sources: its heat, term by term, W.
        temperatures: every node's steady temperature, degC.
        iterations: engine steady solutions used.
        time_constants: the network's time constants there, s (longest first).
        residual_k: the network's steady lubricant temperature less the one the engine ran at,
            K (within the tolerance when converged).
    """

    point: SteadyPoint
    sources: HeatSources
    temperatures: dict[str, float]
    iterations: int
    time_constants: tuple[float, ...] = field(default=())
    residual_k: float = 0.0


WARM_UP_SUBSTEP_S = 0.5
"""Longest step of :func:`warm_up`'s integration, s (below the bearing bodies' time constants)."""
MAX_STEP_K = 40.0
"""Largest change of the lubricant temperature per secant step of :func:`thermal_steady_state`, K."""
MAX_LUBRICANT_C = 200.0
"""Highest lubricant temperature the steady search tries, degC (the lubricant files' range)."""


class _HeatAtTemperature:
    """The engine's steady heat at a lubricant temperature, cached (each costs a traction table
    and a steady solution: about a second or two)."""

    def __init__(self, params: BearingParameters, inner_ring_speed: float, axial_load: float) -> None:
        self.params, self.speed, self.load = params, inner_ring_speed, axial_load
        self.cache: dict[float, tuple[SteadyPoint, HeatSources]] = {}

    def __call__(self, temperature_c: float) -> tuple[SteadyPoint, HeatSources]:
        key = round(float(temperature_c), 3)
        got = self.cache.get(key)
        if got is None:
            warm = params_at_temperature(self.params, key)
            for _ in range(4):
                try:
                    solver = SteadySolver(warm)
                    break
                except StepLimitError:
                    # the lubricant at this temperature lowers the step's stability limit; the
                    # steady solution does not depend on the step (dynamics/steady.py): halve it
                    warm = warm.replace(reduced_time_step=0.5 * warm.reduced_time_step)
            else:
                raise StepLimitError(f"no stable step for {self.params.source} with the lubricant at {key:g} degC")
            point = solver.solve(self.speed, self.load)
            got = self.cache[key] = (point, heat_sources(solver.engine))
        return got


def _steady_temperatures(params: BearingParameters, config: ThermalConfig, speed: float, load: float, t_lub: float, sources: HeatSources) -> tuple[np.ndarray, ThermalNetwork]:
    net = build_network(params, config, speed, load, lubricant_temperature=t_lub)
    return net.steady(node_heat(sources)), net


def thermal_steady_state(params: BearingParameters, config: ThermalConfig, inner_ring_speed: float, axial_load: float, *, tolerance_k: float = 0.2, max_iter: int = 10) -> ThermalSteadyState:
    """The steady state where the dissipation at the lubricant temperature T heats the network to
    T: the root of g(T) = T_lub,ss(heat(T)) - T by secant steps from the bearing file's
    temperature (g falls with T: warmer lubricant, less heat)."""
    heat = _HeatAtTemperature(params, inner_ring_speed, axial_load)
    lub_i = 4  # "lubricant" in NODES

    def g(t: float) -> float:
        _, src = heat(t)
        temps, _ = _steady_temperatures(params, config, inner_ring_speed, axial_load, t, src)
        return float(temps[lub_i]) - t

    lo, hi = config.ambient - 5.0, MAX_LUBRICANT_C

    def clamp(t: float) -> float:
        return min(max(t, lo), hi)

    t0 = clamp(params.lubricant_temperature)
    g0 = g(t0)
    t1 = clamp(t0 + max(min(g0, MAX_STEP_K), -MAX_STEP_K))
    g1 = g(t1)
    it = 2
    while abs(g1) > tolerance_k and it < max_iter:
        slope = (g1 - g0) / (t1 - t0) if t1 != t0 else -1.0
        if not slope < 0.0:
            slope = -1.0
        t0, g0 = t1, g1
        t1 = clamp(t1 + max(min(-g1 / slope, MAX_STEP_K), -MAX_STEP_K))
        g1 = g(t1)
        it += 1
    point, src = heat(t1)
    temps, net = _steady_temperatures(params, config, inner_ring_speed, axial_load, t1, src)
    return ThermalSteadyState(point, src, dict(zip(net.names, map(float, temps))), it, tuple(map(float, net.time_constants())), float(g1))


def warm_up(params: BearingParameters, config: ThermalConfig, inner_ring_speed: float, axial_load: float, duration: float, *, step: float = 1.0, grid: int = 4) -> list[dict[str, float]]:
    """Temperatures and torque over ``duration`` seconds from ambient, at constant speed (rad/s)
    and axial load (N): the engine's steady heat at ``grid`` lubricant temperatures from
    ambient to the coupled steady one, interpolated in the lubricant's temperature as the
    network warms (exact exponential steps of ``step`` s).

    Returns:
        one row per step: ``time_s``, each node's ``<node>_c``, ``friction_torque_nm``,
        ``power_loss_w``.
    """
    steady = thermal_steady_state(params, config, inner_ring_speed, axial_load)
    heat = _HeatAtTemperature(params, inner_ring_speed, axial_load)
    t_hi = max(steady.temperatures["lubricant"], config.ambient + 0.5)
    temps = list(np.linspace(config.ambient, t_hi, grid))
    table = [heat(t) for t in temps]
    # fluid properties of the convection at the steady temperature, where the curve spends most time
    net = build_network(params, config, inner_ring_speed, axial_load, lubricant_temperature=t_hi, initial=config.ambient)
    names = list(net.names)
    q_grid = np.array([net.heat_vector(node_heat(src)) for _, src in table])
    torque_grid = np.array([pt.torque for pt, _ in table])
    rows = []
    t = 0.0
    while t < duration - 1e-9:
        h = min(step, duration - t)
        # the heat follows the lubricant's temperature: sub-steps short beside the bearing's own
        # time constants (seconds), so the piecewise-constant heat does not overshoot
        n_sub = max(1, math.ceil(h / WARM_UP_SUBSTEP_S))
        for _ in range(n_sub):
            t_lub = net.temperature("lubricant")
            q = np.array([np.interp(t_lub, temps, q_grid[:, i]) for i in range(len(names))])
            net.step(q, h / n_sub)
        t += h
        t_lub = net.temperature("lubricant")
        torque = float(np.interp(t_lub, temps, torque_grid))
        row = {"time_s": round(t, 6)}
        row.update({f"{n}_c": round(float(v), 3) for n, v in zip(names, net.temperatures)})
        row["friction_torque_nm"] = round(torque, 6)
        row["power_loss_w"] = round(torque * inner_ring_speed, 4)
        rows.append(row)
    return rows
