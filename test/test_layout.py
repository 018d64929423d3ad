"""The README's layout and the package docstring name every part of the tree, and nothing more."""

from __future__ import annotations

import re
from pathlib import Path

import bearing_rig_sim

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "bearing_rig_sim"


def tree_entries() -> set[str]:
    """Sub-packages (``name/``) and root modules (``name.py``) of the package."""
    entries = {f"{p.name}/" for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    entries |= {p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py")}
    return entries


def readme_layout_entries() -> set[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("## Layout", 1)[1].split("\n## ", 1)[0]
    inside = block.split("    bearing_rig_sim/\n", 1)[1].split("\n    test/", 1)[0]
    names: set[str] = set()
    for line in inside.splitlines():
        if not line.startswith("      ") or line.startswith("       "):
            continue  # a continuation line of the description
        first = line.strip().split("  ", 1)[0]
        names |= {n.strip() for n in first.split(",") if n.strip()}
    return names


def test_readme_layout_lists_the_package_tree() -> None:
    assert readme_layout_entries() == tree_entries()


def test_package_docstring_names_every_subpackage() -> None:
    doc = bearing_rig_sim.__doc__ or ""
    named = set(re.findall(r"bearing_rig_sim\.(\w+)", doc))
    packages = {e.rstrip("/") for e in tree_entries() if e.endswith("/")}
    assert packages <= named, sorted(packages - named)
