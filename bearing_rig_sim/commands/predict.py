"""``bearing-rig predict --rpm R [R ...] --load N``: steady cage speed and slip of the calibrated
twin at given speeds and axial loads; on request the thermal steady state, combined loads and
the mounting.

What each row holds and every option: docs/guide.md, section ``bearing-rig predict``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

from bearing_rig_sim.commands import describe, rig_limit_text
from bearing_rig_sim.config import RPM_TO_RAD_S, check_number, mapping_at, read_mapping, rpm_to_rad_s, shipped_bearing_file
from bearing_rig_sim.dynamics import MIN_AXIAL_LOAD, BearingParameters, Mounting
from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
from bearing_rig_sim.dynamics.calibrations import DEFAULT_CALIBRATION, calibration_file
from bearing_rig_sim.dynamics.parameters import overlay_calibration
from bearing_rig_sim.dynamics.quasi_static import LoadCase, QuasiStaticBearing
from bearing_rig_sim.analysis.slip import BearingKinematics, ThrustContact
from bearing_rig_sim.dynamics.models import BENCH, DEFAULT_MODEL, MODELS, model_parameters
from bearing_rig_sim.dynamics.steady import SKID_SLIP_PCT, CageWhirl, SteadySolver, SteadyState, solver_for
from bearing_rig_sim.errors import RigError
from bearing_rig_sim.rig.mounting import MountingConfig
from bearing_rig_sim.settings_model import check_within_rig, read_file, validate_mapping
from bearing_rig_sim.studies.calibration import steady_states


def register(subparsers: Any) -> None:
    """Add ``predict`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("predict", help="steady slip of the calibrated twin", description=describe(__doc__, "predict"))
    p.add_argument(
        "--rpm",
        type=float,
        nargs="+",
        required=True,
        help=f"inner-ring speeds, rpm, {rig_limit_text('spindle.max_speed_rad_s', unit_in_si=RPM_TO_RAD_S, unit=' rpm')}",
    )
    p.add_argument(
        "--load",
        type=float,
        nargs="+",
        required=True,
        help=f"axial loads, N (one, one per speed, or several at one speed), {rig_limit_text('loading_chain.max_setpoint_n', unit=' N')}",
    )
    p.add_argument("--radial-load", type=float, nargs="+", default=None, help="radial loads, N (one, or one per speed): adds the load distribution")
    p.add_argument(
        "--moment", type=float, nargs=2, default=None, metavar=("M_X", "M_Y"), help="moment on the inner ring, N m (default: tilt held, reaction reported)"
    )
    p.add_argument("--model", choices=MODELS, default=None, help="named model: bench (the bench twin, default) or paper (the paper's own model; docs/paper.md)")
    p.add_argument("--bearing", type=Path, default=None, help="bearing file (default: the shipped H7006C)")
    p.add_argument(
        "--calibration",
        type=str,
        default=None,
        help="named calibration (coupled, the default; isothermal) or a calibration file; a coupled one predicts at the thermal steady state",
    )
    p.add_argument("--lubricant", type=Path, default=None, help="lubricant file replacing the bearing file's (config/lubricants/)")
    p.add_argument("--thermal", action="store_true", help="at the thermal steady state (torque, temperatures)")
    p.add_argument("--transient", type=float, default=None, metavar="S", help="warm-up from ambient over S seconds (one row per step)")
    p.add_argument("--transient-step", type=float, default=10.0, metavar="S", help="step of the warm-up rows, s (default 10)")
    p.add_argument("--clearance", type=float, default=0.0, metavar="M", help="extra diametral clearance, m (negative: interference fit)")
    p.add_argument("--misalignment", type=float, nargs=2, default=None, metavar=("THETA_X", "THETA_Y"), help="inner ring tilts held against the outer, rad")
    p.add_argument("--preload-n", type=float, default=0.0, metavar="N", help="spring preload added to the axial load, N")
    p.add_argument("--preload-displacement", type=float, default=0.0, metavar="M", help="rigid preload of a back-to-back pair, m")
    p.add_argument(
        "--running-hours",
        type=float,
        default=None,
        metavar="H",
        help="the grease's state after H hours of running (its file's running_in law; 0: as calibrated)",
    )
    p.add_argument("--json", action="store_true", help="one JSON object per line")
    p.set_defaults(func=run)


def mounting_of(args: argparse.Namespace) -> Mounting | None:
    """The mounting the command line gives (None: none), checked against the ranges of the rig
    file's ``mounting`` section (:class:`~bearing_rig_sim.rig.mounting.MountingConfig`)."""
    stated = {
        "clearance_change_m": args.clearance,
        "misalignment_rad": list(args.misalignment or (0.0, 0.0)),
        "preload_n": args.preload_n,
        "preload_displacement_m": args.preload_displacement,
    }
    mounting = Mounting.of(validate_mapping(MountingConfig, stated, "command line (--clearance, --misalignment, --preload-n, --preload-displacement)"))
    return None if mounting == Mounting() else mounting


RIG_FREE_MAX_RPM = 100_000.0
"""Highest speed for a bearing that is not the rig's (``--bearing``), rpm: spindle bearings of
35 mm bore run to about 100 000 rpm (NASA TP-2275 to 72 000 rpm)."""
RIG_FREE_MAX_LOAD_N = 20_000.0
"""Largest axial load for a bearing that is not the rig's, N."""


def parameters_of(args: argparse.Namespace) -> BearingParameters:
    """The parameters the command line names: a named model (``--model``, with ``--calibration``
    in place of its own), else the bearing, calibration and lubricant files."""
    if args.calibration is not None:
        args.calibration = calibration_file(args.calibration)  # a name of the bench twin's calibrations, or a file
    elif args.model in (None, BENCH) and args.bearing is None and args.lubricant is None:
        args.calibration = calibration_file(DEFAULT_CALIBRATION)
    if args.model is None:
        return load_parameters(args.bearing, args.calibration, args.lubricant)
    if args.bearing is not None or args.lubricant is not None:
        raise RigError("--model names the bearing and lubricant: give --bearing and --lubricant without it")
    return model_parameters(args.model, calibration=args.calibration)


def slip_readings(params: BearingParameters, s: SteadyState) -> dict[str, Any]:
    """The slip against the pure-rolling cage speed at the loaded contact angle of the point's
    axial load (Harris's thrust equilibrium, :class:`~bearing_rig_sim.analysis.slip.ThrustContact`;
    ``slip_loaded_pct``, beside the paper's nominal ``slip_pct``) and ``gross_skid``: the cage
    more than :data:`~bearing_rig_sim.dynamics.steady.SKID_SLIP_PCT` % behind (the balls slide
    instead of rolling; the traction of the contacts cannot carry the resistances)."""
    thrust = ThrustContact(
        params.ball_count,
        params.contact_angle,
        params.inner_curvature_ratio + params.outer_curvature_ratio - 1.0,
        params.ball_diameter,
        params.combined_constant,
    )
    angle = thrust.loaded_contact_angle(s.axial_load)
    loaded = BearingKinematics(params.ball_diameter, params.pitch_diameter, angle)
    return {
        "slip_loaded_pct": round(float(loaded.slip_rate(s.cage_speed, s.inner_ring_speed)), 4),
        "loaded_contact_angle_deg": round(math.degrees(angle), 4),
        "gross_skid": bool(s.slip_pct > SKID_SLIP_PCT),
    }


def load_parameters(bearing: Path | None, calibration: Path | None, lubricant: Path | None) -> BearingParameters:
    """The bearing file with the calibration laid over it and, with ``lubricant``, that lubricant
    file in place of the bearing file's (the calibration then only when named explicitly). The
    shipped calibration belongs to the shipped bearing: another bearing file gets it only when
    named."""
    path = bearing or shipped_bearing_file()
    doc, source = read_mapping(path), str(path)
    if lubricant is not None:
        lub = mapping_at(doc, ("lubricant",), source)
        doc["lubricant"] = {**lub, "file": str(lubricant.resolve()) if lubricant.suffix else lubricant.name}
    if bearing is not None and calibration is None:
        return BearingParameters.from_mapping(doc, source)
    if lubricant is None or calibration is not None:
        calibration = calibration or calibration_file(DEFAULT_CALIBRATION)
        doc, source = overlay_calibration(doc, read_file(CalibrationFile, calibration)), f"{source} + {calibration}"
    return BearingParameters.from_mapping(doc, source)


def run(args: argparse.Namespace) -> int:
    """Run each point to a steady state and print cage speed and slip."""
    if len(args.rpm) == 1 and len(args.load) > 1:
        args.rpm = args.rpm * len(args.load)  # several loads at one speed
    if len(args.load) not in (1, len(args.rpm)):
        raise RigError(f"--load takes one value, one per speed ({len(args.rpm)}) or several at one speed, got {len(args.load)}")
    loads = args.load * len(args.rpm) if len(args.load) == 1 else args.load
    # the rig file's limits bound the rig's bearing; another bearing (--bearing, e.g. NASA TP-2275
    # at 72 000 rpm) is not on this rig and is held to its plausible ranges only
    on_rig = args.bearing is None
    for n in args.rpm:
        check_number(n, "command line", "--rpm", gt=0.0, le=RIG_FREE_MAX_RPM)
        if on_rig:
            check_within_rig(n, "command line", "--rpm", "spindle.max_speed_rad_s", unit_in_si=RPM_TO_RAD_S, unit=" rpm")
    for f in loads:
        check_number(f, "command line", "--load", ge=MIN_AXIAL_LOAD, le=RIG_FREE_MAX_LOAD_N)
        if on_rig:
            check_within_rig(f, "command line", "--load", "loading_chain.max_setpoint_n", unit=" N")
    if args.transient is not None:
        check_number(args.transient, "command line", "--transient", gt=0.0, le=36000.0)
        check_number(args.transient_step, "command line", "--transient-step", gt=0.0, le=3600.0)
    radial = _radial_loads(args)
    params = parameters_of(args)
    if args.running_hours is not None:
        params = _after_running(params, args.running_hours)
    mounting = mounting_of(args)
    if radial is None and mounting is None and _thermal_calibration(args):
        args.thermal = True  # the coupled twin: its lubricant at the temperature its heat gives it
    if args.thermal or args.transient is not None:
        if mounting is not None:
            raise RigError("--clearance, --misalignment, --preload-n and --preload-displacement take the non-thermal path only (no --thermal, --transient)")
        return _run_thermal(args, params, loads, radial)
    if mounting is not None:
        return _run_mounted(args, params, loads, radial, mounting)
    states = steady_states(params, [(rpm_to_rad_s(n), f) for n, f in zip(args.rpm, loads)])
    unc = _uncertainty(args)
    for k, s in enumerate(states):
        combined = radial is not None and (radial[k] > 0.0 or args.moment is not None)
        whirl: dict[str, Any] | None = None
        if radial is not None and combined:
            solver = solver_for(params)
            s = solver.periodic(s.inner_ring_speed, s.axial_load, radial[k], moment=None if args.moment is None else (args.moment[0], args.moment[1]))
            whirl = whirl_row(solver.engine.cage_whirl_radius, solver.last_whirl)
        row: dict[str, Any] = dict(s.as_row())
        row["rpm"] = round(row["rpm"], 3)
        if unc is not None and not combined:
            _add_interval(row, params, unc, s.inner_ring_speed, s.axial_load, s.slip_pct)
        row.update(s.losses_row(params.composite_roughness))
        if not combined:
            row.update(slip_readings(params, s))
        row["model"] = args.model or DEFAULT_MODEL
        if radial is not None:
            row.update(load_distribution_row(params, s.inner_ring_speed, s.axial_load, radial[k], args.moment))
        if whirl is not None:
            row.update(whirl)
        _print(row, args.json)
    return 0


def whirl_row(radius: float, whirl: CageWhirl | None) -> dict[str, Any]:
    """The cage whirl's figures for ``predict``: ``cage_whirl_radius_um`` (the centre's distance
    from the axis at the window's end, um), ``cage_whirl_frequency_hz`` (signed, > 0 in the
    cage's direction of rotation) and ``cage_whirl_ratio`` (over the cage's rotation
    frequency), both None with ``cage_whirl_reason`` when the centre does not orbit
    (:func:`~bearing_rig_sim.dynamics.steady.cage_whirl`)."""
    frequency = None if whirl is None else whirl.frequency
    ratio = None if whirl is None else whirl.ratio
    return {
        "cage_whirl_radius_um": round(radius * 1e6, 3),
        "cage_whirl_frequency_hz": None if frequency is None else round(frequency, 4),
        "cage_whirl_ratio": None if ratio is None else round(ratio, 4),
        "cage_whirl_reason": "no averaging window" if whirl is None else whirl.reason,
    }


def _run_mounted(args: argparse.Namespace, params: BearingParameters, loads: list[float], radial: list[float] | None, mounting: Mounting) -> int:
    """Each point's steady state with the engine mounted as ``mounting`` (one engine, in this
    process): the direct solver, or the periodic state under a misalignment or a combined load."""
    solver = SteadySolver(params, mounting=mounting)
    moment = None if args.moment is None else (float(args.moment[0]), float(args.moment[1]))
    for k, (n, f) in enumerate(zip(args.rpm, loads)):
        omega = rpm_to_rad_s(n)
        side = radial[k] if radial is not None else 0.0
        periodic = mounting.misalignment != (0.0, 0.0) or side > 0.0 or moment is not None
        s = solver.periodic(omega, f, side, moment=moment) if periodic else solver.solve(omega, f)
        row: dict[str, Any] = dict(s.as_row())
        row["rpm"] = round(row["rpm"], 3)
        row.update(s.losses_row(params.composite_roughness))
        row["clearance_um"] = round(mounting.clearance * 1e6, 4)
        row["misalignment_mrad"] = [round(t * 1e3, 5) + 0.0 for t in mounting.misalignment]
        row["preload_n"] = mounting.preload_force
        row["preload_displacement_um"] = round(mounting.preload_displacement * 1e6, 4)
        if radial is not None:
            row.update(load_distribution_row(params, omega, f + mounting.preload_force, side, args.moment, mounting))
        if periodic:
            row.update(whirl_row(solver.engine.cage_whirl_radius, solver.last_whirl))
        _print(row, args.json)
    return 0


def _after_running(params: BearingParameters, hours: float) -> BearingParameters:
    """The bearing after ``hours`` of running (``--running-hours``; :mod:`~bearing_rig_sim.dynamics.running_in`)."""
    from bearing_rig_sim.dynamics.running_in import SECONDS_PER_HOUR, RunningInError, at_running_time

    check_number(hours, "command line", "--running-hours", ge=0.0, le=100000.0)
    try:
        return at_running_time(params, hours * SECONDS_PER_HOUR)
    except RunningInError as exc:
        raise RigError(f"--running-hours: {exc}") from None


def _uncertainty(args: argparse.Namespace) -> Any:
    """The calibration's uncertainty block, when the calibration in use has one."""
    from bearing_rig_sim.studies.uncertainty import read_uncertainty

    if (args.lubricant is not None or args.bearing is not None) and args.calibration is None:
        return None
    if args.model not in (None, BENCH) and args.calibration is None:
        return None  # the paper model reproduces a model: no bench uncertainty to state
    return read_uncertainty(args.calibration or calibration_file(DEFAULT_CALIBRATION))


def _model_form(args: argparse.Namespace) -> Any:
    """The calibration's model-form block (:class:`~bearing_rig_sim.studies.priors.ModelForm`),
    or None."""
    from bearing_rig_sim.studies.priors import ModelForm

    block = read_file(CalibrationFile, args.calibration or calibration_file(DEFAULT_CALIBRATION)).uncertainty or {}
    return ModelForm.from_dict(block["model_form"]) if "model_form" in block else None


def _thermal_calibration(args: argparse.Namespace) -> bool:
    """Whether the calibration in use was fitted through the thermal steady states
    (``calibration.thermal`` of its file)."""
    if (args.lubricant is not None or args.bearing is not None) and args.calibration is None:
        return False
    if args.model not in (None, BENCH) and args.calibration is None:
        return False
    return read_file(CalibrationFile, args.calibration or calibration_file(DEFAULT_CALIBRATION)).calibration.thermal


def _add_interval(
    row: dict[str, Any],
    params: BearingParameters,
    unc: Any,
    omega: float,
    load: float,
    slip: float,
    thermal: Any = None,
    form: Any = None,
    reference: BearingParameters | None = None,
) -> None:
    """``slip_pct_low`` / ``slip_pct_high``: the 95 % interval from the parameter and load
    uncertainty (:func:`bearing_rig_sim.studies.uncertainty.slip_interval`; with ``thermal``,
    through the coupled thermal steady state); with the calibration's ``form``
    (:class:`~bearing_rig_sim.studies.priors.ModelForm`), widened on each side in quadrature by
    the spread of the refitted twin over its unmeasured inputs (:mod:`bearing_rig_sim.studies.priors`,
    at the point with ``reference``, the calibration's parameters, and the thermal data
    ``thermal``; the gradients are then ``params``' at the steady temperature;
    ``slip_pct_parametric_low`` / ``_high`` and ``model_form_pp`` state the parts)."""
    from bearing_rig_sim.studies.priors import ThermalRunawayError, point_effects, spread, widen
    from bearing_rig_sim.studies.uncertainty import Z95, parametric_sd, slip_gradients

    g_theta, g_load = slip_gradients(params, unc, omega, load, slip, thermal if form is None else None)
    sd = parametric_sd(unc, g_theta, g_load)
    if form is None or reference is None:
        row["slip_pct_low"] = round(slip - Z95 * sd, 4)
        row["slip_pct_high"] = round(slip + Z95 * sd, 4)
        return
    try:
        effects = point_effects(reference, thermal, omega, load)
    except ThermalRunawayError as exc:  # a draw of the priors has no steady state here: no model-form spread to state
        row["slip_pct_low"] = round(slip - Z95 * sd, 4)
        row["slip_pct_high"] = round(slip + Z95 * sd, 4)
        row["model_form_pp"] = None
        row["model_form_reason"] = str(exc)
        return
    lo_shift, hi_shift, kept = spread(effects.effects, form, g_theta)
    low, high = widen(slip, sd, lo_shift, hi_shift)
    row["slip_pct_low"] = round(low, 4)
    row["slip_pct_high"] = round(high, 4)
    row["slip_pct_parametric_low"] = round(slip - Z95 * sd, 4)
    row["slip_pct_parametric_high"] = round(slip + Z95 * sd, 4)
    row["model_form_pp"] = {
        "low": round(lo_shift, 4),
        "high": round(hi_shift, 4),
        "draws_kept": kept,
        "short_hold_lubricant_c": round(effects.short_hold_temperature_c, 2),
    }


def _print(row: dict[str, Any], as_json: bool) -> None:
    if as_json:
        print(json.dumps(row))
        return
    if "time_s" in row:
        print(
            f"{row['time_s']:8.1f} s   outer ring {row['outer_ring_c']:6.2f} degC   lubricant {row['lubricant_c']:6.2f} degC   torque {row['friction_torque_nm'] * 1e3:7.2f} N mm"
        )
        return
    line = (
        f"{row['rpm']:8.1f} rpm {row['axial_load_n']:7.1f} N   cage {row['cage_rpm']:9.3f} rpm   slip {row['slip_pct']:7.3f} %"
        f"   torque {row['friction_torque_nm'] * 1e3:7.2f} N mm   power {row['power_loss_w']:7.2f} W"
    )
    if "slip_pct_low" in row:
        line += f"   slip 95 % [{row['slip_pct_low']:.3f}, {row['slip_pct_high']:.3f}] %"
    if "slip_loaded_pct" in row:
        line += f"   loaded-angle slip {row['slip_loaded_pct']:7.3f} %" + ("   GROSS SKID" if row["gross_skid"] else "")
    if "loaded_balls" in row:
        line += (
            f"   Q {row['ball_load_min_n']:.1f}-{row['ball_load_max_n']:.1f} N on {row['loaded_balls']} balls at {row['contact_angle_max_load_deg']:.2f} deg"
        )
    if "outer_ring_temperature_c" in row:
        line += f"   outer ring {row['outer_ring_temperature_c']:6.2f} degC"
    print(line)


def _run_thermal(args: argparse.Namespace, params: BearingParameters, loads: list[float], radial: list[float] | None = None) -> int:
    from bearing_rig_sim.config import rad_s_to_rpm
    from bearing_rig_sim.thermal.bearing import ThermalConfig
    from bearing_rig_sim.thermal.coupling import params_at_temperature, thermal_steady_state, warm_up

    cfg = ThermalConfig.from_yaml(args.bearing)
    moment = None if args.moment is None else (float(args.moment[0]), float(args.moment[1]))
    for k, (n, f) in enumerate(zip(args.rpm, loads)):
        omega = rpm_to_rad_s(n)
        f_r = radial[k] if radial is not None else 0.0
        combined = radial is not None and (f_r > 0.0 or moment is not None)
        if args.transient is not None:
            extra = {"radial_load_n": f_r} if combined else {}
            for r in warm_up(params, cfg, omega, f, args.transient, step=args.transient_step, radial_load=f_r, moment=moment):
                _print({"rpm": n, "axial_load_n": f, **extra, **r}, args.json)
            continue
        ts = thermal_steady_state(params, cfg, omega, f, radial_load=f_r, moment=moment) if combined else thermal_steady_state(params, cfg, omega, f)
        s = ts.point
        row: dict[str, Any] = dict(s.as_row())
        row["rpm"] = round(rad_s_to_rpm(omega), 3)
        row.update(s.losses_row(params.composite_roughness))
        if not combined:
            row.update(slip_readings(params, s))
        row["outer_ring_temperature_c"] = round(ts.temperatures["outer_ring"], 2)
        row["lubricant_temperature_c"] = round(ts.temperatures["lubricant"], 2)
        row["temperatures_c"] = {k: round(v, 2) for k, v in ts.temperatures.items()}
        row["heat_w"] = {
            "inner_contacts": round(ts.sources.inner_contacts, 4),
            "outer_contacts": round(ts.sources.outer_contacts, 4),
            "drag": round(ts.sources.drag, 4),
            "land": round(ts.sources.land, 4),
            "rolling_and_pockets": round(ts.sources.rolling_and_pockets, 4),
        }
        row["time_constants_s"] = [round(t, 1) for t in ts.time_constants[:3]]
        row["thermal_residual_k"] = round(ts.residual_k, 3)
        unc = None if combined else _uncertainty(args)  # the calibration's interval is an axial-load one
        if unc is not None:
            form = _model_form(args) if _thermal_calibration(args) else None
            if form is not None:
                # the coupled twin: its unmeasured inputs widen the interval (model form); the
                # parameters' gradients are taken at the steady temperature
                warm = params_at_temperature(params, ts.temperatures["lubricant"])
                _add_interval(row, warm, unc, omega, f, s.slip_pct, cfg, form, reference=params)
            elif _thermal_calibration(args):
                # fitted through the thermal steady states: so are the interval's gradients
                _add_interval(row, params, unc, omega, f, s.slip_pct, cfg)
            else:
                _add_interval(row, params_at_temperature(params, ts.temperatures["lubricant"]), unc, omega, f, s.slip_pct)
        if combined:
            iso_pt = solver_for(params).periodic(omega, f, f_r, moment=moment)
            iso_slip, iso_torque = iso_pt.slip_pct, iso_pt.friction_torque
        else:
            iso = steady_states(params, [(omega, f)], workers=1)[0]
            iso_slip, iso_torque = iso.slip_pct, iso.friction_torque
        row["isothermal"] = {"temperature_c": params.lubricant_temperature, "slip_pct": round(iso_slip, 4), "friction_torque_nm": round(iso_torque, 6)}
        row["model"] = args.model or DEFAULT_MODEL
        if args.calibration is not None:
            row["calibration"] = Path(args.calibration).name
        if radial is not None:
            row.update(load_distribution_row(params, omega, f, f_r, args.moment))
        _print(row, args.json)
    return 0


def _radial_loads(args: argparse.Namespace) -> list[float] | None:
    """The radial load of each point, N (None without ``--radial-load``)."""
    if args.radial_load is None:
        if args.moment is not None:
            raise RigError("--moment needs --radial-load (give 0 for none)")
        return None
    if len(args.radial_load) not in (1, len(args.rpm)):
        raise RigError(f"--radial-load takes one value or one per speed ({len(args.rpm)}), got {len(args.radial_load)}")
    for f in args.radial_load:
        check_number(f, "command line", "--radial-load", ge=0.0, le=20000.0)
    for m in args.moment or ():
        check_number(m, "command line", "--moment", ge=-1000.0, le=1000.0)
    return list(args.radial_load) * len(args.rpm) if len(args.radial_load) == 1 else list(args.radial_load)


def load_distribution_row(
    params: BearingParameters, omega: float, axial: float, radial: float, moment: list[float] | None, mounting: Mounting | None = None
) -> dict[str, Any]:
    """The quasi-static load distribution's figures for ``predict`` (N, deg, N m); with
    ``mounting``, its clearance and misalignment (a spring preload is in ``axial``)."""
    fit = mounting or Mounting()
    case = LoadCase(
        axial,
        radial,
        None if moment is None else (float(moment[0]), float(moment[1])),
        inner_ring_speed=omega,
        clearance=fit.clearance,
        misalignment=fit.misalignment,
    )
    sol = QuasiStaticBearing(params).solve(case)
    row: dict[str, Any] = {
        "radial_load_n": radial,
        "ball_load_max_n": round(sol.ball_load_max, 3),
        "ball_load_min_n": round(sol.ball_load_min, 3),
        "loaded_balls": sol.loaded_balls,
        "contact_angle_max_load_deg": round(math.degrees(sol.contact_angle_at_max_load), 4),
    }
    if moment is None:
        row["reaction_moment_n_m"] = [round(m, 5) + 0.0 for m in sol.reaction_moment]
    else:
        row["moment_n_m"] = [float(m) for m in moment]
        row["tilt_mrad"] = [round(t * 1e3, 5) + 0.0 for t in sol.tilt]
    return row
