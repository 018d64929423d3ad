"""The thermal network coupled to the dynamics: lubricant properties follow the lubricant node.

* :func:`params_at_temperature`: a bearing's parameters with its lubricant at another
  temperature: base-oil viscosity and density (Walther / ASTM D341 through the lubricant file's
  two viscosities), the grease's consistency and yield stress
  (:meth:`~bearing_rig_sim.dynamics.lubrication.Lubricant.at_temperature`) and, rebuilt, the
  rheology traction table.
* :class:`ThermalCoupling`: a running engine heats the network chunk by chunk; every
  ``interval`` seconds the network takes the engine's dissipation (term by term) and, when the
  lubricant has moved by ``retune_k`` (default: every step), the engine's lubricant follows the
  lubricant node: its temperature-dependent resistances (grease drag and land through the
  grease's yield stress and consistency, the EHL rolling force through the base oil's viscosity)
  are set to the new temperature, and so is its rheology traction table, blended linearly
  between tables at the two neighbouring temperatures of a grid :data:`TABLE_STEP_K` apart
  (:class:`TractionTableGrid`). A table costs about half a second to build, too long for a real
  time chunk: the grid's tables are built a slice (one contact, load and entrainment speed, a
  millisecond or two) every :data:`TABLE_SLICE_S` of simulated time, ahead of the lubricant's
  temperature, so the session keeps real time and runs the same on any machine. Until the
  table on the far side of the lubricant's temperature is built the nearest built one is used.
* :func:`thermal_steady_state`: the steady operating point where the heat the engine dissipates
  at the lubricant's temperature is what the network carries away at that temperature
  (secant iteration on the lubricant temperature).
* :func:`warm_up`: the temperatures over time from ambient at constant speed and load, the
  mechanics quasi-static (they settle in milliseconds, the network in minutes).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numba import njit

from bearing_rig_sim.dynamics import kernels as kn
from bearing_rig_sim.dynamics.engine import BearingDynamics
from bearing_rig_sim.dynamics.lubrication import film_thickness
from bearing_rig_sim.dynamics.parameters import BearingParameters, derive, table_contact_angles, traction_table
from bearing_rig_sim.dynamics.quasi_static import thermal_clearance_change
from bearing_rig_sim.dynamics.steady import SteadyState, SteadySolver
from bearing_rig_sim.dynamics.step_limit import StepLimitError
from bearing_rig_sim.dynamics.traction import (
    HEADER,
    N_LOAD,
    N_SPEED,
    N_SRR,
    SRR_REF,
    ellipse_traction,
    node_spin_and_heathcote,
    pack_table,
    srr_axis,
    table_axes,
)
from bearing_rig_sim.thermal.bearing import HeatLedger, HeatSources, ThermalConfig, build_network, heat_sources, node_heat
from bearing_rig_sim.thermal.network import ThermalNetwork

TEMPERATURE_DEPENDENT = (
    kn.P_DRAG_LIN,
    kn.P_DRAG_QUAD,
    kn.P_LAND_VISC,
    kn.P_LAND_COULOMB,
    kn.P_DRAG_YIELD,
    kn.P_DRAG_POW,
    kn.P_LAND_POW,
    kn.P_FR_IN,
    kn.P_FR_OUT,
)
"""Entries of the kernel parameter vector that depend on the lubricant temperature (the traction
table aside)."""


def params_at_temperature(params: BearingParameters, temperature_c: float, **changes: object) -> BearingParameters:
    """``params`` with the lubricant at ``temperature_c`` (degC); the bearing file's temperature
    is the reference of the grease's rheology (the calibration's values hold there). ``changes``
    are other fields to set in the same copy."""
    lub = params.lubricant
    if lub is None:
        return params.replace(**changes) if changes else params
    warm = lub.at_temperature(temperature_c, params.lubricant_temperature)
    return params.replace(
        lubricant=warm,
        lubricant_temperature=float(temperature_c),
        oil_viscosity=warm.dynamic_viscosity(temperature_c),
        oil_density=warm.density(temperature_c),
        **changes,
    )


def resistance_vector(params: BearingParameters, temperature_c: float) -> np.ndarray:
    """The kernel parameter vector's temperature-dependent entries at ``temperature_c`` (all
    :data:`kn.P_SIZE` entries; use those of :data:`TEMPERATURE_DEPENDENT`), without building a
    traction table (under a millisecond)."""
    vector, _ = derive(params_at_temperature(params, temperature_c, friction_model="ehl_traction"))  # one copy: the running retune's cost
    return vector[: kn.P_SIZE]


TABLE_STEP_K = 5.0
"""Spacing of the temperature grid of the coupled engine's traction tables, K (grid points at
whole multiples). The table's values move smoothly with the base oil's viscosity: between two
grid points the engine's table is their linear blend."""
TABLE_SLICE_S = 0.1
"""Simulated time between two slices of a table under construction, s: a slice
(:data:`SRR_PER_SLICE` ellipse integrations) costs one to two milliseconds, about five 1 ms
chunks of the reduced engine, so a table (2 x 12 x 14 x 4 slices) takes about 134 s of
simulated time and its building adds about 5 % to the engine's time while it lasts (a slice
every 0.01 s added 40-58 %: ``bearing-rig bench thermal``, ``table_build_pct``). The lubricant
moves 5 K (:data:`TABLE_STEP_K`) in a few minutes once the bearing's own bodies have warmed
(the housing's time constant is about 20 minutes, docs/thermal.md), so the grid keeps up; in
the first seconds of a warm-up the nearest built table stands in."""


