"""The bench's axial loading chain (docs/paper.md section 8) put together, with its interlocks.

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

The elements are in :mod:`.loading_elements`, the load cell and the controller in
:mod:`.force_control`. Units: N, m, s, A, V, kg throughout.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar
from collections.abc import Callable

from bearing_rig_sim.config import ConfigError
from bearing_rig_sim.rig.force_control import ForceController, ForceControllerParams, LoadCell, LoadCellParams
from bearing_rig_sim.rig.loading_elements import (
    ClutchState,
    Housing,
    HousingParams,
    Lever,
    LeverParams,
    LinearBrake,
    LinearBrakeParams,
    MagnetClutch,
    MagnetClutchParams,
    SetpointError,
    WireRope,
    WireRopeParams,
    check_time_step,
    clip,
)
from bearing_rig_sim.rig.parameters import ParameterRecord, bounded

__all__ = [
    "ClutchState",
    "InterlockParams",
    "LoadChainState",
    "LoadingChain",
    "LoadingChainConfig",
    "SetpointError",
]

MODE_ITERATIONS = 4
"""Most times a mechanical step is redone in another contact mode (2 one-sided elements give
at most 4 modes to try; if they keep disagreeing, the last try is kept)."""


@dataclass(frozen=True)
class InterlockParams(ParameterRecord):
    """Trip levels of the loading chain's interlocks.

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.interlocks``.
    """

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

    brake: LinearBrakeParams
    rope: WireRopeParams
    lever: LeverParams
    clutch: MagnetClutchParams
    housing: HousingParams
    load_cell: LoadCellParams
    controller: ForceControllerParams
    interlocks: InterlockParams
    # the bounded numbers after the nested records: a dataclass field with a (typing) default
    # may not precede one without
    max_setpoint_n: float = bounded(gt=0.0)
    """Largest axial-load set-point accepted, N."""
    max_substep_s: float = bounded(gt=0.0, le=0.01)
    """Longest internal integration step, s; longer calls to ``step`` are subdivided."""

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
    def from_yaml(cls, path: str | Path | None = None) -> LoadingChain:
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
        self.check_setpoint(force_n)
        self._setpoint = float(force_n)

    def check_setpoint(self, force_n: object) -> None:
        """Whether :meth:`set_setpoint` would take ``force_n`` N (nothing changes).

        Raises:
            SetpointError: not a finite number, negative, or above ``max_setpoint_n``.
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

    def set_manual_voltage(self, voltage: float | None) -> None:
        """Drive the brake open-loop at ``voltage`` (V), or return to closed loop with None.

        Raises:
            SetpointError: not finite or beyond the brake's supply rails.
        """
        if voltage is None:
            if self._manual_voltage is not None:  # back to closed loop, bumpless from the reading
                self.controller.reset(self.load_cell.value)
            self._manual_voltage = None
            return
        rail = self.config.brake.voltage_limit_v
        if isinstance(voltage, bool) or not isinstance(voltage, (int, float)) or not math.isfinite(voltage):
            raise SetpointError(f"manual brake voltage must be a finite number, got {voltage!r}")
        if abs(voltage) > rail:
            raise SetpointError(f"manual brake voltage must be within +-{rail:g} V (voltage_limit_v), got {voltage:g} V")
        self._manual_voltage = float(voltage)

    def engage(self) -> None:
        """Close the clutch, the lever re-seated at its home first; no effect if engaged.

        Released, the lever is free: the brake's decaying current pulls it down until the rope
        runs out of plunger stroke (some 4.5 mm at the shipped values), and a clutch gripping
        there would leave no travel to load the bearing with. So engaging is the bench's
        procedure, done with nothing reaching the bearing: the lever is lifted back to its home
        (output at 0, the position of the first engagement), the plunger to its start (rope
        just taut, no tension), both at rest; then the magnet grips the housing, unloaded. The
        lifting itself is not integrated (a manual step of the bench, not part of a test).
        """
        if not self.clutch.engaged:
            if self.lever_position > 0.0:  # below home: no return spring brings it back
                self.lever_position, self.lever_velocity = 0.0, 0.0
                self.plunger_position, self.plunger_velocity = 0.0, 0.0
                self._tension = 0.0
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
        reading. A condition that persists trips again at the next step. No effect without a
        fault."""
        if not self.fault:
            return
        self._fault_reason = ""
        self._history.clear()
        self.controller.reset(self.load_cell.value)

    # -- simulation ------------------------------------------------------------------------------
    def step(self, dt: float) -> LoadChainState:
        """Advance the chain by ``dt`` s (subdivided into steps of at most ``max_substep_s``)."""
        dt = check_time_step(dt)
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
            xp, vp = clip(xp, b.stroke_min_m, b.stroke_max_m), 0.0
        if xl < lever.travel_min_m or xl > lever.travel_max_m:
            xl, vl = clip(xl, lever.travel_min_m, lever.travel_max_m), 0.0
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
                self._trip(f"rate limit: load cell force rising at {rate:.0f} N/s > max_rate_n_per_s {limits.max_rate_n_per_s:g} N/s")
                return
        if self.clutch.state is ClutchState.SLIPPING:
            self._trip(f"clutch slip: force reached the magnet's holding force {self.config.clutch.holding_force_n:g} N")

    def _trip(self, reason: str) -> None:
        self._fault_reason = reason
        self._manual_voltage = None
        self.controller.reset(self.load_cell.value)
