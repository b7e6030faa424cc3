"""Training settings of the AutoEncoder-Critic and the GQ-CNN."""

from __future__ import annotations

import math
from typing import Literal

from graspaug.settings import Field, settings


@settings
class AETrainConfig:
    """The two training phases (params section ``ae.train``)."""

    batch_size: int = Field(16, ge=2, description="Shapes per batch.")
    epochs_ae: int = Field(
        90, ge=0, description="Phase 1 epochs: the plain AutoEncoder and its reconstruction loss (`ae.net.output`)."
    )
    epochs_critic: int = Field(
        6, ge=0, description="Phase 2 epochs: AE-Critic initialised from phase 1, warm-up included."
    )
    critic_warmup: int = Field(
        2,
        ge=0,
        description=(
            "First phase-2 epochs in which only the critic learns "
            "(the AE's eq. (2) term then starts from a trained critic)."
        ),
    )
    lr_ae: float = Field(1e-3, gt=0, description="Phase 1 Adam learning rate (paper: 1e-3).")
    lr_schedule: Literal["constant", "cosine"] = Field(
        "constant",
        description=(
            "Phase 1 learning rate over the epochs: `constant` (lr_ae throughout, the paper's) or `cosine` "
            "(lr_ae · ½(1 + cos(π e / epochs_ae)) in epoch e, from lr_ae down towards 0)."
        ),
    )
    lr_ae_critic: float = Field(1e-4, gt=0, description="Phase 2 Adam learning rate of the AutoEncoder (paper: 1e-4).")
    lr_critic: float = Field(1e-3, gt=0, description="Phase 2 Adam learning rate of the Critic (paper: 1e-3).")
    gamma: float = Field(
        0.2,
        ge=0,
        le=1,
        description="γ of eq. (1): the critic sees γx + (1−γ)x̂ as non-interpolated (ACAI: 0.2).",
    )
    lam: float = Field(
        0.5, ge=0, alias="lambda", description="λ of eq. (2): weight of the critic term in the AE loss (ACAI: 0.5)."
    )
    flips: bool = Field(True, description="Flip training grids along random axes (the AE learns shape, not pose).")
    precision: Literal["auto", "float32", "bfloat16"] = Field(
        "auto",
        description=(
            "Arithmetic of both phases' training steps (forward pass and loss): auto (the default: bfloat16 where "
            "the device computes it natively, float32 elsewhere), float32, or bfloat16 mixed precision "
            "(torch.autocast; weights, optimizer, evaluation, embedding and decoding stay float32). The stage logs "
            "what it resolved to; the checkpoints' train_params record it."
        ),
    )


@settings
class NoiseSettings:
    """Dex-Net 2.0's train-time image noise.

    Each image and its gripper depth are multiplied by a Gamma(``gamma_shape``, 1 / ``gamma_shape``) draw
    (mean 1); with probability ``gp_prob`` it also gets a smooth Gaussian-process field: N(0,
    ``gp_sigma``) m on a ``gp_grid`` × ``gp_grid`` grid, upsampled (bicubic) to the image.
    With ``symmetrize``, each image is turned 180° and flipped about either axis with
    probability 0.5 each (a parallel-jaw grasp looks the same).
    """

    gamma_shape: float = Field(
        1000.0,
        ge=0,
        description=(
            "Multiplicative noise ~ Gamma(k, 1/k) per image (Dex-Net: k = 1000; 0: off); unlike Dex-Net it scales "
            "the gripper depth too, so the object's height relative to the gripper keeps its meaning."
        ),
    )
    gp_prob: float = Field(
        0.5, ge=0, le=1, description="Chance of adding smooth Gaussian-process noise to an image (Dex-Net: 0.5)."
    )
    gp_sigma: float = Field(0.005, ge=0, description="Its standard deviation (m) (Dex-Net: 0.005).")
    gp_grid: int = Field(8, ge=1, description="Its grid side before upsampling to the image (Dex-Net: 8 for 32 px).")
    symmetrize: bool = Field(True, description="Turn images 180° and flip them about either axis at random (Dex-Net).")


