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

Everything goes to ``--out``: ``summary.json`` (settings, per-phase figures, seconds), ``reconstructions.npz`` (the
held-out ids, pitches and both reconstructions at 0.5, bit-packed) and, from a project, ``meshes/``. On a CPU keep
it small (the defaults take about 15 minutes on 2 cores); on a GPU raise every count::

    python bench/paper_scale.py --project PROJECT [--device auto] [--train-shapes 24] [--test-shapes 12]
        [--epochs-ae 6] [--epochs-critic 3] [--gqcnn-steps 20] [--batch-size B] [--out bench/out/paper_scale]

A GPU machine with no project (and no pybullet or trimesh) takes the inputs packed on the CPU side: ``--pack FILE``
writes the chosen shapes' grids bit-packed and ``--crops`` rendered train crops in float16 into one .npz (700 + 260
shapes at 64³ and 8,000 crops: a few MB compressed), and ``--packed FILE`` trains from it::

    python bench/paper_scale.py --project PROJECT --train-shapes 700 --test-shapes 260 --pack inputs.npz
    python bench/paper_scale.py --packed inputs.npz --device cuda --epochs-ae 150 --epochs-critic 20 ...

Back on the CPU, ``--label reconstructions.npz --project PROJECT`` (the project the pack came from) meshes each
held-out reconstruction by ``generate``'s recipe (the profile's ``generate.decode``), labels its grasps and the
original's as the ``grasps`` stage does (the project's ``grasps`` params and ``seed``) and writes, per phase,
the graspness kept (after / before over the shapes that meshed, Fieller 95%) to ``--out``/``label.json``::

    python bench/paper_scale.py --label OUT/reconstructions.npz --project PROJECT [--workers 2]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import tempfile
import time
from pathlib import Path

import numpy as np
import torch

from graspaug.device import resolve_device
from graspaug.geometry.voxelize import pack_bits, unpack_bits
from graspaug.nets.ae_critic import AutoEncoder, Critic, decode, encode
from graspaug.nets.gqcnn import GQCNN
from graspaug.parallel import parallel_map
from graspaug.pipeline.params.profiles import profile_params
from graspaug.training.autoencoder import (
    critic_separation,
    occupied,
    reconstruction_iou,
    train_ae_critic,
    train_autoencoder,
)
from graspaug.training.gqcnn import GraspArrays, train_gqcnn

log = logging.getLogger("paper_scale")
OUT = Path(__file__).resolve().parent / "out" / "paper_scale"


def project_inputs(args, resolution: int, margin: int) -> dict:
    """The chosen shapes' grids (bool) and pitches, and the train shapes' rendered crops (``--crops`` at most)."""
    from graspaug.io.meshes import mesh_path
    from graspaug.io.tables import read_table
    from graspaug.pipeline.stages.voxelize import voxelize_file  # the voxelize stage's own grid of one file
    from graspaug.training.gqcnn_data import shapes_datapoints

    shapes = read_table(args.project / "data/shapes.parquet")
    rng = np.random.default_rng(args.seed)
    out = {}
    for split, n in (("train", args.train_shapes), ("test", args.test_shapes)):
        ids = sorted(rng.choice(shapes.shape_id[shapes.split == split].to_numpy(), size=n, replace=False))
        jobs = [(mesh_path(args.project / "data/shapes", s), resolution, margin) for s in ids]
        got = parallel_map(
            lambda job: voxelize_file(*job)[:2], jobs, args.workers, f"voxelize {split} at {resolution}³"
        )
        out |= {f"{split}_ids": np.array(ids), f"{split}_grids": np.stack([g for g, _ in got])}
        out[f"{split}_pitches"] = np.array([p for _, p in got])
    crops, _ = shapes_datapoints(args.project / "data/gqcnn/original", list(out["train_ids"]))
    keep = np.sort(rng.permutation(len(crops))[: args.crops])
    out["crops"] = GraspArrays(crops.images[keep], crops.z[keep], crops.labels[keep])
    return out


def write_pack(inputs: dict, path: Path) -> None:
    """``inputs`` (:func:`project_inputs`) as one compressed .npz: grids bit-packed, crops in float16."""
    crops = inputs["crops"]
    arrays = {k: v for k, v in inputs.items() if k != "crops" and not k.endswith("_grids")}
    arrays |= {f"{s}_grids": pack_bits(inputs[f"{s}_grids"]) for s in ("train", "test")}
    arrays |= {"resolution": inputs["train_grids"].shape[1], "crop_images": crops.images.astype(np.float16)}
    np.savez_compressed(path, crop_z=crops.z, crop_labels=crops.labels, **arrays)


def read_pack(path: Path) -> dict:
    """The inputs a :func:`write_pack` file holds, as :func:`project_inputs` gives them."""
    f = np.load(path)
    r = int(f["resolution"])
    out = {k: f[k] for k in f.files if k.endswith(("_ids", "_pitches"))}
    out |= {f"{s}_grids": unpack_bits(f[f"{s}_grids"], r) for s in ("train", "test")}
    out["crops"] = GraspArrays(f["crop_images"].astype(np.float32), f["crop_z"], f["crop_labels"])
    return out


