"""Per-shape stages on a real Dask distributed cluster give what the local joblib run gives."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from graspaug.parallel import Workers, parallel_map
from graspaug.pipeline.params.profiles import profile_params


def square(x: int) -> int:
    return x * x


def test_workers_check_their_settings():
    with pytest.raises(ValueError, match="needs a scheduler address"):
        Workers(executor="dask")
    with pytest.raises(ValueError, match="joblib or dask"):
        Workers(executor="ray")


def test_local_processes_keep_order():
    assert parallel_map(square, list(range(20)), Workers(n_jobs=2), "squares") == [x * x for x in range(20)]


def worker_address(_: int) -> str:
    from distributed import get_worker

    return get_worker().address


def run_ingest_and_voxelize(folder, params, monkeypatch) -> tuple[pd.DataFrame, dict, dict]:
    from graspaug.io.voxels import read_voxels
    from graspaug.pipeline.stages import ingest, voxelize

    monkeypatch.chdir(folder)
    ingest.run(params)
    voxelize.run(params)
    shapes = pd.read_parquet(folder / "data/shapes.parquet")
    meshes = {p.name: p.read_bytes() for p in sorted((folder / "data/shapes").iterdir())}
    voxels = read_voxels(folder / "data/voxels.npz")
    return shapes, meshes, {"occupancy": voxels.occupancy, "ids": np.asarray(voxels.shape_id), "origin": voxels.origin}


def test_stages_on_a_dask_cluster_equal_the_local_run(repo_root, tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    tiny = profile_params("tiny", repo_root / "profiles")
    params = tiny.model_copy(
        update={
            "data": dataclasses.replace(tiny.data, limit=6),
            "ingest": dataclasses.replace(tiny.ingest, min_shapes=2),
        }
    )
    (tmp_path / "local").mkdir()
    (tmp_path / "cluster").mkdir()
    local = run_ingest_and_voxelize(tmp_path / "local", params, monkeypatch)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        on_cluster = params.model_copy(update={"executor": "dask", "scheduler": cluster.scheduler_address})
        remote = run_ingest_and_voxelize(tmp_path / "cluster", on_cluster, monkeypatch)
        ran_on = set(parallel_map(worker_address, list(range(8)), on_cluster.workers, "where"))
        assert ran_on and ran_on <= set(cluster.scheduler_info["workers"])  # the calls ran on the cluster's workers
    pd.testing.assert_frame_equal(local[0], remote[0])
    assert len(local[1]) == 6 and local[1] == remote[1]  # byte-identical meshes
    for key in local[2]:
        assert np.array_equal(local[2][key], remote[2][key])


def test_workers_hand_freed_memory_back_so_loky_restarts_none(tmp_path):
    """Ingesting real meshes in two worker processes: each worker's resident size would grow with the
    largest mesh it has seen (glibc keeps what was freed), past loky's 300 MB leak guard, which then
    restarts workers with a "A worker stopped … memory leak" warning (seen in 1 of 5 runs of this test with
    freed memory released alone). Workers release freed memory after each shape and raise the guard to
    2 GiB, so none is restarted and nothing is warned of."""
    import warnings

    from graspaug.augment.corpus import ingest_source
    from graspaug.io.sources import pybullet_sources
    from graspaug.pipeline.params.ingest import IngestParams

    cfg = IngestParams()
    sources = pybullet_sources(60)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = parallel_map(
            lambda s: ingest_source(s, cfg.max_faces, cfg.max_file_mb, cfg.surface, tmp_path), sources, 2, "ingest"
        )
    assert len(rows) == 60
    assert not [w for w in caught if "worker stopped" in str(w.message)]
