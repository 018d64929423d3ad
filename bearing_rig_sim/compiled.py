"""The monitor's pulse path compiled to C from its own typed source, with the source as fallback.

The slip monitor handles every pulse of the fibre-optic sensors in Python: the live node a few
thousand a second, ``bearing-rig analyze`` some 600,000 for an hour's bag. mypyc (part of the
pinned ``mypy``) compiles the modules of that path (:data:`COMPILED_MODULES`) to C extension
modules from the very sources the type check reads, so the live monitor and the offline analysis
share one implementation, compiled or not, and give the same statuses to the bit (tested).

**Build.** :func:`main` (run by ``./bootstrap.sh setup``) compiles them
into ``build/compiled/`` beside the package and writes a manifest naming the extension files and
the digest of every package source they were compiled from (:func:`dependencies`: the compiled
modules and the package modules they import, transitively). Nothing is written into the source
tree.

**Load.** :func:`install` (called by the package's ``__init__``) puts a finder first on
``sys.meta_path`` that serves those modules from the extensions only while the manifest's digest
matches the sources as they are now and the interpreter is the one they were built for;
otherwise, or with :data:`PURE_PYTHON_VARIABLE` set (for a debugger, or a host without a
compiler), every module is imported from its source, as if nothing had been built. All or none:
the extensions call each other directly, so one changed source sets them all aside. The check
runs once, when the first of them is imported; :func:`status` says which way it went and why.

**What differs, compiled.** A compiled class is closed: no attribute can be set on it (a method
wrapped for timing, a monkeypatched method); a field or argument read as its annotated type
raises TypeError on another type (the monitor reads a pulse's fields untyped until it has
checked them, so bad pulses are refused the same way). The records these modules return (an
analysis's result, statuses, windows, segments, rows) pickle and deep-copy either way
(:mod:`bearing_rig_sim.picklable`); their stateful classes (a monitor part-way through a stream)
do not, compiled. ``BEARING_RIG_PURE_PYTHON=1`` gives the sources' behaviour in all of this.
"""

from __future__ import annotations

import ast
import importlib.machinery
import importlib.util
import json
import os
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from importlib.abc import MetaPathFinder
from importlib.machinery import ModuleSpec
from pathlib import Path
from types import ModuleType

from bearing_rig_sim.numba_cache import sources_digest

PACKAGE = "bearing_rig_sim"
PACKAGE_DIR = Path(__file__).resolve().parent
BUILD_DIR = PACKAGE_DIR.parent / "build" / "compiled"
"""Where the build puts the extensions and the manifest (the checkout's ``build/``, ignored by git)."""
MANIFEST_NAME = "manifest.json"
GROUP = f"{PACKAGE}__mypyc"
"""mypyc's shared library of the compiled modules (a top-level extension module)."""
PURE_PYTHON_VARIABLE = "BEARING_RIG_PURE_PYTHON"
"""Set to 1 to import every module from its source (and to skip the build in ``bootstrap.sh``)."""

COMPILED_MODULES: tuple[str, ...] = (
    "bearing_rig_sim.bags.cdr",
    "bearing_rig_sim.analysis.phase",
    "bearing_rig_sim.analysis.streaming",
    "bearing_rig_sim.monitoring.windows",
    "bearing_rig_sim.monitoring.monitor",
    "bearing_rig_sim.monitoring.schedule",
    "bearing_rig_sim.offline.series",
    "bearing_rig_sim.offline.segments",
    "bearing_rig_sim.offline.analysis",
)
"""The pulse path: decoding, slip windows, phase and trailing slopes, monitor, schedule, and the
offline analysis' rows, segments and CSV files."""


@dataclass(frozen=True)
class Status:
    """Whether the compiled modules are in use and why (``reason``: a sentence for a person)."""

    active: bool
    reason: str


def source_file(module: str, package_dir: Path = PACKAGE_DIR) -> Path:
    """The source file of a package module (``bearing_rig_sim.a.b`` -> ``a/b.py`` or ``a/b/__init__.py``)."""
    parts = module.split(".")[1:]
    base = package_dir.joinpath(*parts)
    return base / "__init__.py" if base.is_dir() else base.with_suffix(".py")


