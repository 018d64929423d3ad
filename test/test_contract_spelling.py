"""Topic and service names are spelt once, in :mod:`bearing_rig_sim.interfaces`: no string
constant elsewhere in the package spells one (docstrings and comments may name them; messages
and help texts take them from the contract's constants, through f-strings)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from bearing_rig_sim import interfaces

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "bearing_rig_sim"
CONTRACT = PACKAGE / "interfaces.py"

NAMES = sorted({t.name for t in interfaces.TOPICS} | {s.name for s in interfaces.SERVICES}, key=len, reverse=True)
SPELLING = re.compile("(?:" + "|".join(re.escape(n) for n in NAMES) + r")(?![\w/])")
"""A contract name, not followed by more of a name (``/rig/axial_load/set`` is not in
``/rig/axial_load/setpoint``, nor ``/clock`` in ``/clockwork``)."""


def docstring_nodes(tree: ast.AST) -> set[int]:
    """ids of the string constants that stand alone as a statement: module, class and function
    docstrings, and the attribute docstrings under assignments."""
    return {
        id(node.value) for node in ast.walk(tree) if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str)
    }


def spelt_names(source: str, filename: str = "<source>") -> list[tuple[int, str]]:
    """(line, name) of each contract name inside a string constant of ``source`` that is not
    a docstring (f-string pieces included; comments are not in the syntax tree)."""
    tree = ast.parse(source, filename=filename)
    docs = docstring_nodes(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            found += [(node.lineno, m.group(0)) for m in SPELLING.finditer(node.value)]
    return sorted(found)


def test_the_check_finds_literals_and_spares_docstrings_and_comments() -> None:
    source = '''"""Reads ``/rig/speeds``."""
TOPIC = "/rig/cage/pulses"  # not "/rig/truth" in a comment
X = 1
"""An attribute docstring naming /clock."""


def f(n):
    """Publishes /rig/slip_status."""
    return f"no /rig/axial_load/setpoint after {n} s; see /rig/speeds_hz and /clockwork"
'''
    assert spelt_names(source) == [(2, "/rig/cage/pulses"), (9, "/rig/axial_load/setpoint")]


def test_no_topic_or_service_name_is_spelt_outside_the_contract() -> None:
    spelt = [
        f"{path.relative_to(ROOT)}:{line}: {name}"
        for path in sorted(PACKAGE.rglob("*.py"))
        if path != CONTRACT
        for line, name in spelt_names(path.read_text(encoding="utf-8"), str(path))
    ]
    assert not spelt, "topic names spelt outside interfaces.py (use its constants):\n" + "\n".join(spelt)


def test_the_contract_spells_each_name_once() -> None:
    """Each name is one constant: the topics and services have distinct names."""
    names = [t.name for t in interfaces.TOPICS] + [s.name for s in interfaces.SERVICES]
    assert len(names) == len(set(names))
    assert spelt_names(CONTRACT.read_text(encoding="utf-8"))  # the contract itself does spell them
