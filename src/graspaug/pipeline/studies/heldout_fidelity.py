"""``graspaug study heldout-fidelity``: what a trained AutoEncoder keeps of real shapes it never trained on: the recon
pool's fidelity, on the test split.

The ``fidelity`` stage measures the ``recon`` pool: train-split shapes (the AutoEncoder learns every train shape)
decoded from their own latents. This study asks the same of held-out shapes. On a project where ``embed`` and
``render@original`` have run, for ``shapes`` random test-split shapes (``seed``), it

1. decodes each shape's latent (``data/latents.parquet``) with ``models/ae_critic.pt`` and meshes it at the shape's
   own pitch (``data/voxels.npz``) with the recon pool's own runner (``generate``'s recipe, ``generate.decode``; a
   decoder of signed distances: marching cubes at 0 alone);
2. labels the grasps of the original and of its reconstruction as the ``grasps`` stage does (the same ``grasps``
   params and ``seed``, each shape's own generator) and renders their datapoints as the ``render`` stage does;
3. gives, over the shapes that meshed, the graspness kept and the datapoints kept (after / before, ratios of paired
   means, Fieller 95%), the datapoints' positive share (the render stage's label), and how many meshed.

It writes ``summary.json`` and ``per_shape.csv`` to its output folder and returns the table it prints.
"""

from __future__ import annotations

import json
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.augment.candidates import Candidate
from graspaug.augment.decode import mesh_batches
from graspaug.augment.pools import BaseSet
from graspaug.augment.scores import graspness
from graspaug.errors import DataError
from graspaug.experiments.fidelity.numbers import heldout_summary
from graspaug.experiments.fidelity.words import paired_graspness_kept_markdown
from graspaug.grasping.labelled import grasps_of_shapes
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.meshes import mesh_path, write_obj
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.io.voxels import read_voxels
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import AE_CRITIC_MODEL, GENERATED_SUFFIX, LATENTS, SHAPES_TABLE, VOXELS, corpus_files
from graspaug.render.corpus_dataset import render_corpus, with_pool_columns
from graspaug.render.dataset import datapoints_index


def reconstruct(project: Path, ids: list[str], params, folder: Path, workers: int) -> dict[str, str | None]:
    """Each shape of ``ids`` decoded from its own latent and meshed by the recon pool's runner
    (:func:`graspaug.augment.decode.mesh_batches`, parents k and k at weight 0), written to ``folder``/<id>.obj;
    shape id → why it did not mesh (None where it did)."""
    import torch

    ae, _, _ = load_autoencoder(project / AE_CRITIC_MODEL, params.ae.net)
    latents = read_table(project / LATENTS).set_index("shape_id")
    voxels = read_voxels(project / VOXELS)
    pitch = dict(zip(voxels.shape_id, voxels.pitch))
    n, z = len(ids), np.stack(latents.loc[ids, "z"].to_numpy())
    shapes = BaseSet(np.array(ids), z, np.zeros(n), np.zeros(n), np.array([pitch[s] for s in ids]))  # no scores needed
    run_batch = mesh_batches(ae, torch.device("cpu"), shapes, params.generate.decode, workers, "mesh decodes")
    decoded = run_batch([Candidate(k, k, 0.0, "recon") for k in range(n)])
    for shape_id, d in zip(ids, decoded):
        if d.mesh is not None:
            write_obj(d.mesh, mesh_path(folder, shape_id, GENERATED_SUFFIX))
    return {shape_id: d.reason for shape_id, d in zip(ids, decoded)}


