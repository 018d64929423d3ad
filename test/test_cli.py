"""The ``bearing-rig`` command line: version, sub-command dispatch, errors, ``bench`` output."""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import types
from pathlib import Path
from typing import Any
from collections.abc import Iterator

import numpy as np
import pytest

from bearing_rig_sim import __version__, cli
from bearing_rig_sim.commands import bench
from bearing_rig_sim.errors import RigError
from conftest import time_left

FAKE_MODULE = "bearing_rig_sim_test_fake_benchmark"


def _fake_benchmark(behaviour: str = "rows") -> types.ModuleType:
    """A benchmark module: ``--points N`` rows, or raising an error on ``run``."""
    module = types.ModuleType(FAKE_MODULE)
    module.__doc__ = "A fake benchmark for the command-line tests."

    def add_arguments(parser: argparse.ArgumentParser) -> None:
        parser.add_argument("--points", type=int, default=2)

    def run(args: argparse.Namespace) -> Iterator[dict[str, Any]]:
        if behaviour == "rig-error":
            raise RigError("axial load -5 N out of range\n  allowed: [0, 1000] N")
        if behaviour == "bug":
            raise ZeroDivisionError("a bug")
        for i in range(args.points):
            yield {"case": f"p{i}", "rtf": np.float64(1.5 * (i + 1)), "steps": np.int64(10**i)}

    module.add_arguments = add_arguments  # type: ignore[attr-defined]
    module.run = run  # type: ignore[attr-defined]
    return module


@pytest.fixture
def fake_benchmark(monkeypatch: pytest.MonkeyPatch) -> Any:
    """Register a fake benchmark as ``fake``; return a function switching its behaviour."""
    monkeypatch.setitem(bench.BENCHMARKS, "fake", FAKE_MODULE)

    def install(behaviour: str = "rows") -> None:
        monkeypatch.setitem(sys.modules, FAKE_MODULE, _fake_benchmark(behaviour))

    install()
    return install


# -- the program -----------------------------------------------------------------------------
def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0
    assert capsys.readouterr().out == f"bearing-rig {__version__}\n"


def test_unknown_sub_command_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main(["frobnicate"])
    assert info.value.code == 2
    assert "invalid choice: 'frobnicate'" in capsys.readouterr().err


