"""How many phase-1 epochs, with which learning-rate schedule, does the default AutoEncoder need?

The default network (``ae.net`` of the default params: 32³; its decoder of the packed grids' kind) is trained on a
project's train shapes less ``--val-shapes`` of them held out for validation (never the test split), once per
entry of ``--runs`` (``SCHEDULE:EPOCHS``: ``constant:90``, ``cosine:45`` ...; ``ae.train.lr_schedule``), from the
same initial weights and batches' seed. Every ``--every`` epochs (and the last) it logs the validation voxel IoU
(insides: :func:`graspaug.training.autoencoder.reconstruction_iou`) and reconstruction loss, and the seconds spent.

A GPU machine with no project takes the grids packed here (``--pack FILE``: the train split's grids of the
project's ``data/voxels.npz`` of its own ``ae.net.output``, int8 signed distances or bit-packed occupancy, and the
validation choice)::

    python studies/ae_schedule.py --project PROJECT --pack studies/out/ae_schedule_inputs.npz
    python studies/ae_schedule.py --packed studies/out/ae_schedule_inputs.npz --device cuda \\
        --runs constant:90 cosine:30 cosine:45 cosine:60 --out OUT

Writes ``--out``/``summary.json`` (settings and every run's log) and prints the last IoU of each run.
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
from graspaug.geometry.voxelize import pack_bits, unpack_bits
from graspaug.nets.ae_critic import AutoEncoder, reconstruction_loss
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.params.profiles import profile_params
from graspaug.training.autoencoder import reconstruction_iou, train_autoencoder, voxel_grids

log = logging.getLogger("ae_schedule")
OUT = Path(__file__).resolve().parent / "out" / "ae_schedule"


def pack(project: Path, val_shapes: int, seed: int, path: Path) -> str:
    """The project's train-split grids of its own ``ae.net.output`` (int8 distances × 127 / truncation, or
    bit-packed occupancy) and which are held out; returns that output."""
    output = load_params(project / "params.yaml").ae.net.output
    ids, split, grids = voxel_grids(project / "data/voxels.npz", project / "data/shapes.parquet", output)
    train = split == "train"
    val = np.zeros(int(train.sum()), dtype=bool)
    val[np.random.default_rng(seed).choice(len(val), size=val_shapes, replace=False)] = True
    grids = grids[torch.from_numpy(train)].numpy()[:, 0]
    stored = np.rint(grids * 127).astype(np.int8) if output == "sdf" else pack_bits(grids.astype(bool))
    np.savez_compressed(path, ids=ids[train], val=val, grids=stored, output=output, resolution=grids.shape[-1])
    return output


def unpack(path: Path) -> tuple[str, np.ndarray, torch.Tensor]:
    """output, the validation mask and (N, 1, R, R, R) grids as :func:`pack` wrote them."""
    f = np.load(path)
    output, r = str(f["output"]), int(f["resolution"])
    if output == "sdf":
        grids = torch.from_numpy(f["grids"].astype(np.float32) / 127)
    else:
        grids = torch.from_numpy(unpack_bits(f["grids"], r).astype(np.uint8))
    return output, f["val"], grids[:, None]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--project", type=Path, help="a project where voxelize has run (with --pack)")
    parser.add_argument("--pack", type=Path, help="write the train split's grids to this .npz and stop")
    parser.add_argument("--packed", type=Path, help="train from a --pack file")
    parser.add_argument("--val-shapes", type=int, default=100, help="train shapes held out (%(default)s)")
    parser.add_argument("--runs", nargs="+", default=["constant:90", "cosine:45"], help="SCHEDULE:EPOCHS")
    parser.add_argument("--every", type=int, default=5, help="epochs between validations (%(default)s)")
    parser.add_argument("--device", default="auto", help="auto, cpu or cuda (%(default)s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    params = profile_params("default")
    if args.pack:
        if args.project is None:
            parser.error("--pack needs --project")
        output = pack(args.project, args.val_shapes, args.seed, args.pack)
        log.info("packed %s (%s, %.1f MB)", args.pack, output, args.pack.stat().st_size / 1e6)
        return
    if args.packed is None:
        parser.error("give --packed (a --pack file), or --project with --pack")
    output, val, grids = unpack(args.packed)
    net, device = dataclasses.replace(params.ae.net, output=output), resolve_device(args.device)
    train_x, val_x = grids[torch.from_numpy(~val)], grids[torch.from_numpy(val)]
    runs = []
    for run in args.runs:
        schedule, epochs = run.split(":")
        cfg = dataclasses.replace(params.ae.train, epochs_ae=int(epochs), lr_schedule=schedule)
        torch.manual_seed(args.seed)
        ae, logs, start = AutoEncoder(net), [], time.perf_counter()

        def validate(epoch: int, metrics: dict) -> None:  # called within this run's training
            if (epoch + 1) % args.every and epoch + 1 != cfg.epochs_ae:
                return
            with torch.no_grad():
                ae.eval()
                loss = float(reconstruction_loss(ae(val_x.float().to(device)), val_x.float().to(device), output))
            iou = reconstruction_iou(ae, val_x, device)
            logs.append({"epoch": epoch + 1, "train_loss": metrics["loss_recon"], "val_loss": loss, "val_iou": iou})
            logs[-1]["seconds"] = time.perf_counter() - start
            log.info("%s epoch %d: val IoU %.4f, val loss %.4f", run, epoch + 1, iou, loss)

        rate = train_autoencoder(ae, train_x, cfg, device, torch.Generator().manual_seed(args.seed), validate)
        runs.append({"run": run, "shapes_per_s": rate, "log": logs})
    args.out.mkdir(parents=True, exist_ok=True)
    settings = {k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()}
    settings |= {"device": str(device), "output": output, "train": len(train_x), "val": len(val_x)}
    summary = {"settings": settings, "runs": runs}
    (args.out / "summary.json").write_text(json.dumps(summary, indent=1))
    for r in runs:
        print(f"{r['run']:>14}: val IoU {r['log'][-1]['val_iou']:.4f}, {r['shapes_per_s']:.0f} shapes/s")


if __name__ == "__main__":
    main()
