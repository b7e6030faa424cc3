"""Training the AutoEncoder (phase 1) and the AE-Critic (phase 2), and using them (measures, meshes encoded as
``voxelize`` grids them); the batched :func:`~graspaug.nets.ae_critic.encode` and
:func:`~graspaug.nets.ae_critic.decode` they call live beside the network.

Grids travel as ``(N, 1, R, R, R)`` tensors, uint8 occupancy (0/1) or float32 signed distance / truncation
(``ae.net.output``: :mod:`graspaug.nets.ae_critic`), and are turned into float batches on the device. Every
random choice (batch order, flips, α) comes from one ``torch.Generator``. With ``ae.train.precision`` bfloat16
(or ``auto`` on a device with native bfloat16: :func:`graspaug.device.resolve_precision`) the training steps'
forward passes and losses run under ``torch.autocast``; the network outputs are cast back to float32 before
their loss, and weights, optimizers, evaluation, embedding and decoding stay float32.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable

import numpy as np
import torch
from tqdm import tqdm

from graspaug.device import resolve_precision, training_autocast
from graspaug.nets.ae_critic import (
    AutoEncoder,
    Critic,
    autoencoder_loss,
    critic_loss,
    decode,
    encode,
    folded_alpha,
    reconstruction_loss,
    reversed_partners,
)
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


def train_autoencoder(
    ae: AutoEncoder,
    voxels: torch.Tensor,
    cfg: AETrainConfig,
    device: torch.device,
    gen: torch.Generator,
    on_epoch: EpochCallback | None = None,
) -> float:
    """Phase 1: minimize the reconstruction loss (:func:`~graspaug.nets.ae_critic.reconstruction_loss`: BCE of
    occupancy, or the weighted L1 of signed distances) with Adam, its rate set per epoch by :func:`phase_1_schedule`.
    The forward pass and loss run in ``cfg.precision`` (module docstring). Returns shapes/s."""
    ae.to(device)
    precision = resolve_precision(cfg.precision, device)
    opt = torch.optim.Adam(ae.parameters(), lr=cfg.lr_ae)
    schedule = phase_1_schedule(opt, cfg)
    seen, elapsed = 0, 0.0
    for epoch in tqdm(range(cfg.epochs_ae), desc="train AE", unit="epoch"):
        ae.train()
        start, total = time.perf_counter(), 0.0
        batches = _batches(len(voxels), cfg.batch_size, gen)
        for idx in batches:
            x = _as_float(voxels[idx], device)
            if cfg.flips:
                x = _flip(x, gen)
            with training_autocast(precision, device):
                loss = reconstruction_loss(ae(x).float(), x, ae.cfg.output)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
            total += loss.item() * len(idx)
            seen += len(idx)
        elapsed += time.perf_counter() - start
        if batches:  # an epoch without a batch (fewer than 2 shapes) steps no optimizer, so no schedule either
            schedule.step()
        if on_epoch:
            on_epoch(epoch, {"loss_recon": total / max(1, sum(len(b) for b in batches))})
    return seen / max(elapsed, 1e-9)


def checkpoint_params(cfg: AETrainConfig, device: torch.device) -> dict:
    """The training params a checkpoint of a model trained with ``cfg`` on ``device`` records: ``cfg``'s fields
    (``lam`` for λ), ``precision`` as resolved there (:func:`graspaug.device.resolve_precision`'s label, e.g.
    ``"bfloat16 (auto: native on this CPU)"``)."""
    return dataclasses.asdict(cfg) | {"precision": resolve_precision(cfg.precision, device).label}


def batches_per_epoch(n_shapes: int, batch_size: int) -> int:
    """Optimizer steps of one epoch over ``n_shapes`` in batches of ``batch_size`` (a last batch of one shape is
    dropped, as the training phases drop it)."""
    return sum(1 for i in range(0, n_shapes, batch_size) if min(batch_size, n_shapes - i) > 1)


def step_matched(
    cfg: AETrainConfig, n_from: int, n_to: int, epochs_ae: int | None = None, epochs_critic: int | None = None
) -> AETrainConfig:
    """``cfg`` for a training set of ``n_to`` shapes that takes as many SGD steps as ``cfg`` takes on ``n_from``:
    each phase's epochs times :func:`batches_per_epoch` of ``n_from`` over that of ``n_to``, rounded up, unless
    ``epochs_ae`` / ``epochs_critic`` name them; the critic warm-up keeps its share of phase 2 (rounded)."""
    scale = batches_per_epoch(n_from, cfg.batch_size) / max(1, batches_per_epoch(n_to, cfg.batch_size))
    phase_1 = epochs_ae if epochs_ae is not None else math.ceil(cfg.epochs_ae * scale)
    phase_2 = epochs_critic if epochs_critic is not None else math.ceil(cfg.epochs_critic * scale)
    warmup = round(cfg.critic_warmup * phase_2 / cfg.epochs_critic) if cfg.epochs_critic else 0
    return dataclasses.replace(cfg, epochs_ae=phase_1, epochs_critic=phase_2, critic_warmup=min(warmup, phase_2))


def phase_1_schedule(opt: torch.optim.Optimizer, cfg: AETrainConfig) -> torch.optim.lr_scheduler.LambdaLR:
    """Phase 1's learning rate, stepped once per epoch: ``lr_ae`` throughout (``lr_schedule: constant``), or a
    cosine from ``lr_ae`` towards 0 over ``epochs_ae`` (``cosine``: lr_ae · ½(1 + cos(π · epoch / epochs_ae)) in
    epoch ``epoch``, 0-based; the closed form each epoch, so a rate never carries the last one's rounding)."""
    if cfg.lr_schedule == "constant":
        return torch.optim.lr_scheduler.LambdaLR(opt, lambda epoch: 1.0)
    return torch.optim.lr_scheduler.LambdaLR(
        opt, lambda epoch: 0.5 * (1.0 + math.cos(math.pi * epoch / max(cfg.epochs_ae, 1)))
    )


def train_ae_critic(
    ae: AutoEncoder,
    critic: Critic | None,
    voxels: torch.Tensor,
    cfg: AETrainConfig,
    device: torch.device,
    gen: torch.Generator,
    on_epoch: EpochCallback | None = None,
) -> float:
    """Phase 2: critic on eq. (1) with Adam(lr_critic), AE on eq. (2) with Adam(lr_ae_critic).

    ``critic=None`` is the control arm: the same epochs, learning rate, batches, flips and
    warm-up with λ = 0, i.e. more reconstruction training and nothing else. Both arms draw
    the same random numbers, so with the same ``gen`` seed they see the same batches.

    Each batch: z = E(x), x̂ = D(z); partner = the reversed batch (ACAI); α = U(0, 1) folded
    to [0, 0.5]; x̂_α = D((1 − α) z + α z_partner). The first ``critic_warmup`` epochs train
    only the critic (the AE in eval mode; the control arm idles through them), so eq. (2)
    starts from a critic that has learned something. The decoder's BatchNorm layers stay in eval mode: real and
    interpolated latents are decoded with phase 1's running statistics (as every later
    decode is), and interpolated latents never enter those statistics. Both losses' forward passes run in
    ``cfg.precision`` (module docstring). Returns shapes/s.
    """
    ae.to(device)
    precision = resolve_precision(cfg.precision, device)
    opt_ae = torch.optim.Adam(ae.parameters(), lr=cfg.lr_ae_critic)
    if critic is not None:
        critic.to(device)
        opt_c = torch.optim.Adam(critic.parameters(), lr=cfg.lr_critic)
    lam = cfg.lam if critic is not None else 0.0
    seen, elapsed = 0, 0.0
    for epoch in tqdm(
        range(cfg.epochs_critic), desc="train AE-Critic" if critic is not None else "train AE, λ = 0", unit="epoch"
    ):
        train_ae = epoch >= cfg.critic_warmup
        ae.train(train_ae)  # in the warm-up the AE does not learn, its statistics included
        ae.decoder.eval()  # frozen normalization statistics (weights still learn)
        start = time.perf_counter()
        sums = {"loss_recon": 0.0} | ({"loss_reg": 0.0, "loss_critic": 0.0} if critic is not None else {})
        n = 0
        for idx in _batches(len(voxels), cfg.batch_size, gen):
            x = _as_float(voxels[idx], device)
            if cfg.flips:
                x = _flip(x, gen)
            b = len(idx)
            partner = reversed_partners(b).to(device)
            alpha = folded_alpha(b, gen).to(device)
            if critic is None and not train_ae:
                continue  # the control's warm-up: nothing learns, the same random numbers are drawn

            with torch.set_grad_enabled(train_ae), training_autocast(precision, device):
                z = ae.encoder(x)
                recon = ae.decoder(z).float()
                c_interp = None
                if critic is not None:
                    with torch.set_grad_enabled(train_ae and lam > 0):
                        x_alpha = ae.grid(ae.interpolate(z, z[partner], alpha)).float()
                        c_interp = critic(x_alpha).float()
                loss_ae, bce, reg = autoencoder_loss(recon, x, c_interp, lam, ae.cfg.output)  # eq. (2)
            if train_ae:
                opt_ae.zero_grad(set_to_none=True)
                loss_ae.backward()
                opt_ae.step()

            if critic is not None:
                with training_autocast(precision, device):
                    loss_c = critic_loss(critic, x, ae.grid(recon), x_alpha, alpha, cfg.gamma)  # eq. (1)
                opt_c.zero_grad(set_to_none=True)
                loss_c.backward()
                opt_c.step()
                sums["loss_critic"] += loss_c.item() * b
                sums["loss_reg"] += reg.item() * b
            sums["loss_recon"] += bce.item() * b
            n += b
            seen += b
        elapsed += time.perf_counter() - start
        if on_epoch:
            on_epoch(epoch, {k: v / n for k, v in sums.items()} if n else {})
    return seen / max(elapsed, 1e-9)


@torch.no_grad()
def critic_separation(
    ae: AutoEncoder,
    critic: Critic,
    voxels: torch.Tensor,
    device: torch.device,
    n_shapes: int = 200,
    batch_size: int = 64,
) -> dict[str, float]:
    """How well the critic tells held-out real grids from decoded interpolants.

    The first ``n_shapes`` of ``voxels`` (N, 1, R, R, R) (held-out shapes: the test split) are
    paired with the reversed list and interpolated at α evenly spaced over [0.1, 0.5]
    (eval mode). Returns ``auc``: ROC AUC of the critic's output with interpolants as the
    positive class (1 = perfect, 0.5 = chance); ``auc_vs_reconstructions``: the same against
    the reconstructions x̂ instead of the real grids (no binary-vs-soft cue); and the mean
    output on each kind (``real_mean``, ``reconstruction_mean``, ``interp_mean``).
    """
    from sklearn.metrics import roc_auc_score

    grids = voxels[:n_shapes]
    n = len(grids)
    if n < 2:
        return {
            "auc": float("nan"),
            "auc_vs_reconstructions": float("nan"),
            "real_mean": float("nan"),
            "reconstruction_mean": float("nan"),
            "interp_mean": float("nan"),
        }
    alpha = torch.linspace(0.1, 0.5, n)
    z = torch.as_tensor(encode(ae, grids, device))
    z_mix = (1 - alpha[:, None]) * z + alpha[:, None] * z.flip(0)
    critic.eval().to(device)

    def scores(batch_of: Callable[[slice], torch.Tensor]) -> np.ndarray:
        return torch.cat(
            [critic(batch_of(slice(i, i + batch_size)).to(device)).cpu() for i in range(0, n, batch_size)]
        ).numpy()

    real = scores(lambda s: _as_float(grids[s], device))
    recon = scores(lambda s: torch.from_numpy(decode(ae, z[s].numpy(), device))[:, None])
    interp = scores(lambda s: torch.from_numpy(decode(ae, z_mix[s].numpy(), device))[:, None])
    labels = np.r_[np.zeros(n), np.ones(n)]
    return {
        "auc": float(roc_auc_score(labels, np.r_[real, interp])),
        "auc_vs_reconstructions": float(roc_auc_score(labels, np.r_[recon, interp])),
        "real_mean": float(real.mean()),
        "reconstruction_mean": float(recon.mean()),
        "interp_mean": float(interp.mean()),
    }


def mesh_grid(mesh, resolution: int, margin: int, output: str = "occupancy", truncation: float = 3.0) -> np.ndarray:
    """One mesh (trimesh, m) as the ``voxelize`` stage grids it (a ``resolution``³ grid fitted to its bounds with
    ``margin`` empty cells): (R, R, R) occupancy bool, or with ``output`` ``sdf`` its truncated signed distance /
    ``truncation`` (voxels), float32 in [-1, 1]."""
    from graspaug.geometry.sdf import truncated_distance_grid
    from graspaug.geometry.voxelize import fit_grid, voxelize_solid

    grid = fit_grid(mesh.bounds, resolution, margin)
    if output == "sdf":
        return truncated_distance_grid(mesh.vertices, mesh.faces, grid, truncation) / np.float32(truncation)
    return voxelize_solid(mesh.vertices, mesh.faces, grid)


@torch.no_grad()
def encode_meshes(ae: AutoEncoder, meshes, resolution: int, margin: int, device: torch.device) -> np.ndarray:
    """(N, z_dim) float32 latents of N meshes (trimesh, m), each gridded as the ``voxelize`` stage does
    (:func:`mesh_grid` of the autoencoder's ``output``)."""
    cfg = ae.cfg
    grids = [mesh_grid(m, resolution, margin, cfg.output, cfg.truncation) for m in meshes]
    if not grids:
        return np.zeros((0, cfg.z_dim), np.float32)
    kind = np.float32 if cfg.output == "sdf" else np.uint8
    return encode(ae, torch.from_numpy(np.stack(grids)[:, None].astype(kind)), device)


def occupied(grids: np.ndarray, output: str = "occupancy", threshold: float = 0.5) -> np.ndarray:
    """Which voxels of grids of ``output``'s kind are inside: occupancy above ``threshold``, or a negative signed
    distance (the surface's side; ``threshold`` unused)."""
    grids = np.asarray(grids)
    return grids < 0 if output == "sdf" else grids > threshold


def reconstruction_ious(
    ae: AutoEncoder, voxels: torch.Tensor, device: torch.device, threshold: float = 0.5
) -> np.ndarray:
    """(N,) IoU(inside of decode(encode(x)), inside of x) (:func:`occupied`) of each of the (N, 1, R, R, R) grids
    ``voxels``; 1 where both are empty."""
    if len(voxels) == 0:
        return np.zeros(0)
    output = ae.cfg.output
    recon = occupied(decode(ae, encode(ae, voxels, device), device), output, threshold)
    x = occupied(voxels[:, 0].numpy(), output, threshold)
    inter = (recon & x).sum(axis=(1, 2, 3))
    union = (recon | x).sum(axis=(1, 2, 3))
    return np.where(union > 0, inter / np.maximum(union, 1), 1.0)


def reconstruction_iou(ae: AutoEncoder, voxels: torch.Tensor, device: torch.device, threshold: float = 0.5) -> float:
    """Mean over shapes of :func:`reconstruction_ious` (NaN for no shape)."""
    ious = reconstruction_ious(ae, voxels, device, threshold)
    return float(ious.mean()) if len(ious) else float("nan")


def voxel_grids(voxels_path, shapes_path, output: str = "occupancy") -> tuple[np.ndarray, np.ndarray, torch.Tensor]:
    """Every shape's ``shape_id``, ``split`` and (N, 1, R, R, R) grid of ``output``'s kind (uint8 occupancy, or
    float32 signed distance / truncation: the voxel file must hold them), in the voxel file's order."""
    from graspaug.errors import DataError
    from graspaug.io.tables import read_table
    from graspaug.io.voxels import read_voxels

    voxels = read_voxels(voxels_path)
    split = read_table(shapes_path).set_index("shape_id")["split"]
    if output == "sdf":
        if voxels.sdf is None:
            raise DataError(f"{voxels_path} holds no signed distances: run the voxelize stage with ae.net.output: sdf")
        grids = torch.from_numpy(np.ascontiguousarray(voxels.sdf[:, None], dtype=np.float32))
    else:
        grids = torch.from_numpy(voxels.occupancy[:, None].astype(np.uint8))
    return voxels.shape_id, split.reindex(voxels.shape_id).to_numpy(), grids


def grids_by_split(voxels_path, shapes_path, output: str = "occupancy") -> dict[str, torch.Tensor]:
    """(N, 1, R, R, R) grids (:func:`voxel_grids`) of the ``train`` and ``test`` splits, in the voxel file's order."""
    _, labels, grids = voxel_grids(voxels_path, shapes_path, output)
    return {name: grids[labels == name] for name in ("train", "test")}
