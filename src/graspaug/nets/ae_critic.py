"""AutoEncoder-Critic for solid voxel grids (paper Section III; ACAI, Berthelot et al. 2018).

Encoder: conv3d layers with 4³ kernels, BatchNorm + ReLU between, down to a
``top_width × 4 × 4 × 4`` map, flatten, FC → z (128). Decoder mirrors it and
outputs R³ logits. Critic: the encoder's layout *without normalization* (LeakyReLU
0.2, as ACAI's critic), then FC 128 → 1. Its output for one grid depends on that grid
only, never on the rest of the batch: a BatchNorm critic fed batches that are all real
or all interpolated normalizes the difference away.

The paper's "five conv layers, stride 2" cannot take 64³ to 4³ (five halvings
give 2³). The nearest consistent design, used here: log2(R/4) stride-2 layers
(64³ → 4³ in four) followed by one stride-1 layer with a 4³ kernel and "same"
padding, which keeps the paper's five layers, 4³ kernels and the 512×4×4×4 map
(flattened 32768 → FC 128) at R = 64. The decoder mirrors it: FC → top×4³, one
stride-1 conv, then log2(R/4) stride-2 transposed convs back to R³.

Grids: ``cfg.output`` says what a grid holds. ``occupancy``: 0/1 in, the decoder's logits out
(sigmoid: the probability); ``sdf``: the truncated signed distance divided by its truncation, in
[-1, 1] and negative inside, in and out (tanh of the decoder's output). :meth:`AutoEncoder.grid` turns
the decoder's output into a grid of the input's kind; the critic always sees such grids.

Using a trained AutoEncoder: :func:`encode` (grids → latents) and :func:`decode` (latents → grids), in batches,
eval mode, float32: what the training loop (:mod:`graspaug.training.autoencoder`), the embedding and the
generated pools (:mod:`graspaug.augment.decode`) all call.

Widths: layer i of the down path has ``min(base_width * 2**i, top_width)``
channels and the stride-1 layer ``top_width``. Paper profile (R = 64): base 64 →
64, 128, 256, 512, then 512. The CPU default (R = 32) is narrower.
"""

from __future__ import annotations

import numpy as np
import torch
import torch.nn.functional as F
from torch import nn

from graspaug.nets.settings import AEConfig


def _down(c_in: int, c_out: int, normalize: bool = True) -> list[nn.Module]:
    if not normalize:
        return [nn.Conv3d(c_in, c_out, kernel_size=4, stride=2, padding=1), nn.LeakyReLU(0.2, inplace=True)]
    return [
        nn.Conv3d(c_in, c_out, kernel_size=4, stride=2, padding=1, bias=False),
        nn.BatchNorm3d(c_out),
        nn.ReLU(inplace=True),
    ]


def _same(c_in: int, c_out: int, normalize: bool = True) -> list[nn.Module]:
    if not normalize:
        return [nn.Conv3d(c_in, c_out, kernel_size=4, stride=1, padding="same"), nn.LeakyReLU(0.2, inplace=True)]
    return [
        nn.Conv3d(c_in, c_out, kernel_size=4, stride=1, padding="same", bias=False),
        nn.BatchNorm3d(c_out),
        nn.ReLU(inplace=True),
    ]


class Encoder(nn.Module):
    """(B, 1, R, R, R) occupancy in [0, 1] → (B, z_dim) latent.

    ``normalize=False`` drops the BatchNorm layers (and uses LeakyReLU 0.2): the critic's layout.
    """

    def __init__(self, cfg: AEConfig, normalize: bool = True):
        super().__init__()
        w = cfg.widths
        layers: list[nn.Module] = []
        c = 1
        for width in w[:-1]:
            layers += _down(c, width, normalize)
            c = width
        layers += _same(c, w[-1], normalize)
        self.features = nn.Sequential(*layers)
        self.fc = nn.Linear(w[-1] * 4**3, cfg.z_dim)  # 512·4³ = 32768 → 128 at the paper's widths

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        h = self.features(x)  # (B, top, 4, 4, 4)
        return self.fc(h.flatten(1))  # (B, z_dim)


