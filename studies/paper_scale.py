"""The paper profile at its own sizes, briefly: does its AE-Critic train, and how fast is each network?

On a project where ``render@original`` has run (``data/shapes.parquet``, ``data/shapes/``, ``data/gqcnn/original``),
with the ``paper`` profile's networks and learning rates (``profiles/paper.yaml``: 64³ grids, AE widths 64…512,
Dex-Net's GQ-CNN widths):

1. voxelizes ``--train-shapes`` random train shapes and ``--test-shapes`` random test shapes at the profile's
   resolution (solid occupancy, the profile's decoder output, as the ``voxelize`` stage makes it);
2. phase 1, the plain AutoEncoder, ``--epochs-ae`` epochs: the loss per epoch, shapes/s, held-out voxel IoU;
3. phase 2, the AE-Critic (eqs. 1–2), ``--epochs-critic`` epochs with the profile's warm-up (at most all but one of
   them): the critic loss per epoch (finite? its largest against its first), the critic's separation AUC on held-out
   interpolants (0.5: chance; above: it ranks interpolants above real grids), the held-out IoU after, shapes/s;
4. one GQ-CNN at the profile's widths, ``--gqcnn-steps`` SGD steps on the rendered crops of the train shapes:
   samples/s;
5. writes each held-out shape's reconstruction before and after phase 2 as a mesh (``generate``'s recipe, OBJ, in
   ``meshes/``) so the fidelity figures (graspness kept, datapoints per shape) can be computed elsewhere.

Everything goes to ``--out``: ``summary.json`` (settings, per-phase figures, seconds) and ``meshes/``. On a CPU keep
it small (the defaults take about 15 minutes on 2 cores); on a GPU raise every count::

    python studies/paper_scale.py --project PROJECT [--device auto] [--train-shapes 24] [--test-shapes 12]
        [--epochs-ae 6] [--epochs-critic 3] [--gqcnn-steps 20] [--batch-size B] [--out studies/out/paper_scale]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import time
from pathlib import Path

import numpy as np
import torch

from graspaug.device import resolve_device
from graspaug.geometry.from_voxels import mesh_decoded
from graspaug.geometry.voxelize import fit_grid, voxelize_solid
from graspaug.io.meshes import mesh_path, read_mesh, write_obj
from graspaug.io.tables import read_table
from graspaug.nets.ae_critic import AutoEncoder, Critic
from graspaug.nets.gqcnn import GQCNN
from graspaug.parallel import parallel_map
from graspaug.pipeline.params.profiles import profile_params
from graspaug.training.autoencoder import (
    critic_separation,
    decode,
    encode,
    reconstruction_iou,
    train_ae_critic,
    train_autoencoder,
)
from graspaug.training.gqcnn import train_gqcnn
from graspaug.training.gqcnn_data import shapes_datapoints

log = logging.getLogger("paper_scale")
OUT = Path(__file__).resolve().parent / "out" / "paper_scale"


def grid_of(job: tuple[Path, int, int]) -> tuple[np.ndarray, float]:
    """A shape file's solid occupancy (R, R, R) bool and its voxel pitch, m."""
    path, resolution, margin = job
    mesh = read_mesh(path)
    grid = fit_grid(mesh.bounds, resolution, margin)
    return voxelize_solid(mesh.vertices, mesh.faces, grid), grid.pitch


