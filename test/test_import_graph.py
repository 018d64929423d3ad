"""The package's import graph has no cycle and no module imports from a floor above its own.

Every import is read from the source with :mod:`ast`, those inside functions included (a cycle
hidden in a function-level import is still a cycle of the design), and importing
``a.b.c`` counts as importing the packages ``a.b`` too (their ``__init__`` runs). Nothing is
imported to build the graph, so it is the same with or without ROS.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable, Mapping
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "bearing_rig_sim"

FLOORS: tuple[tuple[str, frozenset[str]], ...] = (
    (
        "foundation: the contract, configuration, errors and plumbing",
        frozenset(
            {
                "",
                "errors",
                "config",
                "interfaces",
                "health",
                "clock_guard",
                "dds_profile",
                "executors",
                "settings_model",
                "numba_cache",
                "compiled",
                "picklable",
            }
        ),
    ),
    ("bearing: the bearing's shared facts (kinematics, Hertz contact, materials)", frozenset({"bearing"})),
    ("measurement: the slip analysis, the rig's models and instruments, bag files", frozenset({"analysis", "rig", "instruments", "bags"})),
    ("dynamics: the bearing's dynamics engine, its steady states and quasi-static model", frozenset({"dynamics"})),
    ("thermal: the bearing's heat network, coupled to the dynamics", frozenset({"thermal"})),
    (
        "cores: what the nodes and commands run, without ROS shells",
        frozenset({"simulation", "monitoring", "load_control", "shadow", "offline", "replay", "live", "synthetic", "studies", "sweep"}),
    ),
    ("shells: the ROS 2 nodes and the session that starts them", frozenset({"nodes", "session"})),
    ("front: the command line and its benchmarks", frozenset({"cli", "commands", "benchmarks"})),
)
"""Bottom to top. A unit is a sub-package or a root module of the package (``""`` is the package
itself); a module may import from its own floor and the floors below, never from one above."""


def module_files(package_dir: Path) -> dict[str, Path]:
    """Dotted module name -> source file, for every ``.py`` under ``package_dir``."""
    files = {}
    for path in sorted(package_dir.rglob("*.py")):
        parts = list(path.relative_to(package_dir.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        files[".".join(parts)] = path
    return files


def _resolve(name: str, modules: Iterable[str]) -> str:
    """The longest prefix of ``name`` that is a module (an imported name may be a class)."""
    known = set(modules)
    while name not in known and "." in name:
        name = name.rsplit(".", 1)[0]
    return name


def imports_of(module: str, path: Path, modules: Mapping[str, Path], package: str) -> set[str]:
    """The package's modules that ``module`` imports anywhere in its source, plus the packages
    each of them sits in (other than ``module``'s own)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    is_package = path.name == "__init__.py"
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {_resolve(a.name, modules) for a in node.names if a.name.split(".")[0] == package}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_package else module.split(".")[:-1]
                base = base[: len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != package:
                continue
            for alias in node.names:
                candidate = f"{source}.{alias.name}"
                found.add(candidate if candidate in modules else _resolve(source, modules))
    parts = module.split(".")
    own_packages = {".".join(parts[:i]) for i in range(1, len(parts) + (1 if is_package else 0))}
    for target in list(found):
        pieces = target.split(".")
        found |= {".".join(pieces[:i]) for i in range(1, len(pieces))} - own_packages
    found.discard(module)
    return {m for m in found if m in modules}


def import_graph(package_dir: Path) -> dict[str, set[str]]:
    """Module -> the package's modules it imports (see :func:`imports_of`)."""
    modules = module_files(package_dir)
    return {m: imports_of(m, p, modules, package_dir.name) for m, p in modules.items()}


def cycles(graph: Mapping[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def describe(component: list[str], graph: Mapping[str, set[str]]) -> str:
    inside = set(component)
    return "; ".join(f"{m} -> {', '.join(sorted(graph[m] & inside))}" for m in component)


def unit_of(module: str) -> str:
    """The sub-package or root module a module belongs to (``""``: the package itself)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def floor_of(unit: str) -> int:
    for number, (_, units) in enumerate(FLOORS):
        if unit in units:
            return number
    raise LookupError(unit)


GRAPH = import_graph(ROOT / PACKAGE)


def test_the_graph_sees_function_level_imports_and_package_inits(tmp_path: Path) -> None:
    """A cycle closed only by an import inside a function, and one closed only through a
    package's ``__init__``, are both found."""
    pkg = tmp_path / "toy"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("def f():\n    from toy.b import g\n    return g\n")
    (pkg / "b.py").write_text("from . import a\n\ndef g():\n    return a\n")
    (pkg / "sub" / "__init__.py").write_text("from toy.sub.inner import X\n")
    (pkg / "sub" / "inner.py").write_text("X = 1\n")
    (pkg / "sub" / "leaf.py").write_text("Y = 2\n")
    (pkg / "c.py").write_text("from toy.sub.leaf import Y\n")
    (pkg / "sub" / "back.py").write_text("import toy.c\n")
    (pkg / "sub" / "inner.py").write_text("import toy.sub.back\nX = 1\n")
    graph = import_graph(pkg)
    assert graph["toy.a"] == {"toy.b"}
    assert graph["toy.c"] == {"toy.sub", "toy.sub.leaf"}
    assert sorted(map(tuple, cycles(graph))) == [("toy.a", "toy.b"), ("toy.c", "toy.sub", "toy.sub.back", "toy.sub.inner")]


def test_every_unit_of_the_package_is_on_one_floor() -> None:
    units = {unit_of(m) for m in GRAPH}
    placed = [u for _, floor in FLOORS for u in floor]
    assert len(placed) == len(set(placed)), "a unit is on two floors"
    assert units == set(placed), f"not on a floor: {sorted(units - set(placed))}; gone: {sorted(set(placed) - units)}"


def test_the_models_are_layered() -> None:
    """The shared bearing facts lie below the analysis, the analysis below the dynamics and the
    dynamics below the heat network: three floors, not one."""
    assert floor_of("bearing") < floor_of("analysis") < floor_of("dynamics") < floor_of("thermal")


def test_no_import_cycle() -> None:
    found = cycles(GRAPH)
    assert not found, "import cycles: " + " | ".join(describe(c, GRAPH) for c in found)


def test_no_module_imports_from_a_floor_above_its_own() -> None:
    upward = [
        f"{m} ({FLOORS[floor_of(unit_of(m))][0].split(':')[0]}) imports {t} ({FLOORS[floor_of(unit_of(t))][0].split(':')[0]})"
        for m, targets in sorted(GRAPH.items())
        for t in sorted(targets)
        if floor_of(unit_of(t)) > floor_of(unit_of(m))
    ]
    assert not upward, "\n".join(upward)


@pytest.mark.parametrize(
    ("module", "forbidden"),
    [
        ("bearing_rig_sim.studies.calibration", "bearing_rig_sim.sweep"),
        ("bearing_rig_sim.live.foxglove", "bearing_rig_sim.session"),
        ("bearing_rig_sim.simulation.drive", "bearing_rig_sim.rig.program"),
    ],
)
def test_the_known_reaches_stay_cut(module: str, forbidden: str) -> None:
    """The calibration takes its executor and solver from below the sweep; the live view its
    stamp reader from the bag's CDR module; the spindle drive its profile from
    :mod:`bearing_rig_sim.rig.speed_profile`, not from the program parser."""
    reached = {t for t in GRAPH[module] if t == forbidden or t.startswith(forbidden + ".")}
    assert not reached, f"{module} imports {sorted(reached)}"
