"""Keep numba's on-disk caches true to the sources they were compiled from.

numba (``@njit(cache=True)``) keys a cached function on its own source file only: a kernel that
calls a function of another module keeps that function's old machine code in its cache after
the other module changes. After an update of the package, a cached step of
``dynamics/steady.py`` could then run a superseded ``dynamics/kernels.py``. :func:`refresh`
hashes every module holding cached functions and clears all of their caches together when any
of them changed. :mod:`bearing_rig_sim.dynamics` calls it on import, before any cached
function is first called (numba reads a cache then; ``thermal`` imports ``dynamics``).
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
CACHED_SOURCES: tuple[str, ...] = (
    "dynamics/kernels.py",
    "dynamics/steady.py",
    "dynamics/traction.py",
    "thermal/bearing.py",
    "thermal/coupling.py",
)
"""Every module with ``@njit(cache=True)`` functions, relative to the package (the test checks
the list is complete)."""
STAMP_NAME = "numba-sources.sha256"

_done = False


def sources_digest(files: Iterable[Path]) -> str:
    """SHA-256 over the files' names and contents, in the order given."""
    h = hashlib.sha256()
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def refresh(package_dir: Path = PACKAGE_DIR, sources: Iterable[str] = CACHED_SOURCES) -> bool:
    """Remove the numba cache files (``*.nbi``, ``*.nbc``) next to ``sources`` when their joint
    digest differs from the one recorded at the last refresh; returns whether it removed them.

    A read-only installation is left alone (numba then compiles in memory or uses its own
    cache directory). Runs once per process for the installed package."""
    files = [package_dir / s for s in sources]
    digest = sources_digest(files)
    cache_dirs = sorted({f.parent / "__pycache__" for f in files})
    stamp = package_dir / "__pycache__" / STAMP_NAME
    try:
        if stamp.is_file() and stamp.read_text(encoding="ascii").strip() == digest:
            return False
        for d in cache_dirs:
            if d.is_dir():
                for pattern in ("*.nbi", "*.nbc"):
                    for cached in d.glob(pattern):
                        cached.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(digest + "\n", encoding="ascii")
    except OSError:
        return False
    return True


def refresh_once() -> None:
    """:func:`refresh` for the installed package, once per process."""
    global _done
    if not _done:
        _done = True
        refresh()
