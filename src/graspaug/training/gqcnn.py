"""Training and evaluating a GQ-CNN by Dex-Net 2.0's recipe.

Datapoints travel as :class:`GraspArrays`: depth crops (N, S, S) float32 (m), gripper depths
(N,) (m), labels (N,) 0/1. Every random choice (batch order, noise, symmetrization) comes from
one ``torch.Generator``. The budget rule is a fixed number of SGD steps for every training
set, so a larger (augmented) set gets no more compute than a smaller one.
"""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import torch
import torch.nn.functional as F
from sklearn.metrics import accuracy_score, average_precision_score, roc_auc_score
from tqdm import tqdm

from graspaug.nets.gqcnn import GQCNN
from graspaug.training.settings import NoiseSettings
from graspaug.training.settings import TrainSettings


@dataclass(frozen=True)
class GraspArrays:
    """``images`` (N, S, S) float32 depth crops (m), ``z`` (N,) gripper depths (m), ``labels`` (N,) 0/1."""

    images: np.ndarray
    z: np.ndarray
    labels: np.ndarray

    def __len__(self) -> int:
        return len(self.labels)

    def subset(self, rows: np.ndarray) -> GraspArrays:
        return GraspArrays(self.images[rows], self.z[rows], self.labels[rows])


LogCallback = Callable[[int, dict[str, float]], None]


def normalization(train: GraspArrays) -> tuple[float, float, float, float]:
    """One scalar image mean / std and z mean / std of the training data (Dex-Net)."""
    return (float(train.images.mean()), float(train.images.std()) or 1.0, float(train.z.mean()), float(train.z.std()) or 1.0)


def augment(images: torch.Tensor, z: torch.Tensor, noise: NoiseSettings, gen: torch.Generator) -> tuple[torch.Tensor, torch.Tensor]:
    """Noisy, symmetrized copies of a batch of depth crops (N, 1, S, S) and gripper depths (N,)
    (m). The multiplicative noise scales a crop and its gripper depth together (the scene seen
    nearer or farther), so the object's height relative to the gripper keeps its meaning."""
    n, _, size, _ = images.shape
    if noise.gamma_shape > 0:
        draws = np.random.default_rng(int(torch.randint(2**31, (1,), generator=gen))).gamma(noise.gamma_shape, 1 / noise.gamma_shape, n)
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


def predict(net: GQCNN, data: GraspArrays, device: torch.device, batch: int = 128) -> np.ndarray:
    """P(success) (N,) float32 for every datapoint."""
    net.eval()
    out = np.empty(len(data), dtype=np.float32)
    with torch.inference_mode():
        for start in range(0, len(data), batch):
            images = torch.from_numpy(np.ascontiguousarray(data.images[start : start + batch])).unsqueeze(1).to(device)
            z = torch.from_numpy(np.ascontiguousarray(data.z[start : start + batch], dtype=np.float32)).to(device)
            out[start : start + batch] = net.success_probability(images, z).cpu().numpy()
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


def train_gqcnn(net: GQCNN, train: GraspArrays, val: GraspArrays | None, settings: TrainSettings, device: torch.device, gen: torch.Generator,
                on_log: LogCallback | None = None) -> dict[str, float]:
    """Train ``net`` for ``settings.steps`` SGD steps on batches drawn epoch by epoch from
    ``train`` (softmax cross-entropy); every ``log_every`` steps report the mean loss and train
    accuracy since the last report and, if ``val`` is given, its accuracy and AP. Returns
    throughput figures."""
    if len(train) < 2:
        raise ValueError(f"need at least 2 training datapoints, got {len(train)}")
    net.set_normalization(*normalization(train))
    net.to(device)
    opt = torch.optim.SGD(net.parameters(), lr=settings.lr, momentum=settings.momentum, weight_decay=settings.weight_decay)
    schedule = torch.optim.lr_scheduler.StepLR(opt, step_size=settings.decay_steps, gamma=settings.lr_decay)
    images = torch.from_numpy(np.ascontiguousarray(train.images)).unsqueeze(1)
    z = torch.from_numpy(np.ascontiguousarray(train.z, dtype=np.float32))
    labels = torch.from_numpy(np.asarray(train.labels, dtype=np.int64))
    order, cursor = torch.randperm(len(train), generator=gen), 0
    loss_sum, correct, seen, start = 0.0, 0, 0, time.perf_counter()
    for step in tqdm(range(1, settings.steps + 1), desc="train GQ-CNN", unit="step"):
        if cursor + settings.batch_size > len(order):
            order, cursor = torch.randperm(len(train), generator=gen), 0
        idx = order[cursor : cursor + settings.batch_size]
        cursor += settings.batch_size
        net.train()
        batch, depth = augment(images[idx], z[idx], settings.noise, gen)
        logits = net(batch.to(device), depth.to(device))
        target = labels[idx].to(device)
        loss = F.cross_entropy(logits, target)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        schedule.step()
        loss_sum += loss.item() * len(idx)
        correct += int((logits.argmax(1) == target).sum())
        seen += len(idx)
        if on_log is not None and (step % settings.log_every == 0 or step == settings.steps):
            metrics = {"loss": loss_sum / seen, "train_accuracy": correct / seen, "lr": schedule.get_last_lr()[0]}
            if val is not None and len(val):
                scores = classification_metrics(val.labels, predict(net, val, device, settings.eval_batch))
                metrics.update(val_accuracy=scores["accuracy"], val_ap=scores["ap"] if scores["ap"] is not None else float("nan"))
            on_log(step, metrics)
            loss_sum, correct, seen = 0.0, 0, 0
    seconds = time.perf_counter() - start
    return {"train_seconds": seconds, "samples_per_second": settings.steps * settings.batch_size / seconds}
