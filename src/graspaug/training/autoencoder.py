"""Training the AutoEncoder (phase 1) and the AE-Critic (phase 2), and using them.

Voxel grids travel as ``(N, 1, R, R, R)`` uint8 tensors (0/1) and are turned into
float batches on the device. Every random choice (batch order, flips, α, the
partner permutation) comes from one ``torch.Generator``.
"""
from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np
import torch
from tqdm import tqdm

from graspaug.nets.ae_critic import AutoEncoder, Critic, autoencoder_loss, critic_loss
from graspaug.training.settings import AETrainConfig


EpochCallback = Callable[[int, dict[str, float]], None]


def _batches(n: int, batch_size: int, gen: torch.Generator) -> list[torch.Tensor]:
    order = torch.randperm(n, generator=gen)
    return [order[i : i + batch_size] for i in range(0, n, batch_size) if len(order[i : i + batch_size]) > 1]


def _flip(x: torch.Tensor, gen: torch.Generator) -> torch.Tensor:
    """Flip the whole batch along each spatial axis with probability 0.5."""
    dims = [d for d in (2, 3, 4) if torch.rand((), generator=gen) < 0.5]
    return x.flip(dims) if dims else x


def _as_float(x: torch.Tensor, device: torch.device) -> torch.Tensor:
    return x.to(device=device, dtype=torch.float32, non_blocking=True)


def train_autoencoder(ae: AutoEncoder, voxels: torch.Tensor, cfg: AETrainConfig, device: torch.device, gen: torch.Generator, on_epoch: EpochCallback | None = None) -> float:
    """Phase 1: minimize the reconstruction BCE with Adam(lr_ae). Returns shapes/s."""
    ae.to(device)
    opt = torch.optim.Adam(ae.parameters(), lr=cfg.lr_ae)
    seen, elapsed = 0, 0.0
    for epoch in tqdm(range(cfg.epochs_ae), desc="train AE", unit="epoch"):
        ae.train()
        start, total = time.perf_counter(), 0.0
        batches = _batches(len(voxels), cfg.batch_size, gen)
        for idx in batches:
            x = _as_float(voxels[idx], device)
            if cfg.flips:
                x = _flip(x, gen)
            loss = torch.nn.functional.binary_cross_entropy_with_logits(ae(x), x)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            total += loss.item() * len(idx)
            seen += len(idx)
        elapsed += time.perf_counter() - start
        if on_epoch:
            on_epoch(epoch, {"loss_recon": total / max(1, sum(len(b) for b in batches))})
    return seen / max(elapsed, 1e-9)


def train_ae_critic(ae: AutoEncoder, critic: Critic, voxels: torch.Tensor, cfg: AETrainConfig, device: torch.device, gen: torch.Generator, on_epoch: EpochCallback | None = None) -> float:
    """Phase 2: critic on eq. (1) with Adam(lr_critic), AE on eq. (2) with Adam(lr_ae_critic).

    The first ``critic_warmup`` epochs train only the critic, so the AE's eq. (2) term
    starts from a critic that has learned something rather than from random outputs.

    Each batch: x̂ = AE(x); a partner for every shape from a permutation of the batch;
    α ~ U[0, 0.5]; x̂_α = decode((1 − α) z + α z_partner). Returns shapes/s.
    """
    ae.to(device)
    critic.to(device)
    opt_ae = torch.optim.Adam(ae.parameters(), lr=cfg.lr_ae_critic)
    opt_c = torch.optim.Adam(critic.parameters(), lr=cfg.lr_critic)
    seen, elapsed = 0, 0.0
    for epoch in tqdm(range(cfg.epochs_critic), desc="train AE-Critic", unit="epoch"):
        ae.train()
        critic.train()
        start = time.perf_counter()
        sums = {"loss_recon": 0.0, "loss_reg": 0.0, "loss_critic": 0.0, "critic_real": 0.0, "critic_interp": 0.0}
        n = 0
        for idx in _batches(len(voxels), cfg.batch_size, gen):
            x = _as_float(voxels[idx], device)
            if cfg.flips:
                x = _flip(x, gen)
            b = len(idx)
            partner = torch.randperm(b, generator=gen).to(device)
            alpha = (0.5 * torch.rand(b, generator=gen)).to(device)

            train_ae = epoch >= cfg.critic_warmup
            with torch.set_grad_enabled(train_ae):
                z = ae.encoder(x)
                recon = ae.decoder(z)
                x_alpha = torch.sigmoid(ae.interpolate(z, z[partner], alpha))
                c_interp = critic(x_alpha)
                loss_ae, bce, reg = autoencoder_loss(recon, x, c_interp, cfg.lam)  # eq. (2)
            if train_ae:
                opt_ae.zero_grad(set_to_none=True)
                loss_ae.backward()
                opt_ae.step()

            loss_c = critic_loss(critic, x, torch.sigmoid(recon), x_alpha, alpha, cfg.gamma)  # eq. (1)
            opt_c.zero_grad(set_to_none=True)
            loss_c.backward()
            opt_c.step()

            with torch.no_grad():
                sums["critic_real"] += critic(x).mean().item() * b
            sums["loss_recon"] += bce.item() * b
            sums["loss_reg"] += reg.item() * b
            sums["loss_critic"] += loss_c.item() * b
            sums["critic_interp"] += c_interp.mean().item() * b
            n += b
            seen += b
        elapsed += time.perf_counter() - start
        if on_epoch:
            on_epoch(epoch, {k: v / max(n, 1) for k, v in sums.items()})
    return seen / max(elapsed, 1e-9)


