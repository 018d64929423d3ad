"""The bench's axial loading chain (digest section 8) and its closed-loop force control.

A linear brake pulls a wire rope, which moves a lever down; a clutch on the lever, held by a
permanent magnet, moves the bearing housing down and so presses the bearing axially::

    voltage -> [LinearBrake: coil L/R, force = f(current)] -> plunger (mass, stroke stops)
            -> [WireRope: tension only] -> [Lever: force ratio r] (mass at its output, travel stops)
            -> [MagnetClutch: holding-force limit] -> [Housing: axial stiffness on the bearing]
            -> bearing force -> [LoadCell: noise, low-pass] -> [ForceController: PI(D)] -> voltage

Mechanical model (the choices, and why):

* Two moving bodies: the brake's plunger (position ``x_p``, positive when pulling the rope) and
  the lever, described at its output (``x_l``, positive downwards). The lever is rigid: its
  input moves ``r x_l`` and it passes ``r`` times the rope tension to its output.
* The housing is massless (its mass is lumped into the lever's output mass) and presses the
  bearing through the axial stiffness of housing, load cell and bearing in series. When the
  clutch is engaged the housing's compression is ``x_l - d``, with ``d`` the clutch's grip
  offset; the clutch transmits at most its holding force ``H``: beyond it, it slips and ``d``
  moves so that the housing carries exactly ``H`` (an elastic-plastic coupling).
* The rope and the housing contact are one-sided (tension >= 0, contact force >= 0), so the
  mechanics is piecewise linear. Each step is one backward (implicit) Euler step of the linear
  system of the active mode (rope taut or slack; housing free, in contact or slipping), with the
  mode checked at the end of the step and the step redone in the other mode when it disagrees:
  stable for the stiff housing at a 1 ms step and the rope never pushes, not even inside a step.
* The coil current is integrated exactly over the step (constant voltage, first order L/R);
  back-EMF of the plunger is neglected (assumption: plunger speeds of mm/s give well under
  1 % of the supply voltage).

Units: N, m, s, A, V, kg throughout.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from enum import Enum
from typing import Callable, ClassVar

import numpy as np

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.parameters import ParameterRecord, bounded

MODE_ITERATIONS = 4
"""Most times a mechanical step is redone in another contact mode (2 one-sided elements give
at most 4 modes to try; if they keep disagreeing, the last try is kept)."""


class SetpointError(RigError):
    """A set-point or command was refused (not finite, negative, over its limit); the previous
    value is kept."""


class ClutchState(str, Enum):
    """State of the magnet clutch; compares equal to its string value."""

    RELEASED = "released"
    """Clutch open: no force reaches the housing."""
    ENGAGED = "engaged"
    """Clutch closed and holding."""
    SLIPPING = "slipping"
    """The demanded force reached the magnet's holding force: the clutch slides (a fault)."""

    @property
    def message_code(self) -> int:
        """The ``CLUTCH_*`` constant of AxialLoadState.msg for this state."""
        return {"released": 0, "engaged": 1, "slipping": 2}[self.value]


def _check_dt(dt: float) -> float:
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not math.isfinite(dt) or dt <= 0.0:
        raise RigError(f"loading chain: time step must be a finite number > 0 s, got {dt!r}")
    return float(dt)


def _clip(value: float, low: float, high: float) -> float:
    return min(max(value, low), high)


# ---------------------------------------------------------------------------------------------
# Linear brake
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LinearBrakeParams(ParameterRecord):
    """Linear brake (electromagnetic actuator pulling the rope). Sources: config/rig.yaml."""

    resistance_ohm: float = bounded(gt=0.0)
    """Coil resistance R, ohm."""
    inductance_h: float = bounded(gt=0.0)
    """Coil inductance L, H; electrical time constant L/R."""
    force_constant_n_per_a: float = bounded(gt=0.0)
    """Force per ampere at small current, N/A."""
    saturation_force_n: float = bounded(gt=0.0)
    """Magnetic saturation: force = F_sat tanh(k_f i / F_sat), N."""
    current_limit_a: float = bounded(gt=0.0)
    """Current limit of the coil driver, A (both directions)."""
    voltage_limit_v: float = bounded(gt=0.0)
    """Supply rail of the coil driver, V (both directions)."""
    moving_mass_kg: float = bounded(gt=0.0)
    """Mass of the plunger and rope end fitting, kg."""
    damping_n_s_per_m: float = bounded(ge=0.0)
    """Viscous damping of the plunger's guide, N s/m."""
    stroke_min_m: float = bounded(le=0.0)
    """Plunger end stop on the slack side, m (0 = rope just taut at the start)."""
    stroke_max_m: float = bounded(gt=0.0)
    """Plunger end stop on the pulling side, m."""


