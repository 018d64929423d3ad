"""``bearing-rig shadow``: the twin beside the bench on its measured inputs (predicted slip,
residual, anomalies), live or over a recorded bag.

Both modes, their outputs and exit statuses: docs/guide.md, section ``bearing-rig shadow``.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


from bearing_rig_sim.commands import describe


def register(subparsers: Any) -> None:
    """Add ``shadow`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser(
        "shadow", help="the twin beside the bench: predicted slip, residual, anomalies (live or --bag)", description=describe(__doc__, "shadow")
    )
    p.add_argument("--bag", type=Path, default=None, metavar="BAG", help="run over this bag instead of the live topics")
    p.add_argument("--out", type=Path, default=None, metavar="DIR", help="output folder with --bag (default: out/shadow/<bag name>)")
    p.add_argument("--params", type=Path, default=None, metavar="FILE", help="shadow parameter file (default: config/shadow.yaml)")
    p.add_argument(
        "--calibration",
        type=Path,
        default=None,
        metavar="FILE",
        help="calibration of the twin: a named one (coupled, isothermal) or a file (default: the parameter file's); the lubricant follows the temperature with a coupled one",
    )
    p.add_argument(
        "--recalibrate",
        nargs="?",
        const="",
        default=None,
        metavar="PARAMETER",
        help="track a calibration parameter online (default: the parameter file's recalibrate_parameter); never written to the calibration file",
    )
    p.add_argument(
        "--save-calibration",
        type=Path,
        default=None,
        metavar="FILE",
        help="with --bag --recalibrate: write a copy of the calibration with the estimate to FILE (never over the calibration itself)",
    )
    p.add_argument("ros_args", nargs=argparse.REMAINDER, help="live: after --, arguments for the node (-- --ros-args -p name:=value)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run shadow mode live or over a bag."""
    from bearing_rig_sim.config import ConfigError
    from bearing_rig_sim.dynamics.calibrations import NAMED, calibration_file, is_coupled
    from bearing_rig_sim.shadow import ShadowSettings
    from bearing_rig_sim.shadow.settings import calibration_rms

    settings = ShadowSettings.from_yaml(args.params)
    if args.calibration is not None:
        if str(args.calibration) in NAMED:
            args.calibration = calibration_file(str(args.calibration))
        if not args.calibration.is_file():
            raise ConfigError(str(args.calibration), "calibration", "file not found")
        rms = calibration_rms(args.calibration)
        settings = settings.replace(
            calibration_file=args.calibration.resolve(),
            calibration_rms_slip_pct=rms if rms is not None else settings.calibration_rms_slip_pct,
            lubricant_feedback=is_coupled(args.calibration),  # run as it was fitted
        )
    if args.recalibrate is not None:
        settings = settings.replace(recalibrate=True, recalibrate_parameter=args.recalibrate or settings.recalibrate_parameter)
    if args.bag is None:
        return _live(args, settings)
    from bearing_rig_sim.commands import output_folder
    from bearing_rig_sim.commands.bag import bag_warnings_as_lines
    from bearing_rig_sim.shadow.offline import shadow_bag

    out = output_folder(args.out if args.out is not None else Path("out") / "shadow" / args.bag.resolve().name, "--out")
    with bag_warnings_as_lines():
        result = shadow_bag(args.bag, out, settings)
    c = result.counts
    inside = f"{100.0 * result.inside_fraction:.2f} %" if c["compared"] else "-"
    print(
        f"{args.bag}: {c['windows']} slip windows, {c['compared']} compared, {inside} inside the band, {c['anomalous']} flagged in {len(result.stretches)} stretch(es)"
    )
    for s in result.stretches:
        print(f"  {s.start_s:.3f}-{s.end_s:.3f} s {s.worst.name}: {s.detail}")
    if result.estimate is not None:
        e = result.estimate
        outside = "" if e.in_range or e.range is None else f"; OUTSIDE its plausible range {e.range[0]:g}-{e.range[1]:g}"
        print(f"re-calibrated {e.name}: {e.value:.6g} +- {e.std:.3g} (calibrated {e.calibrated:.6g}{outside}); not written")
    if args.save_calibration is not None:
        _save_calibration(args.save_calibration, settings.calibration_file, result.estimate)
    print(f"report: {out / 'report.md'}; rows: {out / 'residuals.csv'}")
    return 1 if c["anomalous"] else 0


def _live(args: argparse.Namespace, settings: Any) -> int:
    from bearing_rig_sim.nodes.shadow import main

    argv = ["shadow", "--autostart", *[a for a in args.ros_args if a != "--"]]
    extra = []
    if args.params is not None:
        extra += ["--params-file", str(args.params)]
    if args.calibration is not None:
        extra += ["-p", f"calibration_file:={settings.calibration_file}", "-p", f"calibration_rms_slip_pct:={settings.calibration_rms_slip_pct}"]
        extra += ["-p", f"lubricant_feedback:={str(settings.lubricant_feedback).lower()}"]
    if args.recalibrate is not None:
        extra += ["-p", "recalibrate:=true", "-p", f"recalibrate_parameter:={settings.recalibrate_parameter}"]
    if extra:
        argv += (["--ros-args"] if "--ros-args" not in argv else []) + extra
    return main(argv)


def _save_calibration(dest: Path, source: Path | None, estimate: Any) -> None:
    """Write ``source`` with the estimate's value to ``dest`` (a new file, never ``source``).

    Raises:
        RigError: no estimate, the destination is the calibration itself or exists, the estimate
            lies outside the parameter's stated range, or the source is not a valid calibration
            file (:class:`~bearing_rig_sim.config.ConfigError`, naming the file and the key).
    """
    import yaml

    from bearing_rig_sim.config import read_mapping
    from bearing_rig_sim.dynamics.bearing_file import CalibrationFile
    from bearing_rig_sim.errors import RigError
    from bearing_rig_sim.settings_model import validate_mapping

    if estimate is None or source is None:
        raise RigError("--save-calibration needs --recalibrate and a calibration file")
    if dest.exists():
        raise RigError(f"--save-calibration: {dest} exists already, not overwriting")
    if not estimate.in_range:
        raise RigError(f"--save-calibration: {estimate.name} = {estimate.value:.6g} lies outside its stated range {estimate.range}; not written")
    doc = read_mapping(source)
    validate_mapping(CalibrationFile, doc, str(source))  # the raw document is rewritten, checked first
    entry = doc["parameters"][estimate.name]
    if isinstance(entry, dict):
        entry["value"] = float(f"{estimate.value:.6g}")
        entry["source"] = f"online re-calibration by shadow mode (+- {estimate.std:.3g}, {estimate.updates} steady windows); was {estimate.calibrated:.6g}"
    else:
        doc["parameters"][estimate.name] = float(f"{estimate.value:.6g}")
    dest.write_text(yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")
    print(f"calibration with {estimate.name} = {estimate.value:.6g} written to {dest}")
