"""The sweep's result table: Parquet (pyarrow), resumable, one row per point.

While a sweep runs, each finished batch of rows is written as its own small Parquet file under
``DIR/parts/`` (written to a temporary name, then renamed: a killed sweep leaves only whole
files). :meth:`ResultTable.finish` merges ``DIR/results.parquet`` and the parts into a new
``DIR/results.parquet``, one row per point key (the first kept), sorted by the axes, with the
run context in the file's metadata under the key ``bearing_rig_sim``. A second run reads the
keys already present and computes only the others.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any
from collections.abc import Iterable, Sequence

import pyarrow as pa
import pyarrow.parquet as pq

from bearing_rig_sim.errors import RigError
from bearing_rig_sim.sweep.points import COLUMNS

RESULTS_NAME = "results.parquet"
PARTS_DIR = "parts"
METADATA_KEY = b"bearing_rig_sim"


class SweepTableError(RigError):
    """A result table that cannot be resumed or read."""


def schema(axes: Sequence[str], context: dict[str, Any]) -> pa.Schema:
    """The table's schema: :data:`COLUMNS`, one float64 column per axis, the context as
    metadata."""
    fields = [pa.field(name, getattr(pa, kind)()) for name, kind in COLUMNS.items()]
    fields += [pa.field(a, pa.float64()) for a in axes if a not in COLUMNS]
    return pa.schema(fields, metadata={METADATA_KEY: json.dumps(context, sort_keys=True).encode()})


def read_context(path: str | Path) -> dict[str, Any]:
    """The run context stored in a result file's metadata."""
    meta = pq.read_schema(path).metadata or {}
    if METADATA_KEY not in meta:
        raise SweepTableError(f"{path}: not a bearing-rig sweep table (no {METADATA_KEY.decode()} metadata)")
    return dict(json.loads(meta[METADATA_KEY]))


class ResultTable:
    """The result table of one sweep in ``out_dir``.

    Args:
        out_dir: the output folder (created).
        axes: the sweep's axis names (their columns).
        context: the run context (bearing, calibration, version, spec hash, ...). Its
            ``context_key`` entry must match the one of existing results, else they belong to
            another model or code and cannot be resumed.

    Raises:
        SweepTableError: the folder holds results of another context.
    """

    def __init__(self, out_dir: str | Path, axes: Sequence[str], context: dict[str, Any]) -> None:
        self.out_dir = Path(out_dir)
        self.parts_dir = self.out_dir / PARTS_DIR
        self.path = self.out_dir / RESULTS_NAME
        self.schema = schema(axes, context)
        self.context = context
        self.parts_dir.mkdir(parents=True, exist_ok=True)
        self._count = len(list(self.parts_dir.glob("part-*.parquet")))
        for existing in self._files():
            other = read_context(existing)
            if other.get("context_key") != context.get("context_key"):
                raise SweepTableError(
                    f"{existing} holds results of another model or code version (context {other.get('context_key')}, "
                    f"this run {context.get('context_key')}); use another --out folder or remove it"
                )

    def _files(self) -> list[Path]:
        files = sorted(self.parts_dir.glob("part-*.parquet"))
        return ([self.path] if self.path.exists() else []) + files

    def done_keys(self) -> set[str]:
        """Point keys already in the table (merged file and parts)."""
        keys: set[str] = set()
        for path in self._files():
            keys.update(pq.read_table(path, columns=["point_key"]).column("point_key").to_pylist())
        return keys

    def append(self, rows: Iterable[dict[str, Any]]) -> int:
        """Write ``rows`` as one part file (atomically); return how many."""
        rows = list(rows)
        if not rows:
            return 0
        table = pa.Table.from_pylist(rows, schema=self.schema)
        self._count += 1
        final = self.parts_dir / f"part-{os.getpid()}-{self._count:06d}.parquet"
        tmp = final.with_suffix(".tmp")
        pq.write_table(table, tmp)
        os.replace(tmp, final)
        return len(rows)

    def finish(self, sort_by: Sequence[str]) -> Path:
        """Merge everything into ``results.parquet`` (one row per key), remove the parts."""
        parts = self._files()
        tables = [pq.read_table(p).select(self.schema.names).cast(self.schema) for p in parts]
        merged = pa.concat_tables(tables) if tables else self.schema.empty_table()
        seen: set[str] = set()
        keep = []
        for i, key in enumerate(merged.column("point_key").to_pylist()):
            if key not in seen:
                seen.add(key)
                keep.append(i)
        merged = merged.take(keep)
        if merged.num_rows and sort_by:
            merged = merged.sort_by([(c, "ascending") for c in sort_by if c in merged.column_names])
        merged = merged.replace_schema_metadata(self.schema.metadata)
        tmp = self.path.with_suffix(".tmp")
        pq.write_table(merged, tmp)
        os.replace(tmp, self.path)
        for p in parts:
            if p != self.path:
                p.unlink()
        return self.path