class Decoder(nn.Module):
    """(B, z_dim) latent → (B, 1, R, R, R) logits."""

    def __init__(self, cfg: AEConfig):
        super().__init__()
        w = cfg.widths
        self.top = w[-1]
        self.fc = nn.Linear(cfg.z_dim, w[-1] * 4**3)
        up_widths = w[-2::-1]  # e.g. 128 → 64 → 32 → 16 (R >= 8 gives at least one)
        layers: list[nn.Module] = [nn.BatchNorm3d(w[-1]), nn.ReLU(inplace=True)]
        layers += _same(w[-1], up_widths[0])
        c = up_widths[0]
        for i in range(cfg.n_down):
            last = i == cfg.n_down - 1
            c_out = 1 if last else up_widths[i + 1]
            layers.append(nn.ConvTranspose3d(c, c_out, kernel_size=4, stride=2, padding=1, bias=last))
            if not last:
                layers += [nn.BatchNorm3d(c_out), nn.ReLU(inplace=True)]
            c = c_out
        self.net = nn.Sequential(*layers)

    def forward(self, z: torch.Tensor) -> torch.Tensor:
        h = self.fc(z).view(-1, self.top, 4, 4, 4)  # (B, top, 4, 4, 4)
        return self.net(h)  # (B, 1, R, R, R) logits


class Critic(nn.Module):
    """(B, 1, R, R, R) voxel grid → (B,) estimated interpolation weight α.

    No normalization layer: each grid's output depends on that grid alone.
    """

    def __init__(self, cfg: AEConfig):
        super().__init__()
        self.encoder = Encoder(cfg, normalize=False)
        self.head = nn.Linear(cfg.z_dim, 1)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.head(self.encoder(x)).squeeze(1)


class AutoEncoder(nn.Module):
    """Encoder + Decoder: (B, 1, R, R, R) occupancy → (B, 1, R, R, R) logits."""

    def __init__(self, cfg: AEConfig):
        super().__init__()
        self.cfg = cfg
        self.encoder = Encoder(cfg)
        self.decoder = Decoder(cfg)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return self.decoder(self.encoder(x))

    def grid(self, out: torch.Tensor) -> torch.Tensor:
        """The decoder's raw output as a grid of the input's kind: occupancy probabilities (sigmoid) or signed
        distances / truncation in [-1, 1] (tanh)."""
        return torch.tanh(out) if self.cfg.output == "sdf" else torch.sigmoid(out)

    def interpolate(self, z_a: torch.Tensor, z_b: torch.Tensor, alpha: torch.Tensor) -> torch.Tensor:
        """Logits of the shape at ``(1 − α) z_a + α z_b``: α = 0 gives a, α = 1 gives b.

        alpha : (B,) weights in [0, 1]; the critic is trained to recover min(α, 1 − α).
        """
        alpha = alpha.view(-1, 1)
        return self.decoder((1 - alpha) * z_a + alpha * z_b)


