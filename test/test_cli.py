"""The ``bearing-rig`` command line: version, sub-command dispatch, errors, ``bench`` output."""

from __future__ import annotations

import argparse
import json
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
    assert capsys.readouterr().out == (
        "case  rtf  steps\n"
        "----  ---  -----\n"
        "p0    1.5      1\n"
        "p1      3     10\n"
    )


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
    version = subprocess.run([str(script), "--version"], capture_output=True, text=True, timeout=60)
    assert (version.returncode, version.stdout) == (0, f"bearing-rig {__version__}\n")
    unknown = subprocess.run([str(script), "bench", "no-such-benchmark"], capture_output=True, text=True, timeout=60)
    assert unknown.returncode == 2
    assert unknown.stdout == ""
    lines = unknown.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("bearing-rig: error: unknown benchmark 'no-such-benchmark'")
