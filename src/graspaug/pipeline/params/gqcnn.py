"""The ``gqcnn`` section: the GQ-CNN networks of the experiment, their training and the design."""

from __future__ import annotations

from graspaug.nets.settings import GQCNNConfig
from graspaug.settings import Field, settings
from graspaug.training.settings import POOLS, TrainSettings


@settings
class GQCNNParams:
    """GQ-CNN networks per base size × augmentation ratio (paper Section IV-C), their training and the experiment's
    design.

    Per training seed: a 1:0 network (the base set alone) at every base size of `generate`;
    `targeted`, `random` (random-pair interpolants) and `real` (more real train shapes, the
    positive control for augmentation) at every nonzero ratio of `augment_base_sizes`; the
    `ceiling` (every train shape outside validation). Every network of a seed starts from the same weights and noise
    stream; all are validated on the same `val_shapes` train shapes that no network trains on.
    """

    net: GQCNNConfig = Field(default_factory=GQCNNConfig, description="Layer sizes.")
    train: TrainSettings = Field(
        default_factory=TrainSettings, description="SGD schedule, checkpoint choice and train-time noise."
    )
    val_shapes: int = Field(
        100,
        ge=1,
        description="Train-split shapes outside every base set held out for validation (checkpoints and the best "
        "ratio are chosen on them), the same for every network and seed.",
    )
    seeds: tuple[int, ...] = Field(
        (0, 1, 2, 3),
        description="Training seeds, the replicates of the paired design; intervals need at least 2 (the 95% "
        "t-interval is 3.18 standard errors wide on each side with 4 seeds, 2.78 with 5, 4.30 with 3).",
    )
    augment_base_sizes: tuple[int, ...] = Field(
        (50,),
        description="Base sizes that get augmented networks: targeted, random and real at every nonzero ratio of "
        "generate.ratios (the others get their 1:0 network only; study profile: all).",
    )
    ceiling: bool = Field(
        False,
        description="Also train one network per seed on every train shape outside validation (how much of the gap "
        "augmentation closes; study and paper profiles: on).",
    )
    pools: tuple[str, ...] = Field(
        ("targeted", "random", "real", "recon"),
        description="Pools that get augmented networks at every nonzero ratio of augment_base_sizes: `targeted` "
        "(interpolants of rare and graspable neighbours), `random` (interpolants of random pairs), `real` (more real "
        "train shapes, the positive control), `recon` (the real pool's shapes passed through the AutoEncoder alone: "
        "what decoding and meshing cost), `blend` (the targeted pool's pairs and weights interpolated with no "
        "network, by mixing the parents' signed distance fields), `warp` (each targeted pair's nearer parent under a "
        "random smooth deformation: scale, shear, taper, bend), `primitives` (random assemblies of 1 to "
        "generate.primitives.max_parts boxes, cylinders, spheres, capsules and rings), `procedural` (pybullet's "
        "random_urdfs objects as they are, beside a corpus of your own: what procedural objects give for free), "
        "`own` (the targeted recipe decoded by an AutoEncoder-Critic trained on the base set alone, stage "
        "train_ae_own: the augmentation without the other train shapes' geometry); "
        "`generate` makes the generated "
        "ones. `targeted` is always trained.",
    )
    control_ratios: tuple[float, ...] | None = Field(
        None,
        description="Ratios at which the pools other than targeted get networks and shapes (each one of "
        "generate.ratios); null: every nonzero ratio, as targeted. The real-objects profile: [1.0] (the paper's ratios "
        "for targeted, the controls at 1:1); contrasts between two pools use the ratios both have.",
    )
    networks: tuple[tuple[str, int, float], ...] = Field(
        (),
        description="An explicit list of the networks each seed trains, each [pool, B, R], in place of the matrix of "
        "generate.base_sizes x generate.ratios x pools (empty: the matrix; the ceiling still follows `ceiling`). "
        "[targeted, B, 0.0] is the base set alone (none@B); a pool of `pools` at R > 0 needs B among "
        "augment_base_sizes and R among the ratios generate makes for it; `balanced` (the B base shapes alone, "
        "batches drawn at the positive share of targeted at (B, R)) and `views` (the B base shapes plus as many "
        "datapoints from `extra_views` more camera views of themselves as targeted at (B, R) adds) need targeted "
        "at (B, R). The why profile: exactly its plan's arms.",
    )
    extra_views: int = Field(
        0,
        ge=0,
        description="Extra camera views per stable pose of every original shape, rendered with new view seeds by "
        "the render_views stage (data/gqcnn/views, shared by every draw) for the `views` networks (0: none, the "
        "stage writes an empty corpus).",
    )
    members: int = Field(
        1,
        ge=1,
        le=64,
        description="GQ-CNNs trained per network, each from its own initial weights and noise stream (member m of "
        "every network of a seed shares them, so the design stays paired; member 0 is the seed's own network); with "
        "more than one the network's P(success) is their mean (an ensemble, validated, tested and planned with). "
        "More members narrow the seed-to-seed spread of the contrasts; each costs one more network's training time "
        "(the default: 1, to fit make repro's 30 minutes; 2 was the default until 2026-11-28).",
    )

    def __post_init__(self) -> None:
        unknown = sorted(set(self.pools) - set(POOLS))
        if unknown or "targeted" not in self.pools or len(set(self.pools)) != len(self.pools):
            raise ValueError(
                f"gqcnn.pools: distinct names of {list(POOLS)}, targeted among them; got {list(self.pools)}"
            )
        if self.control_ratios is not None and (not self.control_ratios or min(self.control_ratios) <= 0):
            raise ValueError(f"gqcnn.control_ratios: null or ratios > 0; got {list(self.control_ratios)}")
        if not self.seeds or len(set(self.seeds)) != len(self.seeds) or min(self.seeds) < 0:
            raise ValueError(f"gqcnn.seeds: must be distinct seeds >= 0; got {list(self.seeds)}")
