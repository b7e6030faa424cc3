"""The input data of studies/cuda_check.py: real voxel grids and real GQ-CNN crops, as two npz files.

- ``voxels64.npz``: the first ``--shapes`` pybullet_data ``random_urdfs`` shapes (from ``--start-at``) that the
  project's own ingest accepts (load_shape + prepare_shape with the default ``ingest.surface`` settings),
  voxelized solid at 64³ by its own voxelizer (fit_grid, margin 1, + voxelize_solid); keys ``shape_id`` (N,),
  ``packed`` (N, 64³/8) uint8 (graspaug.geometry.voxelize.pack_bits) and ``resolution`` (64). cuda_check.py
  trains the AE on the first 16 and holds out the next 32 (8 with ``--tiny``; the throughput runs use
  all): 48 shapes at least (24 for ``--tiny``).
- ``gqcnn_crops.npz``: the depth crops of a project folder with a rendered dataset (``--project``; read through
  graspaug.io.gqcnn): train = the crops of ``<project>/data/gqcnn/original`` whose shape is in the train split
  of ``<project>/data/shapes.parquet``; held-out = its test-split crops, then every crop of each
  ``<project>/data/gqcnn/gen_<B>`` (by B); keys ``{train,test}_{images,z,labels}`` and ``note``.

The cited results (docs/results.md, "Training on a CUDA GPU") used 128 shapes and the crops of the tiny
profile's pipeline (``render`` of ``original`` and ``gen_6``: 234 train, 54 + 152 held out). Run from the
repository root (~40 s for 128 shapes, plus pybullet_data's import)::

    .venv/bin/python studies/cuda_check_data.py --project PROJECT [--shapes 128] [--data studies/out/cuda/data]
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path

import numpy as np

from graspaug.geometry.loading import MeshRejected, load_shape
from graspaug.geometry.prepare import prepare_shape
from graspaug.geometry.settings import SurfaceSettings
from graspaug.geometry.voxelize import fit_grid, pack_bits, voxelize_solid
from graspaug.io.gqcnn import GraspImages
from graspaug.io.sources import pybullet_sources
from graspaug.io.tables import read_table
from graspaug.pipeline.paths import SHAPES_TABLE, gqcnn_dir

HERE = Path(__file__).resolve().parent
DATA = HERE / "out" / "cuda" / "data"
RESOLUTION = 64


def make_voxels(n_want: int, start_at: int, out: Path) -> None:
    settings = SurfaceSettings()
    ids, grids, t0 = [], [], time.perf_counter()
    for src in pybullet_sources()[start_at:]:
        if len(ids) >= n_want:
            break
        t = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                mesh = prepare_shape(load_shape(src.path, src.unit_scale, 1_000_000, 100.0), settings).mesh
        except (MeshRejected, OSError) as exc:
            print(src.shape_id, "rejected", exc)
            continue
        occ = voxelize_solid(np.asarray(mesh.vertices), np.asarray(mesh.faces), fit_grid(mesh.bounds, RESOLUTION, 1))
        ids.append(src.shape_id)
        grids.append(occ)
        print(src.shape_id, f"fill {occ.mean():.3f}", f"{time.perf_counter() - t:.1f}s", flush=True)
    if len(ids) < n_want:
        raise SystemExit(f"only {len(ids)} of {n_want} shapes accepted")
    occ = np.stack(grids)
    np.savez_compressed(out, shape_id=np.array(ids), packed=pack_bits(occ), resolution=RESOLUTION)
    print(f"{out}: {len(ids)} shapes, {time.perf_counter() - t0:.1f}s total, mean fill {occ.mean():.3f}")


def _arrays(data: GraspImages, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return data.images(rows), data.read("z", rows), data.read("labels", rows)


def make_crops(project: Path, out: Path) -> None:
    split = read_table(project / SHAPES_TABLE).set_index("shape_id")["split"]
    original = GraspImages.open(project / gqcnn_dir("original"))
    shape_split = original.index.shape_id.map(split)
    if shape_split.isna().any():
        missing = sorted(original.index.shape_id[shape_split.isna()].unique())
        raise SystemExit(f"{len(missing)} shapes of the original corpus are not in {SHAPES_TABLE}: {missing[:5]}")
    train_rows = np.flatnonzero((shape_split == "train").to_numpy())
    test_rows = np.flatnonzero((shape_split == "test").to_numpy())
    train = _arrays(original, train_rows)
    held = [_arrays(original, test_rows)]
    parts = [f"original split=test ({len(test_rows)})"]
    generated = sorted(
        (p for p in (project / "data" / "gqcnn").glob("gen_*") if p.name[4:].isdigit()), key=lambda p: int(p.name[4:])
    )
    for folder in generated:
        data = GraspImages.open(folder)
        held.append(_arrays(data, np.arange(len(data))))
        parts.append(f"{folder.name} ({len(data)})")
    test = tuple(np.concatenate([h[i] for h in held]) for i in range(3))
    note = f"train: {project} data/gqcnn/original split=train ({len(train_rows)}); held-out: " + " + ".join(parts)
    np.savez_compressed(
        out,
        train_images=train[0],
        train_z=train[1],
        train_labels=train[2],
        test_images=test[0],
        test_z=test[1],
        test_labels=test[2],
        note=np.array(note),
    )
    print(f"{out}: {note}; positives train {int(train[2].sum())}, held-out {int(test[2].sum())}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--project", type=Path, required=True, help="a project folder with a rendered GQ-CNN dataset")
    ap.add_argument("--data", type=Path, default=DATA, help="where the npz files go (%(default)s)")
    ap.add_argument("--shapes", type=int, default=128, help="voxelized shapes (%(default)s)")
    ap.add_argument("--start-at", type=int, default=0, help="first random_urdfs shape to try (%(default)s)")
    a = ap.parse_args()
    a.data.mkdir(parents=True, exist_ok=True)
    make_crops(a.project, a.data / "gqcnn_crops.npz")
    make_voxels(a.shapes, a.start_at, a.data / f"voxels{RESOLUTION}.npz")


if __name__ == "__main__":
    main()
