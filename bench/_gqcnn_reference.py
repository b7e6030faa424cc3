"""The GQ-CNN training loop as it was before the bench's speed work (a frozen copy, for
``bench/gqcnn_train_speed.py`` only): batch 64, StepLR, torch's default threads, one network
per process, the contiguous layout, the last step's weights; and the network's LRN as it was
then (its power as ``pow``; ``reference_network``). The function computed is the same."""

from __future__ import annotations

import time

import numpy as np
import torch
import torch.nn.functional as F
from tqdm import tqdm

from graspaug.nets.gqcnn import GQCNN, LocalResponseNorm
from graspaug.training.gqcnn import augment, classification_metrics, predict


class PowLocalResponseNorm(LocalResponseNorm):
    """The LRN of the network when the speed work began: the same function, the power as ``pow``."""

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        channels = x.shape[1]
        offset = torch.arange(channels, device=x.device)
        diff = offset[None, :] - offset[:, None]  # input channel - output channel
        band = ((diff >= -(self.size // 2)) & (diff <= (self.size - 1) // 2)).to(x.dtype)
        window = F.conv2d(x * x, band.view(channels, channels, 1, 1))
        return x * (self.k + self.alpha / self.size * window).pow(-self.beta)


def reference_network(config) -> GQCNN:
    """A GQ-CNN of ``config`` with the reference LRN."""
    net = GQCNN(config)
    net.lrn = PowLocalResponseNorm(net.lrn.size, net.lrn.alpha, net.lrn.beta, net.lrn.k)
    return net


def normalization(train):
    return (
        float(train.images.mean()),
        float(train.images.std()) or 1.0,
        float(train.z.mean()),
        float(train.z.std()) or 1.0,
    )


def train_gqcnn_reference(net, train, val, settings, device, gen, on_log=None) -> dict[str, float]:
    """Train ``net`` for ``settings.steps`` SGD steps on batches drawn epoch by epoch from
    ``train`` (softmax cross-entropy); every ``log_every`` steps report the mean loss and train
    accuracy since the last report and, if ``val`` is given, its accuracy and AP. Returns
    throughput figures."""
    if len(train) < 2:
        raise ValueError(f"need at least 2 training datapoints, got {len(train)}")
    net.set_normalization(*normalization(train))
    net.to(device)
    opt = torch.optim.SGD(
        net.parameters(), lr=settings.lr, momentum=settings.momentum, weight_decay=settings.weight_decay
    )
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
                metrics.update(
                    val_accuracy=scores["accuracy"], val_ap=scores["ap"] if scores["ap"] is not None else float("nan")
                )
            on_log(step, metrics)
            loss_sum, correct, seen = 0.0, 0, 0
    seconds = time.perf_counter() - start
    return {"train_seconds": seconds, "samples_per_second": settings.steps * settings.batch_size / seconds}