def decoded_grids(ae, voxels: torch.Tensor, device) -> np.ndarray:
    """Each grid's reconstruction by ``ae`` (N, R, R, R), occupied where the decoder says so."""
    return occupied(decode(ae, encode(ae, voxels, device), device), ae.cfg.output)


def write_mesh(grid: np.ndarray, pitch: float, decode_settings, path: Path) -> bool:
    """One reconstruction (R, R, R) bool meshed by ``generate``'s recipe and written to ``path`` (OBJ); whether it
    meshed."""
    from graspaug.geometry.from_voxels import mesh_decoded
    from graspaug.io.meshes import write_obj

    _, mesh, reason = mesh_decoded(grid.astype(np.float32), float(pitch), decode_settings)
    if reason is None:
        write_obj(mesh, path)
    return reason is None


def write_meshes(grids: np.ndarray, inputs: dict, decode_settings, folder: Path) -> int:
    """Each reconstruction meshed by ``generate``'s recipe into ``folder``/<id>.obj; how many meshed."""
    folder.mkdir(parents=True, exist_ok=True)
    jobs = zip(grids, inputs["test_pitches"], inputs["test_ids"])
    return sum(write_mesh(grid, pitch, decode_settings, folder / f"{shape_id}.obj") for grid, pitch, shape_id in jobs)


def label_shape(job: tuple, project: Path, phases: tuple[str, ...], decode, grasps: tuple) -> dict:
    """One held-out shape's graspness, original and per phase's reconstruction (NaN where it did not mesh)."""
    from graspaug.experiments.fidelity.numbers import mesh_graspness
    from graspaug.io.meshes import mesh_path
    from graspaug.pipeline.paths import GENERATED_SUFFIX

    shape_id, pitch, grids = job
    original = mesh_graspness(mesh_path(project / "data/shapes", shape_id), shape_id, *grasps)
    row = {"shape_id": shape_id, "original": original}
    with tempfile.TemporaryDirectory() as folder:
        for phase, grid in zip(phases, grids):
            file = mesh_path(folder, f"{shape_id}_{phase}", GENERATED_SUFFIX)
            meshed = write_mesh(grid, pitch, decode, file)
            row[phase] = mesh_graspness(file, shape_id, *grasps) if meshed else (float("nan"), 0)
    return row


