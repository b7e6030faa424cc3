"""Accuracy of the solid voxelizer on the default corpus, against a trustworthy reference.

Reference: each source object's convex parts as half-spaces, tested at every voxel
center, then united (ray parity and ``contains`` on the assembly are not
trustworthy: its parts touch face to face). Ours: ``voxelize_solid`` of the closed
outer surface that ingest rebuilds. Prints mean / min / percentiles of IoU.

    python bench/voxelize_accuracy.py --n 1000 --resolution 64
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _corpus import default_shapes
from joblib import Parallel, delayed

from graspaug.geometry.solid import union_contains
from graspaug.geometry.voxelize import fit_grid, iou, voxelize_solid


def shape_iou(shape, resolution: int) -> float:
    grid = fit_grid(shape.mesh.bounds, resolution)
    ours = voxelize_solid(shape.mesh.vertices, shape.mesh.faces, grid)
    ref = union_contains(shape.parts, grid.centers().reshape(-1, 3)).reshape(ours.shape)
    return iou(ours, ref)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000, help="first N default shapes")
    ap.add_argument("--resolution", type=int, default=64)
    ap.add_argument("--n-jobs", type=int, default=2)
    args = ap.parse_args()

    t0 = time.perf_counter()
    shapes = default_shapes(args.n, args.n_jobs)
    t1 = time.perf_counter()
    ious = np.array(Parallel(n_jobs=args.n_jobs)(delayed(shape_iou)(s, args.resolution) for s in shapes))
    worst = np.argsort(ious)[:5]
    print(f"shapes: {len(shapes)} (ingested in {t1 - t0:.1f} s), resolution {args.resolution}³")
    print(
        f"IoU vs half-space reference: mean {ious.mean():.4f}, median {np.median(ious):.4f}, "
        f"p5 {np.percentile(ious, 5):.4f}, min {ious.min():.4f}; share >= 0.97: {(ious >= 0.97).mean():.3f}"
    )
    print("worst: " + ", ".join(f"{shapes[i].shape_id} {ious[i]:.3f}" for i in worst))


if __name__ == "__main__":
    main()