SRR_PER_SLICE = 25
"""SRR nodes per slice of a table under construction (a quarter of a speed's row)."""


class _Slice(NamedTuple):
    contact: int
    load_index: int
    speed_index: int
    srr_start: int


class TableBuild:
    """One traction table at ``temperature_c`` (degC), built a slice at a time: the same table
    as :func:`bearing_rig_sim.dynamics.parameters.traction_table` of the bearing with its
    lubricant at that temperature (:func:`params_at_temperature`), node for node."""

    def __init__(self, params: BearingParameters, temperature_c: float) -> None:
        warm = params_at_temperature(params, temperature_c)
        lub = warm.lubricant
        if lub is None:
            raise ValueError(f"{params.source}: no lubricant file, no traction table")
        self.temperature = float(temperature_c)
        self._contacts = warm.contact_kinematics()
        self._lub = lub
        self._ball_diameter, self._pitch_diameter = warm.ball_diameter, warm.pitch_diameter
        self._angles = table_contact_angles(warm)  # computed once per bearing (the start-up's table)
        self._srrs = srr_axis()
        self._lu, self._lq = table_axes()
        self._eta0 = lub.dynamic_viscosity(self.temperature)
        self._z = lub.roelands_index(self.temperature)
        self._mu = np.zeros((2, N_LOAD, N_SPEED, N_SRR))
        self._pw = np.zeros_like(self._mu)
        self._todo = [_Slice(c, iq, iu, k) for c in range(2) for iq in range(N_LOAD) for iu in range(N_SPEED) for k in range(0, N_SRR, SRR_PER_SLICE)]
        self._next = 0
        self._contact_at_load: dict[tuple[int, int], tuple[float, float, float, float]] = {}
        self._film = 0.0

    @property
    def done(self) -> bool:
        """Whether every slice is built."""
        return self._next >= len(self._todo)

    def step(self) -> None:
        """Build the next slice (one contact, load and entrainment speed; up to
        :data:`SRR_PER_SLICE` SRR nodes)."""
        if self.done:
            return
        c, iq, iu, k0 = self._todo[self._next]
        self._next += 1
        contact, lub = self._contacts[c], self._lub
        q = float(np.exp(self._lq)[iq])
        got = self._contact_at_load.get((c, iq))
        if got is None:
            a, b = contact.hertz.semi_axes(q)
            got = self._contact_at_load[(c, iq)] = (a, b, contact.hertz.max_pressure(q), q)
        a, b, ph, q = got
        spin, kh = node_spin_and_heathcote(contact, self._angles, iq, iu, self._ball_diameter, self._pitch_diameter)
        u = float(np.exp(self._lu)[iu])
        if k0 == 0:
            film = film_thickness(lub, self.temperature, contact.hertz.reduced_modulus, contact.rx, contact.hertz.ellipticity, b, ph, u, q)
            self._film = max(film.central, 1e-9)
        h = self._film
        for k in range(k0, min(k0 + SRR_PER_SLICE, N_SRR)):
            srr = self._srrs[k]
            self._mu[c, iq, iu, k], self._pw[c, iq, iu, k] = ellipse_traction(
                ph, a, b, h, self._eta0, self._z, lub.eyring_stress, lub.limiting_shear_coefficient, lub.shear_modulus, u, srr, spin, kh
            )

    def table(self) -> np.ndarray:
        """The finished table (layout of :data:`bearing_rig_sim.dynamics.traction.HEADER`)."""
        if not self.done:
            raise RuntimeError(f"traction table at {self.temperature:g} degC: {len(self._todo) - self._next} slices still to build")
        return pack_table(self._mu, self._pw)


