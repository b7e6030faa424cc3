"""Training and evaluating a GQ-CNN by Dex-Net 2.0's recipe.

Datapoints travel as :class:`GraspArrays`: depth crops (N, S, S) float32 (m), gripper depths
(N,) (m), labels (N,) 0/1. Every random choice of a network (batch order, noise,
symmetrization) comes from its own ``torch.Generator``, also when several train at once
(:func:`train_members`). The budget rule is a number of passes over each network's own
training set (with a step cap), the learning rate annealed along a cosine, and the weights
with the best validation AP kept: every variant is trained to about the same convergence.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F
from sklearn.metrics import accuracy_score, average_precision_score, roc_auc_score
from torch.optim.swa_utils import AveragedModel, get_ema_multi_avg_fn
from tqdm import tqdm

from graspaug.device import GQCNN_GPU_BFLOAT16, resolve_precision, training_autocast
from graspaug.nets.gqcnn import GQCNN, GQCNNStack
from graspaug.training.settings import NoiseSettings, TrainSettings


@dataclass(frozen=True)
class GraspArrays:
    """``images`` (N, S, S) float32 depth crops (m), ``z`` (N,) gripper depths (m), ``labels`` (N,) 0/1."""

    images: np.ndarray
    z: np.ndarray
    labels: np.ndarray

    def __len__(self) -> int:
        return len(self.labels)


LogCallback = Callable[[int, dict[str, float]], None]
MemberLogCallback = Callable[[int, int, dict[str, float]], None]


def normalization(net: GQCNN, train: GraspArrays) -> tuple[float, float, float, float]:
    """One scalar mean / std of what the conv layers see and of z over the training data (Dex-Net)."""
    images = net.image_input(
        torch.from_numpy(np.ascontiguousarray(train.images)).unsqueeze(1), torch.from_numpy(train.z.astype(np.float32))
    )
    return (float(images.mean()), float(images.std()) or 1.0, float(train.z.mean()), float(train.z.std()) or 1.0)


def augment(
    images: torch.Tensor, z: torch.Tensor, noise: NoiseSettings, gen: torch.Generator
) -> tuple[torch.Tensor, torch.Tensor]:
    """Noisy, symmetrized copies of a batch of depth crops (N, 1, S, S) and gripper depths (N,)
    (m). The multiplicative noise scales a crop and its gripper depth together (the scene seen
    nearer or farther), so the object's height relative to the gripper keeps its meaning."""
    n, _, size, _ = images.shape
    if noise.gamma_shape > 0:
        draws = np.random.default_rng(int(torch.randint(2**31, (1,), generator=gen))).gamma(
            noise.gamma_shape, 1 / noise.gamma_shape, n
        )
        scale = torch.from_numpy(draws.astype(np.float32))
        images, z = images * scale.view(n, 1, 1, 1), z * scale
    if noise.gp_prob > 0 and noise.gp_sigma > 0:
        grid = torch.randn((n, 1, noise.gp_grid, noise.gp_grid), generator=gen) * noise.gp_sigma
        field = F.interpolate(grid, size=(size, size), mode="bicubic", align_corners=False)
        apply = (torch.rand((n,), generator=gen) < noise.gp_prob).float().view(n, 1, 1, 1)
        images = images + apply * field
    if noise.symmetrize:
        for dims in ((2, 3), (3,), (2,)):  # 180° turn, left-right flip, up-down flip
            pick = torch.rand((n,), generator=gen) < 0.5
            if pick.any():
                images = torch.where(pick.view(n, 1, 1, 1), images.flip(dims), images)
    return images, z


def _batches(data: GraspArrays, device: torch.device, batch: int):
    """``data`` in batches of ``batch``: crops (B, 1, S, S) channels-last and gripper depths (B,) on ``device``."""
    for start in range(0, len(data), batch):
        images = torch.from_numpy(np.ascontiguousarray(data.images[start : start + batch])).unsqueeze(1)
        z = torch.from_numpy(np.ascontiguousarray(data.z[start : start + batch], dtype=np.float32))
        yield start, images.to(device, memory_format=torch.channels_last), z.to(device)