def _imported(module: str, tree: ast.AST, package_dir: Path) -> set[str]:
    """The package modules ``module``'s source imports anywhere (type-only imports included:
    mypyc compiles against their types), with their parent packages."""
    found: set[str] = set()
    is_package = source_file(module, package_dir).name == "__init__.py"
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = module.split(".")
                anchor = anchor[: len(anchor) - node.level + (1 if is_package else 0)]
                base = ".".join([*anchor, *([base] if base else [])])
            names = [base, *(f"{base}.{alias.name}" for alias in node.names)]
        for name in names:
            if name == PACKAGE or name.startswith(PACKAGE + "."):
                parts = name.split(".")
                for k in range(1, len(parts) + 1):
                    candidate = ".".join(parts[:k])
                    path = source_file(candidate, package_dir)
                    if path.is_file():
                        found.add(candidate)
    return found


def dependencies(modules: Sequence[str] = COMPILED_MODULES, package_dir: Path = PACKAGE_DIR) -> list[Path]:
    """The source files ``modules`` were compiled from: theirs and those of every package module
    they import, transitively, sorted."""
    seen: set[str] = set()
    todo = list(modules)
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        seen.add(module)
        path = source_file(module, package_dir)
        tree = ast.parse(path.read_bytes(), str(path))
        todo.extend(_imported(module, tree, package_dir) - seen)
    return sorted(source_file(m, package_dir) for m in seen)


class _Finder(MetaPathFinder):
    """Serves the compiled modules from ``build_dir`` while they match the sources (module docstring)."""

    def __init__(self, build_dir: Path = BUILD_DIR, package_dir: Path = PACKAGE_DIR) -> None:
        self.build_dir = build_dir
        self.package_dir = package_dir
        self._names = frozenset((*COMPILED_MODULES, GROUP))
        self._extensions: dict[str, Path] | None = None
        self.status: Status | None = None

    def _check(self) -> dict[str, Path]:
        """The extension of each module when the build is current and not set aside by
        :data:`PURE_PYTHON_VARIABLE`, else {} (with :attr:`status`)."""
        if os.environ.get(PURE_PYTHON_VARIABLE, "") not in ("", "0"):
            return self._set({}, f"{PURE_PYTHON_VARIABLE} is set: the modules run from their sources")
        return self._inspect_build()

    def _inspect_build(self) -> dict[str, Path]:
        """The extension of each module when the build is current, else {} (with :attr:`status`)."""
        manifest_path = self.build_dir / MANIFEST_NAME
        try:
            manifest = json.loads(manifest_path.read_text(encoding="utf-8"))
            sources = [self.package_dir / name for name in manifest["sources"]]
            extensions = {name: self.build_dir / file for name, file in manifest["extensions"].items()}
            tag = manifest["cache_tag"]
        except FileNotFoundError:
            return self._set({}, f"not built ({manifest_path} missing: `./bootstrap.sh setup` builds it)")
        except (OSError, ValueError, KeyError, TypeError) as exc:
            return self._set({}, f"{manifest_path} unreadable ({exc}): the modules run from their sources")
        if tag != sys.implementation.cache_tag:
            return self._set({}, f"built for {tag}, this interpreter is {sys.implementation.cache_tag}: the modules run from their sources")
        if set(extensions) != self._names or not all(path.is_file() for path in extensions.values()):
            return self._set({}, f"{manifest_path} does not list every compiled module: the modules run from their sources")
        try:
            current = sources_digest(sources)
        except OSError as exc:
            return self._set({}, f"a source is missing ({exc}): the modules run from their sources")
        if current != manifest["digest"]:  # an import added to a source changes that source's digest
            return self._set({}, "the sources changed since the build (`./bootstrap.sh setup` rebuilds): the modules run from their sources")
        return self._set(extensions, f"compiled ({len(COMPILED_MODULES)} modules from {self.build_dir})")

    def _set(self, extensions: dict[str, Path], reason: str) -> dict[str, Path]:
        self._extensions = extensions
        self.status = Status(bool(extensions), reason)
        return extensions

    def find_spec(self, fullname: str, path: Sequence[str] | None = None, target: ModuleType | None = None) -> ModuleSpec | None:
        if fullname not in self._names:
            return None
        extensions = self._extensions if self._extensions is not None else self._check()
        file = extensions.get(fullname)
        if file is None:
            return None
        loader = importlib.machinery.ExtensionFileLoader(fullname, str(file))
        return importlib.util.spec_from_file_location(fullname, file, loader=loader)