class TractionTableGrid:
    """The bearing's traction tables at whole multiples of ``step_k`` degC, built on demand a
    slice at a time (:class:`TableBuild`), and their blend at a temperature.

    Args:
        params: the bearing (its lubricant file's temperature laws; its own temperature is the
            reference of the grease's rheology).
        step_k: grid spacing, K (> 0).
    """

    def __init__(self, params: BearingParameters, step_k: float = TABLE_STEP_K) -> None:
        if not math.isfinite(step_k) or step_k <= 0.0:
            raise ValueError(f"step_k must be > 0 K, got {step_k!r}")
        self.params = params
        self.step_k = float(step_k)
        self.tables: dict[int, np.ndarray] = {}
        """Built tables by grid index (temperature = index x step_k)."""
        self.queue: list[int] = []
        """Grid points waiting to be built, first first."""
        self._build: TableBuild | None = None
        self._index = 0

    def temperature(self, index: int) -> float:
        """A grid point's temperature, degC."""
        return index * self.step_k

    def build_now(self, index: int) -> None:
        """Build a grid point's table at once (start-up; about half a second)."""
        if index not in self.tables:
            self.tables[index] = traction_table(params_at_temperature(self.params, self.temperature(index)))

    def want(self, *indices: int) -> None:
        """Build these grid points next, in this order (those not built yet); the table under
        construction is finished first, grid points queued before and not named are dropped."""
        building = self._index if self._build is not None else None
        self.queue = [i for i in dict.fromkeys(indices) if i not in self.tables and i != building]

    def work(self) -> bool:
        """Build one slice of the table under construction (starting the next queued one);
        returns True when a table was finished."""
        if self._build is None:
            if not self.queue:
                return False
            self._index = self.queue.pop(0)
            self._build = TableBuild(self.params, self.temperature(self._index))
        self._build.step()
        if self._build.done:
            self.tables[self._index] = self._build.table()
            self._build = None
            return True
        return False

    @property
    def busy(self) -> bool:
        """Whether a table is being built or waits to be."""
        return self._build is not None or bool(self.queue)

    def bracket(self, temperature_c: float) -> tuple[int, int, float]:
        """The grid points below and above ``temperature_c`` and its weight on the upper one."""
        x = temperature_c / self.step_k
        lo = math.floor(x)
        return lo, lo + 1, x - lo

    def blend(self, temperature_c: float) -> tuple[np.ndarray, float] | None:
        """The table at ``temperature_c``: the linear blend of the two neighbouring grid tables
        when both are built, else the nearer built one of them (None when neither is); with the
        temperature it stands for, degC."""
        some = next(iter(self.tables.values()), None)
        if some is None:
            return None
        out = np.empty_like(some)
        stands_for = self.blend_into(out, temperature_c)
        return None if stands_for is None else (out, stands_for)

    def blend_into(self, out: np.ndarray, temperature_c: float) -> float | None:
        """:meth:`blend` written into ``out`` (a table's size: the engine's parameter vector's
        table, in place, without a copy); returns the temperature it stands for (None, ``out``
        untouched, when neither neighbour is built)."""
        lo, hi, w = self.bracket(temperature_c)
        a, b = self.tables.get(lo), self.tables.get(hi)
        if a is not None and b is not None:
            out[:HEADER] = a[:HEADER]
            body = out[HEADER:]
            np.subtract(b[HEADER:], a[HEADER:], out=body)
            body *= w
            body += a[HEADER:]  # a + w (b - a), as one expression would round it
            return float(temperature_c)
        if a is not None:
            out[:] = a
            return self.temperature(lo)
        if b is not None:
            out[:] = b
            return self.temperature(hi)
        return None


