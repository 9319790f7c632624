"""Batch runs of the suite on Dask distributed: a local cluster by default (one worker process
per core), or the scheduler at an address, so the same run can spread over many machines.

Each scene is one task; results come back as they finish, with a progress bar.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from tqdm import tqdm

from evclust.clusterer import ClustererParams
from evclust.errors import EvclustError
from evclust.suite.evaluate import SceneResult, evaluate_scene
from evclust.suite.prepare import SceneFiles, prepare_scene, split_seeds


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None):
    """A Dask client: on `scheduler` (an address such as tcp://host:8786) or on a local cluster
    of `workers` single-threaded processes (default: one per core)."""
    import dask
    from distributed import Client, LocalCluster

    # The clusterer's loops are compiled and single-threaded: processes, not threads, and no
    # dashboard (a port nobody asked for).
    with dask.config.set({"distributed.worker.daemon": False, "distributed.logging.distributed": "error"}):
        if scheduler:
            try:
                client = Client(scheduler, timeout="20s")
            except OSError as exc:
                raise EvclustError(f"Dask scheduler {scheduler}: {exc}") from None
            with client:
                yield client
            return
        n = workers or os.cpu_count() or 1
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, Client(cluster) as client:
            yield client


def map_scenes(client, fn, items, *args, desc: str = "", progress: bool = True) -> list:
    """fn(item, *args) for every item on the cluster, in the order of `items`."""
    from distributed import as_completed

    futures = [client.submit(fn, item, *args, pure=False) for item in items]
    index = {f.key: i for i, f in enumerate(futures)}
    out = [None] * len(futures)
    with tqdm(total=len(futures), desc=desc, unit="scene", disable=None if progress else True) as bar:
        for future in as_completed(futures):
            out[index[future.key]] = future.result()
            bar.update(1)
    return out


def prepare_split(client, split: str, folder: str | Path, progress: bool = True) -> list[SceneFiles]:
    """Generate and simulate every scene of a split into `folder` (scenes already there are kept)."""
    return map_scenes(client, prepare_scene, split_seeds(split), str(folder), desc=f"prepare {split}", progress=progress)


def run_split(
    client, split: str, folder: str | Path, params: ClustererParams, model: str = "float", progress: bool = True
) -> list[SceneResult]:
    """Track and score every scene of a split (prepared first if needed)."""
    files = prepare_split(client, split, folder, progress)
    return map_scenes(client, evaluate_scene, files, params, model, desc=f"track {split} ({model})", progress=progress)
