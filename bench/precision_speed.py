"""Training speed in float32 against bfloat16 mixed precision (``precision`` of ``ae.train`` and ``gqcnn.train``)
on this machine: one AutoEncoder phase-1 epoch on 200 random 32³ grids (the default ``ae.net``, batch
``ae.train.batch_size``) and 50 GQ-CNN steps (the default ``gqcnn.net``, batch ``gqcnn.train.batch_size``) on random
crops, each timed in both precisions, the two taking turns over ``--rounds`` rounds after one untimed warm-up each.
Prints seconds per AE epoch and per 50 GQ-CNN steps (median of the rounds), the bfloat16 / float32 time ratio (below
1: bfloat16 is faster), the CPU model, whether it computes bfloat16 natively
(:func:`graspaug.device.has_native_bfloat16`), torch's threads and the load average before and after (the
machine may be shared: a loaded machine slows both precisions, less so their ratio).

Random data: speed only, nothing here learns anything worth keeping.

    python bench/precision_speed.py [--rounds 3] [--shapes 200] [--steps 50]
"""

from __future__ import annotations

import argparse
import dataclasses
import logging
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np
import torch

PRECISIONS = ("float32", "bfloat16")
log = logging.getLogger("precision_speed")


def cpu_model() -> str:
    """The CPU's model name (``/proc/cpuinfo`` on Linux, else :func:`platform.processor`)."""
    info = Path("/proc/cpuinfo")
    if info.exists():
        for line in info.read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or platform.machine()


def ae_epoch_seconds(precision: str, grids: torch.Tensor) -> float:
    """Seconds of one phase-1 epoch of the default AutoEncoder over ``grids`` (N, 1, R, R, R) float32."""
    from graspaug.nets.ae_critic import AutoEncoder
    from graspaug.pipeline.params.ae import AEParams
    from graspaug.training.autoencoder import train_autoencoder

    params = AEParams()
    cfg = dataclasses.replace(params.train, epochs_ae=1, precision=precision)
    torch.manual_seed(0)
    ae = AutoEncoder(params.net)
    start = time.perf_counter()
    train_autoencoder(ae, grids, cfg, torch.device("cpu"), torch.Generator().manual_seed(0))
    return time.perf_counter() - start


def gqcnn_seconds(precision: str, steps: int, rng: np.random.Generator) -> float:
    """Seconds of ``steps`` SGD steps of the default GQ-CNN (default batch) on random crops, no validation."""
    from graspaug.nets.gqcnn import GQCNN
    from graspaug.pipeline.params.gqcnn import GQCNNParams
    from graspaug.training.gqcnn import GraspArrays, train_gqcnn

    params = GQCNNParams()
    settings = dataclasses.replace(params.train, min_steps=steps, max_steps=steps, evals=1, precision=precision)
    n, side = 4 * settings.batch_size, params.net.image_size
    data = GraspArrays(
        (0.7 + 0.02 * rng.random((n, side, side))).astype(np.float32),  # depths, m
        (0.69 + 0.01 * rng.random(n)).astype(np.float32),
        rng.integers(0, 2, n),
    )
    torch.manual_seed(0)
    net = GQCNN(params.net)
    start = time.perf_counter()
    train_gqcnn(net, data, None, settings, torch.device("cpu"), torch.Generator().manual_seed(0), progress=False)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--shapes", type=int, default=200)
    parser.add_argument("--steps", type=int, default=50)
    args = parser.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    from graspaug.device import has_native_bfloat16
    from graspaug.pipeline.params.ae import AEParams

    rng = np.random.default_rng(0)
    r = AEParams().net.resolution
    grids = torch.from_numpy(rng.uniform(-1, 1, (args.shapes, 1, r, r, r)).astype(np.float32))  # signed distances
    load_before = os.getloadavg()
    for precision in PRECISIONS:  # warm-up: oneDNN's kernels for each shape and precision
        ae_epoch_seconds(precision, grids[: 2 * AEParams().train.batch_size])
        gqcnn_seconds(precision, 5, rng)
    times = {(task, p): [] for task in ("ae", "gqcnn") for p in PRECISIONS}
    for i in range(args.rounds):
        for precision in PRECISIONS if i % 2 == 0 else PRECISIONS[::-1]:  # each round starts with the other
            times["ae", precision].append(ae_epoch_seconds(precision, grids))
            times["gqcnn", precision].append(gqcnn_seconds(precision, args.steps, rng))
    load_after = os.getloadavg()

    native = has_native_bfloat16(torch.device("cpu"))
    log.info(
        "CPU: %s (%s native bfloat16), torch %s, %d threads; load average %.2f before, %.2f after (%d cores)",
        cpu_model(),
        "with" if native else "WITHOUT",
        torch.__version__,
        torch.get_num_threads(),
        load_before[0],
        load_after[0],
        os.cpu_count(),
    )
    for task, what in (("ae", f"AE phase-1 epoch, {args.shapes} grids {r}³"), ("gqcnn", f"{args.steps} GQ-CNN steps")):
        f32, bf16 = (statistics.median(times[task, p]) for p in PRECISIONS)
        ratios = [b / f for f, b in zip(times[task, "float32"], times[task, "bfloat16"], strict=True)]
        log.info(
            "%s: float32 %.2f s, bfloat16 %.2f s (medians of %d), bfloat16 / float32 %.2f (rounds: %s)",
            what,
            f32,
            bf16,
            args.rounds,
            statistics.median(ratios),
            ", ".join(f"{x:.2f}" for x in ratios),
        )


if __name__ == "__main__":
    main()
