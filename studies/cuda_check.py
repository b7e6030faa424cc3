"""Paper-profile training on a CUDA GPU vs the CPU: throughput, and whether the two devices agree.

What it measures: the project's own networks and training loops (graspaug.nets.ae_critic AutoEncoder and
Critic, graspaug.training.autoencoder train_autoencoder / train_ae_critic / reconstruction_iou /
critic_separation, graspaug.nets.gqcnn GQCNN, graspaug.training.gqcnn train_gqcnn / predict /
classification_metrics) at the paper profile's sizes (profiles/paper.yaml: AE at 64³, widths 64…512, z 128,
batch 16; GQ-CNN 64 filters, fc 1024, batch 64, lr 0.01):

- throughput: samples/s of AE pretrain, AE-Critic joint steps, AE-Critic warm-up (critic only) and GQ-CNN
  training (with its 20 evaluations), under four precision settings on the GPU (float32 with TF32 off, torch's
  defaults = cuDNN TF32 on, TF32 everywhere, TF32 + cudnn.benchmark) and the GQ-CNN under bfloat16 autocast;
- agreement: one short training run of each phase (AE 20 steps, AE-Critic 10, GQ-CNN 100) on the CPU and on
  CUDA from the same weights on the same batches, compared: initial-weight hashes, per-step input hashes,
  per-step losses (relative differences), weights after each phase (relative L2), held-out AE IoU / BCE,
  critic AUC, held-out GQ-CNN AP / accuracy / cross-entropy and P(success). CUDA runs twice with TF32 off (its
  own run-to-run spread, the yardstick for the CPU difference) and once with torch's defaults.

Same initial weights on both machines: every Conv/Linear layer is re-initialized from numpy's PCG64
(np.random.default_rng([seed, layer]).random(), portable across numpy/torch versions) with the distribution
of the project's init (torch default U(±1/sqrt(fan_in)) for the AE/critic; for the GQ-CNN a uniform of the
project's kaiming std), and a sha256 of the initial state_dict is compared. Same batches: the loops draw
every random choice from a CPU torch.Generator (and numpy for the GQ-CNN noise), so they are device
independent; a forward pre-hook hashes every network input, and the hash lists are compared step by step.

Data (``--data``, default studies/out/cuda/data), made by studies/cuda_check_data.py: voxels64.npz (real
random_urdfs shapes at 64³; the AE trains on the first 16, holds out the next 32, and the throughput runs use
all) and gqcnn_crops.npz (a rendered project's GQ-CNN crops: train = train-split crops of the original corpus,
held-out = its test-split crops + every generated corpus).

How to run it (from the repository root; studies/out/ is git-ignored, so the device call must carry it):

1. Here, the data and the CPU reference (``--ref``, default studies/out/cuda/ref; about 8 minutes at the
   paper's sizes on 2 CPU cores)::

       .venv/bin/python studies/cuda_check_data.py --project PROJECT   # a project with a rendered dataset
       .venv/bin/python studies/cuda_check.py cpu-ref                  # -> studies/out/cuda/ref/cpu_ref_paper.*

2. Here, the wheels the device's Python 3.12 image lacks (pydantic and its needs, at the venv's versions)::

       python3 -m pip download --no-deps --only-binary=:all: --python-version 3.12 --implementation cp \\
           --platform manylinux2014_x86_64 -d studies/out/cuda/whl pydantic==2.14.4 pydantic-core==2.50.5 \\
           annotated-types==0.8.0 typing-extensions==4.16.0 typing-inspection==0.4.5

3. On the GPU machine (the project's device tool copies the working tree; carry ``["studies/out/cuda"]``,
   about 30 MB; the command ran 60 s on an H200; timeout_s 420)::

       python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site \\
           studies/out/cuda/whl/*.whl || exit 3; export PYTHONPATH=/tmp/site:src PYTHONUNBUFFERED=1;
       python3 studies/cuda_check.py device --out $OUT

   -> $OUT/results.json (throughput, agreement per precision setting, the CPU reference's summary) and
   $OUT/log.txt. ``--tiny`` (both modes) runs small sizes, to test the script on the CPU
   (``cpu-ref --tiny`` takes seconds; ``device --tiny --device cpu`` compares the CPU with itself).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import platform
import sys
import time
import traceback
import warnings
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

import graspaug.training.autoencoder as _ae_mod
from graspaug.geometry.voxelize import unpack_bits
from graspaug.nets.ae_critic import AutoEncoder, Critic
from graspaug.nets.gqcnn import GQCNN
from graspaug.nets.settings import AEConfig, GQCNNConfig
from graspaug.training.autoencoder import critic_separation, reconstruction_iou, train_ae_critic, train_autoencoder
from graspaug.training.gqcnn import GraspArrays, classification_metrics, predict, train_gqcnn
from graspaug.training.settings import AETrainConfig, TrainSettings

warnings.filterwarnings("ignore", message="Using padding='same'")
_ae_mod.tqdm = lambda it, **kw: it  # quiet progress bars (the loops are otherwise untouched)

HERE = Path(__file__).resolve().parent
DATA = HERE / "out" / "cuda" / "data"
REF = HERE / "out" / "cuda" / "ref"
LOG: list[str] = []


def log(*a):
    line = " ".join(str(x) for x in a)
    print(line, flush=True)
    LOG.append(line)


# ---------------------------------------------------------------- sizes
def sizes(tiny: bool) -> dict:
    if tiny:
        return dict(
            res=16,
            ae=dict(resolution=16, z_dim=16, base_width=4, top_width=16, output="occupancy"),
            gq=dict(filters=8, fc=64),
            ae_steps=4,
            critic_steps=3,
            warmup=1,
            gq_steps=6,
            held=8,
            tp_ae_epochs=1,
            tp_gq_steps=10,
        )
    # paper profile: profiles/paper.yaml (ae.net 64/128/64/512, gqcnn.net 64/1024, gqcnn.train batch 64 lr 0.01
    # evals 20); ae.train.batch_size is not set there: the default 16
    return dict(
        res=64,
        ae=dict(resolution=64, z_dim=128, base_width=64, top_width=512, output="occupancy"),
        gq=dict(filters=64, fc=1024),
        ae_steps=20,
        critic_steps=10,
        warmup=2,
        gq_steps=100,
        held=32,
        tp_ae_epochs=3,
        tp_gq_steps=500,
    )


def load_voxels(data: Path, res: int) -> torch.Tensor:
    d = np.load(data / "voxels64.npz")
    occ = unpack_bits(d["packed"], int(d["resolution"]))
    if res != 64:
        occ = occ[:, :: 64 // res, :: 64 // res, :: 64 // res]
    return torch.from_numpy(occ[:, None].astype(np.uint8))  # (N, 1, R, R, R) uint8, as voxel_grids() gives


def load_crops(data: Path) -> tuple[GraspArrays, GraspArrays]:
    d = np.load(data / "gqcnn_crops.npz")
    tr = GraspArrays(d["train_images"], d["train_z"], d["train_labels"])
    te = GraspArrays(d["test_images"], d["test_z"], d["test_labels"])
    return tr, te


# ---------------------------------------------------------------- portable init / fingerprints
def portable_init(model: nn.Module, seed: int, scheme: str) -> None:
    layer = 0
    with torch.no_grad():
        for m in model.modules():
            if not isinstance(m, (nn.Conv2d, nn.Conv3d, nn.ConvTranspose3d, nn.Linear)):
                continue
            w = m.weight
            fan_in = (
                w.shape[1] * int(np.prod(w.shape[2:])) if w.dim() > 1 else 1
            )  # torch's convention (ConvTranspose too)
            if scheme == "torch_default":
                bound, bias_bound = 1 / math.sqrt(fan_in), 1 / math.sqrt(fan_in)
            else:  # gqcnn: kaiming std sqrt(2/fan_in) (fc4 parts: sqrt(2/(fc+pose_fc))), zero bias; uniform of that std
                std = math.sqrt(2 / fan_in)
                if isinstance(model, GQCNN) and (m is model.fc4_image or m is model.fc4_pose):
                    std = math.sqrt(2 / (model.config.fc + model.config.pose_fc))
                bound, bias_bound = math.sqrt(3) * std, 0.0
            rng = np.random.default_rng([seed, layer])
            w.copy_(torch.from_numpy(((2 * rng.random(w.numel()) - 1) * bound).astype(np.float32)).view_as(w))
            if m.bias is not None:
                m.bias.copy_(torch.from_numpy(((2 * rng.random(m.bias.numel()) - 1) * bias_bound).astype(np.float32)))
            layer += 1


def state_sha(model: nn.Module) -> str:
    h = hashlib.sha256()
    for k, v in model.state_dict().items():
        h.update(k.encode())
        h.update(np.ascontiguousarray(v.detach().cpu().numpy()).tobytes())
    return h.hexdigest()


def tensor_hash(t: torch.Tensor) -> str:
    return hashlib.sha1(np.ascontiguousarray(t.detach().float().cpu().numpy()).tobytes()).hexdigest()[:16]


def weight_sample(model: nn.Module, per_tensor: int | None) -> dict[str, np.ndarray]:
    """Float tensors of the state_dict, flattened; every k-th element when per_tensor is set (k fixed by numel)."""
    out = {}
    for k, v in model.state_dict().items():
        if not v.is_floating_point():
            continue
        flat = v.detach().cpu().reshape(-1).numpy().astype(np.float32)
        if per_tensor is not None and flat.size > per_tensor:
            flat = flat[:: -(-flat.size // per_tensor)]
        out[k] = flat.copy()
    return out


def rng_probe() -> dict:
    g = torch.Generator().manual_seed(123)
    return {
        "randperm": torch.randperm(16, generator=g).tolist(),
        "rand": torch.rand(4, generator=g).tolist(),
        "randn": torch.randn(4, generator=g).tolist(),
        "randint": torch.randint(2**31, (2,), generator=g).tolist(),
        "np_gamma": np.random.default_rng(7).gamma(1000.0, 1 / 1000.0, 4).tolist(),
        "np_random": np.random.default_rng([1, 2]).random(3).tolist(),
    }


# ---------------------------------------------------------------- agreement run (same on CPU and CUDA)
def agreement(device: torch.device, S: dict, vox: torch.Tensor, crops) -> dict:
    res: dict = {}
    cfg = AEConfig(**S["ae"])
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    portable_init(ae, 11, "torch_default")
    portable_init(critic, 12, "torch_default")
    res["ae_init_sha"], res["critic_init_sha"] = state_sha(ae), state_sha(critic)
    hashes: list[str] = []
    ae.encoder.register_forward_pre_hook(lambda m, a: hashes.append(tensor_hash(a[0])))
    train_vox, held = vox[:16], vox[16 : 16 + S["held"]]
    tcfg = AETrainConfig(
        batch_size=16, epochs_ae=S["ae_steps"], epochs_critic=S["critic_steps"], critic_warmup=S["warmup"]
    )
    gen = torch.Generator().manual_seed(1)
    ticks, losses = [], []
    t0 = time.perf_counter()
    train_autoencoder(
        ae,
        train_vox,
        tcfg,
        device,
        gen,
        lambda e, m: (ticks.append(time.perf_counter()), losses.append(m["loss_recon"])),
    )
    res["ae_loss"] = losses
    res["ae_times"] = [t0] + ticks
    # steady samples/s: steps 2..N (the first step holds one-off costs)
    res["ae_sps"] = 16 * (len(ticks) - 1) / (ticks[-1] - ticks[0])
    res["ae_hashes"] = list(hashes)
    hashes.clear()
    with torch.no_grad():
        res["ae_heldout_iou"] = reconstruction_iou(ae, held, device)
        ae.eval()
        bce = [
            F.binary_cross_entropy_with_logits(
                ae(held[i : i + 8].to(device).float()), held[i : i + 8].to(device).float(), reduction="sum"
            ).item()
            for i in range(0, len(held), 8)
        ]
        res["ae_heldout_bce"] = sum(bce) / held.numel()
    res["ae_w1"] = weight_sample(ae, 32768)

    ticks2, m2 = [], []
    t0 = time.perf_counter()
    train_ae_critic(
        ae, critic, train_vox, tcfg, device, gen, lambda e, m: (ticks2.append(time.perf_counter()), m2.append(m))
    )
    res["critic_losses"] = {k: [m[k] for m in m2] for k in ("loss_recon", "loss_reg", "loss_critic")}
    joint = ticks2[S["warmup"] :]  # ends of the joint epochs (the AE learns); steady rate from the 2nd joint step on
    res["critic_sps"] = 16 * (len(joint) - 1) / (joint[-1] - joint[0]) if len(joint) > 1 else float("nan")
    res["critic_warmup_sps"] = (
        16 * (S["warmup"] - 1) / (ticks2[S["warmup"] - 1] - ticks2[0]) if S["warmup"] > 1 else float("nan")
    )
    res["critic_hashes"] = list(hashes)
    hashes.clear()
    res["ae2_heldout_iou"] = reconstruction_iou(ae, held, device)
    res["critic_separation"] = critic_separation(ae, critic, held, device, n_shapes=len(held), batch_size=16)
    res["ae_w2"] = weight_sample(ae, 32768)
    res["critic_w2"] = weight_sample(critic, 32768)
    del ae, critic
    if device.type == "cuda":
        torch.cuda.empty_cache()

    # GQ-CNN: paper widths, batch 64, lr 0.01; N steps, one log per step (per-step loss), no validation during
    # training (so the final weights are the last ones), then P(success) on the held-out crops.
    train, test = crops
    net = GQCNN(GQCNNConfig(**S["gq"]))
    portable_init(net, 13, "gqcnn")
    res["gq_init_sha"] = state_sha(net)
    gq_hashes: list[str] = []
    net.register_forward_pre_hook(lambda m, a: gq_hashes.append(tensor_hash(a[0]) + tensor_hash(a[1])))
    st = TrainSettings(
        epochs=25.0, min_steps=S["gq_steps"], max_steps=S["gq_steps"], batch_size=64, lr=0.01, evals=S["gq_steps"]
    )
    gq_log = []
    out = train_gqcnn(
        net,
        train,
        None,
        st,
        device,
        torch.Generator().manual_seed(2),
        on_log=lambda s, m: gq_log.append(m),
        progress=False,
    )
    res["gq_loss"] = [m["loss"] for m in gq_log]
    res["gq_train_acc"] = [m["train_accuracy"] for m in gq_log]
    res["gq_sps_loop"] = out["samples_per_second"]
    res["gq_hashes"] = list(gq_hashes)
    p_test = predict(net, test, device, 256)
    p_train = predict(net, train, device, 256)
    res["gq_p_test"], res["gq_p_train"] = p_test, p_train
    res["gq_test_metrics"] = classification_metrics(test.labels, p_test)
    res["gq_train_metrics"] = classification_metrics(train.labels, p_train)
    pt = np.clip(p_test.astype(np.float64), 1e-7, 1 - 1e-7)
    res["gq_test_ce"] = float(-np.mean(np.where(test.labels > 0, np.log(pt), np.log(1 - pt))))
    res["gq_w"] = weight_sample(net, None)
    return res


# ---------------------------------------------------------------- comparison
def rel(a, b):
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return np.abs(a - b) / np.maximum(np.abs(b), 1e-30)


def cmp_weights(a: dict, b: dict) -> dict:
    rl2, scaled = {}, {}
    for k in b:
        d = a[k].astype(np.float64) - b[k].astype(np.float64)
        nb = np.linalg.norm(b[k].astype(np.float64))
        rl2[k] = float(np.linalg.norm(d) / nb) if nb > 0 else float(np.linalg.norm(d))
        scaled[k] = float(np.abs(d).max() / max(np.abs(b[k]).max(), 1e-30))
    worst = max(rl2, key=rl2.get)
    return {
        "max_rel_l2": rl2[worst],
        "worst_tensor": worst,
        "median_rel_l2": float(np.median(list(rl2.values()))),
        "max_absdiff_over_tensor_maxabs": max(scaled.values()),
        "values_compared": int(sum(v.size for v in b.values())),
    }


def compare(r: dict, ref: dict) -> dict:
    c: dict = {}
    c["init_identical"] = all(r[k] == ref[k] for k in ("ae_init_sha", "critic_init_sha", "gq_init_sha"))
    for k in ("ae_hashes", "critic_hashes", "gq_hashes"):
        c[k.replace("hashes", "inputs_identical")] = r[k] == ref[k]
        if r[k] != ref[k]:
            c[k.replace("hashes", "first_input_mismatch")] = next(
                (i for i, (x, y) in enumerate(zip(r[k], ref[k])) if x != y), min(len(r[k]), len(ref[k]))
            )
    ae_rel = rel(r["ae_loss"], ref["ae_loss"])
    c["ae_loss_rel_per_step"] = ae_rel.tolist()
    c["ae_loss_max_rel"] = float(ae_rel.max())
    for k in ("loss_recon", "loss_reg", "loss_critic"):
        x = rel(r["critic_losses"][k], ref["critic_losses"][k])
        c[f"critic_{k}_rel_per_step"] = x.tolist()
        c[f"critic_{k}_max_rel"] = float(x.max())
    gq = rel(r["gq_loss"], ref["gq_loss"])
    c["gq_loss_rel_per_step"] = gq.tolist()
    c["gq_loss_max_rel"] = float(gq.max())
    c["gq_train_acc_max_absdiff"] = float(np.max(np.abs(np.subtract(r["gq_train_acc"], ref["gq_train_acc"]))))
    c["weights_ae_after_pretrain"] = cmp_weights(r["ae_w1"], ref["ae_w1"])
    c["weights_ae_after_critic_phase"] = cmp_weights(r["ae_w2"], ref["ae_w2"])
    c["weights_critic_after_critic_phase"] = cmp_weights(r["critic_w2"], ref["critic_w2"])
    c["weights_gqcnn_final"] = cmp_weights(r["gq_w"], ref["gq_w"])
    c["ae_heldout_iou"] = [r["ae_heldout_iou"], ref["ae_heldout_iou"]]
    c["ae_heldout_bce"] = [r["ae_heldout_bce"], ref["ae_heldout_bce"]]
    c["ae2_heldout_iou"] = [r["ae2_heldout_iou"], ref["ae2_heldout_iou"]]
    c["critic_auc"] = [r["critic_separation"]["auc"], ref["critic_separation"]["auc"]]
    c["gq_test_ap"] = [r["gq_test_metrics"]["ap"], ref["gq_test_metrics"]["ap"]]
    c["gq_test_accuracy"] = [r["gq_test_metrics"]["accuracy"], ref["gq_test_metrics"]["accuracy"]]
    c["gq_test_ce"] = [r["gq_test_ce"], ref["gq_test_ce"]]
    c["gq_train_ap"] = [r["gq_train_metrics"]["ap"], ref["gq_train_metrics"]["ap"]]
    c["gq_p_test_max_absdiff"] = float(np.abs(r["gq_p_test"] - ref["gq_p_test"]).max())
    c["gq_p_train_max_absdiff"] = float(np.abs(r["gq_p_train"] - ref["gq_p_train"]).max())
    c["gq_test_same_decisions"] = bool(((r["gq_p_test"] > 0.5) == (ref["gq_p_test"] > 0.5)).all())
    return c


def summary(r: dict) -> dict:
    """The scalar part of an agreement result (what goes into JSON)."""
    keep = (
        "ae_init_sha",
        "critic_init_sha",
        "gq_init_sha",
        "ae_loss",
        "ae_sps",
        "ae_heldout_iou",
        "ae_heldout_bce",
        "critic_losses",
        "critic_sps",
        "critic_warmup_sps",
        "ae2_heldout_iou",
        "critic_separation",
        "gq_loss",
        "gq_train_acc",
        "gq_sps_loop",
        "gq_test_metrics",
        "gq_train_metrics",
        "gq_test_ce",
    )
    return {k: r[k] for k in keep}


def save_ref(r: dict, path: Path) -> None:
    arrays = {}
    for group in ("ae_w1", "ae_w2", "critic_w2", "gq_w"):
        for k, v in r[group].items():
            arrays[f"{group}::{k}"] = v
    arrays["gq_p_test"], arrays["gq_p_train"] = r["gq_p_test"], r["gq_p_train"]
    np.savez(path.with_suffix(".npz"), **arrays)
    meta = {k: v for k, v in r.items() if k not in ("ae_w1", "ae_w2", "critic_w2", "gq_w", "gq_p_test", "gq_p_train")}
    path.with_suffix(".json").write_text(json.dumps(meta, indent=1, default=float))


def load_ref(path: Path) -> dict:
    r = json.loads(path.with_suffix(".json").read_text())
    z = np.load(path.with_suffix(".npz"))
    for group in ("ae_w1", "ae_w2", "critic_w2", "gq_w"):
        r[group] = {k.split("::", 1)[1]: z[k] for k in z.files if k.startswith(group + "::")}
    r["gq_p_test"], r["gq_p_train"] = z["gq_p_test"], z["gq_p_train"]
    return r


# ---------------------------------------------------------------- throughput (project loops, full 128-shape set)
def set_precision(mode: str) -> None:
    tf32_conv, tf32_mm, bench = {
        "fp32_strict": (False, False, False),
        "torch_default": (True, False, False),
        "tf32_all": (True, True, False),
        "tf32_all_benchmark": (True, True, True),
    }[mode]
    torch.backends.cudnn.allow_tf32 = tf32_conv
    torch.backends.cuda.matmul.allow_tf32 = tf32_mm
    torch.backends.cudnn.benchmark = bench


def throughput(device: torch.device, S: dict, vox: torch.Tensor, crops, gq_precision: str = "float32") -> dict:
    out = {}
    cfg = AEConfig(**S["ae"])
    torch.manual_seed(0)
    ae, critic = AutoEncoder(cfg), Critic(cfg)
    gen = torch.Generator().manual_seed(0)
    if device.type == "cuda":
        torch.cuda.reset_peak_memory_stats()
    train_autoencoder(ae, vox, AETrainConfig(batch_size=16, epochs_ae=1), device, gen)  # warm-up epoch
    out["ae_pretrain_sps"] = train_autoencoder(
        ae, vox, AETrainConfig(batch_size=16, epochs_ae=S["tp_ae_epochs"]), device, gen
    )
    train_ae_critic(
        ae, critic, vox, AETrainConfig(batch_size=16, epochs_critic=1, critic_warmup=0), device, gen
    )  # warm-up
    out["ae_critic_sps"] = train_ae_critic(
        ae, critic, vox, AETrainConfig(batch_size=16, epochs_critic=S["tp_ae_epochs"], critic_warmup=0), device, gen
    )
    out["ae_critic_warmup_phase_sps"] = train_ae_critic(
        ae, critic, vox, AETrainConfig(batch_size=16, epochs_critic=1, critic_warmup=1), device, gen
    )
    out["ae_samples_per_timed_run"] = len(vox) * S["tp_ae_epochs"]
    if device.type == "cuda":
        out["ae_peak_mem_gib"] = torch.cuda.max_memory_allocated() / 2**30
    del ae, critic
    train, test = crops
    net = GQCNN(GQCNNConfig(**S["gq"]))
    warm = TrainSettings(
        epochs=25.0, min_steps=20, max_steps=20, batch_size=64, lr=0.01, evals=1, precision=gq_precision
    )
    train_gqcnn(net, train, test, warm, device, torch.Generator().manual_seed(0), progress=False)
    n = S["tp_gq_steps"]
    st = TrainSettings(
        epochs=25.0,
        min_steps=n,
        max_steps=n,
        batch_size=64,
        lr=0.01,
        evals=20 if n >= 20 else 1,
        precision=gq_precision,
    )
    r = train_gqcnn(net, train, test, st, device, torch.Generator().manual_seed(0), progress=False)
    out["gq_sps"], out["gq_steps"], out["gq_evals"] = r["samples_per_second"], n, st.evals
    if device.type == "cuda":
        torch.cuda.empty_cache()
    return out


def throughput_gq_only(device: torch.device, S: dict, crops, precision: str = "float32") -> dict:
    """GQ-CNN samples/s with the paper's settings (batch 64, lr 0.01, evals 20 on the held-out crops); on the CPU
    100 steps (4 evals)."""
    train, test = crops
    net = GQCNN(GQCNNConfig(**S["gq"]))
    n = S["tp_gq_steps"] if device.type == "cuda" else max(S["gq_steps"], 8)
    evals = max(1, n // 25)
    warm = TrainSettings(epochs=25.0, min_steps=5, max_steps=5, batch_size=64, lr=0.01, evals=1, precision=precision)
    train_gqcnn(net, train, test, warm, device, torch.Generator().manual_seed(0), progress=False)
    st = TrainSettings(epochs=25.0, min_steps=n, max_steps=n, batch_size=64, lr=0.01, evals=evals, precision=precision)
    r = train_gqcnn(net, train, test, st, device, torch.Generator().manual_seed(0), progress=False)
    return {"gq_sps": r["samples_per_second"], "gq_steps": n, "gq_evals": evals, "precision": precision}


def env() -> dict:
    e = {
        "python": sys.version.split()[0],
        "torch": torch.__version__,
        "numpy": np.__version__,
        "cpu_threads": torch.get_num_threads(),
        "host_cpus": os.cpu_count(),
        "platform": platform.platform(),
        "date_utc": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()),
    }
    if torch.cuda.is_available():
        e |= {"cuda": torch.version.cuda, "cudnn": torch.backends.cudnn.version(), "gpu": torch.cuda.get_device_name(0)}
    return e


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("mode", choices=["cpu-ref", "device"])
    ap.add_argument("--tiny", action="store_true", help="small sizes (to test the script on the CPU)")
    ap.add_argument("--device", default="cuda")
    ap.add_argument("--data", default=str(DATA), help="folder of voxels64.npz and gqcnn_crops.npz (%(default)s)")
    ap.add_argument("--ref", default=str(REF), help="folder of the CPU reference cpu_ref_{paper,tiny} (%(default)s)")
    ap.add_argument("--out", default=os.environ.get("OUT", str(HERE / "out" / "cuda" / "results")))
    a = ap.parse_args()
    S = sizes(a.tiny)
    data = Path(a.data)
    vox, crops = load_voxels(data, S["res"]), load_crops(data)
    if len(vox) < 16 + S["held"]:
        raise SystemExit(f"{data / 'voxels64.npz'}: {len(vox)} shapes; these sizes need {16 + S['held']}")
    tag = "tiny" if a.tiny else "paper"
    ref_path = Path(a.ref) / f"cpu_ref_{tag}"
    log(
        f"mode {a.mode} sizes {tag}: voxels {tuple(vox.shape)} fill {vox.float().mean():.3f}; "
        f"crops train {len(crops[0])} held-out {len(crops[1])}"
    )
    log("env", json.dumps(env()))
    if a.mode == "cpu-ref":
        ref_path.parent.mkdir(parents=True, exist_ok=True)
        t = time.perf_counter()
        r = agreement(torch.device("cpu"), S, vox, crops)
        r["env"], r["rng_probe"], r["seconds"] = env(), rng_probe(), time.perf_counter() - t
        t = time.perf_counter()
        r["cpu_gq_throughput"] = cpu_gq_tp = throughput_gq_only(torch.device("cpu"), S, crops)
        save_ref(r, ref_path)
        log(json.dumps(summary(r) | {"cpu_gq_throughput": cpu_gq_tp, "seconds": r["seconds"]}, default=float))
        return

    out_dir = Path(a.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    device = torch.device(a.device)
    results: dict = {"env": env(), "sizes": S, "notes": []}
    t_all = time.perf_counter()
    try:
        ref = load_ref(ref_path)
        results["cpu_reference"] = {
            "env": ref["env"],
            "seconds": ref["seconds"],
            "summary": summary(ref),
            "cpu_gq_throughput": ref["cpu_gq_throughput"],
        }
        probe = rng_probe()
        results["rng_probe_identical"] = probe == ref["rng_probe"]
        log("rng probe identical to the CPU machine's:", results["rng_probe_identical"])
        # 1) agreement, strict float32 (TF32 off), twice (CUDA run-to-run), then with torch's default (cuDNN TF32 on)
        results["agreement"] = {}
        for name, mode in (
            ("fp32_strict", "fp32_strict"),
            ("fp32_strict_rerun", "fp32_strict"),
            ("torch_default_cudnn_tf32", "torch_default"),
        ):
            if device.type == "cuda":
                set_precision(mode)
            t = time.perf_counter()
            r = agreement(device, S, vox, crops)
            c = compare(r, ref)
            c["seconds"] = time.perf_counter() - t
            c["precision"] = {
                "cudnn.allow_tf32": torch.backends.cudnn.allow_tf32,
                "cuda.matmul.allow_tf32": torch.backends.cuda.matmul.allow_tf32,
                "cudnn.benchmark": torch.backends.cudnn.benchmark,
                "cudnn.deterministic": torch.backends.cudnn.deterministic,
            }
            c["summary"] = summary(r)
            if name == "fp32_strict":
                first = r
            elif name == "fp32_strict_rerun":
                c["vs_first_cuda_run"] = {k: v for k, v in compare(r, first).items() if not k.endswith("per_step")}
            results["agreement"][name] = c
            shown = {k: v for k, v in c.items() if not k.endswith("per_step") and k != "summary"}
            log(f"agreement {name} ({c['seconds']:.1f}s):", json.dumps(shown, default=float))
            (out_dir / "results.json").write_text(json.dumps(results, indent=1, default=float))
        # 2) throughput on the whole voxel set / every training crop
        results["throughput"] = {}
        modes = (
            ("fp32_strict", "torch_default", "tf32_all", "tf32_all_benchmark")
            if device.type == "cuda"
            else ("fp32_strict",)
        )
        for mode in modes:
            if device.type == "cuda":
                set_precision(mode)
            t = time.perf_counter()
            tp = throughput(device, S, vox, crops)
            tp["seconds"] = time.perf_counter() - t
            results["throughput"][mode] = tp
            log(f"throughput {mode}:", json.dumps(tp, default=float))
            (out_dir / "results.json").write_text(json.dumps(results, indent=1, default=float))
        if device.type == "cuda":
            set_precision("torch_default")
            t = time.perf_counter()
            tp = throughput_gq_only(device, S, crops, "bfloat16")
            results["throughput"]["gq_bfloat16_autocast"] = tp | {"seconds": time.perf_counter() - t}
            log("throughput gq bfloat16:", json.dumps(tp, default=float))
    except Exception:  # keep what was measured
        results["error"] = traceback.format_exc()
        log(results["error"])
    results["seconds_total"] = time.perf_counter() - t_all
    (out_dir / "results.json").write_text(json.dumps(results, indent=1, default=float))
    (out_dir / "log.txt").write_text("\n".join(LOG) + "\n")
    log(f"done in {results['seconds_total']:.1f}s")


if __name__ == "__main__":
    main()
