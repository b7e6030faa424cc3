"""GQ-CNN training throughput on the CPU: the loop as it was (``_gqcnn_reference.py``: batch 64,
torch's default threads, one network per process) against the current one (batch 128, and the
stage's layout: ``n_jobs`` networks at once, one thread each), on the same rendered datapoints,
the same network (default ``gqcnn.net``) and the same number of SGD steps.

Needs ``data/gqcnn/original`` (``dvc repro render@original`` with the default params).

    python bench/gqcnn_train_speed.py [--steps 300] [--datapoints 20000] [--jobs 2]

Prints samples/s of each and the ratio to the reference.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import torch
from joblib import Parallel, delayed

sys.path.insert(0, str(Path(__file__).parent))
from _gqcnn_reference import train_gqcnn_reference  # noqa: E402

from graspaug.io.gqcnn import GraspImages  # noqa: E402
from graspaug.nets.gqcnn import GQCNN  # noqa: E402
from graspaug.nets.settings import GQCNNConfig  # noqa: E402
from graspaug.paths import gqcnn_dir  # noqa: E402
from graspaug.training.gqcnn import GraspArrays, train_gqcnn  # noqa: E402
from graspaug.training.settings import NoiseSettings, TrainSettings  # noqa: E402


def load(n: int) -> GraspArrays:
    data = GraspImages.open(gqcnn_dir("original"))
    rows = np.flatnonzero((data.index.split == "train").to_numpy())[:n]
    return GraspArrays(data.images(rows), data.read("z", rows), data.read("labels", rows))


def reference_run(train: GraspArrays, steps: int) -> float:
    settings = SimpleNamespace(steps=steps, batch_size=64, lr=0.01, momentum=0.9, weight_decay=5e-4, lr_decay=0.95, decay_steps=100,
                               log_every=steps, eval_batch=128, noise=NoiseSettings())
    torch.manual_seed(0)
    start = time.perf_counter()
    train_gqcnn_reference(GQCNN(GQCNNConfig()), train, None, settings, torch.device("cpu"), torch.Generator().manual_seed(0))
    return steps * 64 / (time.perf_counter() - start)


def current_one(train: GraspArrays, steps: int, threads: int, seed: int) -> float:
    torch.set_num_threads(threads)
    settings = TrainSettings(min_steps=steps, max_steps=steps, evals=1)
    torch.manual_seed(seed)
    start = time.perf_counter()
    train_gqcnn(GQCNN(GQCNNConfig()), train, None, settings, torch.device("cpu"), torch.Generator().manual_seed(seed), progress=False)
    return steps * settings.batch_size / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--datapoints", type=int, default=20000)
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    train = load(args.datapoints)
    cores = os.cpu_count()
    print(f"{len(train)} datapoints, {args.steps} steps per network, {GQCNN(GQCNNConfig()).describe()['parameters']} parameters, {cores} cores")
    reference = reference_run(train, args.steps)
    print(f"reference (batch 64, {torch.get_num_threads()} threads, one network):   {reference:8.0f} samples/s")
    one = current_one(train, args.steps, torch.get_num_threads(), 0)
    print(f"current, one network (batch 128, {torch.get_num_threads()} threads):     {one:8.0f} samples/s  ({one / reference:.2f}x)")
    start = time.perf_counter()
    Parallel(n_jobs=args.jobs)(delayed(current_one)(train, args.steps, 1, seed) for seed in range(args.jobs))  # the stage's layout
    both = args.jobs * args.steps * TrainSettings().batch_size / (time.perf_counter() - start)
    print(f"current, {args.jobs} networks at once (1 thread each, worker start-up included): {both:8.0f} samples/s  ({both / reference:.2f}x)")


if __name__ == "__main__":
    main()