_finder: _Finder | None = None


def install() -> None:
    """Put the finder first on ``sys.meta_path`` (once per process)."""
    global _finder
    if _finder is None:
        _finder = _Finder()
        sys.meta_path.insert(0, _finder)


def status() -> Status:
    """Whether the compiled modules are in use in this process, and why."""
    if _finder is None:
        return Status(False, "the finder is not installed")
    if _finder.status is None:
        _finder._check()
    assert _finder.status is not None
    active = _finder.status.active and all(
        getattr(sys.modules.get(name), "__file__", "").endswith(tuple(importlib.machinery.EXTENSION_SUFFIXES))
        for name in COMPILED_MODULES
        if name in sys.modules
    )
    return Status(active, _finder.status.reason)


def current(build_dir: Path = BUILD_DIR, package_dir: Path = PACKAGE_DIR) -> bool:
    """Whether ``build_dir`` holds a build of the sources as they are now, for this interpreter."""
    return bool(_Finder(build_dir, package_dir)._inspect_build())


def build(build_dir: Path = BUILD_DIR, package_dir: Path = PACKAGE_DIR, jobs: int = 2) -> None:
    """Compile :data:`COMPILED_MODULES` with mypyc into ``build_dir`` and write its manifest.

    Raises:
        RuntimeError: mypyc or the C compiler failed (their output names what).
    """
    from mypyc.build import mypycify  # only the build needs mypy
    from setuptools import setup

    sources = dependencies(COMPILED_MODULES, package_dir)
    digest = sources_digest(sources)
    manifest_path = build_dir / MANIFEST_NAME
    manifest_path.unlink(missing_ok=True)  # a failed build leaves none: the sources run
    root = package_dir.parent
    here = Path.cwd()
    os.chdir(root)  # mypyc names the modules by their paths from the working directory
    try:
        paths = [str(source_file(m, package_dir).relative_to(root)) for m in COMPILED_MODULES]
        extensions = mypycify(paths, target_dir=str(build_dir / "c"), group_name=PACKAGE, multi_file=True)
        try:
            setup(
                name=f"{PACKAGE}-compiled",
                ext_modules=extensions,
                script_args=["--quiet", "build_ext", "--build-lib", str(build_dir / "lib"), "--build-temp", str(build_dir / "temp"), "--parallel", str(jobs)],
            )
        except SystemExit as exc:  # setuptools reports a failed compiler this way
            raise RuntimeError(f"compiling {', '.join(paths)} failed: {exc}") from exc
    finally:
        os.chdir(here)
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    files = {name: Path("lib", *name.split(".")).with_name(name.split(".")[-1] + suffix) for name in (*COMPILED_MODULES, GROUP)}
    missing = [str(build_dir / f) for f in files.values() if not (build_dir / f).is_file()]
    if missing:
        raise RuntimeError(f"the build left out {', '.join(missing)}")
    manifest = {
        "cache_tag": sys.implementation.cache_tag,
        "digest": digest,
        "sources": [str(s.relative_to(package_dir)) for s in sources],
        "extensions": {name: str(f) for name, f in files.items()},
    }
    manifest_path.write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")


def main() -> int:
    """Build (``./bootstrap.sh setup`` runs it when :func:`current` says the build is not);
    exit 1 with the compiler's complaint on failure."""
    try:
        build()
    except RuntimeError as exc:
        print(f"{__name__}: {exc}", file=sys.stderr)
        return 1
    print(f"{__name__}: {len(COMPILED_MODULES)} modules compiled into {BUILD_DIR}", file=sys.stderr)
    return 0