@settings
class TrainSettings:
    """SGD with momentum and L2 weight decay, the learning rate annealed from ``lr`` to
    ``lr × final_lr`` along a cosine, for ``epochs`` passes over the network's own training set
    (at least ``min_steps``, at most ``max_steps`` steps); the checkpoint with the best
    validation AP of ``evals`` evenly spaced evaluations is kept (params section ``gqcnn.train``)."""

    epochs: float = Field(
        8.0,
        gt=0,
        description=(
            "Passes over the network's own training set (the budget rule: every variant sees each of its "
            "datapoints about as often, so a larger set gets more steps)."
        ),
    )
    min_steps: int = Field(500, ge=1, description="Fewest SGD steps, for the smallest training sets.")
    max_steps: int = Field(
        1000, ge=1, description="Most SGD steps, a cap for the largest training sets (the CPU budget)."
    )
    batch_size: int = Field(128, ge=2, description="Datapoints per step (Dex-Net: 64-128).")
    lr: float = Field(0.02, gt=0, description="SGD learning rate at the start (Dex-Net: 0.01 at batch 64).")
    final_lr: float = Field(
        0.01, gt=0, le=1, description="Learning rate at the last step, as a share of lr (cosine annealing)."
    )
    momentum: float = Field(0.9, ge=0, le=1, description="SGD momentum (Dex-Net: 0.9).")
    weight_decay: float = Field(5e-4, ge=0, description="L2 weight decay (Dex-Net: 5e-4).")
    ema_decay: float = Field(
        0.0,
        ge=0,
        lt=1,
        description=(
            "Decay of an exponential moving average of the weights (Polyak averaging), updated after every step; "
            "validation, the kept checkpoint and the test use the averaged weights (0: off, the raw weights)."
        ),
    )
    precision: Literal["auto", "float32", "bfloat16"] = Field(
        "auto",
        description=(
            "Arithmetic of the training steps' convolutions and matrix products: auto (the default: bfloat16 on a "
            "CPU that computes it natively, AVX512-BF16 or AMX; float32 elsewhere, and on a GPU, where bfloat16 was "
            "measured slower for this network), float32, or bfloat16 mixed precision (torch.autocast; weights, "
            "optimizer, loss, validation and test stay float32). The stage logs what it resolved to; the card "
            "records it."
        ),
    )
    evals: int = Field(
        5,
        ge=1,
        description=(
            "Validation evaluations per network, evenly spaced over its steps (the last at the last step); "
            "the weights with the best validation AP are kept."
        ),
    )
    eval_batch: int = Field(256, ge=1, description="Datapoints per inference batch.")
    noise: NoiseSettings = Field(default_factory=NoiseSettings, description="Dex-Net 2.0's train-time image noise.")

    def __post_init__(self) -> None:
        if self.min_steps > self.max_steps:
            raise ValueError(f"min_steps ({self.min_steps}) must not exceed max_steps ({self.max_steps})")

    def steps_for(self, n_datapoints: int) -> int:
        """SGD steps for a training set of ``n_datapoints``: ``epochs`` passes, clipped to [min_steps, max_steps]."""
        return int(min(self.max_steps, max(self.min_steps, -(-self.epochs * n_datapoints // self.batch_size))))


POOLS = ("targeted", "random", "real", "recon", "blend", "warp", "primitives", "procedural", "own")
"""Pools of augmented networks, in report order: ``targeted`` / ``random`` (interpolants of the
base set's rare-and-graspable neighbours / of random pairs), ``real`` (more real train shapes, the
positive control), ``recon`` (the real pool's shapes decoded from their own latents), ``blend``
(the targeted pool's pairs and weights interpolated with no network: mixed signed distance fields),
``warp`` (each targeted pair's nearer parent under a random smooth deformation: the handcrafted
augmentation), ``primitives`` (random assemblies of primitives: procedural objects, no real parent) and
``procedural`` (objects of pybullet's procedural ``random_urdfs`` corpus added as they are: what a researcher whose own
corpus is real objects gets for free) and ``own`` (the targeted recipe decoded by an AutoEncoder-Critic trained on the
base set alone: the augmentation without the train split's other shapes)."""

SAMPLED_POOLS = ("balanced", "views")
"""Arms of the base shapes alone that mirror targeted at their (B, R): ``balanced`` (batches drawn at targeted's
positive share) and ``views`` (as many more datapoints as targeted adds, from extra views of the base shapes)."""


def check_networks(networks, base_sizes, ratios, augment_base_sizes, pools, control_ratios=None) -> str | None:
    """Why the explicit list ``networks`` (``gqcnn.networks``) cannot be trained with these ``generate`` and ``gqcnn``
    settings (one line naming the key), or None: a 1:0 network needs its B among generate.base_sizes; a pool of
    :data:`POOLS` at R > 0 needs to be among gqcnn.pools, B among gqcnn.augment_base_sizes and R among the
    ratios it is generated at (every nonzero one of ``ratios`` for targeted, ``control_ratios`` for the others where
    given: :func:`graspaug.training.variants.pool_ratios`); ``balanced`` and ``views`` need targeted at their (B, R)
    generated the same way."""
    seen = set()
    for entry in networks:
        pool, b, r = str(entry[0]), int(entry[1]), float(entry[2])
        where = f"gqcnn.networks: [{pool}, {b}, {r:g}]"
        if pool not in POOLS + SAMPLED_POOLS:
            return f"{where}: unknown pool; known: {', '.join(POOLS + SAMPLED_POOLS)}"
        v = ("targeted" if r == 0 else pool, b, r)  # ratio 0 of any pool is the targeted network
        if v in seen:
            return f"{where}: listed twice (ratio 0 of any pool is the targeted network)"
        seen.add(v)
        if r == 0:
            if b not in base_sizes:
                return f"{where}: base size {b} is not among generate.base_sizes {list(base_sizes)}"
            continue
        if b not in augment_base_sizes:
            return f"{where}: base size {b} is not among gqcnn.augment_base_sizes {list(augment_base_sizes)}"
        mirrored = "targeted" if pool in SAMPLED_POOLS else pool
        if mirrored not in pools:
            return f"{where}: pool {mirrored} is not among gqcnn.pools {list(pools)} (generate makes no such shapes)"
        made = ratios if mirrored == "targeted" or control_ratios is None else control_ratios
        if r not in {float(x) for x in made if x > 0}:
            return f"{where}: ratio {r:g} is not among the ratios generate makes for {mirrored} {list(ratios)}"
        if math.floor(r * b + 0.5) < 1:  # graspaug.augment.candidates.ratio_count
            return f"{where}: ratio {r:g} of {b} base shapes adds no shape"
    return None


def networks_at(networks, base_size: int) -> dict[str, set[float]] | None:
    """The generated pools an explicit ``gqcnn.networks`` list trains on at ``base_size``, each with the ratios it is
    trained at (``balanced`` and ``views`` at (B, R) need targeted's shapes at (B, R)); None without a list (then
    every pool of ``gqcnn.pools`` at every augmented base size), so ``generate`` and ``train_ae_own`` make only the
    shapes some network trains on."""
    if not networks:
        return None
    out: dict[str, set[float]] = {}
    for pool, b, r in networks:
        if int(b) == int(base_size) and float(r) > 0:
            out.setdefault("targeted" if pool in SAMPLED_POOLS else str(pool), set()).add(float(r))
    return out


def listed_pools(cfg, pools, networks, base_size: int) -> tuple:
    """``generate``'s settings ``cfg`` and its ``pools`` at ``base_size`` cut to what ``gqcnn.networks`` trains on there
    (:func:`networks_at`: the pools, and targeted's ratios); unchanged without a list."""
    import dataclasses

    wanted = networks_at(networks, base_size)
    if wanted is None:
        return cfg, list(pools)
    if wanted.get("targeted"):
        cfg = dataclasses.replace(cfg, ratios=tuple(sorted({0.0, *wanted["targeted"]})))
    return cfg, [p for p in pools if p in wanted]
