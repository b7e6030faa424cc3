"""How faithful are the generated pools, before any training? (issue #33, item 3) One table per run.

For base size B of a finished default run, per pool (every generated pool: ``targeted``,
``random``, ``recon``, ``blend`` as ``gqcnn.pools`` made them, and the ``real`` pool's first B
shapes of training seed 0's split, the control): shapes, distinct parents and α counts (generated
pools), graspness (share of sampled grasps with robust ε above the threshold) against the mean of
each shape's two parents, the share of positive rendered datapoints, datapoints per shape, median
sorted extents, and coverage / MMD / 1-NN accuracy on the
Chamfer distance against as many held-out real shapes (a seeded draw from the test split; Chamfer
on ``--points`` surface points per shape, :mod:`graspaug.experiments.fidelity`). Prints one JSON
line per pool. Run it in a project where ``render_generated@B`` and ``train_gqcnn@0`` have run:

    python studies/fidelity.py [--base-size 50] [--points 512]
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
import pandas as pd

from graspaug.config import Params
from graspaug.experiments.fidelity import distribution_distances, surface_cloud
from graspaug.generation import ratio_count
from graspaug.io.meshes import mesh_path, read_mesh
from graspaug.io.tables import read_table
from graspaug.paths import (
    SCORES,
    SHAPES_DIR,
    generated_index,
    generated_meshes,
    gqcnn_dir,
    gqcnn_seed_dir,
    grasps_table,
)
from graspaug.rng import shape_rng


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base-size", type=int, default=50)
    parser.add_argument("--points", type=int, default=512)
    args = parser.parse_args()
    params, b = Params(), args.base_size
    start = time.perf_counter()
    generated = read_table(generated_index(b))
    split = json.loads((gqcnn_seed_dir(0) / "split.json").read_text())
    pools = {p: list(generated.shape_id[generated.pool == p]) for p in generated.pool.unique()}  # every generated one
    pools["real"] = list(split["real_pool"][: ratio_count(1.0, b)])
    scores = read_table(SCORES).set_index("shape_id").graspness
    gen_grasps = read_table(grasps_table(f"gen_{b}")).groupby("shape_id").success.mean()
    original = read_table(gqcnn_dir("original") / "index.parquet")
    rendered = pd.concat([original, read_table(gqcnn_dir(f"gen_{b}") / "index.parquet")])
    test_ids = sorted(original.shape_id[original.split == "test"].unique())
    rng = shape_rng(params.seed, "fidelity", f"reference-{b}")
    reference_ids = [test_ids[i] for i in sorted(rng.choice(len(test_ids), size=b, replace=False))]
    reference = [surface_cloud(read_mesh(mesh_path(SHAPES_DIR, s)), args.points, rng) for s in reference_ids]
    for pool, ids in pools.items():
        is_generated = pool != "real"
        meshes = [
            read_mesh(mesh_path(generated_meshes(b), s, ".obj") if is_generated else mesh_path(SHAPES_DIR, s))
            for s in ids
        ]
        rows = rendered[rendered.shape_id.isin(ids)]
        extents = np.median(np.sort([m.extents for m in meshes], axis=1), axis=0)
        line = {"base_size": b, "pool": pool, "shapes": len(ids)}
        if is_generated:
            g = generated.set_index("shape_id").loc[ids]
            child = gen_grasps.reindex(ids).to_numpy()
            parents = 0.5 * (scores.loc[g.parent_a].to_numpy() + scores.loc[g.parent_b].to_numpy())
            line |= {
                "distinct_parents": int(len(set(g.parent_a) | set(g.parent_b))),
                "alphas": {f"{a:g}": int(n) for a, n in g.alpha.value_counts().sort_index().items()},
                "graspness": round(float(np.nanmean(child)), 4),
                "parents_graspness": round(float(np.mean(parents)), 4),
                "graspness_kept": round(float(np.nanmean(child) / np.mean(parents)), 3),
            }
        else:
            line["graspness"] = round(float(scores.reindex(ids).mean()), 4)
        line |= {
            "positive_share": round(float(rows.label.mean()), 4),
            "datapoints_per_shape": round(len(rows) / len(ids), 1),
            "median_sorted_extents_cm": [round(100 * float(e), 2) for e in extents],
            **{
                k: round(v, 5)
                for k, v in distribution_distances(
                    [surface_cloud(m, args.points, rng) for m in meshes], reference
                ).items()
            },
            "seconds": round(time.perf_counter() - start, 1),
        }
        print(json.dumps(line))


if __name__ == "__main__":
    main()
