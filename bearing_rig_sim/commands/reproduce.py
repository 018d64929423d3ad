"""``bearing-rig reproduce [--out DIR] [--model bench|paper]``: the paper's three experiments on
both models (the bench twin and the paper's own model), each model's CSVs, figures (5-10
analogues) and report in ``DIR/<model>/``, and ``DIR/report.md`` setting them beside the paper's
Tables 3, 5 and 7."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from bearing_rig_sim.commands import describe
from bearing_rig_sim.analysis.stability import K1_AXIAL_LOAD
from bearing_rig_sim.config import BEARING_MODELS
from bearing_rig_sim.dynamics import BearingParameters
from bearing_rig_sim.studies.reproduction_report import Outputs


def register(subparsers: Any) -> None:
    """Add ``reproduce`` to the ``bearing-rig`` parser."""
    p = subparsers.add_parser("reproduce", help="run the paper's experiments and write a report", description=describe(__doc__, "reproduce"))
    p.add_argument("--out", type=Path, default=Path("out/reproduce"), help="output folder (default: out/reproduce)")
    p.add_argument("--model", choices=BEARING_MODELS, default=None, help="one named model only (default: both, side by side)")
    p.add_argument("--bearing", type=Path, default=None, help="bearing file: one custom model instead (with --calibration)")
    p.add_argument("--calibration", type=Path, default=None, help="calibration file (default: the shipped bench calibration)")
    p.add_argument("--no-cache", action="store_true", help="run the experiments even if cached results match the inputs")
    p.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Run or reuse the experiments and write the outputs."""
    from bearing_rig_sim.commands import output_folder
    from bearing_rig_sim.config import shipped_calibration_file
    from bearing_rig_sim.errors import RigError
    from bearing_rig_sim.studies.reproduction import reproduce, reproduce_models

    if args.workers is not None and args.workers < 1:
        raise RigError(f"--workers must be >= 1, got {args.workers}")
    output_folder(args.out, "--out")  # before the experiments, not after them
    if args.bearing is not None or args.calibration is not None:
        if args.model is not None:
            raise RigError("--model names the bearing and calibration: give --bearing and --calibration without it")
        params = BearingParameters.from_yaml(args.bearing, args.calibration or shipped_calibration_file())
        _print_outputs(reproduce(args.out, params, workers=args.workers, use_cache=not args.no_cache, progress=not args.quiet))
        return 0
    models = (args.model,) if args.model is not None else BEARING_MODELS
    results = reproduce_models(args.out, models, workers=args.workers, use_cache=not args.no_cache, progress=not args.quiet)
    for name, outputs in results.items():
        print(f"model {name}:")
        _print_outputs(outputs)
    if len(results) > 1:
        print(f"side by side: {args.out / 'report.md'}")
    return 0


def _print_outputs(out: Outputs) -> None:
    """One model's headline figures."""
    print(f"{'reused cached results' if out.cached else 'ran the experiments'}; wrote {len(out.files)} files to {out.out_dir}")
    print(f"validation RMS (twin - bench, 4 rows): {out.validation_rms_pct:.3f} pp")
    for rpm, f in out.load_onsets_n.items():
        why = out.reasons.get(f"{rpm:.0f} rpm", "not reached in 50-700 N")
        print(f"  {rpm:6.0f} rpm: {f'stable from {f:.0f} N' if f is not None else why} (k1 = {K1_AXIAL_LOAD:g} %/N, the shipped reading)")
    for a, t in out.acceleration_onsets_s.items():
        why = out.reasons.get(f"{a:.0f} rad/s^2", "not reached")
        print(f"  {a:4.0f} rad/s^2: {f'stable from {t:.2f} s' if t is not None else why} (k2 = -3e-2 %/s)")
    print(f"report: {out.out_dir / 'report.md'}")