def predict(net: GQCNN, data: GraspArrays, device: torch.device, batch: int = 128) -> np.ndarray:
    """P(success) (N,) float32 for every datapoint."""
    net.eval()
    out = np.empty(len(data), dtype=np.float32)
    with torch.inference_mode():
        for start, images, z in _batches(data, device, batch):
            out[start : start + batch] = net.success_probability(images, z).cpu().numpy()
    return out


def predict_members(stack: GQCNNStack, data: GraspArrays, device: torch.device, batch: int = 128) -> np.ndarray:
    """P(success) (K, N) float32 of every member of ``stack`` for every datapoint, in one pass."""
    stack.eval()
    out = np.empty((stack.k, len(data)), dtype=np.float32)
    with torch.inference_mode():
        for start, images, z in _batches(data, device, batch):
            logits = stack(images.expand(stack.k, *images.shape), z.expand(stack.k, *z.shape))
            out[:, start : start + batch] = torch.softmax(logits, dim=-1)[..., 1].cpu().numpy()
    return out


def classification_metrics(labels: np.ndarray, probability: np.ndarray) -> dict[str, float | None]:
    """Average Precision (sklearn), accuracy at 0.5, ROC AUC and the positive share; AP and
    AUC are None when only one class is present."""
    labels = np.asarray(labels).astype(int)
    both = 0 < labels.sum() < len(labels)
    return {
        "ap": float(average_precision_score(labels, probability)) if both else None,
        "accuracy": float(accuracy_score(labels, probability > 0.5)) if len(labels) else None,
        "roc_auc": float(roc_auc_score(labels, probability)) if both else None,
        "positive_share": float(labels.mean()) if len(labels) else None,
        "datapoints": int(len(labels)),
    }


class BatchSampler:
    """The row indices of one member's training batches, drawn with its generator ``gen`` from a training set of
    ``labels`` (N,) 0/1: epoch by epoch (every row once per pass in a fresh random order, a pass's remainder left
    out), or, with ``positive_share``, from the positive and the negative rows apart, each epoch by epoch, so that
    the first s batches hold round(s · share · ``batch``) positives: the share of positives drawn is
    ``positive_share`` to within half a datapoint over the run (the ``balanced`` networks). ``drawn`` and
    ``positives`` count what it has drawn."""

    def __init__(self, labels: torch.Tensor, batch: int, gen: torch.Generator, positive_share: float | None = None):
        self.labels, self.batch, self.gen, self.share = labels, batch, gen, positive_share
        self.drawn = self.positives = self.steps = 0
        if positive_share is None:
            self.order, self.cursor = torch.randperm(len(labels), generator=gen), 0
            return
        if not 0.0 <= positive_share <= 1.0:
            raise ValueError(f"positive share must lie in [0, 1], got {positive_share}")
        self.rows = [torch.nonzero(labels == 1).flatten(), torch.nonzero(labels != 1).flatten()]
        for rows, wanted, name in zip(self.rows, (positive_share > 0, positive_share < 1), ("positive", "negative")):
            if wanted and not len(rows):
                raise ValueError(f"positive share {positive_share:g} asks for {name} datapoints; the set has none")
        self.orders = [torch.randperm(len(r), generator=gen) if len(r) else r for r in self.rows]
        self.cursors = [0, 0]

    def _take(self, part: int, k: int) -> torch.Tensor:
        """``k`` rows of part ``part`` (0: positives, 1: negatives), continuing its pass and starting new ones."""
        out = []
        while k > 0:
            if self.cursors[part] >= len(self.orders[part]):
                self.orders[part], self.cursors[part] = torch.randperm(len(self.rows[part]), generator=self.gen), 0
            got = self.orders[part][self.cursors[part] : self.cursors[part] + k]
            self.cursors[part] += len(got)
            out.append(self.rows[part][got])
            k -= len(got)
        return torch.cat(out) if out else torch.zeros(0, dtype=torch.long)

    def __call__(self) -> torch.Tensor:
        """The next batch's row indices (``batch``,)."""
        self.steps += 1
        if self.share is None:
            if self.cursor + self.batch > len(self.order):
                self.order, self.cursor = torch.randperm(len(self.labels), generator=self.gen), 0
            idx = self.order[self.cursor : self.cursor + self.batch]
            self.cursor += self.batch
        else:
            due = math.floor(self.steps * self.share * self.batch + 0.5) - self.positives
            idx = torch.cat([self._take(0, due), self._take(1, self.batch - due)])
        self.drawn += len(idx)
        self.positives += int(self.labels[idx].sum())
        return idx

    @property
    def drawn_share(self) -> float | None:
        """The share of positives among the datapoints drawn so far (None before the first batch)."""
        return self.positives / self.drawn if self.drawn else None


