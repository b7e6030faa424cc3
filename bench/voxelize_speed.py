"""Speed of the solid voxelizer against trimesh on the same meshes, in one run.

Reference: ``mesh.voxelized(pitch).fill()`` (trimesh: surface voxels by
subdivision, then a morphological fill). Ours: ``voxelize_solid``. Both get the
same closed outer surfaces (the first N default shapes as ingest makes them)
and the same pitch (largest extent / (R - 2)). Prints the time of each, the
speed ratio, the IoU between the two occupancies (ours at our voxel centers,
trimesh's looked up at the same points), and each one's IoU against the
half-space reference of the source's convex parts.

    python bench/voxelize_speed.py --n 100 --resolution 64
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _corpus import default_shapes

from graspaug.geometry.solid import union_contains
from graspaug.geometry.voxelize import fit_grid, iou, voxelize_solid


def trimesh_at(vg, grid) -> np.ndarray:
    """A trimesh VoxelGrid read at our grid's voxel centers: (R, R, R) bool."""
    centers = grid.centers().reshape(-1, 3)
    idx = vg.points_to_indices(centers)
    inside = np.all((idx >= 0) & (idx < np.array(vg.matrix.shape)), axis=1)
    occ = np.zeros(len(centers), dtype=bool)
    occ[inside] = vg.matrix[tuple(idx[inside].T)]
    return occ.reshape((grid.resolution,) * 3)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100, help="first N default shapes")
    ap.add_argument("--resolution", type=int, default=64)
    args = ap.parse_args()

    shapes = default_shapes(args.n)
    grids = [fit_grid(s.mesh.bounds, args.resolution) for s in shapes]
    for s in shapes[:3]:  # warm caches (trimesh's lazy properties are per mesh; use copies below)
        voxelize_solid(s.mesh.vertices, s.mesh.faces, grids[0])

    t0 = time.perf_counter()
    ours = [voxelize_solid(s.mesh.vertices, s.mesh.faces, g) for s, g in zip(shapes, grids)]
    t_ours = time.perf_counter() - t0

    t0 = time.perf_counter()
    ref = [s.mesh.copy().voxelized(g.pitch).fill() for s, g in zip(shapes, grids)]
    t_ref = time.perf_counter() - t0

    theirs = [trimesh_at(vg, g) for vg, g in zip(ref, grids)]
    refs = [
        union_contains(s.parts, g.centers().reshape(-1, 3)).reshape(o.shape) for s, g, o in zip(shapes, grids, ours)
    ]
    ious = np.array([iou(o, t) for o, t in zip(ours, theirs)])
    ours_ref = np.array([iou(o, r) for o, r in zip(ours, refs)])
    theirs_ref = np.array([iou(t, r) for t, r in zip(theirs, refs)])
    print(
        f"{len(shapes)} default shapes at {args.resolution}³ (median "
        f"{int(np.median([len(s.mesh.faces) for s in shapes]))} faces), one process"
    )
    print(f"trimesh voxelized(pitch).fill(): {t_ref:.2f} s ({1000 * t_ref / len(shapes):.1f} ms/shape)")
    print(f"graspaug voxelize_solid:        {t_ours:.3f} s ({1000 * t_ours / len(shapes):.2f} ms/shape)")
    print(f"speed ratio: {t_ref / t_ours:.1f}x")
    print(f"IoU ours vs trimesh: mean {ious.mean():.4f}, min {ious.min():.4f}")
    print(
        f"IoU vs the half-space reference (source convex parts): ours mean {ours_ref.mean():.4f} (min "
        f"{ours_ref.min():.4f}), "
        f"trimesh mean {theirs_ref.mean():.4f} (min {theirs_ref.min():.4f})"
    )


if __name__ == "__main__":
    main()
