"""The numba cache guard: caches go when any module with cached kernels changes, and the list of
such modules is complete (numba keys a cache on the function's own file only)."""

from __future__ import annotations

import re
from pathlib import Path

from bearing_rig_sim import numba_cache


def _tree(root: Path) -> None:
    for rel in ("a/kernels.py", "b/steady.py"):
        f = root / rel
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text("x = 1\n")
        (f.parent / "__pycache__").mkdir(exist_ok=True)
        (f.parent / "__pycache__" / f"{f.stem}.step-10.py311.nbi").write_bytes(b"i")
        (f.parent / "__pycache__" / f"{f.stem}.step-10.py311.1.nbc").write_bytes(b"c")
        (f.parent / "__pycache__" / f"{f.stem}.cpython-311.pyc").write_bytes(b"p")


def _cached(root: Path) -> list[str]:
    return sorted(p.name for p in root.rglob("*.nb[ic]"))


def test_a_change_in_one_module_clears_the_caches_of_all(tmp_path: Path) -> None:
    _tree(tmp_path)
    sources = ("a/kernels.py", "b/steady.py")
    assert numba_cache.refresh(tmp_path, sources)  # no stamp yet: caches of unknown origin go
    assert _cached(tmp_path) == []
    _tree(tmp_path)
    assert not numba_cache.refresh(tmp_path, sources)  # same sources: caches kept
    assert len(_cached(tmp_path)) == 4
    (tmp_path / "a/kernels.py").write_text("x = 2\n")  # the callee changes, the caller does not
    assert numba_cache.refresh(tmp_path, sources)
    assert _cached(tmp_path) == []
    assert len(list(tmp_path.rglob("*.pyc"))) == 2  # bytecode is Python's business


def test_every_module_with_cached_kernels_is_listed() -> None:
    package = numba_cache.PACKAGE_DIR
    cached = {
        p.relative_to(package).as_posix()
        for p in package.rglob("*.py")
        if re.search(r"cache\s*=\s*True", p.read_text(encoding="utf-8")) and p.name != "numba_cache.py"
    }
    assert cached == set(numba_cache.CACHED_SOURCES)