def label_and_render(shapes: pd.DataFrame, folder: Path, suffix: str, params, workers: int, label: str) -> pd.DataFrame:
    """Per shape of ``shapes`` (corpus rows; meshes ``folder``/<id><suffix>): graspness, grasps labelled, datapoints
    rendered and how many the render stage labels positive (:func:`graspaug.render.dataset.datapoints_index`), the
    stable poses the render considered (NaN without datapoints) and the grasps with at least one datapoint, as the
    ``grasps`` and ``render`` stages make them."""
    ids = list(shapes.shape_id)
    if not ids:
        raise DataError("heldout-fidelity: no reconstruction meshed, nothing to label")
    grasps, _ = grasps_of_shapes(folder, ids, suffix, params.grasps, params.seed, workers, f"grasps ({label})")
    index = {s: i for i, s in enumerate(ids)}
    score, count = graspness(grasps.success.to_numpy(), grasps.shape_id.map(index).to_numpy(), len(ids))
    shapes = with_pool_columns(shapes.reset_index(drop=True).copy())
    hand = params.grasps.gripper
    by_shape, results = render_corpus(
        shapes, grasps, folder, suffix, params.render, hand, params.seed, workers, f"render ({label})"
    )
    _, parts, _, _, n_poses = datapoints_index(shapes, by_shape, results, params.grasps.threshold)
    rendered = [s for s, (data, _) in zip(ids, results) if data is not None]
    part = dict(zip(rendered, parts))
    poses = dict(zip(rendered, n_poses))  # a shape without datapoints: left out, as render does
    return pd.DataFrame(
        {
            "shape_id": ids,
            "graspness": score,
            "grasps": count,
            "datapoints": [len(part[s]) if s in part else 0 for s in ids],
            "positives": [int(part[s].label.sum()) if s in part else 0 for s in ids],
            "stable_poses": [poses.get(s, np.nan) for s in ids],
            "grasps_rendered": [part[s].grasp_id.nunique() if s in part else 0 for s in ids],
        }
    )


def run(project: Path, n_shapes: int, seed: int, workers: int, out: Path) -> str:
    """The study (module docstring) on ``n_shapes`` test shapes of ``project`` drawn with ``seed``; writes
    ``per_shape.csv`` and ``summary.json`` into the folder ``out``; the text to print."""
    project = project.resolve()
    params = load_params(project / "params.yaml")
    _, mesh_dir, suffix = corpus_files("original")
    shapes = read_table(project / SHAPES_TABLE)  # with the split
    test = shapes.shape_id[shapes.split == "test"].to_numpy()
    rng = np.random.default_rng(seed)
    ids = sorted(rng.choice(test, size=min(n_shapes, len(test)), replace=False).tolist())
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        reasons = reconstruct(project, ids, params, folder, workers)
        made = [s for s in ids if reasons[s] is None]
        rows = shapes.set_index("shape_id", drop=False)
        before = label_and_render(rows.loc[ids], project / mesh_dir, suffix, params, workers, "originals")
        after = label_and_render(rows.loc[made], folder, GENERATED_SUFFIX, params, workers, "reconstructions")
    per_shape = before.merge(after, on="shape_id", how="left", suffixes=("_before", "_after"))
    per_shape["meshed"] = per_shape.shape_id.map(lambda s: reasons[s] is None)
    per_shape["reason"] = per_shape.shape_id.map(reasons)
    summary = heldout_summary(per_shape) | {
        "decoder": params.ae.net.output,
        "project": str(project),
        "shape_seed": seed,
        "seconds": round(time.perf_counter() - start, 1),
    }
    write_csv(per_shape, out / "per_shape.csv")
    write_json(json.loads(json.dumps(summary, default=float)), out / "summary.json")
    table = paired_graspness_kept_markdown(pd.DataFrame([{"variant": f"{summary['decoder']} recon, test"} | summary]))
    ends = (summary[f"datapoints_kept{e}"] for e in ("", "_low", "_high"))
    kept = ["n/a" if v is None else f"{v:.1%}" for v in ends]
    return table + (
        f"\ndatapoints / shape {summary['datapoints_before']:.1f} -> {summary['datapoints_after']:.1f}: kept "
        f"{kept[0]} [{kept[1]}, {kept[2]}]; positive share {summary['positive_before']:.3f} -> "
        f"{summary['positive_after']:.3f}; stable poses {summary['stable_poses_before']:.2f} -> "
        f"{summary['stable_poses_after']:.2f}; grasps with a datapoint {summary['grasps_rendered_before']:.1f} -> "
        f"{summary['grasps_rendered_after']:.1f}; {summary['seconds']} s"
    )