class LinearBrake:
    """Coil with first-order electrical dynamics and a saturating force.

    ``L di/dt = V - R i`` integrated exactly over each step for a constant voltage; the current
    is held within the driver's current limit; force ``F = F_sat tanh(k_f i / F_sat)`` (N).
    """

    def __init__(self, params: LinearBrakeParams) -> None:
        self.params = params
        self.current = 0.0
        """Coil current, A."""
        self.voltage = 0.0
        """Voltage applied in the last step (after the supply rails), V."""

    @property
    def time_constant(self) -> float:
        """Electrical time constant L/R, s."""
        return self.params.inductance_h / self.params.resistance_ohm

    def force_at(self, current: float) -> float:
        """Pull on the rope for a coil current, N (negative current pushes)."""
        p = self.params
        return p.saturation_force_n * math.tanh(p.force_constant_n_per_a * current / p.saturation_force_n)

    @property
    def force(self) -> float:
        """Pull on the rope at the present current, N."""
        return self.force_at(self.current)

    def step(self, voltage: float, dt: float) -> float:
        """Apply ``voltage`` (V, clipped to the supply rails) for ``dt`` s; return the force, N.

        Raises:
            SetpointError: the voltage is not finite.
        """
        dt = _check_dt(dt)
        if not math.isfinite(voltage):
            raise SetpointError(f"linear brake: voltage must be finite, got {voltage!r}")
        p = self.params
        self.voltage = _clip(voltage, -p.voltage_limit_v, p.voltage_limit_v)
        target = self.voltage / p.resistance_ohm
        self.current = target + (self.current - target) * math.exp(-dt / self.time_constant)
        self.current = _clip(self.current, -p.current_limit_a, p.current_limit_a)
        return self.force

    def reset(self) -> None:
        """Coil de-energised."""
        self.current = 0.0
        self.voltage = 0.0


# ---------------------------------------------------------------------------------------------
# Wire rope, lever, clutch, housing
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class WireRopeParams(ParameterRecord):
    """Steel wire rope between the brake and the lever. Sources: config/rig.yaml."""

    stiffness_n_per_m: float = bounded(gt=0.0)
    """Axial stiffness EA/length, N/m."""
    damping_n_s_per_m: float = bounded(ge=0.0)
    """Internal (strand friction) damping, N s/m."""


class WireRope:
    """A rope: pulls in proportion to its stretch, never pushes.

    ``T = k s + c ds/dt`` while stretched (``s > 0``), floored at 0 (the damping can slow the
    unloading but not push), and ``T = 0`` when slack.
    """

    def __init__(self, params: WireRopeParams) -> None:
        self.params = params

    def tension(self, stretch: float, stretch_rate: float) -> float:
        """Rope tension, N (>= 0), for a stretch (m) and its rate (m/s)."""
        if stretch <= 0.0:
            return 0.0
        return max(0.0, self.params.stiffness_n_per_m * stretch + self.params.damping_n_s_per_m * stretch_rate)


@dataclass(frozen=True)
class LeverParams(ParameterRecord):
    """Lever between the rope and the clutch. Sources: config/rig.yaml."""

    force_ratio: float = bounded(ge=1.0, le=20.0)
    """Output force / input force (1); the input moves ``force_ratio`` times the output."""
    output_mass_kg: float = bounded(gt=0.0)
    """Lever inertia and housing mass reduced to the lever's output, kg."""
    damping_n_s_per_m: float = bounded(ge=0.0)
    """Viscous damping of the lever pivot and housing guides at the output, N s/m."""
    travel_min_m: float = bounded(le=0.0)
    """Upper stop of the lever output, m (0 = clutch grip position at the start)."""
    travel_max_m: float = bounded(gt=0.0)
    """Lower stop of the lever output, m."""


