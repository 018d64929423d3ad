"""``bearing-rig calibrate DATA.csv``: fit the engine's uncertain resistances to bench slip data.

The thermal fit and where the result goes: docs/guide.md, section ``bearing-rig calibrate``."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from bearing_rig_sim.studies.calibration import DEFAULT_FITTED, calibrate, read_bench_csv, write_calibration
from bearing_rig_sim.studies.uncertainty import LOAD_SIGMA_N, check_identifiable, fit_uncertainty
from bearing_rig_sim.commands import describe, output_file
from bearing_rig_sim.config import check_number, rad_s_to_rpm
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.parameters import CALIBRATABLE
from bearing_rig_sim.thermal.bearing import ThermalConfig


def register(subparsers: Any) -> None:
    """Add ``calibrate`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("calibrate", help="fit uncertain resistances to bench slip data", description=describe(__doc__, "calibrate"))
    p.add_argument("data", type=Path, help="CSV with columns inner_ring_rpm, axial_load_n, slip_pct")
    p.add_argument("--bearing", type=Path, default=None, help="bearing file (default: the shipped H7006C)")
    p.add_argument("--fit", nargs="+", default=list(DEFAULT_FITTED), choices=sorted(CALIBRATABLE), help="parameters to fit")
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="calibration file to write (default: out/calibration/<data>.yaml; the shipped config/calibration/ files change only when named here)",
    )
    p.add_argument("--force", action="store_true", help="replace the --out file if it exists")
    p.add_argument(
        "--load-sigma",
        type=float,
        default=LOAD_SIGMA_N,
        metavar="N",
        help=f"standard uncertainty of the bench's axial load, N (a nuisance offset common to all rows; default {LOAD_SIGMA_N:g})",
    )
    p.add_argument("--thermal", action="store_true", help="fit the coupled thermal steady states (the bench's warm slips; the bearing file's thermal: section)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Calibrate, write the calibration file, print the RMS difference."""
    points = read_bench_csv(args.data)
    out = output_file(args.out or Path("out") / "calibration" / f"{args.data.stem}.yaml", "--out", overwrite=args.force)
    check_number(args.load_sigma, "command line", "--load-sigma", ge=0.0, le=1000.0)
    thermal = ThermalConfig.from_yaml(args.bearing) if args.thermal else None
    result = calibrate(BearingParameters.from_yaml(args.bearing), points, fitted=tuple(args.fit), thermal=thermal)
    names = tuple(result.fitted)
    unc = fit_uncertainty(
        result.params,
        [(p.inner_ring_speed, p.axial_load, p.slip_pct) for p in points],
        names,
        [result.fitted[n] for n in names],
        load_sigma_n=args.load_sigma,
        thermal=thermal,
    )
    check_identifiable(names, np.array(unc.noise_correlation), unc.condition_number)  # refused before anything is written
    write_calibration(result, out, args.data.name)
    with out.open("a", encoding="utf-8") as stream:
        stream.write(yaml.safe_dump({"uncertainty": unc.as_dict()}, sort_keys=False))
    if args.json:
        print(
            json.dumps(
                {
                    "fitted": result.fitted,
                    "fixed": result.fixed,
                    "rms_slip_pct": result.rms_pct,
                    "thermal": result.thermal,
                    "file": str(out),
                    "uncertainty": unc.as_dict(),
                }
            )
        )
        return 0
    print(f"{'rpm':>8} {'load N':>8} {'bench %':>8} {'twin %':>8} {'diff pp':>8}" + (f" {'lub degC':>8} {'outer degC':>10}" if result.thermal else ""))
    for p, s in zip(result.points, result.predicted):
        line = f"{rad_s_to_rpm(p.inner_ring_speed):8.0f} {p.axial_load:8.1f} {p.slip_pct:8.3f} {s.slip_pct:8.3f} {s.slip_pct - p.slip_pct:8.3f}"
        if result.thermal:
            line += f" {s.lubricant_temperature:8.2f} {s.outer_ring_temperature:10.2f}"
        print(line)
    for name, value, se in zip(unc.names, unc.values, unc.standard_errors):
        print(f"fitted {name} = {value:.6g} +- {100 * se:.1f} % (standard error, load uncertainty +-{unc.load_sigma_n:g} N included)")
    for a in range(len(names)):
        for b in range(a + 1, len(names)):
            print(f"correlation {names[a]} / {names[b]}: {unc.correlation[a][b]:+.3f} (data alone {unc.noise_correlation[a][b]:+.3f})")
    for name, c in zip(names, unc.load_correlation):
        print(f"correlation {name} / true load, data alone: {c:+.3f}" + ("  (not separable from the load by these rows)" if abs(c) > 0.99 else ""))
    for name, value in result.fixed.items():
        print(f"fixed  {name} = {value:.6g}")
    print(f"RMS difference: {result.rms_pct:.3f} percentage points ({result.evaluations} model evaluations)")
    print(f"written: {out}")
    return 0