@njit(cache=True)
def _largest_step(table: np.ndarray) -> float:
    """max |mu[k+1] - mu[k]| between neighbouring SRR nodes of a table (layout of
    :data:`~bearing_rig_sim.dynamics.traction.HEADER`: (mu, power) pairs, SRR fastest), in one
    pass: ``np.max(np.abs(np.diff(mu_nodes(table, 0), axis=1)))`` without its copies (a fifth
    of the running retune's time)."""
    ns = int(table[0])
    rows = 2 * int(table[1]) * int(table[2])
    largest = 0.0
    for row in range(rows):
        start = HEADER + 2 * ns * row
        for k in range(ns - 1):
            d = abs(table[start + 2 * k + 2] - table[start + 2 * k])
            if d > largest:
                largest = d
    return largest


def steepest_traction_slope(table: np.ndarray) -> float:
    """The table's steepest d mu/d SRR (the kernel's ``P_MU_SLOPE_MAX``, as
    :func:`bearing_rig_sim.dynamics.parameters.derive` sets it)."""
    n_srr, xi_max = int(table[0]), table[3]
    return _largest_step(table) / (2.0 * xi_max / (n_srr - 1)) / SRR_REF


class ThermalCoupling:
    """A running engine and the bearing's network, coupled at chunk level.

    Args:
        engine: the dynamics engine (its parameters' lubricant temperature is the reference).
        config: the bearing file's thermal data.
        interval: how often (s of simulated time) the network takes the engine's heat (> 0);
            the network's shortest time constant is seconds, so 0.1 s resolves it.
        retune_k: lubricant temperature change (K) after which the engine's lubricant is set to
            the new temperature (0: at every network step).
        initial: start temperature of every node, degC (default: ambient).
        feedback: set the engine's lubricant to the lubricant node's temperature (both ways);
            False leaves the engine as its parameters say and only tracks the temperatures (one
            way).
        tables: with ``feedback``, let the rheology traction table follow the temperature too
            (:class:`TractionTableGrid`; the tables bracketing the start temperature are built
            here, about a second); False keeps the bearing file's table (the resistances still
            follow).
        grid: a traction grid of this bearing built beforehand (its tables around the start
            temperature are built here when missing); default a new one.
        expansion: at every network step set the engine's clearance to the one it had here plus
            the rings' and balls' thermal change since the network's start temperatures
            (:func:`~bearing_rig_sim.dynamics.quasi_static.thermal_clearance_change`, the nodes
            ``inner_ring``, ``outer_ring``, ``balls``; :meth:`BearingDynamics.set_clearance`).
            Off by default: the clearance then stays the engine's.
    """

    def __init__(
        self,
        engine: BearingDynamics,
        config: ThermalConfig,
        *,
        interval: float = 0.1,
        retune_k: float = 0.0,
        initial: float | None = None,
        feedback: bool = True,
        tables: bool = True,
        grid: TractionTableGrid | None = None,
        expansion: bool = False,
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
        self.expansion = bool(expansion)
        self._fitted = (engine.clearance, *(self.network.temperature(n) for n in ("inner_ring", "outer_ring", "balls")))
        self._pending = 0.0
        self._dissipated = (engine.dissipated, engine.damping_dissipated)
        self.applied_temperature = self.params.lubricant_temperature
        """The lubricant temperature the engine's resistances are set to, degC."""
        self.sources = HeatSources(0.0, 0.0, 0.0, 0.0, 0.0)
        """The latest interval's mean heat, split, W."""
        self.table_temperature = self.params.lubricant_temperature
        """The temperature the engine's traction table stands for, degC."""
        self.grid: TractionTableGrid | None = None
        """The traction tables on their temperature grid (None: the table stays the file's)."""
        self._slice_pending = 0.0
        self._previous_temperature = -math.inf
        if self.feedback and tables and self.params.lubricant is not None and self.params.friction_model == "rheology":
            self.grid = grid if grid is not None else TractionTableGrid(self.params)
            lo, hi, _ = self.grid.bracket(self.network.temperature("lubricant"))
            self.grid.build_now(lo)
            self.grid.build_now(hi)
        if self.feedback:
            self._retune(self.network.temperature("lubricant"))

    def temperature(self, node: str) -> float:
        """A node's temperature, degC."""
        return self.network.temperature(node)

    def advance(self, h: float) -> bool:
        """Account ``h`` seconds of the engine's running (call after each chunk); returns True
        when the network stepped.

        The network takes the interval's mean dissipation: the heat the engine accumulated step
        by step since the last network step (:attr:`BearingDynamics.dissipated`) over the
        interval's length, split by the proportions of the engine's terms at its last step
        (:func:`heat_sources`). The heat into the network is the dissipated heat exactly; a
        power sampled at the interval's end would lag a run-up by half an interval."""
        self._pending += h
        if self.grid is not None and self.grid.busy:
            self._slice_pending += h
            if self._slice_pending >= TABLE_SLICE_S - 1e-12:
                self._slice_pending = 0.0
                self.grid.work()
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
        heat, damping = engine.dissipated - self._dissipated[0], engine.damping_dissipated - self._dissipated[1]
        self._dissipated = (engine.dissipated, engine.damping_dissipated)
        split = heat_sources(engine) if engine.inner_ring_speed > 0.0 else HeatSources(0.0, 0.0, 0.0, 0.0, 0.0)
        self.sources = split.scaled((heat - damping) / self._pending, damping / self._pending)
        self.network.step(self.network.heat_vector(node_heat(self.sources)), self._pending)
        self._pending = 0.0
        if self.expansion:
            clearance, t_in, t_out, t_balls = self._fitted
            warm = [self.network.temperature(n) - t for n, t in (("inner_ring", t_in), ("outer_ring", t_out), ("balls", t_balls))]
            engine.set_clearance(clearance + thermal_clearance_change(self.params, warm[0], warm[1], warm[2], 0.0))
        t_lub = self.network.temperature("lubricant")
        if self.feedback and abs(t_lub - self.applied_temperature) >= self.retune_k:
            self._retune(t_lub)
        return True

    def retune(self) -> None:
        """Set the engine's lubricant to the lubricant node's temperature now (after the engine
        was re-initialised; with ``feedback`` only)."""
        if self.feedback:
            self._retune(self.network.temperature("lubricant"))

    def rebind(self, engine: BearingDynamics) -> None:
        """Go on with another engine (other parameters of the same bearing: an online
        re-calibration); its lubricant is set to the network's temperature. The traction grid
        is rebuilt for the new parameters when they change the film's rheology."""
        self.engine = engine
        self._dissipated = (engine.dissipated, engine.damping_dissipated)
        if engine.params != self.params:
            self.params = engine.params
            if self.grid is not None:
                self.grid = TractionTableGrid(self.params)
                lo, hi, _ = self.grid.bracket(self.network.temperature("lubricant"))
                self.grid.build_now(lo)
                self.grid.build_now(hi)
        self.retune()

    def _retune(self, temperature_c: float) -> None:
        v = resistance_vector(self.params, temperature_c)
        vector = self.engine.vector
        for i in TEMPERATURE_DEPENDENT:
            vector[i] = v[i]
        self.applied_temperature = float(temperature_c)
        grid = self.grid
        if grid is None:
            return
        lo, hi, w = grid.bracket(temperature_c)
        # the two neighbours (the nearer first), then the next one the way the lubricant goes
        ahead = (hi + 1,) if temperature_c >= self._previous_temperature else (lo - 1,)
        grid.want(*((hi, lo) if w >= 0.5 else (lo, hi)), *ahead)
        self._previous_temperature = float(temperature_c)
        base = int(vector[kn.P_TABLE])
        table = vector[base:]  # the table ends the vector (parameters.derive)
        stands_for = grid.blend_into(table, temperature_c)
        if stands_for is not None:
            self.table_temperature = stands_for
            vector[kn.P_MU_SLOPE_MAX] = steepest_traction_slope(table)


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

    point: SteadyState
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


class HeatAtTemperature:
    """The engine's steady heat at a lubricant temperature, cached (each costs a traction table
    and a steady solution: about a second or two). Under a radial load (or a moment) the steady
    state is periodic (:meth:`SteadySolver.periodic`): its heat, term by term, is each term's
    energy over a window of whole ball-pass periods, as long as the periodic state's averaging
    window and following it, over the window's length (:class:`HeatLedger`).

    Args:
        params: the bearing (its lubricant at the file's temperature).
        inner_ring_speed: rad/s (> 0).
        axial_load: N.
        radial_load: N (0: the axial steady state).
        moment: (M_x, M_y) N m with the tilts free, or None.

    Calling it with a lubricant temperature (degC) returns the engine's steady point there and
    its heat, term by term (W).
    """

    def __init__(
        self, params: BearingParameters, inner_ring_speed: float, axial_load: float, radial_load: float = 0.0, moment: tuple[float, float] | None = None
    ) -> None:
        self.params, self.speed, self.load = params, inner_ring_speed, axial_load
        self.radial, self.moment = radial_load, moment
        self.cache: dict[float, tuple[SteadyState, HeatSources]] = {}

    def __call__(self, temperature_c: float) -> tuple[SteadyState, HeatSources]:
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
            if self.radial > 0.0 or self.moment is not None:
                point = solver.periodic(self.speed, self.load, self.radial, moment=self.moment)
                window = solver.last_average
                assert window is not None and window.duration > 0.0
                # the heat split: each term's energy over the next window of as many whole
                # ball-pass periods, stepped and summed step by step
                ledger = HeatLedger(solver.engine)
                ledger.advance(window.duration)
                sources = ledger.mean()
            else:
                point = solver.solve(self.speed, self.load)
                sources = heat_sources(solver.engine)
            got = self.cache[key] = (point, sources)
        return got


def _steady_temperatures(
    params: BearingParameters, config: ThermalConfig, speed: float, load: float, t_lub: float, sources: HeatSources
) -> tuple[np.ndarray, ThermalNetwork]:
    net = build_network(params, config, speed, load, lubricant_temperature=t_lub)
    return net.steady(node_heat(sources)), net


def thermal_steady_state(
    params: BearingParameters,
    config: ThermalConfig,
    inner_ring_speed: float,
    axial_load: float,
    *,
    tolerance_k: float = 0.2,
    max_iter: int = 10,
    radial_load: float = 0.0,
    moment: tuple[float, float] | None = None,
    heat: HeatAtTemperature | None = None,
    start_c: float | None = None,
) -> ThermalSteadyState:
    """The steady state where the dissipation at the lubricant temperature T heats the network to
    T: the root of g(T) = T_lub,ss(heat(T)) - T by secant steps from the bearing file's
    temperature (g falls with T: warmer lubricant, less heat). With ``radial_load`` (N) or
    ``moment`` (N m, tilts free) the engine's steady state is the periodic one under the
    combined load; the network's conductances stay those of the axial load. ``heat``: the
    engine's heat at this point, cached (shared by steady states of other thermal data);
    ``start_c``: the secant's first temperature (default the bearing file's), degC."""
    heat = heat if heat is not None else HeatAtTemperature(params, inner_ring_speed, axial_load, radial_load, moment)
    lub_i = 4  # "lubricant" in NODES

    def g(t: float) -> float:
        _, src = heat(t)
        temps, _ = _steady_temperatures(params, config, inner_ring_speed, axial_load, t, src)
        return float(temps[lub_i]) - t

    lo, hi = config.ambient - 5.0, MAX_LUBRICANT_C

    def clamp(t: float) -> float:
        return min(max(t, lo), hi)

    t0 = clamp(params.lubricant_temperature if start_c is None else start_c)
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


def warm_up(
    params: BearingParameters,
    config: ThermalConfig,
    inner_ring_speed: float,
    axial_load: float,
    duration: float,
    *,
    step: float = 1.0,
    grid: int = 4,
    radial_load: float = 0.0,
    moment: tuple[float, float] | None = None,
) -> list[dict[str, float]]:
    """Temperatures and torque over ``duration`` seconds from ambient, at constant speed (rad/s)
    and axial load (N): the engine's steady heat at ``grid`` lubricant temperatures from
    ambient to the coupled steady one, interpolated in the lubricant's temperature as the
    network warms (exact exponential steps of ``step`` s). With ``radial_load`` (N) or
    ``moment`` (N m) the heat is the periodic state's under the combined load
    (:func:`thermal_steady_state`).

    Returns:
        one row per step: ``time_s``, each node's ``<node>_c``, ``friction_torque_nm``,
        ``power_loss_w``.
    """
    steady = thermal_steady_state(params, config, inner_ring_speed, axial_load, radial_load=radial_load, moment=moment)
    heat = HeatAtTemperature(params, inner_ring_speed, axial_load, radial_load, moment)
    t_hi = max(steady.temperatures["lubricant"], config.ambient + 0.5)
    temps = list(np.linspace(config.ambient, t_hi, grid))
    table = [heat(t) for t in temps]
    # fluid properties of the convection at the steady temperature, where the curve spends most time
    net = build_network(params, config, inner_ring_speed, axial_load, lubricant_temperature=t_hi, initial=config.ambient)
    names = list(net.names)
    q_grid = np.array([net.heat_vector(node_heat(src)) for _, src in table])
    torque_grid = np.array([pt.friction_torque for pt, _ in table])
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
