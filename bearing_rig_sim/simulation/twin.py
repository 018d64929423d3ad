"""The rig's digital twin, one chunk at a time: engine, spindle drive, axial load, instruments.

:class:`RigTwin` advances the dynamics engine by one chunk (``chunk_s`` of ``config/simulator.yaml``) at the current axial
load, with the inner-ring acceleration the :class:`~bearing_rig_sim.simulation.drive.SpindleDrive`
asks for, then shows the motion to the bench's instruments (the rig file's ``sensors`` section,
:class:`~bearing_rig_sim.simulation.instruments.TwinInstruments`), among them the two
fibre-optic sensors of the bench (docs/paper.md section 8):

* spindle sensor: the inner-ring angle (the spindle carries the inner ring);
* cage sensor: the angle of the cage segment carrying the reflective strip
  (``Observation.cage_angle``).

Each sensor emits one pulse per strip passage, its time interpolated inside the chunk, with its
timing jitter (:class:`~bearing_rig_sim.instruments.fibre_optic.FibreOpticSensor`). The measured speeds
come from the pulses alone, through the bench's counter
(:class:`~bearing_rig_sim.instruments.fibre_optic.PulseCounter`): never from the engine's true speed.
The ground truth (true speeds, slip, contact loads) is reported beside them, for the truth topic.

A counter's estimate is the mean speed over its last window of whole revolutions, so it lags a
changing speed. When the pulses stop coming (a shaft slowing to rest), the counter's last
estimate would freeze; the twin instead reports no more than one strip spacing over the time
since the last pulse (the shaft cannot have been faster, or the next strip would have passed),
and 0 once no pulse has come for ``counter_timeout`` seconds, as a bench counter's display falls
to zero.

Units: s, rad, rad/s, rad/s^2, N, m; slip in percent.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from bearing_rig_sim.analysis.slip import BearingKinematics
from bearing_rig_sim.config import shipped_bearing_file
from bearing_rig_sim.dynamics.models import model_parameters
from bearing_rig_sim.dynamics import MIN_AXIAL_LOAD, BearingDynamics, BearingParameters, Mounting, Observation, OperatingEnvelope
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.instruments.base import Reading
from bearing_rig_sim.instruments.fibre_optic import TWO_PI, FibreOpticSensor, Pulse, PulseCounter
from bearing_rig_sim.instruments.registry import InstrumentSet
from bearing_rig_sim.rig.mounting import MountingConfig
from bearing_rig_sim.rig.program import RigLimits
from bearing_rig_sim.simulation.drive import SpindleCommand, SpindleDrive
from bearing_rig_sim.simulation.instruments import TwinInstruments
from bearing_rig_sim.simulation.settings import SimulatorSettings
from bearing_rig_sim.thermal.bearing import ThermalConfig
from bearing_rig_sim.thermal.coupling import ThermalCoupling

CHUNK_STEP_TOLERANCE = 1e-6
"""How close (in engine steps) the chunk length must be to a whole number of engine steps (1)."""


class TwinError(RigError):
    """A twin option out of range (chunk length, timeout, initial state)."""


class AxialLoadError(RigError):
    """An axial force the twin refuses (non-finite or negative); the load stays as it was."""


class MomentError(RigError):
    """A moment the twin refuses (non-finite components, above the rig file's moment limit, or
    any moment on the axisymmetric ``stiff`` model); the loads stay as they were."""


class RadialLoadError(RigError):
    """A radial force the twin refuses (non-finite components, above the rig file's radial
    limit, or any radial load on the axisymmetric ``stiff`` model); the loads stay as they were."""


@dataclass(frozen=True)
class MeasuredSpeeds:
    """What the bench's pulse counters show at the end of a chunk.

    Attributes:
        inner_ring_speed: spindle speed from the spindle pulses, rad/s (0 before the first
            whole-revolution window and after ``counter_timeout`` without pulses).
        cage_speed: cage speed from the cage pulses, rad/s (same rules).
        inner_ring_angle: spindle angle counted by pulses since its first pulse,
            ``2 pi pulse_index / strip_count`` of the latest pulse, rad (0 before any).
        cage_angle: cage angle counted the same way, rad.
    """

    inner_ring_speed: float
    cage_speed: float
    inner_ring_angle: float
    cage_angle: float


@dataclass(frozen=True)
class TruthSummary:
    """The engine's ground truth at the end of a chunk (fields of SimulatorTruth.msg, without the
    pacing figures ``real_time_factor`` and ``overruns``, which belong to the node's loop).

    Speeds rad/s, acceleration rad/s^2, loads N, angles rad, displacement m, slip percent.
    ``slip_rate`` is NaN while the inner ring is at rest (the slip rate is undefined there).
    Contact angles are means over the balls with a non-zero contact load (NaN if none).
    Friction torque N m and power loss W: the engine's dissipation at the chunk's last step.
    ``cage_whirl_radius``: distance of the cage centre from the bearing axis, m.
    ``balls``: the per-ball state (:class:`BallTruth`); ``cage_centre``: the cage centre's (x, y)
    displacement in the bearing frame, m.
    """

    time: float
    inner_ring_speed: float
    inner_ring_acceleration: float
    cage_speed: float
    theoretical_cage_speed: float
    slip_rate: float
    axial_load: float
    inner_contact_load_mean: float
    inner_contact_load_max: float
    outer_contact_load_mean: float
    outer_contact_load_max: float
    pocket_load_max: float
    inner_contact_angle: float
    outer_contact_angle: float
    inner_ring_axial_displacement: float
    step_count: int
    friction_torque: float = 0.0
    power_loss: float = 0.0
    cage_whirl_radius: float = 0.0
    balls: BallTruth | None = None
    cage_centre: tuple[float, float] = (0.0, 0.0)


@dataclass(frozen=True)
class BallTruth:
    """Per ball (index k = ball k, in cage pocket k), from the engine's observation.

    Azimuths from the bearing frame's x axis (the radial load's azimuth is measured from it),
    in [0, 2 pi), rad; orbit and spin speeds rad/s (spin: about the ball's own axis); contact
    loads N (0: out of contact); contact angles rad, of the line from the ball centre to each
    groove's curvature centre (the contact angle where the ball is loaded); pocket loads N,
    > 0 where the ball pushes the cage forward.
    """

    azimuth: np.ndarray
    orbit_speed: np.ndarray
    spin_speed: np.ndarray
    inner_contact_load: np.ndarray
    outer_contact_load: np.ndarray
    inner_contact_angle: np.ndarray
    outer_contact_angle: np.ndarray
    pocket_load: np.ndarray


@dataclass(frozen=True)
class TickOutput:
    """Everything one chunk produced.

    Attributes:
        start_time: simulated time at the chunk's start, s.
        time: simulated time at its end, s.
        spindle_pulses: pulses of the spindle sensor inside the chunk, in time order.
        cage_pulses: pulses of the cage sensor inside the chunk, in time order.
        measured: the counters' speeds and pulse-counted angles at the chunk's end.
        truth: the engine's ground truth at the chunk's end (None if not asked for).
        readings: every instrument's readings inside the chunk by contract topic, in time order
            (the pulses included).
    """

    start_time: float
    time: float
    spindle_pulses: list[Pulse]
    cage_pulses: list[Pulse]
    measured: MeasuredSpeeds
    truth: TruthSummary | None
    readings: dict[str, Sequence[Reading]]


def counted_speed(counter: PulseCounter, strip_count: int, now: float, timeout: float) -> float:
    """The speed a bench counter shows at ``now`` (s), rad/s.

    The counter's latest whole-revolution estimate, capped at one strip spacing over the time
    since the latest pulse (the shaft cannot have turned faster since, or the next strip would
    have passed), and 0 before the first estimate or after ``timeout`` s without a pulse.
    """
    speed = counter.speed
    last = counter.last_pulse_time
    if speed is None or last is None:
        return 0.0
    silent = now - last
    if silent > timeout:
        return 0.0
    if silent > 0.0:
        speed = min(speed, TWO_PI / strip_count / silent)
    return speed


def _mean_where_loaded(values: np.ndarray, loads: np.ndarray) -> float:
    mask = loads > 0.0
    return float(np.mean(values[mask])) if np.any(mask) else math.nan


def twin_options(settings: SimulatorSettings | None = None, rig_file: str | Path | None = None) -> dict[str, Any]:
    """The keyword options of :class:`RigTwin` as the simulator runs it: chunk, start, counter
    timeout and command lead from its ``settings`` (default: the shipped
    ``config/simulator.yaml``), the spindle's and the loaders' limits from ``rig_file`` (default:
    the shipped ``config/rig.yaml``; absent ``combined_loading``: 0 N and 0 N m).

    Raises:
        ConfigError: a file is missing or malformed (naming the file and key).
    """
    s = settings if settings is not None else SimulatorSettings.from_yaml()
    limits = RigLimits.from_rig_file(rig_file)
    return {
        "chunk": s.chunk_s,
        "initial_speed": s.initial_speed_rad_s,
        "initial_axial_load": s.initial_axial_load_n,
        "counter_timeout": s.counter_timeout_s,
        "max_command_lead": s.max_command_lead_s,
        "max_speed": limits.max_speed_rad_s,
        "max_acceleration": limits.max_acceleration_rad_s2,
        "max_radial_load": limits.max_radial_load_n,
        "radial_limit_source": f"combined_loading.max_radial_setpoint_n in {limits.source}",
        "max_moment": limits.max_moment_n_m,
        "moment_limit_source": f"combined_loading.max_moment_setpoint_n_m in {limits.source}",
    }


class RigTwin:
    """The engine, the spindle drive, the axial load and the bench's instruments.

    The options have no defaults here: :func:`twin_options` gives the simulator's (its settings
    and its rig file's limits), which :meth:`from_files` uses.

    Args:
        engine: the dynamics engine; initialised here at ``initial_speed`` and
            ``initial_axial_load``.
        instruments: the bench's instruments (``sensors`` section of ``config/rig.yaml``), among
            them a fibre-optic sensor on the inner ring and one on the cage.
        kinematics: the bearing's geometry for the truth's theoretical cage speed and slip
            (nominal contact angle).
        chunk: default chunk length, s; a whole number of engine time steps.
        initial_speed: spindle speed at the start, rad/s (>= 0).
        initial_axial_load: axial load at the start, N (finite, >= 0; below the engine's
            minimum it is raised to it and flagged, see :meth:`set_axial_load`).
        counter_timeout: a counter shows 0 after this long without a pulse, s (> 0).
        max_speed: highest spindle target speed, rad/s (see :class:`SpindleDrive`).
        max_acceleration: highest spindle acceleration, rad/s^2.
        max_command_lead: how far ahead a command's time may lie, s.
        max_radial_load: largest radial force accepted, N (>= 0; :meth:`from_files` takes it
            from the rig file's ``combined_loading.max_radial_setpoint_n``: 0 for a loading
            chain that loads only axially).
        radial_limit_source: where ``max_radial_load`` comes from, named in a refusal.
        max_moment: largest moment accepted, N m (>= 0; :meth:`from_files`: the rig file's
            ``combined_loading.max_moment_setpoint_n_m``).
        moment_limit_source: where ``max_moment`` comes from, named in a refusal.

    Raises:
        TwinError: an option out of range.
        AxialLoadError: a bad initial load.
        SpindleCommandError: a bad initial speed or limit.
    """

    def __init__(
        self,
        engine: BearingDynamics,
        instruments: InstrumentSet,
        kinematics: BearingKinematics,
        *,
        chunk: float,
        initial_speed: float,
        initial_axial_load: float,
        counter_timeout: float,
        max_speed: float,
        max_acceleration: float,
        max_command_lead: float,
        max_radial_load: float,
        max_moment: float,
        radial_limit_source: str = "max_radial_load",
        moment_limit_source: str = "max_moment",
    ) -> None:
        self.engine = engine
        self.kinematics = kinematics
        self.chunk = self._check_chunk(chunk)
        if isinstance(counter_timeout, bool) or not isinstance(counter_timeout, (int, float)) or not counter_timeout > 0.0:
            raise TwinError(f"counter_timeout: must be > 0 s, got {counter_timeout!r}")
        self.counter_timeout = float(counter_timeout)
        if isinstance(max_radial_load, bool) or not isinstance(max_radial_load, (int, float)) or not max_radial_load >= 0.0:
            raise TwinError(f"max_radial_load: must be >= 0 N, got {max_radial_load!r}")
        self.max_radial_load = float(max_radial_load)
        """Largest radial force accepted, N (:meth:`set_loads`)."""
        self.radial_limit_source = radial_limit_source
        if isinstance(max_moment, bool) or not isinstance(max_moment, (int, float)) or not max_moment >= 0.0:
            raise TwinError(f"max_moment: must be >= 0 N m, got {max_moment!r}")
        self.max_moment = float(max_moment)
        """Largest moment accepted, N m (:meth:`set_loads`)."""
        self.moment_limit_source = moment_limit_source
        self.drive = SpindleDrive(initial_speed, 0.0, max_speed=max_speed, max_acceleration=max_acceleration, max_lead=max_command_lead)
        self.load_clamped = False
        """Whether the latest axial force asked for was below the engine's minimum
        (:data:`~bearing_rig_sim.dynamics.MIN_AXIAL_LOAD`) and was raised to it."""
        self.requested_axial_load = 0.0
        """The latest axial force asked for, N (before raising it to the minimum)."""
        self._load = self._checked_load(initial_axial_load)
        self._radial = 0.0
        self._radial_angle = 0.0
        self._moment = (0.0, 0.0)
        engine.initialise(self.drive.speed_at(0.0), self._load, time=0.0)
        self.instruments = TwinInstruments(instruments)
        """The bench's instruments, shown the motion after each chunk."""
        self.spindle_sensor: FibreOpticSensor = self.instruments.spindle_sensor
        self.cage_sensor: FibreOpticSensor = self.instruments.cage_sensor
        self.spindle_counter: PulseCounter = self.instruments.spindle_counter
        self.cage_counter: PulseCounter = self.instruments.cage_counter
        self._last_index: dict[str, int | None] = {"spindle": None, "cage": None}
        self.step_count = 0
        """Engine integration steps since the start (1)."""
        self._acceleration = 0.0
        self._angles = engine.angles()
        self.thermal: ThermalCoupling | None = None
        """The bearing's thermal network, when attached (:meth:`attach_thermal`): it takes the
        engine's heat chunk by chunk and sets the lubricant's temperature."""

    def attach_thermal(self, bearing_file: str | Path | None = None, *, initial_rise_k: float = 0.0, **options: Any) -> ThermalCoupling:
        """Couple the bearing's thermal network (the bearing file's ``thermal:`` section; default
        the shipped H7006C) to the engine from the next chunk on, every node starting
        ``initial_rise_k`` (K, >= 0) above the file's ambient; ``options`` are those of
        :class:`~bearing_rig_sim.thermal.coupling.ThermalCoupling` (by default coupled both ways:
        the engine's lubricant follows the lubricant node every 0.1 s)."""
        if not math.isfinite(initial_rise_k) or initial_rise_k < 0.0:
            raise TwinError(f"initial_rise_k: must be a finite number >= 0 K, got {initial_rise_k!r}")
        config = ThermalConfig.from_yaml(bearing_file)
        options.setdefault("initial", config.ambient + initial_rise_k)
        coupling = ThermalCoupling(self.engine, config, **options)
        self.instruments.check_thermal(coupling)
        self.thermal = coupling
        return coupling

    @classmethod
    def from_files(
        cls,
        bearing_file: str | Path | None = None,
        calibration_file: str | Path | None = None,
        rig_file: str | Path | None = None,
        *,
        model: str = "reduced",
        bearing_model: str = "bench",
        settings: SimulatorSettings | None = None,
        **options: Any,
    ) -> RigTwin:
        """A twin from a bearing file, an optional calibration overlay and a rig file.

        Args:
            bearing_file: bearing data (default: the shipped one, :data:`~bearing_rig_sim.config.SHIPPED_BEARING_FILE`).
            calibration_file: calibration laid over it (None: none).
            rig_file: rig data with the ``sensors`` section (the instruments) and the test bearing's ``mounting``
                (clearance, misalignment, preload; default: ``config/rig.yaml``).
            model: the engine's model, ``"reduced"`` (real time) or ``"stiff"``.
            bearing_model: the bearing's physics (:data:`~bearing_rig_sim.config.BEARING_MODELS`):
                ``"bench"`` the bearing file with the calibration; ``"paper"`` the paper's own
                model (:mod:`bearing_rig_sim.dynamics.models`; the two files are not used).
            settings: the simulator's settings giving the options (default: the shipped
                ``config/simulator.yaml``); see :func:`twin_options`.
            options: keyword options of :class:`RigTwin` that replace those.

        Raises:
            ConfigError: a file is missing or malformed (naming the file and key).
            StepLimitError: the bearing file's step exceeds the model's stability limit over
                the rig file's envelope (top spindle speed, largest axial load).
        """
        if bearing_model == "bench":
            bearing = Path(bearing_file) if bearing_file is not None else shipped_bearing_file()
            params = BearingParameters.from_yaml(bearing, calibration_file)
        else:
            params = model_parameters(bearing_model)
        mounting = Mounting.of(MountingConfig.from_rig_file(rig_file))
        engine = BearingDynamics(params, model=model, envelope=OperatingEnvelope.from_rig_file(rig_file), mounting=mounting)
        instruments = InstrumentSet.from_rig_file(rig_file)
        kinematics = BearingKinematics(params.ball_diameter, params.pitch_diameter, params.contact_angle)
        return cls(engine, instruments, kinematics, **(twin_options(settings, rig_file) | options))

    def _check_chunk(self, chunk: float) -> float:
        if isinstance(chunk, bool) or not isinstance(chunk, (int, float)) or not math.isfinite(chunk) or not chunk > 0.0:
            raise TwinError(f"chunk: must be a finite number > 0 s, got {chunk!r}")
        steps = chunk / self.engine.time_step
        if steps < 1.0 - CHUNK_STEP_TOLERANCE or abs(steps - round(steps)) > CHUNK_STEP_TOLERANCE:
            raise TwinError(f"chunk: {chunk!r} s is not a whole number of engine time steps ({self.engine.time_step!r} s)")
        return float(chunk)

    # -- inputs --------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        """Simulated time, s."""
        return self.engine.time

    @property
    def axial_load(self) -> float:
        """The axial load the engine applies, N (at least the engine's minimum)."""
        return self._load

    def _checked_load(self, force_n: float) -> float:
        if isinstance(force_n, bool) or not isinstance(force_n, (int, float)) or not math.isfinite(force_n):
            raise AxialLoadError(f"axial force: must be a finite number of newtons, got {force_n!r}")
        if force_n < 0.0:
            raise AxialLoadError(f"axial force: must be >= 0 N (the loading chain pulls, it cannot push), got {force_n!r}")
        self.requested_axial_load = float(force_n)
        self.load_clamped = force_n < MIN_AXIAL_LOAD
        return max(float(force_n), MIN_AXIAL_LOAD)

    def set_axial_load(self, force_n: float) -> float:
        """Apply the axial force ``force_n`` (N) from the next chunk on; returns the force applied.

        A force below the engine's minimum (:data:`~bearing_rig_sim.dynamics.MIN_AXIAL_LOAD`,
        1 N) is raised to it and :attr:`load_clamped` is set (cleared by the next force at or
        above the minimum).

        Raises:
            AxialLoadError: a non-finite or negative force; the load stays as it was.
        """
        self._load = self._checked_load(force_n)
        return self._load

    @property
    def radial_load(self) -> float:
        """The radial load the engine applies, N (>= 0; at :attr:`radial_angle`, see
        :meth:`set_loads`)."""
        return self._radial

    @property
    def radial_angle(self) -> float:
        """The radial load's azimuth from the bearing's x axis, rad (the load zone's azimuth;
        kept from the last non-zero radial force)."""
        return self._radial_angle

    @property
    def moment(self) -> tuple[float, float]:
        """The moment applied across the axis, (torque.x, torque.y) about the bearing frame's x
        and y axes, N m; (0, 0): none, the inner ring's tilts held (see :meth:`set_loads`)."""
        return self._moment

    @property
    def ring_moment(self) -> tuple[float, float]:
        """The moment of the balls' contact loads on the inner ring about the frame's x and y
        axes, N m (same convention as :attr:`moment`): with the tilts held, the reaction the
        spindle's second bearing supplies; under an applied moment, balancing it."""
        mx, my = self.engine.observe().ring_moment
        return my, -mx

    def _checked_pair(self, error: type[RigError], what: str, field: str, unit: str, pair: tuple[float, float], limit: float, source: str) -> float:
        """The magnitude of a load across the axis (``field``.x, ``field``.y), refused with
        ``error`` if a component is not a finite number, above ``limit`` (from ``source``) or
        on the axisymmetric stiff model."""
        for name, value in zip("xy", pair):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise error(f"{what}: {field}.{name} must be a finite number of {unit}, got {value!r}")
        size = math.hypot(*pair)
        symbol = "N" if unit == "newtons" else "N m"
        if size > limit:
            raise error(f"{what}: {size:g} {symbol} is above the rig's limit of {limit:g} {symbol} ({source})")
        if size > 0.0 and self.engine.model != "reduced":
            raise error(f"{what}: {size:g} {symbol} needs the reduced model (the {self.engine.model} model is axisymmetric)")
        return size

    def set_loads(
        self, axial_n: float, radial_x_n: float = 0.0, radial_y_n: float = 0.0, torque_x_n_m: float = 0.0, torque_y_n_m: float = 0.0
    ) -> tuple[float, float]:
        """Apply an axial force, a radial force (its x and y components in the bearing's frame,
        N) and a moment across the axis (about the frame's x and y axes, N m) from the next
        chunk on; returns the axial and radial loads applied, N.

        The radial load is the components' magnitude, at the azimuth atan2(y, x) from the
        bearing's x axis: the engine centres its load zone there (the bearing's frame is the
        engine's, so the zone's place relative to the cage sensor's strip is the bench's). A
        radial force above :attr:`max_radial_load` (the rig file's loading chain) is refused.
        A moment frees the inner ring's two tilts in the engine (``BearingDynamics.set_moment``;
        the engine counts M_x = sum Q_i sin a_i R_i cos psi, which is -torque.y for the axial
        load pushing the ring along +z, and M_y = torque.x); none (both 0) holds them, as the
        spindle's second bearing does, and :attr:`ring_moment` is the reaction. A moment above
        :attr:`max_moment` is refused. The axial force is handled as by
        :meth:`set_axial_load`. All are checked before any is applied.

        Raises:
            AxialLoadError: a non-finite or negative axial force.
            RadialLoadError: a non-finite component, a radial force above the limit, or a
                radial load on the stiff model.
            MomentError: a non-finite component, a moment above the limit, or a moment on the
                stiff model.
            Either way all loads stay as they were.
        """
        radial = self._checked_pair(
            RadialLoadError, "radial force", "force", "newtons", (radial_x_n, radial_y_n), self.max_radial_load, self.radial_limit_source
        )
        self._checked_pair(MomentError, "moment", "torque", "newton metres", (torque_x_n_m, torque_y_n_m), self.max_moment, self.moment_limit_source)
        moment = (float(torque_x_n_m), float(torque_y_n_m))
        self.set_axial_load(axial_n)
        if moment != self._moment:
            self.engine.set_moment(None if moment == (0.0, 0.0) else (-moment[1], moment[0]))
            self._moment = moment
        self._radial = radial
        if radial > 0.0:
            self._radial_angle = math.atan2(radial_y_n, radial_x_n)
        return self._load, self._radial

    def command_spindle(self, command: SpindleCommand) -> None:
        """Give the spindle drive a speed command (see :meth:`SpindleDrive.submit`).

        Raises:
            SpindleCommandError: an invalid command; the drive keeps its previous one.
        """
        self.drive.submit(command, self.engine.time, self.engine.inner_ring_speed)

    # -- one chunk -----------------------------------------------------------------------------
    def tick(self, h: float | None = None, *, with_truth: bool = True) -> TickOutput:
        """Advance the engine by one chunk of ``h`` seconds (default :attr:`chunk`).

        Args:
            h: chunk length, s; a whole number of engine steps.
            with_truth: also summarise the ground truth (about a third of a chunk's cost in
                Python; the node asks for it only when it publishes the truth).

        Returns:
            The pulses of the chunk, every instrument's readings, the counters' speeds and the
            ground truth at its end.

        Raises:
            TwinError: ``h`` not a whole number of engine steps.
            DynamicsDivergedError: the engine's state left what a bearing can do (non-finite,
                a body turning backwards or faster than the inner ring has turned); nothing of
                the chunk is returned and the twin cannot continue (the node halts and reports
                it on /diagnostics; a session then ends with exit status 1).
        """
        h = self.chunk if h is None else self._check_chunk(h)
        engine = self.engine
        _, inner_before, cage_before = self._angles
        t0 = engine.time
        steps = int(round(h / engine.time_step))
        t_end = t0 + steps * engine.time_step
        accel = self.drive.chunk_acceleration(t0, h, engine.inner_ring_speed)
        engine.advance(h, axial_load=self._load, inner_ring_acceleration=accel, radial_load=self._radial, radial_angle=self._radial_angle)
        remaining = t_end - engine.time
        if remaining > 0.5 * engine.time_step:
            # A deceleration that reaches rest inside the chunk: the engine stops integrating
            # there rather than reverse; the rest of the chunk is spent at the profile's speed.
            engine.set_inner_ring_speed(max(self.drive.speed_at(t_end), 0.0))
            engine.advance(remaining, axial_load=self._load, radial_load=self._radial, radial_angle=self._radial_angle)
        self.step_count += steps
        self._acceleration = accel
        if self.thermal is not None:
            self.thermal.advance(t_end - t0)
        self._angles = t1, inner_after, cage_after = engine.angles()
        spindle, cage, readings = self.instruments.observe(t0, t1, (inner_before, cage_before), (inner_after, cage_after), engine.friction_torque, self.thermal)
        if spindle:
            self._last_index["spindle"] = spindle[-1].pulse_index
        if cage:
            self._last_index["cage"] = cage[-1].pulse_index
        truth = self._truth(engine.observe()) if with_truth else None
        return TickOutput(t0, t1, spindle, cage, self.measured(t1), truth, readings)

    def measured(self, now: float | None = None) -> MeasuredSpeeds:
        """The counters' speeds and pulse-counted angles at ``now`` (s; default: the twin's time)."""
        t = self.engine.time if now is None else now
        spindle_n = self.spindle_sensor.strip_count
        cage_n = self.cage_sensor.strip_count
        spindle_i, cage_i = self._last_index["spindle"], self._last_index["cage"]
        return MeasuredSpeeds(
            inner_ring_speed=counted_speed(self.spindle_counter, spindle_n, t, self.counter_timeout),
            cage_speed=counted_speed(self.cage_counter, cage_n, t, self.counter_timeout),
            inner_ring_angle=0.0 if spindle_i is None else TWO_PI * spindle_i / spindle_n,
            cage_angle=0.0 if cage_i is None else TWO_PI * cage_i / cage_n,
        )

    def truth(self) -> TruthSummary:
        """The ground truth now (see :class:`TruthSummary`)."""
        return self._truth(self.engine.observe())

    def _truth(self, obs: Observation) -> TruthSummary:
        inner = obs.inner_ring_speed
        kin = self.kinematics
        slip = kin.slip_rate(obs.cage_speed, inner) if inner > 0.0 else math.nan
        qi, qo = obs.inner_contact_loads, obs.outer_contact_loads
        return TruthSummary(
            time=obs.time,
            inner_ring_speed=inner,
            inner_ring_acceleration=self._acceleration,
            cage_speed=obs.cage_speed,
            theoretical_cage_speed=kin.epicyclic_ratio() * inner,
            slip_rate=slip,
            axial_load=obs.axial_load,
            inner_contact_load_mean=float(np.mean(qi)),
            inner_contact_load_max=float(np.max(qi)),
            outer_contact_load_mean=float(np.mean(qo)),
            outer_contact_load_max=float(np.max(qo)),
            pocket_load_max=float(np.max(np.abs(obs.pocket_loads))),
            inner_contact_angle=_mean_where_loaded(obs.inner_contact_angles, qi),
            outer_contact_angle=_mean_where_loaded(obs.outer_contact_angles, qo),
            inner_ring_axial_displacement=obs.inner_ring_axial_displacement,
            step_count=self.step_count,
            friction_torque=self.engine.friction_torque(),
            power_loss=self.engine.power_loss(),
            cage_whirl_radius=obs.cage_whirl_radius,
            balls=BallTruth(
                azimuth=obs.ball_azimuths,
                orbit_speed=obs.ball_orbit_speeds,
                spin_speed=obs.ball_spin_speeds,
                inner_contact_load=qi,
                outer_contact_load=qo,
                inner_contact_angle=obs.inner_contact_angles,
                outer_contact_angle=obs.outer_contact_angles,
                pocket_load=obs.pocket_loads,
            ),
            cage_centre=obs.cage_centre,
        )
