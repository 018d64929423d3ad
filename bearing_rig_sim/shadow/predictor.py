"""The dynamics engine driven by the bench's measured inputs, and its slip over any window (no ROS).

:class:`MeasuredDrive` advances one :class:`~bearing_rig_sim.dynamics.BearingDynamics` through the
bench's time: the inner-ring speed follows the straight line between consecutive measured speed
points (constant angular acceleration between them), the axial force is the load cell's, both
given chunk by chunk. Cage speed and slip remain outputs of the integration.

The engine's time is the bench time less an origin (the first speed point), so bench stamps of
about 1.7e9 s lose no precision. The integrals of the cage and inner-ring speeds are kept at each
chunk's end, so the mean speeds over any interval since the oldest one still needed (a slip
window of the bench) follow by linear interpolation of the integrals: the predicted slip of a
window is taken over exactly the window's interval.

The engine (re)starts from its kinematic state at a speed point: at the first one, after a gap
longer than ``max_speed_gap_s`` (a stopped spindle, a sensor gap, a clock jump forward) and after a
clock jump back. :attr:`MeasuredDrive.started_at` says when, so that windows before the slip has
settled are not compared.

With the bearing's thermal network (``thermal=``, the bearing file's ``thermal:`` section) the
engine is coupled to it as the rig session's is, the lubricant following the network's
temperature only with ``lubricant_feedback``
(:class:`~bearing_rig_sim.thermal.coupling.ThermalCoupling`): the network starts at its first
start (at :attr:`MeasuredDrive.thermal_start_c`, the bench's thermocouple when known, else
ambient) and keeps its temperatures across restarts (the bearing does not cool when the engine
restarts). Beside the speeds, the friction torque's integral and the outer ring's temperature
through the thermocouple's lag (noise-free) are kept at each chunk's end, so a window also gets
the twin's mean torque and its thermocouple reading at the window's end.

Units: s, rad/s, rad/s^2, N, N m, degC; slip in percent.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Callable
from dataclasses import dataclass

from bearing_rig_sim.dynamics import MIN_AXIAL_LOAD, BearingDynamics, BearingParameters, Mounting
from bearing_rig_sim.shadow.inputs import SpeedPoint
from bearing_rig_sim.thermal.bearing import ThermalConfig
from bearing_rig_sim.thermal.coupling import ThermalCoupling, TractionTableGrid
from bearing_rig_sim.instruments.first_order import FirstOrderLag, ThermocoupleSettings
from bearing_rig_sim.instruments.registry import InstrumentSet
from bearing_rig_sim.interfaces import OUTER_RING_TEMPERATURE


TORQUE_PERIOD_S = 0.01
"""How often the twin's friction torque is evaluated, s of engine time (the housing torque
meter's 100 Hz)."""


@dataclass(frozen=True)
class Prediction:
    """The engine's mean speeds over one interval.

    Attributes:
        start_time, end_time: the interval, s (bench clock).
        cage_speed: mean cage speed, rad/s.
        inner_ring_speed: mean inner-ring speed, rad/s.
        axial_load: mean axial force applied, N.
        friction_torque: mean friction torque, N m.
        outer_ring_temperature: the outer ring's temperature at ``end_time`` through the
            thermocouple's lag, degC (NaN without the thermal network).
    """

    start_time: float
    end_time: float
    cage_speed: float
    inner_ring_speed: float
    axial_load: float
    friction_torque: float = math.nan
    outer_ring_temperature: float = math.nan