def test_a_sub_command_is_required(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main([])
    assert info.value.code == 2
    assert "required: COMMAND" in capsys.readouterr().err


def test_every_listed_command_registers_itself() -> None:
    parser = cli.build_parser()
    (sub_commands,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    assert list(sub_commands.choices) == list(cli.COMMANDS)
    for name, sub_parser in sub_commands.choices.items():
        assert callable(sub_parser.get_default("func")), f"{name} sets no func"


# -- errors ----------------------------------------------------------------------------------
def test_unknown_benchmark_lists_the_known_ones(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(bench, "BENCHMARKS", {"rig": "x.rig", "dynamics": "x.dynamics"})
    assert cli.main(["bench", "nope"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == "bearing-rig: error: unknown benchmark 'nope'; known benchmarks: dynamics, rig\n"


def test_unknown_benchmark_with_none_registered(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(bench, "BENCHMARKS", {})
    assert cli.main(["bench", "dynamics"]) == 2
    assert capsys.readouterr().err == "bearing-rig: error: unknown benchmark 'dynamics'; known benchmarks: none registered yet\n"


def test_rig_error_becomes_one_line_and_exit_2(fake_benchmark: Any, capsys: pytest.CaptureFixture[str]) -> None:
    fake_benchmark("rig-error")
    assert cli.main(["bench", "fake"]) == 2
    err = capsys.readouterr().err
    assert err == "bearing-rig: error: axial load -5 N out of range allowed: [0, 1000] N\n"


def test_other_exceptions_keep_their_traceback(fake_benchmark: Any) -> None:
    fake_benchmark("bug")
    with pytest.raises(ZeroDivisionError):
        cli.main(["bench", "fake"])


def test_benchmark_module_without_run_is_reported(monkeypatch: pytest.MonkeyPatch, fake_benchmark: Any) -> None:
    broken = types.ModuleType(FAKE_MODULE)
    broken.add_arguments = lambda parser: None  # type: ignore[attr-defined]
    monkeypatch.setitem(sys.modules, FAKE_MODULE, broken)
    with pytest.raises(TypeError, match=f"benchmark module {FAKE_MODULE} has no run"):
        cli.main(["bench", "fake"])


# -- bench output ----------------------------------------------------------------------------
@pytest.mark.parametrize("argv", [["bench", "fake", "--json", "--points", "3"], ["bench", "--json", "fake", "--points", "3"]])
def test_bench_json_lines(fake_benchmark: Any, capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    assert cli.main(argv) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [json.loads(line) for line in lines] == [
        {"case": "p0", "rtf": 1.5, "steps": 1},
        {"case": "p1", "rtf": 3.0, "steps": 10},
        {"case": "p2", "rtf": 4.5, "steps": 100},
    ]


def test_bench_table_is_aligned(fake_benchmark: Any, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["bench", "fake", "--points", "2"]) == 0
    # Text columns left-aligned, numeric columns right-aligned, two spaces between columns.
    assert capsys.readouterr().out == ("case  rtf  steps\n----  ---  -----\np0    1.5      1\np1      3     10\n")


def test_table_with_missing_keys_and_no_rows() -> None:
    out = _Capture()
    bench.print_table([{"name": "a"}, {"name": "long-name", "rtf": 12.25}], out)
    assert out.text == "name         rtf\n---------  -----\na\nlong-name  12.25\n"
    empty = _Capture()
    bench.print_table([], empty)
    assert empty.text == "(no results)\n"


def test_benchmark_options_are_validated(fake_benchmark: Any, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as info:
        cli.main(["bench", "fake", "--points", "many"])
    assert info.value.code == 2
    assert "bearing-rig bench fake: error: argument --points: invalid int value: 'many'" in capsys.readouterr().err


class _Capture:
    """A minimal text stream."""

    def __init__(self) -> None:
        self.text = ""

    def write(self, s: str) -> int:
        self.text += s
        return len(s)

    def flush(self) -> None:
        pass


# -- the installed entry point ---------------------------------------------------------------
def test_installed_console_script() -> None:
    script = Path(sys.prefix) / "bin" / "bearing-rig"
    assert script.is_file(), f"{script} missing: run ./bootstrap.sh setup"
    version = subprocess.run([str(script), "--version"], capture_output=True, text=True, timeout=time_left())
    assert (version.returncode, version.stdout) == (0, f"bearing-rig {__version__}\n")
    unknown = subprocess.run([str(script), "bench", "no-such-benchmark"], capture_output=True, text=True, timeout=time_left())
    assert unknown.returncode == 2
    assert unknown.stdout == ""
    lines = unknown.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("bearing-rig: error: unknown benchmark 'no-such-benchmark'")


# -- user errors of the commands: one line, exit status 2, before any long work ---------------------
def one_line_error(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("bearing-rig: error: ") and len(err.strip().splitlines()) == 1, err
    return err


def test_non_utf8_program_and_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    program = tmp_path / "p.yaml"
    program.write_bytes("name: caf\u00e9\n".encode("latin-1"))
    assert "not UTF-8 text" in one_line_error(["run", str(program)], capsys)
    data = tmp_path / "bench.csv"
    data.write_bytes("inner_ring_rpm,axial_load_n,slip_pct\n900,100,3.2\u00e9\n".encode("latin-1"))
    assert "not UTF-8 text" in one_line_error(["calibrate", str(data), "--out", str(tmp_path / "c.yaml")], capsys)


def test_a_program_is_found_by_its_name_or_its_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """``bearing-rig run acceleration`` runs config/programs/acceleration.yaml; a path is taken as
    it is (also a file of a shipped program's name in the working folder); neither is one line
    naming the argument and the shipped programs (the folder's listing)."""
    from bearing_rig_sim.rig.program import program_file

    folder = Path(__file__).resolve().parents[1] / "config" / "programs"
    shipped = sorted(f.removesuffix(".yaml") for f in os.listdir(folder) if f.endswith(".yaml"))
    assert "acceleration" in shipped and "validation" in shipped
    for name in ("acceleration", "acceleration.yaml"):
        assert program_file(name).resolve() == folder / "acceleration.yaml"
    monkeypatch.chdir(tmp_path)
    own = tmp_path / "acceleration.yaml"
    own.write_text("name: own\n")
    assert program_file("acceleration.yaml") == Path("acceleration.yaml")
    assert program_file(str(own)) == own
    err = one_line_error(["run", "acceleraton"], capsys)
    assert err.startswith("bearing-rig: error: acceleraton: no such program file") and f"(shipped: {', '.join(shipped)};" in err
    assert "no such program file" in one_line_error(["run", str(tmp_path / "sub" / "validation.yaml")], capsys)


@pytest.mark.parametrize("value, problem", [("nan", "must be finite"), ("inf", "must be finite"), ("0", "must be > 0"), ("1e9", "must be <= 3600")])
def test_startup_timeout_is_bounded(value: str, problem: str, capsys: pytest.CaptureFixture[str]) -> None:
    err = one_line_error(["run", "--startup-timeout", value], capsys)
    assert "--startup-timeout" in err and problem in err


def test_analyze_out_that_cannot_be_a_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    in_the_way = tmp_path / "file"
    in_the_way.write_text("")
    bag = tmp_path / "bag"
    bag.mkdir()  # not read: the output folder is checked first
    err = one_line_error(["analyze", str(bag), "--out", str(in_the_way / "sub")], capsys)
    assert f"--out {in_the_way / 'sub'}: cannot create the folder" in err


@pytest.mark.parametrize("command", ["reproduce", "sweep", "shadow"])
def test_every_out_folder_is_checked_before_the_work(command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--out`` under a file: one line naming the option, where a traceback came after the
    work (``reproduce``)."""
    from bearing_rig_sim.config import config_path

    in_the_way = tmp_path / "file"
    in_the_way.write_text("")
    bag = tmp_path / "bag"
    bag.mkdir()
    first = {"reproduce": [], "sweep": [str(config_path("sweeps", "paper_load_grid.yaml"))], "shadow": ["--bag", str(bag)]}[command]
    err = one_line_error([command, *first, "--out", str(in_the_way / "sub")], capsys)
    assert f"--out {in_the_way / 'sub'}: cannot create the folder" in err


def test_reproduce_refuses_a_worker_count_below_one(capsys: pytest.CaptureFixture[str]) -> None:
    assert "--workers must be >= 1, got 0" in one_line_error(["reproduce", "--workers", "0"], capsys)


def test_calibrate_writes_under_out_by_default_and_never_replaces_a_file_unasked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The shipped calibration (config/calibration/h7006c_table3.yaml) used to be the default
    output of ``calibrate config/calibration/h7006c_table3.csv``: overwritten without a word."""
    import hashlib

    from bearing_rig_sim.config import config_path

    shipped = config_path("calibration", "h7006c_table3.yaml")
    before = hashlib.sha256(shipped.read_bytes()).hexdigest()
    data = config_path("calibration", "h7006c_table3.csv")
    monkeypatch.chdir(tmp_path)
    default = tmp_path / "out" / "calibration" / "h7006c_table3.yaml"
    default.parent.mkdir(parents=True)
    default.write_text("earlier result\n")
    err = one_line_error(["calibrate", str(data)], capsys)  # refused before the fit starts
    assert "out/calibration/h7006c_table3.yaml: exists; give --force" in err
    err = one_line_error(["calibrate", str(data), "--out", str(shipped)], capsys)
    assert "exists; give --force" in err
    assert default.read_text() == "earlier result\n"
    assert hashlib.sha256(shipped.read_bytes()).hexdigest() == before


def test_run_refuses_a_program_beyond_the_shipped_rig_naming_the_segment(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Checked at start, before any node runs: config/rig.yaml's spindle goes to 10 000 rpm."""
    program = tmp_path / "fast.yaml"
    program.write_text(
        "name: fast\nbearing: bearings/h7006c.yaml\nstability_criterion: time\nsegments:\n"
        "  - {name: n5000, speed_rpm: 5000, ramp_s: 1.0, axial_load_n: 100, dwell_s: 1.0}\n"
        "  - {name: n12000, speed_rpm: 12000, ramp_s: 2.0, axial_load_n: 100, dwell_s: 1.0}\n",
        encoding="utf-8",
    )
    err = one_line_error(["run", str(program), "--bag-dir", str(tmp_path / "bags")], capsys)
    assert "segments[1].speed_rpm: segment 'n12000': 12000 rpm is above the rig's limit of 10000 rpm" in err
    assert not (tmp_path / "bags").exists()  # nothing started, nothing recorded


def _rig_limits() -> tuple[float, float]:
    """The shipped rig's spindle speed limit (rpm) and set-point limit (N), read with PyYAML."""
    import yaml

    from bearing_rig_sim.config import config_path

    rig = yaml.safe_load(config_path("rig.yaml").read_text(encoding="utf-8"))
    return rig["spindle"]["max_speed_rad_s"] * 30.0 / np.pi, rig["loading_chain"]["max_setpoint_n"]


@pytest.mark.parametrize(
    ("argv", "key", "limit"),
    [
        (["predict", "--rpm", "900", "--load", "5000"], "loading_chain.max_setpoint_n", "1000 N"),
        (["predict", "--rpm", "12000", "--load", "100"], "spindle.max_speed_rad_s", "10000 rpm"),
    ],
)
def test_predict_refuses_what_the_rig_file_does_not_allow(argv: list[str], key: str, limit: str, capsys: pytest.CaptureFixture[str]) -> None:
    """One line naming the option, the rig file's limit and where it is written (config/rig.yaml:
    10 000 rpm, 1000 N); the limits themselves are accepted."""
    speed, load = _rig_limits()
    assert f"{speed:.6g} rpm" == "10000 rpm" and f"{load:g} N" == "1000 N"
    assert cli.main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("bearing-rig: error: command line: --") and f"must be <= {limit}, the rig's limit ({key} in " in err, err
    assert cli.main(["predict", "--rpm", f"{speed:.6g}", "--load", f"{load:g}", "--json"]) == 0


@pytest.mark.parametrize(
    ("axis", "value", "key"), [("axial_load_n", 5000, "loading_chain.max_setpoint_n"), ("inner_ring_speed_rpm", 12000, "spindle.max_speed_rad_s")]
)
def test_a_sweep_axis_beyond_the_rig_is_refused_before_any_point_runs(
    axis: str, value: float, key: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    grid = {"inner_ring_speed_rpm": [1000], "axial_load_n": [100]} | {axis: [value]}
    spec = tmp_path / "beyond.yaml"
    spec.write_text(json.dumps({"sweep": {"name": "beyond"}, "grid": grid}), encoding="utf-8")
    assert cli.main(["sweep", str(spec), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"grid.{axis}[0]: must be <= " in err and f"the rig's limit ({key} in " in err, err
    assert not (tmp_path / "out" / "results.parquet").exists()


HELP_HEADINGS = ("options:", "positional arguments:")


def help_description(text: str) -> list[str]:
    """The lines of a ``--help`` between its usage (up to the first blank line) and its first
    list of arguments, blank lines left out."""
    lines = text.splitlines()
    start = lines.index("") if "" in lines else len(lines)
    end = next((i for i, line in enumerate(lines) if line in HELP_HEADINGS), len(lines))
    return [line for line in lines[start:end] if line.strip()]


def guide_anchors() -> set[str]:
    """The anchors of docs/guide.md's headings, as GitHub makes them (lower case, punctuation but
    hyphens dropped, spaces as hyphens)."""
    text = (Path(__file__).resolve().parent.parent / "docs" / "guide.md").read_text(encoding="utf-8")
    headings = [line.lstrip("#").strip() for line in text.splitlines() if line.startswith("#")]
    return {re.sub(r"[^\w\- ]", "", h.lower()).replace(" ", "-") for h in headings}


SUB_COMMANDS = [[name] for name in cli.COMMANDS] + [["bag", "info"], ["bag", "repair"]]


@pytest.mark.parametrize("command", SUB_COMMANDS, ids=" ".join)
def test_help_is_a_line_or_two_then_the_options(command: list[str], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """At most 5 lines between the usage and the options (on an 80-column terminal), ending with
    the section of docs/guide.md that explains the command in full."""
    monkeypatch.setenv("COLUMNS", "80")
    with pytest.raises(SystemExit) as exit_info:
        cli.main([*command, "--help"])
    assert exit_info.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith(f"usage: bearing-rig {' '.join(command)}")
    description = help_description(text)
    assert len(description) <= 5, "\n".join(description)
    # prose, its syntax left to the usage line: no markup, no conjunction left from a stripped syntax
    assert description[0][:1].isupper() and not re.match(r"(And|Or)\b", description[0]), description
    assert "``" not in " ".join(description), description
    assert any(line in text.splitlines() for line in HELP_HEADINGS)
    if len(command) == 1:  # a sub-command names its section of the guide, and the section exists
        links = re.findall(r"docs/guide\.md#([\w-]+)", " ".join(description))
        assert links == [f"bearing-rig-{command[0]}"], description
        assert links[0] in guide_anchors()


def test_the_help_description_counts_what_lies_between_usage_and_options() -> None:
    """The measure above can fail: a long paragraph counts in full."""
    text = "usage: bearing-rig x [-h]\n\n" + "word " * 200 + "\n\noptions:\n  -h, --help  show this help\n"
    assert len(help_description(text)) == 1
    wrapped = "usage: bearing-rig x [-h]\n\n" + "\n".join(["a line of text"] * 50) + "\n\noptions:\n"
    assert len(help_description(wrapped)) == 50


def test_predict_help_shows_the_rig_files_limits(monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """The bound --help states is the one the check applies: the rig file's (read with PyYAML)."""
    speed, load = _rig_limits()
    monkeypatch.setenv("COLUMNS", "200")
    with pytest.raises(SystemExit):
        cli.main(["predict", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert f"at most {speed:.6g} rpm (spindle.max_speed_rad_s in rig.yaml)" in text
    assert f"at most {load:g} N (loading_chain.max_setpoint_n in rig.yaml)" in text
