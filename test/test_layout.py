"""The README's layout and the package docstring name every part of the tree, and nothing more;
the README stays short and links every page under docs/, and no link between them is broken."""

from __future__ import annotations

import re
from pathlib import Path

import bearing_rig_sim

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = ROOT / "bearing_rig_sim"
README_MAX_LINES = 250
"""What it is, the two commands, one screen of usage, where to read on; the rest is in docs/."""

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


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


def test_readme_is_short() -> None:
    lines = (ROOT / "README.md").read_text(encoding="utf-8").count("\n")
    assert lines <= README_MAX_LINES, f"README.md has {lines} lines; move reference material into docs/"


def test_readme_keeps_the_two_set_up_commands() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "./bootstrap.sh run" in text and "./bootstrap.sh test" in text


def test_every_docs_page_is_linked_from_the_readme() -> None:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    linked = {target.split("#", 1)[0] for target in LINK.findall(text)}
    pages = {f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md")}
    assert pages, "no docs pages"
    assert pages <= linked, f"docs pages not linked from README.md: {sorted(pages - linked)}"


def slug(heading: str) -> str:
    """A markdown heading's anchor as GitHub makes it."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    return {slug(line.lstrip("#")) for line in path.read_text(encoding="utf-8").splitlines() if re.match(r"#{1,6} ", line)}


def test_slug_follows_github() -> None:
    assert slug("Running a session (`bearing-rig run`)") == "running-a-session-bearing-rig-run"
    assert slug("What `bootstrap.sh` does") == "what-bootstrapsh-does"


def test_links_between_the_readme_and_docs_reach_a_file_and_heading() -> None:
    broken = []
    for document in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        for target in LINK.findall(document.read_text(encoding="utf-8")):
            if re.match(r"[a-z]+:", target):
                continue  # a web address
            name, _, anchor = target.partition("#")
            path = (document.parent / name).resolve() if name else document
            if not path.exists():
                broken.append(f"{document.relative_to(ROOT)}: {target} (no such file)")
            elif anchor and path.suffix == ".md" and anchor not in anchors(path):
                broken.append(f"{document.relative_to(ROOT)}: {target} (no such heading)")
    assert not broken, "\n".join(broken)