def label_reconstructions(path: Path, project: Path, decode, workers: int, out: Path) -> None:
    """Graspness kept by the held-out reconstructions in ``path`` (a ``reconstructions.npz``), per phase: the
    table printed and written to ``out``/``label.json``."""
    import pandas as pd

    from graspaug.experiments.fidelity.numbers import paired_graspness_kept
    from graspaug.experiments.fidelity.words import paired_graspness_kept_markdown
    from graspaug.pipeline.params.model import load_params

    f = np.load(path)
    phases = tuple(k for k in ("ae", "ae_critic") if k in f.files)
    resolution = int(f["resolution"]) if "resolution" in f.files else round((8 * f["ae"].shape[1]) ** (1 / 3))
    grids = {k: unpack_bits(f[k], resolution) for k in phases}  # bit-packed R³ (files before 2026-11-27: no R)
    params = load_params(project / "params.yaml")
    grasps = (params.grasps, params.seed)
    jobs = [(s, p, [grids[k][i] for k in phases]) for i, (s, p) in enumerate(zip(f["ids"], f["pitches"]))]
    start = time.perf_counter()
    rows = parallel_map(lambda job: label_shape(job, project, phases, decode, grasps), jobs, workers, "label")
    before = np.array([r["original"][0] for r in rows])
    table = []
    for phase in phases:
        after = np.array([r[phase][0] for r in rows])
        meshed = np.isfinite(after)
        table.append({"variant": phase, "shapes": len(rows), "meshed": int(meshed.sum())})
        table[-1] |= paired_graspness_kept(after[meshed], before[meshed])
    out.mkdir(parents=True, exist_ok=True)
    summary = {"reconstructions": str(path), "project": str(project), "decode": dataclasses.asdict(decode)}
    summary |= {"n_grasps": params.grasps.sampler.n_grasps, "rows": table, "seconds": time.perf_counter() - start}
    (out / "label.json").write_text(json.dumps(summary, indent=1, default=float))
    print(paired_graspness_kept_markdown(pd.DataFrame(table)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--project", type=Path, help="a project where render@original has run")
    parser.add_argument("--pack", type=Path, help="only write the chosen inputs to this .npz (to carry to a GPU)")
    parser.add_argument("--packed", type=Path, help="read the inputs from a --pack file instead of a project")
    parser.add_argument("--crops", type=int, default=8000, help="rendered train crops packed (%(default)s)")
    parser.add_argument("--device", default="auto", help="auto, cpu or cuda (%(default)s)")
    parser.add_argument("--train-shapes", type=int, default=24)
    parser.add_argument("--test-shapes", type=int, default=12)
    parser.add_argument("--epochs-ae", type=int, default=6)
    parser.add_argument("--epochs-critic", type=int, default=3)
    parser.add_argument("--gqcnn-steps", type=int, default=20)
    parser.add_argument("--batch-size", type=int, default=None, help="AE batch (default: the profile's)")
    parser.add_argument("--workers", type=int, default=2, help="processes for voxelizing (%(default)s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--label", type=Path, help="a reconstructions.npz to mesh and label (needs --project)")
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    params = profile_params("paper")
    if args.label:
        if args.project is None:
            parser.error("--label needs --project: the project whose shapes the reconstructions are")
        label_reconstructions(args.label, args.project, params.generate.decode, args.workers, args.out)
        return
    net, device, start = params.ae.net, resolve_device(args.device), time.perf_counter()
    train_cfg = dataclasses.replace(
        params.ae.train,
        epochs_ae=args.epochs_ae,
        epochs_critic=args.epochs_critic,
        critic_warmup=min(params.ae.train.critic_warmup, max(args.epochs_critic - 1, 0)),
        batch_size=args.batch_size or params.ae.train.batch_size,
    )

    if (args.project is None) == (args.packed is None):
        parser.error("give --project (a project where render@original has run) or --packed (a --pack file)")
    inputs = read_pack(args.packed) if args.packed else project_inputs(args, net.resolution, params.voxelize.margin)
    args.train_shapes, args.test_shapes = len(inputs["train_ids"]), len(inputs["test_ids"])  # as read (--packed)
    if args.pack:
        write_pack(inputs, args.pack)
        log.info("packed %s (%.1f MB)", args.pack, args.pack.stat().st_size / 1e6)
        return
    voxels = {split: torch.from_numpy(inputs[f"{split}_grids"][:, None]) for split in ("train", "test")}
    seconds = {"inputs": time.perf_counter() - start}

    torch.manual_seed(args.seed)
    ae, critic, gen = AutoEncoder(net), Critic(net), torch.Generator().manual_seed(args.seed)
    logs: dict[str, list] = {"ae": [], "ae_critic": []}
    t = time.perf_counter()
    ae_rate = train_autoencoder(ae, voxels["train"], train_cfg, device, gen, lambda e, m: logs["ae"].append(m))
    seconds["phase_1"] = time.perf_counter() - t
    iou_before = reconstruction_iou(ae, voxels["test"], device)
    decoded = {"ae": decoded_grids(ae, voxels["test"], device)}
    t = time.perf_counter()
    critic_rate = train_ae_critic(
        ae, critic, voxels["train"], train_cfg, device, gen, lambda e, m: logs["ae_critic"].append(m)
    )
    seconds["phase_2"] = time.perf_counter() - t
    separation = critic_separation(ae, critic, voxels["test"], device, n_shapes=len(voxels["test"]))
    iou_after = reconstruction_iou(ae, voxels["test"], device)
    decoded["ae_critic"] = decoded_grids(ae, voxels["test"], device)
    args.out.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(  # held-out reconstructions at 0.5, bit-packed, for the fidelity figures elsewhere
        args.out / "reconstructions.npz",
        ids=inputs["test_ids"],
        pitches=inputs["test_pitches"],
        resolution=net.resolution,
        **{name: pack_bits(grids) for name, grids in decoded.items()},
    )
    meshed = {}
    if args.project is not None:  # meshes need trimesh and the corpus' decode settings: on the CPU side
        for name, grids in decoded.items():
            meshed[name] = write_meshes(grids, inputs, params.generate.decode, args.out / "meshes" / name)
    critic_losses = [m["loss_critic"] for m in logs["ae_critic"]]

    gq_rate = None
    if args.gqcnn_steps > 0:
        data = inputs["crops"]
        gq_cfg = dataclasses.replace(
            params.gqcnn.train, min_steps=args.gqcnn_steps, max_steps=args.gqcnn_steps, evals=1
        )
        t = time.perf_counter()
        train_gqcnn(GQCNN(params.gqcnn.net), data, None, gq_cfg, device, torch.Generator().manual_seed(args.seed))
        seconds["gqcnn"] = time.perf_counter() - t
        gq_rate = args.gqcnn_steps * gq_cfg.batch_size / seconds["gqcnn"]

    summary = {
        "settings": {k: str(v) if isinstance(v, Path) else v for k, v in vars(args).items()} | {"device": str(device)},
        "net": {"resolution": net.resolution, "widths": net.widths, "z_dim": net.z_dim},
        "train": dataclasses.asdict(train_cfg),
        "phase_1": {"shapes_per_s": ae_rate, "loss": logs["ae"], "test_iou": iou_before, "meshed": meshed.get("ae")},
        "phase_2": {
            "shapes_per_s": critic_rate,
            "loss": logs["ae_critic"],
            "critic_loss_finite": bool(np.isfinite(critic_losses).all()),
            "critic_loss_growth": max(critic_losses) / critic_losses[0] if critic_losses else None,
            "separation": separation,
            "test_iou": iou_after,
            "meshed": meshed.get("ae_critic"),
        },
        "gqcnn": {"samples_per_s": gq_rate, "filters": params.gqcnn.net.filters, "fc": params.gqcnn.net.fc},
        "seconds": seconds | {"all": time.perf_counter() - start},
    }
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