class Lever:
    """A rigid lever: force ratio ``r`` and, by virtual work, displacement ratio ``1 / r``."""

    def __init__(self, params: LeverParams) -> None:
        self.params = params

    @property
    def ratio(self) -> float:
        """Output force / input force (1)."""
        return self.params.force_ratio

    def output_force(self, input_force: float) -> float:
        """Force at the output for a force at the input, N."""
        return self.ratio * input_force

    def input_displacement(self, output_displacement: float) -> float:
        """Input (rope end) displacement for an output displacement, m."""
        return self.ratio * output_displacement


@dataclass(frozen=True)
class MagnetClutchParams(ParameterRecord):
    """Permanent-magnet clutch on the lever. Sources: config/rig.yaml."""

    holding_force_n: float = bounded(gt=0.0)
    """Largest force the magnet's grip transmits before slipping, N."""


class MagnetClutch:
    """Clutch between the lever output and the housing, held by a permanent magnet.

    Engaged, it grips the lever at the offset ``d`` (lever output position minus housing
    compression) and transmits up to ``holding_force_n``; at the limit it slips: it transmits the
    limit and its grip offset follows the lever. Released, it transmits nothing.
    """

    def __init__(self, params: MagnetClutchParams) -> None:
        self.params = params
        self.state = ClutchState.RELEASED
        self.offset = 0.0
        """Grip offset d, m: lever output position at which the housing carries no force."""

    @property
    def engaged(self) -> bool:
        """True unless released (slipping counts as engaged)."""
        return self.state is not ClutchState.RELEASED

    def engage(self, lever_position: float) -> None:
        """Grip the lever where it is, with the housing unloaded."""
        if self.state is ClutchState.RELEASED:
            self.offset = lever_position
            self.state = ClutchState.ENGAGED

    def release(self) -> None:
        """Open the clutch."""
        self.state = ClutchState.RELEASED

    def slip_to(self, lever_position: float, compression: float) -> None:
        """Slide so that the housing compression is ``compression`` (m); state slipping."""
        self.offset = lever_position - compression
        self.state = ClutchState.SLIPPING


@dataclass(frozen=True)
class HousingParams(ParameterRecord):
    """Bearing housing, load cell and bearing seen axially. Sources: config/rig.yaml."""

    axial_stiffness_n_per_m: float = bounded(gt=0.0)
    """Series stiffness of housing, load cell and bearing, N/m."""
    axial_damping_n_s_per_m: float = bounded(ge=0.0)
    """Structural damping of that stack, N s/m."""


class Housing:
    """The housing pressing the bearing: a one-sided spring-damper (it can push, not pull)."""

    def __init__(self, params: HousingParams) -> None:
        self.params = params

    @property
    def stiffness(self) -> float:
        """Axial stiffness, N/m."""
        return self.params.axial_stiffness_n_per_m

    def force(self, compression: float, rate: float) -> float:
        """Force on the bearing, N (>= 0), for a compression (m) and its rate (m/s)."""
        if compression <= 0.0:
            return 0.0
        return max(0.0, self.stiffness * compression + self.params.axial_damping_n_s_per_m * rate)


# ---------------------------------------------------------------------------------------------
# Load cell and controller
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LoadCellParams(ParameterRecord):
    """Load cell under the housing. Sources: config/rig.yaml."""

    noise_std_n: float = bounded(ge=0.0)
    """Standard deviation of the Gaussian noise of each sample, N."""
    cutoff_hz: float = bounded(ge=0.0)
    """Cut-off of the first-order low-pass filter, Hz; 0 = no filter."""
    seed: int = bounded(ge=0)
    """Seed of the noise generator (1)."""


class LoadCell:
    """Measures the housing force with Gaussian noise and an optional first-order low-pass."""

    def __init__(self, params: LoadCellParams) -> None:
        self.params = params
        self._rng = np.random.default_rng(params.seed)
        self.value = 0.0
        """Latest (noisy, filtered) reading, N."""
        self._primed = False

    def measure(self, force: float, dt: float) -> float:
        """Sample ``force`` (N) after ``dt`` s; return the reading, N."""
        dt = _check_dt(dt)
        sample = force
        if self.params.noise_std_n > 0.0:
            sample += float(self._rng.normal(0.0, self.params.noise_std_n))
        if self.params.cutoff_hz > 0.0 and self._primed:
            gain = 1.0 - math.exp(-2.0 * math.pi * self.params.cutoff_hz * dt)
            self.value += gain * (sample - self.value)
        else:
            self.value = sample
        self._primed = True
        return self.value

    def reset(self) -> None:
        """Forget the filter state (the noise generator continues)."""
        self.value = 0.0
        self._primed = False


