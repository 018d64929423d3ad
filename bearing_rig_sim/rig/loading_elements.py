"""Elements of the bench's axial loading chain (docs/paper.md section 8): linear brake, wire rope,
lever, permanent-magnet clutch and bearing housing; how they are put together and integrated is
in :mod:`bearing_rig_sim.rig.loading`.

Units: N, m, s, A, V, kg throughout. Parameter values and their sources: ``config/rig.yaml``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum

from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.parameters import ParameterRecord, bounded


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


def check_time_step(dt: float) -> float:
    """``dt`` as a float if it is a finite number > 0 s.

    Raises:
        RigError: otherwise.
    """
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not math.isfinite(dt) or dt <= 0.0:
        raise RigError(f"loading chain: time step must be a finite number > 0 s, got {dt!r}")
    return float(dt)


def clip(value: float, low: float, high: float) -> float:
    """``value`` limited to [low, high]."""
    return min(max(value, low), high)


# ---------------------------------------------------------------------------------------------
# Linear brake
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LinearBrakeParams(ParameterRecord):
    """Linear brake (electromagnetic actuator pulling the rope).

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.brake``.
    """

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
        dt = check_time_step(dt)
        if not math.isfinite(voltage):
            raise SetpointError(f"linear brake: voltage must be finite, got {voltage!r}")
        p = self.params
        self.voltage = clip(voltage, -p.voltage_limit_v, p.voltage_limit_v)
        target = self.voltage / p.resistance_ohm
        self.current = target + (self.current - target) * math.exp(-dt / self.time_constant)
        self.current = clip(self.current, -p.current_limit_a, p.current_limit_a)
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
    """Steel wire rope between the brake and the lever.

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.rope``.
    """

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
    """Lever between the rope and the clutch.

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.lever``.
    """

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


@dataclass(frozen=True)
class MagnetClutchParams(ParameterRecord):
    """Permanent-magnet clutch on the lever.

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.clutch``.
    """

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
    """Bearing housing, load cell and bearing seen axially.

    The paper gives no values: each value's source (datasheet-typical, or an assumption with
    its reason) is beside it in ``config/rig.yaml``, section ``loading_chain.housing``.
    """

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