def reversed_partners(batch_size: int) -> torch.Tensor:
    """(B,) partner index of each sample: ACAI's reversed batch, i ↔ B − 1 − i.

    With an odd B the middle sample would meet itself; it takes sample 0 instead.
    Batches are shuffled every epoch, so the pairs change from epoch to epoch.
    """
    if batch_size < 2:
        raise ValueError(f"a batch needs at least 2 samples to pair them, got {batch_size}")
    partner = torch.arange(batch_size - 1, -1, -1)
    if batch_size % 2:
        partner[batch_size // 2] = 0
    return partner


def folded_alpha(batch_size: int, gen: torch.Generator) -> torch.Tensor:
    """(B,) interpolation weights as in ACAI: U(0, 1) folded onto [0, 0.5] by α ↦ 0.5 − |α − 0.5|."""
    u = torch.rand(batch_size, generator=gen)
    return 0.5 - (u - 0.5).abs()


def critic_loss(
    critic: Critic, x: torch.Tensor, x_hat: torch.Tensor, x_alpha: torch.Tensor, alpha: torch.Tensor, gamma: float
) -> torch.Tensor:
    """Eq. (1): ‖C(x̂_α) − α‖² + ‖C(γx + (1 − γ)x̂)‖², batch means.

    x : (B, 1, R, R, R) real grids; x_hat : their reconstructions (probabilities);
    x_alpha : decoded interpolations (probabilities); alpha : (B,) their weights in [0, 0.5].
    All inputs are detached here: this loss trains the critic only. Both kinds of input go
    through the critic in one pass (it has no batch statistics, so this changes nothing).
    """
    real_mix = gamma * x + (1 - gamma) * x_hat.detach()  # (B, 1, R, R, R): a non-interpolated grid
    # float32 scores: under bfloat16 autocast the loss itself stays float32
    c_interp, c_real = critic(torch.cat([x_alpha.detach(), real_mix])).float().split(len(x))
    return (c_interp - alpha).pow(2).mean() + c_real.pow(2).mean()  # eq. (1)


SURFACE_WEIGHT = 10.0
"""With output ``sdf``: the L1 weight of a voxel whose target lies within the truncation (a distance the surface
is made of) against 1 for a clamped voxel."""


def reconstruction_loss(out: torch.Tensor, x: torch.Tensor, output: str = "occupancy") -> torch.Tensor:
    """L_B of eq. (2) for the decoder's raw output ``out`` and the target grids ``x`` (B, 1, R, R, R).

    ``occupancy``: binary cross-entropy on the logits. ``sdf``: L1 between tanh(out) and the normalized signed
    distance, voxels whose target lies within the truncation (|x| < 1) weighted :data:`SURFACE_WEIGHT`, the
    weighted mean over the batch.
    """
    if output == "occupancy":
        return F.binary_cross_entropy_with_logits(out, x)
    weight = torch.where(x.abs() < 1.0, SURFACE_WEIGHT, 1.0)
    return (weight * (torch.tanh(out) - x).abs()).sum() / weight.sum()


def autoencoder_loss(
    recon_out: torch.Tensor,
    x: torch.Tensor,
    critic_on_interp: torch.Tensor | None,
    lam: float,
    output: str = "occupancy",
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Eq. (2): L_B(x̂, x) + λ‖C(x̂_α)‖². Returns (total, reconstruction loss, regularizer).

    ``recon_out``: the decoder's raw output; L_B is :func:`reconstruction_loss` for ``output``. With λ = 0 (or no
    critic output) the total is L_B alone: the critic term sends no gradient to the autoencoder, not even a
    zero-weighted one.
    """
    bce = reconstruction_loss(recon_out, x, output)
    if critic_on_interp is None:
        return bce, bce, torch.zeros((), device=bce.device)
    reg = critic_on_interp.pow(2).mean()
    if lam == 0:
        return bce, bce, reg.detach()
    return bce + lam * reg, bce, reg


@torch.no_grad()
def encode(ae: AutoEncoder, voxels: torch.Tensor, device: torch.device, batch_size: int = 64) -> np.ndarray:
    """(N, z_dim) float32 latents of (N, 1, R, R, R) grids (eval mode)."""
    ae.eval().to(device)
    batches = (voxels[i : i + batch_size] for i in range(0, len(voxels), batch_size))
    out = [ae.encoder(x.to(device=device, dtype=torch.float32, non_blocking=True)).cpu() for x in batches]
    return torch.cat(out).numpy() if out else np.zeros((0, ae.cfg.z_dim), np.float32)


@torch.no_grad()
def decode(ae: AutoEncoder, z: np.ndarray, device: torch.device, batch_size: int = 64) -> np.ndarray:
    """(N, R, R, R) float32 grids of (N, z_dim) latents (eval mode), of the input's kind (:meth:`AutoEncoder.grid`):
    occupancy probabilities, or signed distances / truncation in [-1, 1]."""
    ae.eval().to(device)
    zt = torch.as_tensor(np.asarray(z, dtype=np.float32))
    if len(zt) == 0:
        r = ae.cfg.resolution
        return np.zeros((0, r, r, r), np.float32)
    out = [ae.grid(ae.decoder(zt[i : i + batch_size].to(device))).cpu() for i in range(0, len(zt), batch_size)]
    return torch.cat(out)[:, 0].numpy()
