"""GQ-CNN training throughput on the CPU: the loop as it was when the speed work began
(``_gqcnn_reference.py``: batch 64, contiguous layout, the LRN power as ``pow``, glibc's default
allocator settings) against the current one (``graspaug.training.gqcnn.train_gqcnn`` as the
``train_gqcnn`` stage runs it: batch 128, channels-last, ``graspaug.device.keep_freed_memory``)
in each of its two precisions (``gqcnn.train.precision``: float32, and bfloat16 mixed
precision), on the same rendered datapoints, the same network (default ``gqcnn.net``), the same
number of SGD steps and torch's default threads.

Each measurement runs in a fresh process (the allocator setting is process-wide), and the three
loops take turns over ``--rounds`` rounds (each round starts with another), so a machine that
speeds up or slows down during the run shifts all; the ratios printed are the medians of the
rounds' ratios. Needs ``data/gqcnn/original`` (``dvc repro render@original`` with the default
params).

    python bench/gqcnn_train_speed.py [--steps 300] [--datapoints 20000] [--rounds 3]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

LOOPS = ["reference", "float32", "bfloat16"]


def load(n: int):
    from graspaug.io.gqcnn import GraspImages
    from graspaug.paths import gqcnn_dir
    from graspaug.training.gqcnn import GraspArrays

    data = GraspImages.open(gqcnn_dir("original"))
    rows = np.flatnonzero((data.index.split == "train").to_numpy())[:n]
    return GraspArrays(data.images(rows), data.read("z", rows), data.read("labels", rows))


def measure(which: str, steps: int, datapoints: int) -> dict:
    """Train one network for ``steps`` steps in this process; samples/s and page faults per step."""
    import resource
    from types import SimpleNamespace

    import torch

    from graspaug.nets.gqcnn import GQCNN
    from graspaug.nets.settings import GQCNNConfig
    from graspaug.training.settings import NoiseSettings, TrainSettings

    train = load(datapoints)
    torch.manual_seed(0)
    gen = torch.Generator().manual_seed(0)
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    if which == "reference":
        sys.path.insert(0, str(Path(__file__).parent))
        from _gqcnn_reference import reference_network, train_gqcnn_reference

        settings = SimpleNamespace(
            steps=steps,
            batch_size=64,
            lr=0.01,
            momentum=0.9,
            weight_decay=5e-4,
            lr_decay=0.95,
            decay_steps=100,
            log_every=steps,
            eval_batch=128,
            noise=NoiseSettings(),
        )
        net, batch = reference_network(GQCNNConfig()), 64
        start = time.perf_counter()
        train_gqcnn_reference(net, train, None, settings, torch.device("cpu"), gen)
    else:
        from graspaug.device import keep_freed_memory
        from graspaug.training.gqcnn import train_gqcnn

        keep_freed_memory()  # as every stage does (graspaug.cli)
        settings = TrainSettings(min_steps=steps, max_steps=steps, evals=1, precision=which)
        net, batch = GQCNN(GQCNNConfig()), settings.batch_size
        start = time.perf_counter()
        train_gqcnn(net, train, None, settings, torch.device("cpu"), gen, progress=False)
    seconds = time.perf_counter() - start
    return {
        "samples_per_second": steps * batch / seconds,
        "faults_per_step": (resource.getrusage(resource.RUSAGE_SELF).ru_minflt - faults) / steps,
        "threads": torch.get_num_threads(),
        "parameters": sum(p.numel() for p in net.parameters()),
    }


def same_function() -> None:
    """The reference network computes what the current one does (same weights, same outputs)."""
    import torch

    from graspaug.nets.gqcnn import GQCNN
    from graspaug.nets.settings import GQCNNConfig

    sys.path.insert(0, str(Path(__file__).parent))
    from _gqcnn_reference import reference_network

    torch.manual_seed(0)
    current = GQCNN(GQCNNConfig()).eval()
    reference = reference_network(GQCNNConfig()).eval()
    reference.load_state_dict(current.state_dict())
    images, z = torch.rand(16, 1, 32, 32) * 0.05 + 0.6, torch.rand(16) * 0.05 + 0.6
    with torch.no_grad():
        torch.testing.assert_close(reference(images, z), current(images, z), rtol=1e-5, atol=1e-6)


def run(which: str, args) -> dict:
    out = subprocess.run(
        [
            sys.executable,
            __file__,
            "--measure",
            which,
            "--steps",
            str(args.steps),
            "--datapoints",
            str(args.datapoints),
        ],
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--datapoints", type=int, default=20000)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--measure", choices=LOOPS, help=argparse.SUPPRESS)  # one measurement (a child process)
    args = parser.parse_args()
    if args.measure:
        print(json.dumps(measure(args.measure, args.steps, args.datapoints)))
        return
    same_function()
    import torch

    from graspaug.device import has_native_bfloat16

    bf16 = "with" if has_native_bfloat16(torch.device("cpu")) else "WITHOUT (bfloat16 is emulated, slow)"
    print(
        f"{args.datapoints} datapoints, {args.steps} steps per network, {os.cpu_count()} cores {bf16} bfloat16 "
        "instructions, "
        f"{args.rounds} rounds, one fresh process per run"
    )
    ratios: dict[str, list[float]] = {"float32": [], "bfloat16": []}
    for r in range(args.rounds):
        order = LOOPS[r % 3 :] + LOOPS[: r % 3]
        got = {which: run(which, args) for which in order}
        ref = got["reference"]
        line = (
            f"round {r + 1}: reference (batch 64, {ref['threads']} threads) {ref['samples_per_second']:6.0f} "
            f"samples/s, {ref['faults_per_step']:4.0f} page faults/step"
        )
        for precision in ratios:
            ratios[precision].append(got[precision]["samples_per_second"] / ref["samples_per_second"])
            speed, faults = got[precision]["samples_per_second"], got[precision]["faults_per_step"]
            line += f"; current {precision} {speed:6.0f} ({faults:4.0f}): {ratios[precision][-1]:.2f}x"
        print(line, flush=True)
    for precision, values in ratios.items():
        print(
            f"current loop, {precision}: median ratio over {args.rounds} rounds {np.median(values):.2f}x (rounds: "
            f"{', '.join(f'{x:.2f}' for x in values)})"
        )


if __name__ == "__main__":
    main()