@dataclass(frozen=True)
class ForceControllerParams(ParameterRecord):
    """PI(D) force controller driving the brake voltage. Sources: config/rig.yaml."""

    proportional_gain_v_per_n: float = bounded(ge=0.0)
    """Kp, V/N."""
    integral_gain_v_per_n_s: float = bounded(ge=0.0)
    """Ki, V/(N s)."""
    derivative_gain_v_s_per_n: float = bounded(ge=0.0)
    """Kd on the measurement (not the error, so set-point changes give no kick), V s/N."""
    derivative_filter_s: float = bounded(gt=0.0)
    """Time constant of the first-order filter on the derivative, s."""
    output_min_v: float = bounded(le=0.0)
    """Lowest voltage command, V (negative drives the brake backwards to unload faster)."""
    output_max_v: float = bounded(gt=0.0)
    """Highest voltage command, V."""
    setpoint_rate_n_per_s: float = bounded(gt=0.0)
    """Largest rate of change of the set-point seen by the loop, N/s."""


class ForceController:
    """PI(D) on the load-cell force with set-point rate limiting, output saturation and
    anti-windup by conditional integration (the integrator holds while the output is saturated
    and the error would drive it further into saturation)."""

    def __init__(self, params: ForceControllerParams) -> None:
        self.params = params
        self.reset(0.0)

    def reset(self, measured: float) -> None:
        """Restart from a measured force (N): integrator empty, set-point ramp starting there."""
        self.integral = 0.0
        """Integrator state, V."""
        self.ramped_setpoint = measured
        """Set-point after rate limiting, N."""
        self._derivative = 0.0
        self._last_measured: float | None = None

    def update(self, setpoint: float, measured: float, dt: float) -> float:
        """One control period: the voltage command (V) for a set-point and a measurement (N)."""
        p = self.params
        dt = _check_dt(dt)
        max_change = p.setpoint_rate_n_per_s * dt
        self.ramped_setpoint += _clip(setpoint - self.ramped_setpoint, -max_change, max_change)
        error = self.ramped_setpoint - measured
        if p.derivative_gain_v_s_per_n > 0.0 and self._last_measured is not None:
            raw = (measured - self._last_measured) / dt
            self._derivative += (raw - self._derivative) * (1.0 - math.exp(-dt / p.derivative_filter_s))
        self._last_measured = measured
        integral = self.integral + p.integral_gain_v_per_n_s * error * dt
        unsaturated = p.proportional_gain_v_per_n * error + integral - p.derivative_gain_v_s_per_n * self._derivative
        command = _clip(unsaturated, p.output_min_v, p.output_max_v)
        winding_up = (unsaturated > p.output_max_v and error > 0.0) or (unsaturated < p.output_min_v and error < 0.0)
        if not winding_up:
            self.integral = integral
        return command


# ---------------------------------------------------------------------------------------------
# The chain
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class InterlockParams(ParameterRecord):
    """Trip levels of the loading chain's interlocks. Sources: config/rig.yaml."""

    max_force_n: float = bounded(gt=0.0)
    """Load limit: the chain faults when the load cell reads more, N."""
    max_rate_n_per_s: float = bounded(gt=0.0)
    """Rate limit: the chain faults when the load cell's force rises faster, N/s."""
    rate_window_s: float = bounded(gt=0.0, le=1.0)
    """Window over which the rate of rise is measured (averages the load-cell noise), s."""


@dataclass(frozen=True)
class LoadingChainConfig(ParameterRecord):
    """The ``loading_chain`` section of ``config/rig.yaml``."""

    SECTION: ClassVar[str] = "loading_chain"

    max_setpoint_n: float = bounded(gt=0.0)
    """Largest axial-load set-point accepted, N."""
    max_substep_s: float = bounded(gt=0.0, le=0.01)
    """Longest internal integration step, s; longer calls to ``step`` are subdivided."""
    brake: LinearBrakeParams
    rope: WireRopeParams
    lever: LeverParams
    clutch: MagnetClutchParams
    housing: HousingParams
    load_cell: LoadCellParams
    controller: ForceControllerParams
    interlocks: InterlockParams

    def check_consistency(self, error: Callable[[str, str], ConfigError]) -> None:
        """The load-limit trip must sit above the largest set-point."""
        if self.interlocks.max_force_n <= self.max_setpoint_n:
            raise error(
                "interlocks.max_force_n",
                f"must be > max_setpoint_n ({self.max_setpoint_n}), got {self.interlocks.max_force_n}",
            )


