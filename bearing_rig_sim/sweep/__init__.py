"""Sweeps at scale: operating maps, tolerances and calibration points on Dask distributed.

* :mod:`.spec`: the validated sweep specification (grid axes and random samples, each with its
  unit).
* :mod:`.points`: what a worker computes for a batch of points (no Dask).
* :mod:`.table`: the resumable Parquet result table with the run context in its metadata.
* :mod:`.runner`: the sweep on a ``LocalCluster`` or an existing Dask cluster.
* :mod:`.operating_map`: the slip map with the skid boundary and the SKF minimum axial load.
"""