@torch.no_grad()
def encode(ae: AutoEncoder, voxels: torch.Tensor, device: torch.device, batch_size: int = 64) -> np.ndarray:
    """(N, z_dim) float32 latents of (N, 1, R, R, R) grids (eval mode)."""
    ae.eval().to(device)
    out = [ae.encoder(_as_float(voxels[i : i + batch_size], device)).cpu() for i in range(0, len(voxels), batch_size)]
    return torch.cat(out).numpy() if out else np.zeros((0, ae.cfg.z_dim), np.float32)


@torch.no_grad()
def decode(ae: AutoEncoder, z: np.ndarray, device: torch.device, batch_size: int = 64) -> np.ndarray:
    """(N, R, R, R) float32 occupancy probabilities of (N, z_dim) latents (eval mode)."""
    ae.eval().to(device)
    zt = torch.as_tensor(np.asarray(z, dtype=np.float32))
    if len(zt) == 0:
        r = ae.cfg.resolution
        return np.zeros((0, r, r, r), np.float32)
    out = [torch.sigmoid(ae.decoder(zt[i : i + batch_size].to(device))).cpu() for i in range(0, len(zt), batch_size)]
    return torch.cat(out)[:, 0].numpy()


def reconstruction_iou(ae: AutoEncoder, voxels: torch.Tensor, device: torch.device, threshold: float = 0.5) -> float:
    """Mean over shapes of IoU(decode(encode(x)) > threshold, x)."""
    if len(voxels) == 0:
        return float("nan")
    recon = decode(ae, encode(ae, voxels, device), device) > threshold
    x = voxels[:, 0].numpy().astype(bool)
    inter = (recon & x).sum(axis=(1, 2, 3))
    union = (recon | x).sum(axis=(1, 2, 3))
    return float(np.mean(np.where(union > 0, inter / np.maximum(union, 1), 1.0)))


def voxel_grids(voxels_path, shapes_path) -> tuple[np.ndarray, np.ndarray, torch.Tensor]:
    """Every shape's ``shape_id``, ``split`` and (N, 1, R, R, R) uint8 grid, in the voxel file's order."""
    from graspaug.io.tables import read_table
    from graspaug.io.voxels import read_voxels

    voxels = read_voxels(voxels_path)
    split = read_table(shapes_path).set_index("shape_id")["split"]
    return voxels.shape_id, split.reindex(voxels.shape_id).to_numpy(), torch.from_numpy(voxels.occupancy[:, None].astype(np.uint8))


def grids_by_split(voxels_path, shapes_path) -> dict[str, torch.Tensor]:
    """(N, 1, R, R, R) uint8 grids of the ``train`` and ``test`` splits, in the voxel file's order."""
    _, labels, grids = voxel_grids(voxels_path, shapes_path)
    return {name: grids[labels == name] for name in ("train", "test")}
