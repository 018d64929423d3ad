"""Where many independent jobs run: the executor choice shared by the studies (calibration, the
paper's experiments) and the operating-map sweeps.

* :func:`open_client`: a Dask client on a given scheduler or on a new ``LocalCluster``;
* :func:`cluster_executor`: a ``concurrent.futures`` executor on Dask workers;
* :func:`process_pool`: the Dask cluster named in Dask's configuration
  (``DASK_SCHEDULER_ADDRESS``) when there is one, else forked local processes.

Dask and distributed are imported only when a cluster is used. This module sits below both
:mod:`bearing_rig_sim.studies` and :mod:`bearing_rig_sim.sweep` and imports neither.
"""

from __future__ import annotations

import logging
import multiprocessing
import os
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from contextlib import AbstractContextManager, contextmanager
from typing import Any

from bearing_rig_sim.errors import RigError

__all__ = ["SchedulerUnreachable", "cluster_executor", "open_client", "process_pool"]


class SchedulerUnreachable(RigError):
    """The Dask scheduler at the given address does not answer."""


def open_client(scheduler: str | None, workers: int | None) -> tuple[Any, Any]:
    """A Dask client on ``scheduler`` (address) or on a new ``LocalCluster`` of ``workers``
    single-threaded worker processes (default: one per core). Returns (client, cluster or
    None); close both when done.

    Raises:
        SchedulerUnreachable: ``scheduler`` is given and does not answer within 20 s.
    """
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout="20s"), None
        except OSError as exc:
            raise SchedulerUnreachable(f"cannot reach the Dask scheduler at {scheduler}: {exc}") from exc
    n = workers or os.cpu_count() or 1
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=logging.ERROR)
    return Client(cluster), cluster


@contextmanager
def cluster_executor(workers: int | None = None) -> Iterator[Executor]:
    """A ``concurrent.futures`` executor on Dask workers, for code written against a process
    pool: the cluster whose address is in Dask's configuration (``DASK_SCHEDULER_ADDRESS``) if
    there is one, else a ``LocalCluster`` of ``workers`` processes. Results of ``map`` come in
    order."""
    import dask

    client, cluster = open_client(dask.config.get("scheduler-address", None), workers)
    try:
        yield client.get_executor(pure=False)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def process_pool(workers: int) -> AbstractContextManager[Executor]:
    """Where points run in parallel: on the Dask cluster named by ``DASK_SCHEDULER_ADDRESS``
    when it is set (:func:`cluster_executor`), else on ``workers`` forked processes (they
    inherit the compiled kernels and start at once)."""
    import dask

    if dask.config.get("scheduler-address", None):
        return cluster_executor(workers)
    return ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork"))