def cosine_lr(step: int, steps: int, final: float) -> float:
    """Learning-rate factor at ``step`` (0-based) of ``steps``: 1 at the start, ``final`` at the last step."""
    return final + (1 - final) * 0.5 * (1 + math.cos(math.pi * step / max(steps - 1, 1)))


def train_gqcnn(
    net: GQCNN,
    train: GraspArrays,
    val: GraspArrays | None,
    settings: TrainSettings,
    device: torch.device,
    gen: torch.Generator,
    on_log: LogCallback | None = None,
    progress: bool = True,
) -> dict:
    """Train one network: :func:`train_members` with one member."""
    log = None if on_log is None else lambda member, step, metrics: on_log(step, metrics)
    return train_members([net], train, val, settings, device, [gen], log, progress)[0]


def train_members(
    nets: list[GQCNN],
    train: GraspArrays,
    val: GraspArrays | None,
    settings: TrainSettings,
    device: torch.device,
    gens: list[torch.Generator],
    on_log: MemberLogCallback | None = None,
    progress: bool = True,
    positive_share: float | None = None,
) -> list[dict]:
    """Train the K networks ``nets`` (one config) at once, as one :class:`GQCNNStack`, for
    ``settings.steps_for(len(train))`` SGD steps each, on batches drawn epoch by epoch from
    ``train`` (softmax cross-entropy), evaluating validation AP ``settings.evals`` times. Member
    k draws its batch order and noise from ``gens[k]`` alone and its gradient is that of its own
    loss, so it is trained as it would be alone (up to float rounding; a test checks it). Each
    net ends with the weights of its best evaluation (the last ones without ``val``).
    With ``settings.precision = "bfloat16"`` (or ``auto`` on a device with native bfloat16:
    :func:`graspaug.device.resolve_precision`) the training steps' forward and backward run in
    bfloat16 mixed precision (``torch.autocast``); the weights, the optimizer, the loss and every
    evaluation stay float32. With ``settings.ema_decay > 0`` the evaluated and kept weights are
    an exponential moving average of the trained ones (``torch.optim.swa_utils.AveragedModel``),
    updated every step. With ``positive_share`` every member's batches hold that share of positives
    (:class:`BatchSampler`; the ``balanced`` networks), else they are drawn epoch by epoch.
    ``on_log(member, step, metrics)`` gets each member's mean loss and train accuracy since the
    last evaluation, the learning rate and the validation AP / accuracy. Returns per member the
    steps, the best step, its validation AP and predictions (N_val,) (None without ``val``), and
    throughput (the samples of every member) and the share of positives among the datapoints it drew."""
    if len(train) < 2:
        raise ValueError(f"need at least 2 training datapoints, got {len(train)}")
    if len(gens) != len(nets):
        raise ValueError(f"one generator per member: {len(nets)} members, {len(gens)} generators")
    precision = resolve_precision(settings.precision, device, GQCNN_GPU_BFLOAT16)
    stats = normalization(nets[0], train)
    for net in nets:
        net.set_normalization(*stats)
    stack = GQCNNStack(nets).to(device, memory_format=torch.channels_last)  # ~1.3× faster on the CPU at these widths
    # the weights that are evaluated and kept: an exponential moving average of the trained ones, or those themselves
    averaged = (
        AveragedModel(stack, multi_avg_fn=get_ema_multi_avg_fn(settings.ema_decay), use_buffers=True)
        if settings.ema_decay > 0
        else None
    )
    evaluated = averaged.module if averaged is not None else stack
    steps, k = settings.steps_for(len(train)), len(nets)
    opt = torch.optim.SGD(
        stack.parameters(), lr=settings.lr, momentum=settings.momentum, weight_decay=settings.weight_decay
    )
    schedule = torch.optim.lr_scheduler.LambdaLR(opt, lambda step: cosine_lr(step, steps, settings.final_lr))
    eval_at = {int(round(steps * (i + 1) / settings.evals)) for i in range(settings.evals)}
    images = torch.from_numpy(np.ascontiguousarray(train.images)).unsqueeze(1)
    z = torch.from_numpy(np.ascontiguousarray(train.z, dtype=np.float32))
    labels = torch.from_numpy(np.asarray(train.labels, dtype=np.int64))
    batch_size = min(settings.batch_size, len(train))
    samplers = [BatchSampler(labels, batch_size, gen, positive_share) for gen in gens]
    best = [{"step": steps, "val_ap": float("nan"), "state": None} for _ in nets]
    loss_sum, correct, seen, start = torch.zeros(k), torch.zeros(k), 0, time.perf_counter()
    for step in tqdm(range(1, steps + 1), desc="train GQ-CNN", unit="step", disable=not progress):
        crops, depths, targets = [], [], []
        for m, gen in enumerate(gens):  # each member's batch and noise from its own generator
            idx = samplers[m]()
            batch, depth = augment(images[idx], z[idx], settings.noise, gen)
            crops.append(batch)
            depths.append(depth)
            targets.append(labels[idx])
        stack.train()
        with training_autocast(precision, device):
            logits = stack(torch.stack(crops).to(device), torch.stack(depths).to(device)).float()  # (K, B, 2)
        target = torch.stack(targets).to(device)
        # one call per member: a single member's loss is then computed exactly as before the stack
        losses = torch.stack([F.cross_entropy(logits[m], target[m]) for m in range(k)])
        opt.zero_grad(set_to_none=True)
        losses.sum().backward()  # member m's gradient is that of its own loss
        opt.step()
        if averaged is not None:
            averaged.update_parameters(stack)
        lr_used = schedule.get_last_lr()[0]
        schedule.step()
        loss_sum += losses.detach().cpu() * batch_size
        correct += (logits.argmax(2) == target).sum(1).cpu()
        seen += batch_size
        if step in eval_at:
            probabilities = (
                predict_members(evaluated, val, device, settings.eval_batch) if val is not None and len(val) else None
            )
            for m in range(k):
                metrics = {"loss": float(loss_sum[m]) / seen, "train_accuracy": float(correct[m]) / seen, "lr": lr_used}
                if probabilities is not None:
                    scores = classification_metrics(val.labels, probabilities[m])
                    ap = scores["ap"] if scores["ap"] is not None else float("nan")
                    metrics.update(val_accuracy=scores["accuracy"], val_ap=ap)
                    if best[m]["state"] is None or (
                        math.isfinite(ap) and not ap <= best[m]["val_ap"]
                    ):  # ties keep the earlier; a NaN is replaced
                        best[m] = {
                            "step": step,
                            "val_ap": ap,
                            "state": evaluated.member_state(m),
                            "val_predictions": probabilities[m],
                        }
                if on_log is not None:
                    on_log(m, step, metrics)
            loss_sum, correct, seen = torch.zeros(k), torch.zeros(k), 0
    seconds = time.perf_counter() - start
    for m, net in enumerate(nets):
        if best[m]["state"] is not None:
            net.load_state_dict(best[m]["state"])
        else:
            net.load_state_dict(evaluated.member_state(m))
    return [
        {
            "steps": steps,
            "best_step": b["step"],
            "best_val_ap": b["val_ap"],
            "val_predictions": b.get("val_predictions"),
            "train_seconds": seconds,
            "samples_per_second": k * steps * batch_size / seconds,
            "drawn_positive_share": samplers[m].drawn_share,
        }
        for m, b in enumerate(best)
    ]
