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
    from graspaug.pipeline.stages import ingest, split, voxelize

    monkeypatch.chdir(folder)
    ingest.run(params)
    split.run(params)
    voxelize.run(params)
    shapes = pd.read_parquet(folder / "data/shapes.parquet")
    meshes = {p.name: p.read_bytes() for p in sorted((folder / "data/shapes").iterdir())}
    voxels = read_voxels(folder / "data/voxels.npz")
    return shapes, meshes, {"occupancy": voxels.occupancy, "ids": np.asarray(voxels.shape_id), "origin": voxels.origin}


def test_stages_on_a_dask_cluster_equal_the_local_run(repo_root, tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    tiny = profile_params("tiny", repo_root / "profiles")
    params = tiny.model_copy(  # 6 shapes: an experiment they hold (split refuses fewer shapes than settings need)
        update={
            "data": dataclasses.replace(tiny.data, limit=6),
            "ingest": dataclasses.replace(tiny.ingest, min_shapes=2),
            "generate": dataclasses.replace(tiny.generate, base_sizes=[2]),
            "gqcnn": dataclasses.replace(
                tiny.gqcnn, augment_base_sizes=[2], pools=["targeted", "random"], val_shapes=1
            ),
            "lifelong": dataclasses.replace(tiny.lifelong, rounds={}),
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


@pytest.fixture(scope="module")
def rendered_tiny(repo_root, tmp_path_factory):
    """A project folder holding the tiny profile's ingested, graded and rendered original shapes (20 default
    objects, about 30 s) and params that train its three 1:0 and ceiling networks (no generated shapes)."""
    from graspaug.pipeline.stages import grasps, ingest, render, split

    tiny = profile_params("tiny", repo_root / "profiles")
    params = tiny.model_copy(update={"gqcnn": dataclasses.replace(tiny.gqcnn, augment_base_sizes=())})
    folder = tmp_path_factory.mktemp("rendered")
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(folder)
        ingest.run(params)
        split.run(params)
        grasps.run(params)
        render.run(params)
    return folder, params


def run_train_gqcnn(source, folder, params, monkeypatch) -> dict[str, bytes]:
    """``train_gqcnn`` seed 0 in a copy ``folder`` of the project ``source``: every output file's bytes by path
    (the timing file left out)."""
    import shutil

    from graspaug.pipeline.stages import train_gqcnn

    shutil.copytree(source, folder)
    monkeypatch.chdir(folder)
    train_gqcnn.run(params, 0)
    outputs = [*sorted((folder / "models/gqcnn/s0").rglob("*")), folder / "metrics/gqcnn/s0.json"]
    outputs += [folder / "reports/gqcnn/networks/s0.json", folder / "reports/gqcnn/validation/s0.csv"]
    return {str(p.relative_to(folder)): p.read_bytes() for p in outputs if p.is_file()}


def test_train_gqcnn_on_a_dask_cluster_equals_the_local_run_byte_for_byte(rendered_tiny, tmp_path, monkeypatch):
    """The networks of a seed go one per task to a real two-worker LocalCluster, each task with one torch
    thread; a local run at one thread writes the same bytes (at another thread count float sums round
    differently: docs/cluster.md)."""
    import torch

    from graspaug.training.networks import TASK_THREADS

    distributed = pytest.importorskip("distributed")
    source, params = rendered_tiny
    before = torch.get_num_threads()
    torch.set_num_threads(TASK_THREADS)
    try:
        local = run_train_gqcnn(source, tmp_path / "local", params, monkeypatch)
    finally:
        torch.set_num_threads(before)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        on_cluster = params.model_copy(update={"executor": "dask", "scheduler": cluster.scheduler_address})
        with distributed.Client(cluster) as client, distributed.get_task_stream(client) as stream:
            remote = run_train_gqcnn(source, tmp_path / "cluster", on_cluster, monkeypatch)
        workers = set(cluster.scheduler_info["workers"])
    # one task per network (a joblib batch of one call), each on one of the cluster's workers
    tasks = [t for t in stream.data if str(t["key"]).startswith("batch_of__in_folder_1_calls")]
    assert len(tasks) == 3 and {t["worker"] for t in tasks} <= workers, stream.data
    models = sorted(p for p in local if p.endswith("model.pt"))
    assert models == [f"models/gqcnn/s0/{n}/model.pt" for n in ("ceiling", "targeted/4-0", "targeted/6-0")]
    assert local.keys() == remote.keys()
    assert [p for p in local if local[p] != remote[p]] == []
    timing = (tmp_path / "cluster/reports/timing/train_gqcnn/s0.json").read_text()
    assert '"threads": 1' in timing and '"networks": 3' in timing
