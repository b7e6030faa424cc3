"""Grasp Quality CNN (Dex-Net 2.0, Mahler et al. 2017): P(success | depth crop, gripper depth).

    image 1×32×32 ─ conv1_1 7×7 ─ conv1_2 5×5 ─ LRN ─ maxpool 2 ─ conv2_1 3×3 ─ conv2_2 3×3 ─ LRN
                  [─ maxpool 2 (2018 config)] ─ fc3 (1024) ─┐
    gripper depth z ─ pc1 (16) ─────────────────────────────┴─ fc4 (1024) ─ fc5 (2 logits)

With ``image_input = depth_minus_gripper`` the conv layers see the crop minus the gripper
depth (gqcnn's ``im_depth_sub``). ReLU after every layer but fc5, SAME padding, LRN over 5 channels (TF depth radius 2,
α 2e-5, β 0.75, bias 1), weights ~ N(0, 2 / fan_in). fc4 sums fc3 and pc1 through their own
weights (Dex-Net's merge). Paper widths: 64 filters, fc3 = fc4 = 1024; the CPU default is
narrower (``GQCNNConfig``). :class:`GQCNNEnsemble` averages the P(success) of several
GQ-CNNs of one config (``gqcnn.members``). Inputs are normalized by the training set's statistics, kept in
the model (``image_mean``, ``image_std``, ``z_mean``, ``z_std``) so a saved model takes raw
depths in meters.
"""

from __future__ import annotations

from dataclasses import asdict

import torch
import torch.nn.functional as F
from torch import nn

from graspaug.nets.settings import GQCNNConfig


class LocalResponseNorm(nn.Module):
    """``x / (k + alpha / size * sum of x² over the size nearest channels) ** beta``, the same
    function as ``torch.nn.LocalResponseNorm`` (a test checks it). The channel window sum is a
    1×1 convolution with a 0/1 band matrix, several times faster on the CPU than torch's
    pooling of a 5-D copy; the power is ``exp(-beta * log(.))``, twice as fast as ``pow`` with a
    fractional exponent (the base is ≥ k = 1, so the log is defined)."""

    def __init__(self, size: int, alpha: float, beta: float, k: float) -> None:
        super().__init__()
        self.size, self.alpha, self.beta, self.k = size, alpha, beta, k

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        channels = x.shape[1]
        offset = torch.arange(channels, device=x.device)
        diff = offset[None, :] - offset[:, None]  # input channel - output channel
        band = ((diff >= -(self.size // 2)) & (diff <= (self.size - 1) // 2)).to(x.dtype)
        window = F.conv2d(x * x, band.view(channels, channels, 1, 1))
        return x * torch.exp(torch.log(self.k + self.alpha / self.size * window) * -self.beta)


class GQCNN(nn.Module):
    def __init__(self, config: GQCNNConfig = GQCNNConfig()) -> None:
        super().__init__()
        self.config = config
        c = config.filters
        self.conv1_1 = nn.Conv2d(1, c, 7, padding="same")
        self.conv1_2 = nn.Conv2d(c, c, 5, padding="same")
        self.conv2_1 = nn.Conv2d(c, c, 3, padding="same")
        self.conv2_2 = nn.Conv2d(c, c, 3, padding="same")
        # torch divides alpha by the window (5), TF's tf.nn.lrn does not: 2e-5 * 5
        self.lrn = LocalResponseNorm(size=5, alpha=2e-5 * 5, beta=0.75, k=1.0)
        side = config.image_size // (4 if config.pool_after_conv2 else 2)
        self.fc3 = nn.Linear(c * side * side, config.fc)
        self.pc1 = nn.Linear(1, config.pose_fc)
        self.fc4_image = nn.Linear(config.fc, config.fc)
        self.fc4_pose = nn.Linear(config.pose_fc, config.fc, bias=False)
        self.fc5 = nn.Linear(config.fc, 2)
        for module in self.modules():
            if isinstance(module, (nn.Conv2d, nn.Linear)):
                nn.init.kaiming_normal_(module.weight, nonlinearity="relu")  # std sqrt(2 / fan_in)
                if module.bias is not None:
                    nn.init.zeros_(module.bias)
        # fc4 is one layer over [fc3, pc1] in Dex-Net: one std sqrt(2 / (fc + pose_fc)) for both parts
        for part in (self.fc4_image, self.fc4_pose):
            nn.init.normal_(part.weight, std=(2.0 / (config.fc + config.pose_fc)) ** 0.5)
        for name in ("image_mean", "image_std", "z_mean", "z_std"):
            self.register_buffer(name, torch.tensor(0.0 if name.endswith("mean") else 1.0))

    def image_input(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """What the conv layers see before normalization: depth crops (N, 1, S, S), m, or the
        crops minus the gripper depths z (N,)."""
        if self.config.image_input == "depth_minus_gripper":
            return images - z.view(-1, 1, 1, 1)
        return images

    def set_normalization(self, image_mean: float, image_std: float, z_mean: float, z_std: float) -> None:
        """Scalar statistics of the training images and gripper depths (m)."""
        for name, value in (("image_mean", image_mean), ("image_std", image_std), ("z_mean", z_mean), ("z_std", z_std)):
            getattr(self, name).fill_(float(value))

    def forward(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """Logits (N, 2) [failure, success] for depth crops (N, 1, S, S) and gripper depths (N,), meters."""
        x = (self.image_input(images, z) - self.image_mean) / self.image_std
        x = F.relu(self.conv1_1(x))
        x = self.lrn(F.relu(self.conv1_2(x)))
        x = F.max_pool2d(x, 2)
        x = F.relu(self.conv2_1(x))
        x = self.lrn(F.relu(self.conv2_2(x)))
        if self.config.pool_after_conv2:
            x = F.max_pool2d(x, 2)
        x = F.relu(self.fc3(x.flatten(1)))
        p = F.relu(self.pc1(((z - self.z_mean) / self.z_std).reshape(-1, 1)))
        x = F.relu(self.fc4_image(x) + self.fc4_pose(p))
        return self.fc5(x)

    def success_probability(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """P(success) (N,) = softmax of the logits, second class."""
        return torch.softmax(self.forward(images, z), dim=1)[:, 1]

    def describe(self) -> dict:
        return {**asdict(self.config), "parameters": sum(p.numel() for p in self.parameters())}


class GQCNNEnsemble(nn.Module):
    """K trained GQ-CNNs of one config as one model: P(success) is the mean of the members'
    (``gqcnn.members``). Same interface as :class:`GQCNN`: ``forward`` gives logits
    [log(1 − p), log p] (N, 2), whose softmax is that mean."""

    def __init__(self, members: list[GQCNN]) -> None:
        super().__init__()
        if not members or any(m.config != members[0].config for m in members):
            raise ValueError("an ensemble needs at least one member and one config for all")
        self.config = members[0].config
        self.members = nn.ModuleList(members)

    def success_probability(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """Mean P(success) (N,) of the members for crops (N, 1, S, S) and gripper depths (N,), meters."""
        return torch.stack([m.success_probability(images, z) for m in self.members]).mean(0)

    def forward(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        p = self.success_probability(images, z).clamp(1e-12, 1 - 1e-7)
        return torch.stack([torch.log1p(-p), torch.log(p)], dim=1)

    def describe(self) -> dict:
        return {
            **asdict(self.config),
            "members": len(self.members),
            "parameters": sum(p.numel() for p in self.parameters()),
        }
