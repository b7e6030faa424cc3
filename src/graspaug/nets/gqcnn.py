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

    def forward(self, x: torch.Tensor, groups: int = 1) -> torch.Tensor:
        """``x`` (N, G·C, H, W): the norm over the C channels of each of ``groups`` groups apart
        (the members of a :class:`GQCNNStack`)."""
        channels = x.shape[1] // groups
        offset = torch.arange(channels, device=x.device)
        diff = offset[None, :] - offset[:, None]  # input channel - output channel
        band = ((diff >= -(self.size // 2)) & (diff <= (self.size - 1) // 2)).to(x.dtype)
        window = F.conv2d(x * x, band.repeat(groups, 1).view(groups * channels, channels, 1, 1), groups=groups)
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


_CONVS = ("conv1_1", "conv1_2", "conv2_1", "conv2_2")
_LINEARS = ("fc3", "pc1", "fc4_image", "fc5")  # and fc4_pose, which has no bias
_NORMALIZATION = ("image_mean", "image_std", "z_mean", "z_std")


class GQCNNStack(nn.Module):
    """K GQ-CNNs of one config as one model, to train them at once: member k takes its own
    batch, crops (K, N, 1, S, S) and gripper depths (K, N), m → logits (K, N, 2), and computes
    what its :class:`GQCNN` computes (a test checks it). Every parameter is stacked along the
    members: a conv layer's filters are one grouped convolution (member k's are output channels
    k·C … (k+1)·C − 1), a fully connected layer's weights (K, in, out) one batched matrix
    product. One member is its own GQCNN, unstacked. :meth:`member_state` gives a member's weights
    back as a GQCNN state dict."""

    def __init__(self, members: list[GQCNN]) -> None:
        super().__init__()
        if not members or any(m.config != members[0].config for m in members):
            raise ValueError("a stack needs at least one member and one config for all")
        self.k, self.config, self.lrn = len(members), members[0].config, members[0].lrn
        if self.k == 1:
            self.single = members[0]
            return
        stack = lambda tensors: nn.Parameter(torch.stack([t.detach() for t in tensors]))  # noqa: E731
        for name in _CONVS:
            layers = [getattr(m, name) for m in members]
            self.register_parameter(f"{name}_weight", nn.Parameter(torch.cat([c.weight.detach() for c in layers])))
            self.register_parameter(f"{name}_bias", nn.Parameter(torch.cat([c.bias.detach() for c in layers])))
        for name in _LINEARS:
            layers = [getattr(m, name) for m in members]
            self.register_parameter(f"{name}_weight", stack(c.weight.t() for c in layers))
            self.register_parameter(f"{name}_bias", stack(c.bias.unsqueeze(0) for c in layers))
        self.fc4_pose_weight = stack(m.fc4_pose.weight.t() for m in members)
        for name in _NORMALIZATION:
            self.register_buffer(name, torch.stack([getattr(m, name) for m in members]).clone())

    def conv(self, x: torch.Tensor, name: str) -> torch.Tensor:
        """ReLU of conv layer ``name`` of every member: (N, K·C_in, H, W) → (N, K·C, H, W)."""
        weight, bias = getattr(self, f"{name}_weight"), getattr(self, f"{name}_bias")
        return F.relu(F.conv2d(x, weight, bias, padding="same", groups=self.k))

    def forward(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        """Logits (K, N, 2) for crops (K, N, 1, S, S) and gripper depths (K, N), meters."""
        if self.k == 1:
            return self.single(images[0], z[0]).unsqueeze(0)
        k, n = z.shape
        x = (
            images[:, :, 0] - z[..., None, None]
            if self.config.image_input == "depth_minus_gripper"
            else images[:, :, 0]
        )
        x = (x - self.image_mean.view(k, 1, 1, 1)) / self.image_std.view(k, 1, 1, 1)
        x = x.transpose(0, 1).contiguous(memory_format=torch.channels_last)  # (N, K, S, S): member k is channel k
        x = self.lrn(self.conv(self.conv(x, "conv1_1"), "conv1_2"), groups=k)
        x = F.max_pool2d(x, 2)
        x = self.lrn(self.conv(self.conv(x, "conv2_1"), "conv2_2"), groups=k)
        if self.config.pool_after_conv2:
            x = F.max_pool2d(x, 2)
        x = x.reshape(n, k, -1).transpose(0, 1)  # (K, N, C·h·w), each member's features in (C, h, w) order
        x = F.relu(torch.baddbmm(self.fc3_bias, x, self.fc3_weight))
        p = ((z - self.z_mean.view(k, 1)) / self.z_std.view(k, 1)).unsqueeze(-1)
        p = F.relu(torch.baddbmm(self.pc1_bias, p, self.pc1_weight))
        x = F.relu(torch.baddbmm(self.fc4_image_bias, x, self.fc4_image_weight) + torch.bmm(p, self.fc4_pose_weight))
        return torch.baddbmm(self.fc5_bias, x, self.fc5_weight)

    def member_state(self, k: int) -> dict[str, torch.Tensor]:
        """Member ``k``'s weights and normalization as a :class:`GQCNN` state dict (copies)."""
        if self.k == 1:
            return {name: t.detach().clone() for name, t in self.single.state_dict().items()}
        c = self.config.filters
        state = {}
        for name in _CONVS:
            state[f"{name}.weight"] = getattr(self, f"{name}_weight")[k * c : (k + 1) * c]
            state[f"{name}.bias"] = getattr(self, f"{name}_bias")[k * c : (k + 1) * c]
        for name in _LINEARS:
            state[f"{name}.weight"] = getattr(self, f"{name}_weight")[k].t()
            state[f"{name}.bias"] = getattr(self, f"{name}_bias")[k, 0]
        state["fc4_pose.weight"] = self.fc4_pose_weight[k].t()
        state.update({name: getattr(self, name)[k] for name in _NORMALIZATION})
        return {name: t.detach().clone().contiguous() for name, t in state.items()}


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
