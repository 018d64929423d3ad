"""``bearing-rig predict --rpm R [R ...] --load N``: steady cage speed and slip from the calibrated
engine (one JSON object per line with ``--json``)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from bearing_rig_sim.studies.calibration import steady_states
from bearing_rig_sim.config import check_number, config_path, rpm_to_rad_s
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.errors import RigError


def register(subparsers: Any) -> None:
    """Add ``predict`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("predict", help="steady slip of the calibrated twin", description=__doc__)
    p.add_argument("--rpm", type=float, nargs="+", required=True, help="inner-ring speeds, rpm")
    p.add_argument("--load", type=float, nargs="+", required=True, help="axial loads, N (one, or one per speed)")
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
    params = BearingParameters.from_yaml(args.bearing, args.calibration or config_path("calibration", "h7006c_table3.yaml"))
    states = steady_states(params, [(rpm_to_rad_s(n), f) for n, f in zip(args.rpm, loads)])
    for s in states:
        row: dict[str, Any] = dict(s.as_row())
        row["rpm"] = round(row["rpm"], 3)
        row.update(s.losses_row(params.composite_roughness))
        print(
            json.dumps(row)
            if args.json
            else f"{row['rpm']:8.1f} rpm {row['axial_load_n']:7.1f} N   cage {row['cage_rpm']:9.3f} rpm   slip {row['slip_pct']:7.3f} %"
            f"   torque {row['friction_torque_nm'] * 1e3:7.2f} N mm   power {row['power_loss_w']:7.2f} W"
        )
    return 0
