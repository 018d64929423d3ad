"""Value classes that pickle and deep-copy the same compiled or from their sources.

The modules of the monitor's pulse path are compiled (:mod:`bearing_rig_sim.compiled`), and a
compiled class keeps its fields in C slots, not in a ``__dict__``: pickle and ``copy`` would
restore an object by setting its fields one by one, which a frozen dataclass refuses
(``FrozenInstanceError``). :func:`by_fields` registers, in :mod:`copyreg`'s table that both
consult, a reduction that rebuilds the object through its constructor from its fields' values,
which works for either build and for frozen and mutable dataclasses alike. It is for records
(statuses, windows, segments, rows, an analysis's result), whose every field is a constructor
argument; the stateful classes (a monitor part-way through a stream) are not covered.
"""

from __future__ import annotations

import copyreg
import dataclasses
from typing import Any


def _reduce(obj: Any) -> tuple[type, tuple[Any, ...]]:
    return type(obj), tuple(getattr(obj, f.name) for f in dataclasses.fields(obj))


def by_fields(*classes: type) -> None:
    """Let ``pickle`` and ``copy`` rebuild instances of these dataclasses by calling each
    class with its fields' values in order.

    Raises:
        TypeError: a class that is not a dataclass, or has a field its constructor does not take.
    """
    for cls in classes:
        if not dataclasses.is_dataclass(cls):
            raise TypeError(f"{cls.__qualname__} is not a dataclass")
        skipped = [f.name for f in dataclasses.fields(cls) if not f.init]
        if skipped:
            raise TypeError(f"{cls.__qualname__}: fields not taken by the constructor: {', '.join(skipped)}")
        copyreg.pickle(cls, _reduce)
