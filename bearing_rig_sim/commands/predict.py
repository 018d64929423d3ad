"""``bearing-rig predict --rpm R [R ...] --load N``: steady cage speed and slip from the calibrated
engine (one JSON object per line with ``--json``).

With ``--radial-load`` (and ``--moment``) each point also gets the quasi-static load
distribution under the combined load (dynamics/quasi_static.py): ``ball_load_max_n``,
``ball_load_min_n``, ``loaded_balls``, ``contact_angle_max_load_deg`` and, with the tilt held
(no ``--moment``), ``reaction_moment_n_m`` [M_x, M_y]. The slip is still that of the axial load
(the dynamic engine is axisymmetric); ``cage_whirl_radius_um`` is not computed (no cage whirl)."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

from bearing_rig_sim.studies.calibration import steady_states
from bearing_rig_sim.config import check_number, config_path, rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.quasi_static import LoadCase, QuasiStaticBearing
from bearing_rig_sim.errors import RigError


def register(subparsers: Any) -> None:
    """Add ``predict`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("predict", help="steady slip of the calibrated twin", description=__doc__)
    p.add_argument("--rpm", type=float, nargs="+", required=True, help="inner-ring speeds, rpm")
    p.add_argument("--load", type=float, nargs="+", required=True, help="axial loads, N (one, or one per speed)")
    p.add_argument("--radial-load", type=float, nargs="+", default=None, help="radial loads, N (one, or one per speed): adds the load distribution")
    p.add_argument("--moment", type=float, nargs=2, default=None, metavar=("M_X", "M_Y"), help="moment on the inner ring, N m (default: tilt held, reaction reported)")
    p.add_argument("--bearing", type=Path, default=None, help="bearing file (default: config/bearings/h7006c.yaml)")
    p.add_argument("--calibration", type=Path, default=None, help="calibration file (default: config/calibration/h7006c_table3.yaml)")
    p.add_argument("--json", action="store_true", help="one JSON object per line")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run each point to a steady state and print cage speed and slip."""
    if len(args.load) not in (1, len(args.rpm)):
        raise RigError(f"--load takes one value or one per speed ({len(args.rpm)}), got {len(args.load)}")
    loads = args.load * len(args.rpm) if len(args.load) == 1 else args.load
    for n in args.rpm:
        check_number(n, "command line", "--rpm", gt=0.0, le=30000.0)
    for f in loads:
        check_number(f, "command line", "--load", ge=1.0, le=20000.0)
    radial = _radial_loads(args)
    params = BearingParameters.from_yaml(args.bearing, args.calibration or config_path("calibration", "h7006c_table3.yaml"))
    states = steady_states(params, [(rpm_to_rad_s(n), f) for n, f in zip(args.rpm, loads)])
    for k, s in enumerate(states):
        row: dict[str, Any] = dict(s.as_row())
        row["rpm"] = round(row["rpm"], 3)
        row.update(s.losses_row(params.composite_roughness))
        if radial is not None:
            row.update(load_distribution_row(params, s.inner_ring_speed, s.axial_load, radial[k], args.moment))
        print(
            json.dumps(row)
            if args.json
            else f"{row['rpm']:8.1f} rpm {row['axial_load_n']:7.1f} N   cage {row['cage_rpm']:9.3f} rpm   slip {row['slip_pct']:7.3f} %"
            f"   torque {row['friction_torque_nm'] * 1e3:7.2f} N mm   power {row['power_loss_w']:7.2f} W"
            + (
                f"   Q {row['ball_load_min_n']:.1f}-{row['ball_load_max_n']:.1f} N on {row['loaded_balls']} balls"
                f" at {row['contact_angle_max_load_deg']:.2f} deg"
                if "loaded_balls" in row
                else ""
            )
        )
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


def load_distribution_row(params: BearingParameters, omega: float, axial: float, radial: float, moment: list[float] | None) -> dict[str, Any]:
    """The quasi-static load distribution's figures for ``predict`` (N, deg, N m)."""
    case = LoadCase(axial, radial, None if moment is None else (float(moment[0]), float(moment[1])), inner_ring_speed=omega)
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