@dataclass(frozen=True)
class LoadChainState:
    """State of the loading chain after a step (fields of AxialLoadState.msg, plus ``time`` and
    ``ramped_setpoint``)."""

    time: float
    """Chain time since construction, s."""
    setpoint: float
    """Axial load requested (accepted set-point), N."""
    ramped_setpoint: float
    """Set-point after the controller's rate limit, N."""
    load_cell_force: float
    """Force read by the load cell (noise, filter), N."""
    bearing_force: float
    """Axial force actually reaching the bearing, N."""
    brake_current: float
    """Linear-brake coil current, A."""
    brake_force: float
    """Linear-brake pull on the rope, N."""
    rope_tension: float
    """Wire-rope tension, N (>= 0)."""
    clutch_state: ClutchState
    """Released, engaged or slipping."""
    fault: bool
    """True while an interlock is tripped."""
    fault_reason: str
    """Which interlock tripped and why; empty when none."""


@dataclass
class _Mode:
    rope_taut: bool
    housing: str  # "free", "contact" or "slip"


class LoadingChain:
    """Linear brake, rope, lever, clutch, housing, load cell and force controller together.

    Starts at rest, unloaded, clutch released, no fault. Closed-loop force control runs while
    the clutch is engaged and no fault is latched; :meth:`set_manual_voltage` drives the brake
    open-loop instead (commissioning). Interlocks, evaluated every step on the load-cell
    reading and the clutch: load limit, rate limit, clutch slip. A trip latches a fault, drops
    the brake command to 0 V and leaves manual mode, until :meth:`reset_fault`.
    """

    def __init__(self, config: LoadingChainConfig) -> None:
        self.config = config
        self.brake = LinearBrake(config.brake)
        self.rope = WireRope(config.rope)
        self.lever = Lever(config.lever)
        self.clutch = MagnetClutch(config.clutch)
        self.housing = Housing(config.housing)
        self.load_cell = LoadCell(config.load_cell)
        self.controller = ForceController(config.controller)
        self.time = 0.0
        """Chain time, s."""
        self.plunger_position = 0.0
        """Brake plunger position x_p, m (positive pulls the rope)."""
        self.plunger_velocity = 0.0
        """Plunger velocity, m/s."""
        self.lever_position = 0.0
        """Lever output position x_l, m (positive presses the bearing)."""
        self.lever_velocity = 0.0
        """Lever output velocity, m/s."""
        self._setpoint = 0.0
        self._manual_voltage: float | None = None
        self._fault_reason = ""
        self._history: deque[tuple[float, float]] = deque()
        self._tension = 0.0
        self._bearing_force = 0.0

    @classmethod
    def from_yaml(cls, path: str | None = None) -> "LoadingChain":
        """A chain with the ``loading_chain`` parameters of a rig file (default: shipped)."""
        return cls(LoadingChainConfig.from_yaml(path))

    # -- commands --------------------------------------------------------------------------------
    @property
    def setpoint(self) -> float:
        """Accepted axial-load set-point, N."""
        return self._setpoint

    def set_setpoint(self, force_n: float) -> None:
        """Request an axial load, N.

        Raises:
            SetpointError: not a finite number, negative, or above ``max_setpoint_n``; the
                previous set-point is kept.
        """
        limit = self.config.max_setpoint_n
        keep = f"keeping {self._setpoint:g} N"
        if isinstance(force_n, bool) or not isinstance(force_n, (int, float)):
            raise SetpointError(f"axial-load set-point must be a number, got {force_n!r}; {keep}")
        if not math.isfinite(force_n):
            raise SetpointError(f"axial-load set-point must be finite, got {force_n!r}; {keep}")
        if force_n < 0.0:
            raise SetpointError(f"axial-load set-point must be >= 0 N, got {force_n:g} N; {keep}")
        if force_n > limit:
            raise SetpointError(f"axial-load set-point must be <= {limit:g} N (max_setpoint_n), got {force_n:g} N; {keep}")
        self._setpoint = float(force_n)

    def set_manual_voltage(self, voltage: float | None) -> None:
        """Drive the brake open-loop at ``voltage`` (V), or return to closed loop with None.

        Raises:
            SetpointError: not finite or beyond the brake's supply rails.
        """
        if voltage is None:
            self._manual_voltage = None
            self.controller.reset(self.load_cell.value)
            return
        rail = self.config.brake.voltage_limit_v
        if isinstance(voltage, bool) or not isinstance(voltage, (int, float)) or not math.isfinite(voltage):
            raise SetpointError(f"manual brake voltage must be a finite number, got {voltage!r}")
        if abs(voltage) > rail:
            raise SetpointError(f"manual brake voltage must be within +-{rail:g} V (voltage_limit_v), got {voltage:g} V")
        self._manual_voltage = float(voltage)

    def engage(self) -> None:
        """Close the clutch: it grips the lever where it is, with the housing unloaded."""
        self.clutch.engage(self.lever_position)
        self.controller.reset(self.load_cell.value)

    def release(self) -> None:
        """Open the clutch: the housing is unloaded; closed-loop control stops."""
        self.clutch.release()

    @property
    def fault(self) -> bool:
        """True while an interlock is tripped."""
        return bool(self._fault_reason)

    @property
    def fault_reason(self) -> str:
        """Which interlock tripped and why; empty when none."""
        return self._fault_reason

    def reset_fault(self) -> None:
        """Clear a latched fault; control resumes with the set-point ramping from the present
        reading. A condition that persists trips again at the next step."""
        self._fault_reason = ""
        self._history.clear()
        self.controller.reset(self.load_cell.value)

    # -- simulation ------------------------------------------------------------------------------
    def step(self, dt: float) -> LoadChainState:
        """Advance the chain by ``dt`` s (subdivided into steps of at most ``max_substep_s``)."""
        dt = _check_dt(dt)
        count = max(1, math.ceil(dt / self.config.max_substep_s - 1e-9))
        h = dt / count
        for _ in range(count):
            self._substep(h)
        return self.state()

    def state(self) -> LoadChainState:
        """The present state, without advancing."""
        return LoadChainState(
            time=self.time,
            setpoint=self._setpoint,
            ramped_setpoint=self.controller.ramped_setpoint,
            load_cell_force=self.load_cell.value,
            bearing_force=self._bearing_force,
            brake_current=self.brake.current,
            brake_force=self.brake.force,
            rope_tension=self._tension,
            clutch_state=self.clutch.state,
            fault=self.fault,
            fault_reason=self._fault_reason,
        )

    def _voltage_command(self, h: float) -> float:
        measured = self.load_cell.value
        if self.fault:
            self.controller.reset(measured)
            return 0.0
        if self._manual_voltage is not None:
            self.controller.reset(measured)
            return self._manual_voltage
        if not self.clutch.engaged:
            self.controller.reset(measured)
            return 0.0
        return self.controller.update(self._setpoint, measured, h)

    def _substep(self, h: float) -> None:
        brake_force = self.brake.step(self._voltage_command(h), h)
        self._mechanics(brake_force, h)
        self.time += h
        reading = self.load_cell.measure(self._bearing_force, h)
        self._check_interlocks(reading)

    def _solve(self, mode: _Mode, brake_force: float, h: float) -> tuple[float, float, float, float]:
        """One backward-Euler step of the linear system of ``mode``: (x_p, v_p, x_l, v_l)."""
        b, rope, lever, housing = self.config.brake, self.config.rope, self.config.lever, self.config.housing
        r = lever.force_ratio
        # stiffness K, damping C and constant force f0 on the coordinates (x_p, x_l)
        kpp = kpl = kll = 0.0
        cpp, cpl, cll = b.damping_n_s_per_m, 0.0, lever.damping_n_s_per_m
        fp, fl = brake_force, 0.0
        if mode.rope_taut:
            k, c = rope.stiffness_n_per_m, rope.damping_n_s_per_m
            kpp, kpl, kll = k, -r * k, r * r * k
            cpp, cpl, cll = cpp + c, -r * c, cll + r * r * c
        if mode.housing == "contact":
            kll += housing.axial_stiffness_n_per_m
            cll += housing.axial_damping_n_s_per_m
            fl += housing.axial_stiffness_n_per_m * self.clutch.offset
        elif mode.housing == "slip":
            fl -= self.config.clutch.holding_force_n
        xp, vp, xl, vl = self.plunger_position, self.plunger_velocity, self.lever_position, self.lever_velocity
        mp, ml = b.moving_mass_kg, lever.output_mass_kg
        # (M + h C + h^2 K) v_new = M v + h (f0 - K x)
        a11 = mp + h * cpp + h * h * kpp
        a12 = h * cpl + h * h * kpl
        a22 = ml + h * cll + h * h * kll
        r1 = mp * vp + h * (fp - kpp * xp - kpl * xl)
        r2 = ml * vl + h * (fl - kpl * xp - kll * xl)
        det = a11 * a22 - a12 * a12
        vp_new = (r1 * a22 - a12 * r2) / det
        vl_new = (a11 * r2 - a12 * r1) / det
        return xp + h * vp_new, vp_new, xl + h * vl_new, vl_new

    def _mode_at(self, xp: float, vp: float, xl: float, vl: float) -> _Mode:
        """The contact mode consistent with a state (what each one-sided element is doing)."""
        r = self.lever.ratio
        taut = self.rope.tension(xp - r * xl, vp - r * vl) > 0.0
        if not self.clutch.engaged:
            return _Mode(taut, "free")
        force = self.housing.force(xl - self.clutch.offset, vl)
        if force >= self.config.clutch.holding_force_n:
            return _Mode(taut, "slip")
        return _Mode(taut, "contact" if force > 0.0 else "free")

    def _mechanics(self, brake_force: float, h: float) -> None:
        mode = self._mode_at(self.plunger_position, self.plunger_velocity, self.lever_position, self.lever_velocity)
        tried: list[_Mode] = []
        for _ in range(MODE_ITERATIONS):
            tried.append(mode)
            xp, vp, xl, vl = self._solve(mode, brake_force, h)
            found = self._mode_at(xp, vp, xl, vl)
            if found == mode:
                break
            if found in tried:  # the element changes state inside the step: take the safe side
                found = _Mode(False, mode.housing) if found.rope_taut != mode.rope_taut else found
                xp, vp, xl, vl = self._solve(found, brake_force, h)
                mode = found
                break
            mode = found
        b, lever = self.config.brake, self.config.lever
        if xp < b.stroke_min_m or xp > b.stroke_max_m:
            xp, vp = _clip(xp, b.stroke_min_m, b.stroke_max_m), 0.0
        if xl < lever.travel_min_m or xl > lever.travel_max_m:
            xl, vl = _clip(xl, lever.travel_min_m, lever.travel_max_m), 0.0
        self.plunger_position, self.plunger_velocity, self.lever_position, self.lever_velocity = xp, vp, xl, vl
        r = self.lever.ratio
        self._tension = self.rope.tension(xp - r * xl, vp - r * vl) if mode.rope_taut else 0.0
        self._bearing_force = self._clutch_force(mode, xl, vl)

    def _clutch_force(self, mode: _Mode, xl: float, vl: float) -> float:
        """Force through the clutch into the housing (= on the bearing) after a step, N."""
        if not self.clutch.engaged:
            return 0.0
        holding = self.config.clutch.holding_force_n
        if mode.housing == "slip":
            self.clutch.slip_to(xl, holding / self.housing.stiffness)
            return holding
        self.clutch.state = ClutchState.ENGAGED
        if mode.housing == "free":
            return 0.0
        return min(self.housing.force(xl - self.clutch.offset, vl), holding)

    def _check_interlocks(self, reading: float) -> None:
        limits = self.config.interlocks
        history = self._history
        history.append((self.time, reading))
        while len(history) > 1 and history[1][0] <= self.time - limits.rate_window_s + 1e-12:
            history.popleft()
        if self.fault:
            return
        if reading > limits.max_force_n:
            self._trip(f"load limit: load cell reads {reading:.1f} N > max_force_n {limits.max_force_n:g} N")
            return
        span = self.time - history[0][0]
        if span >= limits.rate_window_s - 1e-12:
            rate = (reading - history[0][1]) / span
            if rate > limits.max_rate_n_per_s:
                self._trip(
                    f"rate limit: load cell force rising at {rate:.0f} N/s > max_rate_n_per_s {limits.max_rate_n_per_s:g} N/s"
                )
                return
        if self.clutch.state is ClutchState.SLIPPING:
            self._trip(
                f"clutch slip: force reached the magnet's holding force {self.config.clutch.holding_force_n:g} N"
            )

    def _trip(self, reason: str) -> None:
        self._fault_reason = reason
        self._manual_voltage = None
        self.controller.reset(self.load_cell.value)
