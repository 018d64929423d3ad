"""``bearing-rig calibrate DATA.csv``: fit the engine's uncertain resistances to bench slip data.

The thermal fit and where the result goes: docs/guide.md, section ``bearing-rig calibrate``."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from bearing_rig_sim.studies.bench_run import is_run_file
from bearing_rig_sim.studies.calibration import (
    DEFAULT_FITTED,
    PAPER_HEADER,
    CalibrationResult,
    calibrate,
    calibration_entries,
    read_bench_csv,
    with_values,
    write_calibration,
)
from bearing_rig_sim.studies.uncertainty import LOAD_SIGMA_N, check_identifiable, fit_uncertainty
from bearing_rig_sim.commands import describe, output_file
from bearing_rig_sim.config import ConfigError, check_number, rad_s_to_rpm
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.dynamics.calibrations import NAMED, calibration_file
from bearing_rig_sim.dynamics.models import MODELS, PAPER, model_parameters
from bearing_rig_sim.dynamics.parameters import CALIBRATABLE
from bearing_rig_sim.thermal.bearing import ThermalConfig


def register(subparsers: Any) -> None:
    """Add ``calibrate`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("calibrate", help="fit uncertain resistances to bench slip data", description=describe(__doc__, "calibrate"))
    p.add_argument(
        "data",
        type=Path,
        help="CSV with columns inner_ring_rpm, axial_load_n, slip_pct; or a bench run adding hold_s, outer_ring_temperature_c, friction_torque_n_mm (with --thermal)",
    )
    p.add_argument("--bearing", type=Path, default=None, help="bearing file (default: the shipped H7006C)")
    p.add_argument("--model", choices=MODELS, default=None, help="start from a named model's files, uncalibrated (instead of --bearing)")
    p.add_argument("--fit", nargs="+", default=list(DEFAULT_FITTED), choices=sorted(CALIBRATABLE), help="parameters to fit")
    p.add_argument(
        "--fix",
        nargs="+",
        default=[],
        metavar="NAME=VALUE",
        help="parameters held at a value during the fit and written with it (e.g. consistency_temperature_exponent=0)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=None,
        help="calibration file to write, or a named calibration (coupled, isothermal: its shipped file) (default: out/calibration/<data>.yaml; the shipped files change only when named here, with --force)",
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
    points = [] if is_run_file(args.data) else read_bench_csv(args.data)
    target = calibration_file(str(args.out)) if args.out is not None and str(args.out) in NAMED else args.out  # a named calibration's file
    out = output_file(target or Path("out") / "calibration" / f"{args.data.stem}.yaml", "--out", overwrite=args.force)
    check_number(args.load_sigma, "command line", "--load-sigma", ge=0.0, le=1000.0)
    thermal = ThermalConfig.from_yaml(args.bearing) if args.thermal else None
    if args.model is not None and args.bearing is not None:
        raise ConfigError("command line", "--model", "names the bearing file: give --model or --bearing, not both")
    params = model_parameters(args.model, calibrated=False) if args.model is not None else BearingParameters.from_yaml(args.bearing)
    if is_run_file(args.data):
        if thermal is None:
            raise ConfigError("command line", "--thermal", f"{args.data} is a bench run (hold, temperature or torque columns): it needs --thermal")
        return _calibrate_run(args, with_values(params, _fixed_values(args.fix)), thermal, out)
    result = calibrate(params, points, fitted=tuple(args.fit), fixed=_fixed_values(args.fix), thermal=thermal)
    if args.model == PAPER:
        # The paper model is fitted to another model's output, which has no bench noise and no
        # load uncertainty: there is no interval to state, only the fit's RMS.
        write_calibration(result, out, args.data.name, PAPER_HEADER)
        _print_rows(result)
        for name, value in result.fitted.items():
            print(f"fitted {name} = {value:.6g}")
        print(f"RMS difference: {result.rms_pct:.3f} percentage points ({result.evaluations} model evaluations)")
        print(f"written: {out}")
        return 0
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
    block = unc.as_dict()
    if thermal is not None:
        # the coupled twin's unmeasured inputs at the rows, for the model-form part of predict's intervals
        from bearing_rig_sim.studies.priors import model_form

        rows = [(p.inner_ring_speed, p.axial_load) for p in points]
        block["model_form"] = model_form(result.params, thermal, rows, names, np.array(unc.jacobian)).as_dict()
    write_calibration(result, out, args.data.name)
    with out.open("a", encoding="utf-8") as stream:
        stream.write(yaml.safe_dump({"uncertainty": block}, sort_keys=False))
    if args.json:
        print(
            json.dumps(
                {
                    "fitted": result.fitted,
                    "fixed": result.fixed,
                    "rms_slip_pct": result.rms_pct,
                    "thermal": result.thermal,
                    "file": str(out),
                    "uncertainty": block,
                }
            )
        )
        return 0
    _print_rows(result)
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


def _calibrate_run(args: argparse.Namespace, params: BearingParameters, thermal: ThermalConfig, out: Path) -> int:
    """A logged bench run (hold, temperature, torque; :mod:`bearing_rig_sim.studies.bench_run`):
    fit, write the calibration file, print the residuals."""
    from bearing_rig_sim.studies.bench_run import fit_run, read_bench_run

    rows = read_bench_run(args.data)
    fit = fit_run(params, thermal, rows, tuple(args.fit))
    fixed = _fixed_values(args.fix)
    doc = {
        "calibration": {
            "data": args.data.name,
            "fitted": [f"{CALIBRATABLE[k][0]}.{CALIBRATABLE[k][1]}" for k in fit.fitted],
            "fixed": {f"{CALIBRATABLE[k][0]}.{CALIBRATABLE[k][1]}": float(v) for k, v in fixed.items()},
            "thermal": True,
            "run_rms": {k: round(v, 4) for k, v in fit.rms.items()},
            "rows": [
                {"rpm": round(rad_s_to_rpm(r.inner_ring_speed), 3), "axial_load_n": r.axial_load, "hold_s": None if not np.isfinite(r.hold) else r.hold}
                | {f"measured_{k}": v for k, v in r.measured().items()}
                | {f"model_{k}": round(v, 4) for k, v in st.quantities().items()}
                for r, st in zip(rows, fit.states)
            ],
        },
        "parameters": calibration_entries({**fixed, **fit.fitted}, args.data.name),
    }
    header = (
        "# Calibration of the coupled twin against a logged bench run (hold, slip, outer-ring temperature,\n"
        "# torque). Regenerate with `bearing-rig calibrate RUN.csv --thermal --fit ...`; docs/thermal.md,\n"
        '# section "The bench run that settles the priors".\n'
    )
    out.write_text(header + yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    if args.json:
        print(json.dumps({"fitted": fit.fitted, "fixed": fixed, "rms": fit.rms, "thermal": True, "file": str(out)}))
        return 0
    for name, value in fit.fitted.items():
        print(f"fitted {name} = {value:.6g}")
    for key, value in fit.rms.items():
        print(f"RMS {key}: {value:.4g}")
    print(f"({fit.evaluations} model evaluations) written: {out}")
    return 0


def _fixed_values(items: list[str]) -> dict[str, float]:
    """``--fix NAME=VALUE ...`` as a mapping, each name calibratable and each value a number."""
    fixed: dict[str, float] = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep or name not in CALIBRATABLE:
            raise ConfigError("command line", "--fix", f"takes NAME=VALUE with NAME one of {', '.join(sorted(CALIBRATABLE))}, got {item!r}")
        try:
            fixed[name] = check_number(float(text), "command line", f"--fix {name}")
        except ValueError:
            raise ConfigError("command line", f"--fix {name}", f"must be a number, got {text!r}") from None
    return fixed


def _print_rows(result: CalibrationResult) -> None:
    """The data rows beside the fitted model's, and the fitted values."""
    print(f"{'rpm':>8} {'load N':>8} {'data %':>8} {'model %':>8} {'diff pp':>8}" + (f" {'lub degC':>8} {'outer degC':>10}" if result.thermal else ""))
    for p, s in zip(result.points, result.predicted):
        line = f"{rad_s_to_rpm(p.inner_ring_speed):8.0f} {p.axial_load:8.1f} {p.slip_pct:8.3f} {s.slip_pct:8.3f} {s.slip_pct - p.slip_pct:8.3f}"
        if result.thermal:
            line += f" {s.lubricant_temperature:8.2f} {s.outer_ring_temperature:10.2f}"
        print(line)