def write_reconstructions(ae, voxels, pitches, ids, decode_settings, device, folder: Path) -> int:
    """Each grid's reconstruction meshed by ``generate``'s recipe into ``folder``/<id>.obj; how many meshed."""
    folder.mkdir(parents=True, exist_ok=True)
    grids = decode(ae, encode(ae, voxels, device), device)
    meshed = 0
    for grid, pitch, shape_id in zip(grids, pitches, ids):
        _, mesh, reason = mesh_decoded(grid, pitch, decode_settings)
        if reason is None:
            write_obj(mesh, folder / f"{shape_id}.obj")
            meshed += 1
    return meshed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--project", type=Path, required=True, help="a project where render@original has run")
    parser.add_argument("--device", default="auto", help="auto, cpu or cuda (%(default)s)")
    parser.add_argument("--train-shapes", type=int, default=24)
    parser.add_argument("--test-shapes", type=int, default=12)
    parser.add_argument("--epochs-ae", type=int, default=6)
    parser.add_argument("--epochs-critic", type=int, default=3)
    parser.add_argument("--gqcnn-steps", type=int, default=20)
    parser.add_argument("--batch-size", type=int, default=None, help="AE batch (default: the profile's)")
    parser.add_argument("--workers", type=int, default=2, help="processes for voxelizing (%(default)s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    params = profile_params("paper")
    net, device, start = params.ae.net, resolve_device(args.device), time.perf_counter()
    train_cfg = dataclasses.replace(
        params.ae.train,
        epochs_ae=args.epochs_ae,
        epochs_critic=args.epochs_critic,
        critic_warmup=min(params.ae.train.critic_warmup, max(args.epochs_critic - 1, 0)),
        batch_size=args.batch_size or params.ae.train.batch_size,
    )

    shapes = read_table(args.project / "data/shapes.parquet")
    rng = np.random.default_rng(args.seed)
    chosen = {
        split: sorted(rng.choice(shapes.shape_id[shapes.split == split].to_numpy(), size=n, replace=False))
        for split, n in (("train", args.train_shapes), ("test", args.test_shapes))
    }
    margin = params.voxelize.margin
    grids = {
        split: parallel_map(
            grid_of,
            [(mesh_path(args.project / "data/shapes", s), net.resolution, margin) for s in ids],
            args.workers,
            f"voxelize {split} at {net.resolution}³",
        )
        for split, ids in chosen.items()
    }
    voxels = {split: torch.from_numpy(np.stack([g for g, _ in got])[:, None]) for split, got in grids.items()}
    seconds = {"voxelize": time.perf_counter() - start}

    torch.manual_seed(args.seed)
    ae, critic, gen = AutoEncoder(net), Critic(net), torch.Generator().manual_seed(args.seed)
    logs: dict[str, list] = {"ae": [], "ae_critic": []}
    t = time.perf_counter()
    ae_rate = train_autoencoder(ae, voxels["train"], train_cfg, device, gen, lambda e, m: logs["ae"].append(m))
    seconds["phase_1"] = time.perf_counter() - t
    iou_before = reconstruction_iou(ae, voxels["test"], device)
    pitches = [p for _, p in grids["test"]]
    before = write_reconstructions(
        ae, voxels["test"], pitches, chosen["test"], params.generate.decode, device, args.out / "meshes" / "ae"
    )
    t = time.perf_counter()
    critic_rate = train_ae_critic(
        ae, critic, voxels["train"], train_cfg, device, gen, lambda e, m: logs["ae_critic"].append(m)
    )
    seconds["phase_2"] = time.perf_counter() - t
    separation = critic_separation(ae, critic, voxels["test"], device, n_shapes=len(voxels["test"]))
    iou_after = reconstruction_iou(ae, voxels["test"], device)
    after = write_reconstructions(
        ae, voxels["test"], pitches, chosen["test"], params.generate.decode, device, args.out / "meshes" / "ae_critic"
    )
    critic_losses = [m["loss_critic"] for m in logs["ae_critic"]]

    gq_rate = None
    if args.gqcnn_steps > 0:
        data, _ = shapes_datapoints(args.project / "data/gqcnn/original", chosen["train"])
        gq_cfg = dataclasses.replace(
            params.gqcnn.train, min_steps=args.gqcnn_steps, max_steps=args.gqcnn_steps, evals=1
        )
        t = time.perf_counter()
        train_gqcnn(GQCNN(params.gqcnn.net), data, None, gq_cfg, device, torch.Generator().manual_seed(args.seed))
        seconds["gqcnn"] = time.perf_counter() - t
        gq_rate = args.gqcnn_steps * gq_cfg.batch_size / seconds["gqcnn"]

    summary = {
        "settings": vars(args) | {"project": str(args.project), "out": str(args.out), "device": str(device)},
        "net": {"resolution": net.resolution, "widths": net.widths, "z_dim": net.z_dim},
        "train": dataclasses.asdict(train_cfg),
        "phase_1": {"shapes_per_s": ae_rate, "loss": logs["ae"], "test_iou": iou_before, "meshed": before},
        "phase_2": {
            "shapes_per_s": critic_rate,
            "loss": logs["ae_critic"],
            "critic_loss_finite": bool(np.isfinite(critic_losses).all()),
            "critic_loss_growth": max(critic_losses) / critic_losses[0] if critic_losses else None,
            "separation": separation,
            "test_iou": iou_after,
            "meshed": after,
        },
        "gqcnn": {"samples_per_s": gq_rate, "filters": params.gqcnn.net.filters, "fc": params.gqcnn.net.fc},
        "seconds": seconds | {"all": time.perf_counter() - start},
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "summary.json").write_text(json.dumps(summary, indent=1, default=float))
    log.info(
        "phase 1: IoU %.3f, %.1f shapes/s; phase 2: critic loss %s, AUC %.3f, IoU %.3f, %.1f shapes/s; GQ-CNN %s "
        "samples/s; %.0f s",
        iou_before,
        ae_rate,
        [round(v, 4) for v in critic_losses],
        separation["auc"],
        iou_after,
        critic_rate,
        None if gq_rate is None else round(gq_rate),
        summary["seconds"]["all"],
    )


if __name__ == "__main__":
    main()
