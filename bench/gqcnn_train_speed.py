"""GQ-CNN training throughput on the CPU: the loop as it was when the speed work began
(``_gqcnn_reference.py``: batch 64, contiguous layout, the LRN power as ``pow``, glibc's default
allocator settings) against the current one-network loop (``graspaug.training.gqcnn.train_gqcnn``:
batch 128, channels-last, ``graspaug.device.keep_freed_memory``) in each of its two precisions
(``gqcnn.train.precision``: float32, and bfloat16 mixed precision), on the same rendered
datapoints, the same network (default ``gqcnn.net``), the same number of SGD steps and torch's
default threads.

Each measurement runs in a fresh process (the allocator setting is process-wide), and the four
loops and the peak measurement take turns over ``--rounds`` rounds (each round starts with
another), so a machine that speeds up or slows down during the run shifts all; the ratios printed
are the medians of the rounds' ratios. Needs ``data/gqcnn/original`` (``dvc repro render@original`` with the default
params).

The limit: the network's arithmetic per training sample (forward and backward, counted from the
layer shapes: :func:`flops_per_sample`) times samples/s is the loop's achieved FLOP/s, printed as
a share of the machine's peak float32 FLOP/s, measured in the same run (a 2048² matrix product,
torch's default threads, its own fresh process in every round). A fourth loop, ``members``,
trains ``--members`` members of one network at once as one model, as the ``train_gqcnn`` stage
does (``graspaug.training.gqcnn.train_members``: grouped convolutions, batched matrix
products), each member on its own batches and noise; its samples/s count every member's.

    python bench/gqcnn_train_speed.py [--steps 300] [--datapoints 20000] [--rounds 3] [--members 3]
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

LOOPS = ["reference", "float32", "bfloat16", "members"]


def load(n: int):
    from graspaug.io.gqcnn import GraspImages
    from graspaug.pipeline.paths import gqcnn_dir
    from graspaug.training.gqcnn import GraspArrays

    data = GraspImages.open(gqcnn_dir("original"))
    rows = np.flatnonzero((data.index.split == "train").to_numpy())[:n]
    return GraspArrays(data.images(rows), data.read("z", rows), data.read("labels", rows))


def flops_per_sample(config) -> dict[str, float]:
    """Floating-point operations (multiply and add counted apart) of one training sample of a
    GQ-CNN of ``config``: the forward pass, and the backward pass (each weighted layer's weight
    gradient, and the input gradient of every layer but the first convolution, whose input is
    data). Convolutions, the LRN's channel window (a 1×1 convolution) and the fully connected
    layers; the element-wise work (ReLU, LRN power, pooling, noise) is not counted."""
    s, c, side = config.image_size, config.filters, config.image_size // (4 if config.pool_after_conv2 else 2)
    # (multiply-adds, has weights, needs the input gradient)
    layers = [
        (s * s * c * 49, True, False),  # conv1_1, 7×7 from 1 channel
        (s * s * c * c * 25, True, True),  # conv1_2, 5×5
        (s * s * c * c, False, True),  # LRN window
        (2 * (s // 2) ** 2 * c * c * 9, True, True),  # conv2_1, conv2_2, 3×3
        ((s // 2) ** 2 * c * c, False, True),  # LRN window
        (c * side * side * config.fc, True, True),  # fc3
        (config.pose_fc, True, False),  # pc1, from the gripper depth
        (config.fc * config.fc + config.pose_fc * config.fc + config.fc * 2, True, True),  # fc4, fc5
    ]
    forward = 2.0 * sum(m for m, _, _ in layers)
    backward = 2.0 * sum(m * (weights + grad_input) for m, weights, grad_input in layers)
    return {"forward": forward, "backward": backward, "total": forward + backward}


def measure_peak(n: int = 2048, reps: int = 10) -> dict:
    """The machine's float32 FLOP/s in a large matrix product (n × n, torch's default threads):
    the median over ``reps`` products after a warm-up."""
    import torch

    a, b = torch.randn(n, n), torch.randn(n, n)
    for _ in range(3):
        a @ b
    times = []
    for _ in range(reps):
        start = time.perf_counter()
        a @ b
        times.append(time.perf_counter() - start)
    return {"flops_per_second": 2 * n**3 / float(np.median(times)), "threads": torch.get_num_threads()}


def measure(which: str, steps: int, datapoints: int, members: int) -> dict:
    """Train one network (``members`` at once for the ``members`` loop) for ``steps`` steps in this process;
    samples/s and page faults per step."""
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
    elif which == "members":
        from graspaug.device import keep_freed_memory
        from graspaug.training.gqcnn import train_members

        keep_freed_memory()
        settings = TrainSettings(min_steps=steps, max_steps=steps, evals=1)
        nets = [GQCNN(GQCNNConfig()) for _ in range(members)]
        gens = [torch.Generator().manual_seed(m) for m in range(members)]
        net, batch = nets[0], settings.batch_size * members  # every member's samples
        start = time.perf_counter()
        train_members(nets, train, None, settings, torch.device("cpu"), gens, progress=False)
    else:
        from graspaug.device import keep_freed_memory
        from graspaug.training.gqcnn import train_gqcnn

        keep_freed_memory()  # as every stage does (graspaug.pipeline.cli)
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


def same_function(members: int) -> None:
    """The reference network and a stack of members compute what the current network does
    (same weights, same outputs)."""
    import torch

    from graspaug.nets.gqcnn import GQCNN, GQCNNStack
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
    nets = [GQCNN(GQCNNConfig()).eval() for _ in range(members)]
    for m, net in enumerate(nets):
        net.set_normalization(0.6 + m * 0.01, 0.02, 0.62, 0.03)
    batches = torch.rand(members, 16, 1, 32, 32) * 0.05 + 0.6, torch.rand(members, 16) * 0.05 + 0.6
    with torch.no_grad():
        each = torch.stack([net(batches[0][m], batches[1][m]) for m, net in enumerate(nets)])
        torch.testing.assert_close(GQCNNStack(nets)(*batches), each, rtol=1e-4, atol=1e-5)


def run(which: str, args) -> dict:
    command = [sys.executable, __file__, "--measure", which, "--steps", str(args.steps)]
    command += ["--datapoints", str(args.datapoints), "--members", str(args.members)]
    out = subprocess.run(command, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--datapoints", type=int, default=20000)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--members", type=int, default=3, help="members of the members loop (default: gqcnn.members)")
    parser.add_argument("--measure", choices=[*LOOPS, "peak"], help=argparse.SUPPRESS)  # one measurement (a child)
    args = parser.parse_args()
    if args.measure == "peak":
        print(json.dumps(measure_peak()))
        return
    if args.measure:
        print(json.dumps(measure(args.measure, args.steps, args.datapoints, args.members)))
        return
    same_function(args.members)
    import torch

    from graspaug.device import has_native_bfloat16
    from graspaug.nets.settings import GQCNNConfig

    flops = flops_per_sample(GQCNNConfig())
    bf16 = "with" if has_native_bfloat16(torch.device("cpu")) else "WITHOUT (bfloat16 is emulated, slow)"
    print(
        f"{args.datapoints} datapoints, {args.steps} steps per network, {os.cpu_count()} cores {bf16} bfloat16 "
        f"instructions, {args.rounds} rounds, one fresh process per run; the default GQ-CNN: "
        f"{flops['total'] / 1e6:.2f} MFLOP per training sample ({flops['forward'] / 1e6:.2f} forward, "
        f"{flops['backward'] / 1e6:.2f} backward)",
        flush=True,
    )
    loops = LOOPS[1:]
    speeds: dict[str, list[float]] = {which: [] for which in LOOPS}
    peaks: list[float] = []
    for r in range(args.rounds):
        order = ["peak", *LOOPS]
        order = order[r % len(order) :] + order[: r % len(order)]
        got = {which: run(which, args) for which in order}
        peaks.append(got["peak"]["flops_per_second"])
        for which in LOOPS:
            speeds[which].append(got[which]["samples_per_second"])
        ref = got["reference"]
        line = (
            f"round {r + 1}: peak {peaks[-1] / 1e9:.0f} GFLOP/s; reference (batch 64, {ref['threads']} threads) "
            f"{ref['samples_per_second']:6.0f} samples/s ({ref['faults_per_step']:.0f} page faults/step)"
        )
        for which in loops:
            speed = got[which]["samples_per_second"]
            faults = got[which]["faults_per_step"]
            line += f"; {which} {speed:6.0f} ({speed / ref['samples_per_second']:.2f}x, {faults:.0f} faults/step)"
        print(line, flush=True)
    peak = float(np.median(peaks))
    print(f"peak float32: median {peak / 1e9:.0f} GFLOP/s over {args.rounds} rounds")
    for which in LOOPS:
        speed = float(np.median(speeds[which]))
        ratios = [s / ref for s, ref in zip(speeds[which], speeds["reference"], strict=True)]
        achieved = speed * flops["total"]
        print(
            f"{which:9s}: median {speed:6.0f} samples/s, {np.median(ratios):.2f}x the reference (rounds: "
            f"{', '.join(f'{x:.2f}' for x in ratios)}), {achieved / 1e9:.0f} GFLOP/s = {achieved / peak:.0%} of peak"
        )
    print(f"at 100% of peak the network would train {peak / flops['total']:,.0f} samples/s")


if __name__ == "__main__":
    main()