class MeasuredDrive:
    """One engine following the measured inputs (see the module docstring).

    Args:
        params: the bearing with its calibration.
        model: the engine's model.
        chunk: longest engine advance per call, s.
        max_speed_gap: speed points further apart restart the engine, s.
        load_at: the axial force (N) to apply at a bench time (s); NaN: none known yet.
        thermal: the bearing's thermal network data (None: isothermal, at the bearing file's
            lubricant temperature).
        lubricant_feedback: with ``thermal``, the engine's lubricant follows the network's
            lubricant temperature (False: held at the bearing file's, the calibration's).
        mounting: the test bearing's clearance, misalignment and preload (the rig file's
            ``mounting`` section; default none).
        thermocouple: the bench's outer-ring thermocouple, whose lag the predicted reading goes
            through (noise-free); default the shipped rig file's (used with ``thermal`` only).
    """

    def __init__(
        self,
        params: BearingParameters,
        *,
        model: str = "reduced",
        chunk: float = 1e-3,
        max_speed_gap: float = 0.5,
        load_at: Callable[[float], float],
        thermal: ThermalConfig | None = None,
        lubricant_feedback: bool = False,
        mounting: Mounting | None = None,
        thermocouple: ThermocoupleSettings | None = None,
    ) -> None:
        self.engine = BearingDynamics(params, model=model, mounting=mounting)
        self.thermal_config = thermal
        self.coupling: ThermalCoupling | None = None
        """The engine's thermal network (None: isothermal); it starts warming at the first start."""
        self.thermal_start_c: float | None = None
        """Start temperature of the network at the first start, degC (None: ambient)."""
        self._grid: TractionTableGrid | None = None
        if lubricant_feedback and thermal is not None and params.lubricant is not None and params.friction_model == "rheology":
            # the traction tables around ambient now, not in the first pulse's callback
            self._grid = TractionTableGrid(params)
            lo, hi, _ = self._grid.bracket(thermal.ambient)
            self._grid.build_now(lo)
            self._grid.build_now(hi)
        self._thermal_started = False
        if thermal is not None:
            # built now (the node's configure), not in the first pulse's callback
            self.coupling = ThermalCoupling(self.engine, thermal, feedback=lubricant_feedback, grid=self._grid)
        if thermocouple is None and thermal is not None:
            thermocouple = InstrumentSet.from_rig_file().on_topic(OUTER_RING_TEMPERATURE.name, ThermocoupleSettings)
        self._thermocouple = FirstOrderLag(thermocouple.time_constant_s, 0.0, None) if thermocouple is not None else None
        self._torque_now = 0.0
        self._torque_age = math.inf
        self.chunk = chunk
        self.max_speed_gap = max_speed_gap
        self.load_at = load_at
        self.origin: float | None = None
        """Bench time of the engine's time 0, s (None before the first start)."""
        self.started_at = -math.inf
        """Bench time of the latest (re)start, s."""
        self.restarts = 0
        """Engine (re)starts, the first included (1)."""
        self._last_point: SpeedPoint | None = None
        self._times: list[float] = []
        self._cage: list[float] = []
        self._inner: list[float] = []
        self._load: list[float] = []
        self._torque: list[float] = []
        self._temperature: list[float] = []
        self._cum = (0.0, 0.0, 0.0, 0.0)

    @property
    def thermal_started(self) -> bool:
        """Whether the thermal network has started (at the engine's first start)."""
        return self._thermal_started

    @property
    def time(self) -> float:
        """Bench time the engine has reached, s (-inf before the first start)."""
        return -math.inf if self.origin is None else self.origin + self.engine.time

    def _force(self, t: float) -> float:
        load = self.load_at(t)
        return max(load, MIN_AXIAL_LOAD) if math.isfinite(load) else self.engine.axial_load

    def restart(self, point: SpeedPoint) -> bool:
        """(Re)start the engine at ``point`` from its kinematic state; False if no force is known
        yet (nothing happens)."""
        load = self.load_at(point.time)
        if not math.isfinite(load):
            return False
        if self.origin is None:
            self.origin = point.time
        self.engine.initialise(point.speed, max(load, MIN_AXIAL_LOAD), time=point.time - self.origin)
        if self.coupling is not None:
            if not self._thermal_started:
                self._thermal_started = True
                if self.thermal_start_c is not None:  # the bench's bearing at its first reading
                    net = self.coupling.network
                    net.temperatures[:] = self.thermal_start_c
                    net.initial_temperatures[:] = self.thermal_start_c
                    grid = self.coupling.grid
                    if grid is not None:
                        lo, hi, _ = grid.bracket(self.thermal_start_c)
                        grid.build_now(lo)
                        grid.build_now(hi)
            self.coupling.retune()
        self.started_at = point.time
        self.restarts += 1
        self._last_point = point
        self._times, self._cage, self._inner, self._load, self._torque = [point.time], [0.0], [0.0], [0.0], [0.0]
        self._temperature = [self._thermocouple_reading(0.0)]
        self._cum = (0.0, 0.0, 0.0, 0.0)
        self._torque_age = math.inf
        return True

    def _friction_torque(self, h: float) -> float:
        """The engine's friction torque, N m, evaluated every :data:`TORQUE_PERIOD_S` of engine
        time and held between (the torque meter's own rate; it costs a quarter of a chunk)."""
        self._torque_age += h
        if self._torque_age >= TORQUE_PERIOD_S - 1e-12:
            self._torque_now = self.engine.friction_torque()
            self._torque_age = 0.0
        return self._torque_now

    def _thermocouple_reading(self, h: float) -> float:
        if self.coupling is None or self._thermocouple is None:
            return math.nan
        return self._thermocouple.update(self.coupling.temperature("outer_ring"), h)

    def jump_back(self) -> None:
        """The bench clock went back: the next speed point restarts the engine."""
        self._last_point = None
        self.origin = None

    def follow(self, point: SpeedPoint) -> None:
        """Advance the engine to ``point``'s time, its speed moving linearly to ``point``'s speed."""
        last = self._last_point
        if last is None or point.time - last.time > self.max_speed_gap or point.time < last.time:
            self.restart(point)
            return
        if point.time <= self.time:
            return
        assert self.origin is not None
        engine = self.engine
        step = engine.time_step
        target = point.time - self.origin
        accel = (point.speed - engine.inner_ring_speed) / (target - engine.time)
        while target - engine.time > 0.5 * step:
            h = min(self.chunk, target - engine.time)
            t_end = self.origin + engine.time + h
            load = self._force(t_end)
            t0 = engine.time
            avg = engine.advance(h, axial_load=load, inner_ring_acceleration=accel)
            if avg.duration <= 0.0 and engine.time <= t0:
                # a deceleration to rest: the engine stops at zero speed; spend the rest at rest
                engine.set_inner_ring_speed(0.0)
                avg = engine.advance(h, axial_load=load)
                if avg.duration <= 0.0:
                    break
            if self.coupling is not None:
                self.coupling.advance(avg.duration)
            cum_c, cum_i, cum_l, cum_m = self._cum
            self._cum = (
                cum_c + avg.cage_speed * avg.duration,
                cum_i + avg.inner_ring_speed * avg.duration,
                cum_l + load * avg.duration,
                cum_m + self._friction_torque(avg.duration) * avg.duration,
            )
            self._times.append(self.origin + engine.time)
            self._cage.append(self._cum[0])
            self._inner.append(self._cum[1])
            self._load.append(self._cum[2])
            self._torque.append(self._cum[3])
            self._temperature.append(self._thermocouple_reading(avg.duration))
        self._last_point = point

    def _integrals(self, t: float) -> tuple[float, float, float, float, float]:
        times = self._times
        k = bisect.bisect_right(times, t) - 1
        k = max(0, min(k, len(times) - 2))
        t0, t1 = times[k], times[k + 1]
        f = (t - t0) / (t1 - t0)
        return tuple(  # type: ignore[return-value]  # a fixed-length tuple built from a generator
            a[k] + f * (a[k + 1] - a[k]) for a in (self._cage, self._inner, self._load, self._torque, self._temperature)
        )

    def covers(self, start: float, end: float) -> bool:
        """Whether the engine has run over all of ``[start, end]`` since its latest start."""
        return len(self._times) >= 2 and self._times[0] <= start and end <= self._times[-1]

    def predict(self, start: float, end: float) -> Prediction | None:
        """The engine's mean speeds over ``[start, end]`` (bench s); None unless :meth:`covers`."""
        if end <= start or not self.covers(start, end):
            return None
        c0, i0, l0, m0, _ = self._integrals(start)
        c1, i1, l1, m1, temperature = self._integrals(end)
        d = end - start
        return Prediction(start, end, (c1 - c0) / d, (i1 - i0) / d, (l1 - l0) / d, (m1 - m0) / d, temperature)

    def forget_before(self, time: float) -> None:
        """Drop the integrals before ``time`` (s), keeping one point at or before it."""
        k = bisect.bisect_right(self._times, time) - 1
        if k > 0:
            for a in (self._times, self._cage, self._inner, self._load, self._torque, self._temperature):
                del a[:k]

    def swap_parameters(self, params: BearingParameters) -> None:
        """Go on with other bearing parameters from the present state (online re-calibration)."""
        snap = self.engine.snapshot()
        engine = BearingDynamics(params, model=self.engine.model, time_step=self.engine.time_step, mounting=self.engine.mounting)
        engine.restore(snap)
        self.engine = engine
        if self.coupling is not None:
            self.coupling.rebind(engine)
