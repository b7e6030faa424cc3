"""GQ-CNN members trained at once on a CUDA GPU: what ``train_members`` buys where the CPU gains little.

Measures, on one device, samples/s (every member's samples) of ``graspaug.training.gqcnn.train_members``
with K = 1 (``train_gqcnn``'s loop), 3 (the default ``gqcnn.members``) and 15 (a seed's five default networks
× three members) members, for the default network (8 filters, fc 64, batch 128) and Dex-Net's widths (64
filters, fc 1024, batch 64); and whether a member trained in a stack of three ends as it does alone (the
largest difference of its P(success) on 2,000 held-out crops, and both APs, after ``--equal-steps`` steps).
Learning rates: 0.02 (default) and 0.01 (the paper profile). Data: synthetic crops (an object 2 cm above a
table under the jaws or beside them, as in the training tests), so the study carries nothing; speed does not
depend on what the crops show.

    python studies/cuda_members.py --device cuda --out DIR      # on the GPU machine (DIR/results.json)
    python studies/cuda_members.py --device cpu --steps 20       # the same on the CPU

On the project's device machine (its Python lacks pydantic: carry the wheels as studies/cuda_check.py says)::

    python3 -m pip install -q --no-index --no-deps --target /tmp/site studies/out/cuda/whl/*.whl || exit 3
    export PYTHONPATH=/tmp/site:src PYTHONUNBUFFERED=1; python3 studies/cuda_members.py --out $OUT
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from graspaug.nets.gqcnn import GQCNN
from graspaug.nets.settings import GQCNNConfig
from graspaug.training.gqcnn import GraspArrays, classification_metrics, predict, train_gqcnn, train_members
from graspaug.training.settings import TrainSettings


def crops(n: int, rng: np.random.Generator) -> GraspArrays:
    """Positives: an object 2 cm above the table under the gripper; negatives: beside it."""
    images = np.full((n, 32, 32), 0.7, np.float32) + rng.uniform(-0.02, 0.02, (n, 1, 1)).astype(np.float32)
    labels = rng.random(n) < 0.3
    for i in range(n):
        half, cy = rng.integers(3, 6), 16 + rng.integers(-3, 4)
        cx = 16 if labels[i] else rng.choice([5, 27])
        images[i, cy - half : cy + half, cx - half : cx + half] -= 0.02
    return GraspArrays(images, (images[:, 16, 16] + 0.01).astype(np.float32), labels.astype(np.uint8))


def speed(config: GQCNNConfig, k: int, train: GraspArrays, settings: TrainSettings, device: torch.device) -> float:
    """Samples/s of ``k`` members trained at once (after a warm-up run of a few steps)."""
    nets = [GQCNN(config) for _ in range(k)]
    gens = [torch.Generator().manual_seed(m) for m in range(k)]
    warm = TrainSettings(min_steps=3, max_steps=3, batch_size=settings.batch_size, evals=1)
    train_members(nets, train, None, warm, device, gens, progress=False)
    if device.type == "cuda":
        torch.cuda.synchronize()
    start = time.perf_counter()
    train_members(nets, train, None, settings, device, gens, progress=False)
    if device.type == "cuda":
        torch.cuda.synchronize()
    return k * settings.max_steps * settings.batch_size / (time.perf_counter() - start)


def equivalence(config: GQCNNConfig, train, held_out, steps: int, batch: int, lr: float, device: torch.device) -> dict:
    """Member 1 of a stack of three against the same member trained alone (same weights, same noise stream)."""
    torch.manual_seed(0)
    inits = [GQCNN(config).state_dict() for _ in range(3)]

    def fresh(m: int) -> GQCNN:
        net = GQCNN(config)
        net.load_state_dict(inits[m])
        return net

    settings = TrainSettings(min_steps=steps, max_steps=steps, batch_size=batch, lr=lr, evals=1)
    stacked = [fresh(m) for m in range(3)]
    train_members(
        stacked, train, None, settings, device, [torch.Generator().manual_seed(m) for m in range(3)], None, False
    )
    alone = fresh(1)
    train_gqcnn(alone, train, None, settings, device, torch.Generator().manual_seed(1), progress=False)
    p_stack, p_alone = predict(stacked[1].to(device), held_out, device), predict(alone.to(device), held_out, device)
    weights = [
        float((a - b.to(a.device)).norm() / (a.norm() + 1e-12))
        for a, b in zip(alone.state_dict().values(), stacked[1].state_dict().values(), strict=True)
    ]
    ap = lambda p: classification_metrics(held_out.labels, p)["ap"] if np.isfinite(p).all() else None  # noqa: E731
    return {
        "steps": steps,
        "lr": lr,
        "max_abs_p_difference": float(np.abs(p_stack - p_alone).max()),
        "ap_stacked": ap(p_stack),
        "ap_alone": ap(p_alone),
        "max_relative_weight_difference": max(weights),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--device", default="cuda")
    parser.add_argument("--steps", type=int, default=200, help="timed steps per run")
    parser.add_argument("--equal-steps", type=int, default=100, help="steps of the equivalence run")
    parser.add_argument("--members", type=int, nargs="+", default=[1, 3, 15])
    parser.add_argument("--out", type=Path, default=Path("studies/out/cuda_members"))
    args = parser.parse_args()
    device = torch.device(args.device)
    rng = np.random.default_rng(0)
    train, held_out = crops(20_000, rng), crops(2_000, rng)
    name = torch.cuda.get_device_name() if device.type == "cuda" else "cpu"
    results = {"device": name, "torch": torch.__version__, "threads": torch.get_num_threads(), "runs": []}
    for label, config, batch, lr in (
        ("default", GQCNNConfig(), 128, 0.02),
        ("dexnet", GQCNNConfig(filters=64, fc=1024), 64, 0.01),  # the paper profile's batch and learning rate
    ):
        settings = TrainSettings(min_steps=args.steps, max_steps=args.steps, batch_size=batch, lr=lr, evals=1)
        for k in args.members:
            run = {
                "network": label,
                "batch": batch,
                "members": k,
                "samples_per_second": speed(config, k, train, settings, device),
            }
            results["runs"].append(run)
            print(json.dumps(run), flush=True)
        results[f"equivalence_{label}"] = equivalence(config, train, held_out, args.equal_steps, batch, lr, device)
        print(json.dumps(results[f"equivalence_{label}"]), flush=True)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "results.json").write_text(json.dumps(results, indent=1) + "\n")


if __name__ == "__main__":
    main()
