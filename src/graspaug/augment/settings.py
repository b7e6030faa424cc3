"""Settings of the paper's method (:mod:`graspaug.augment`): new shapes from rare and graspable neighbours."""

from __future__ import annotations

from typing import Any

from pydantic import model_validator

from graspaug.geometry.settings import BlendSettings, DecodeSettings, PrimitiveSettings, WarpSettings
from graspaug.settings import Field, settings


def floats_written_as_floats(raw: Any, section: str, key: str) -> Any:
    """``raw`` unchanged, or a ValueError when the list at ``key`` holds an int (ratios name folders: 1.0, not 1)."""
    written = (raw or {}).get(key) or [] if isinstance(raw, dict) else []
    if any(isinstance(value, int) and not isinstance(value, bool) for value in written):
        raise ValueError(
            f"{section}.{key}: write every ratio as a float (1.0, not 1): DVC names the networks' folders after "
            f"them; got {written}"
        )
    return raw


@settings
class OwnGeneratorSettings:
    """The `own` pool's generator: an AutoEncoder-Critic trained on the base set alone (ae.net, ae.train but epochs)."""

    epochs_ae: int | None = Field(
        None,
        ge=1,
        description="Phase 1 epochs of the own AE on its B base shapes; null: as many SGD steps as the main AE's "
        "ae.train.epochs_ae took on the train split (epochs scaled by its batches per epoch over the base set's).",
    )
    epochs_critic: int | None = Field(
        None,
        ge=1,
        description="Phase 2 epochs (AE-Critic, critic warm-up scaled alike); null: as many SGD steps as the main "
        "AE-Critic's ae.train.epochs_critic took on the train split.",
    )


@settings
class GenerateSettings:
    """New shapes from rare and graspable neighbours of each base set (paper Section III-C)."""

    base_sizes: tuple[int, ...] = Field(
        (50, 200),
        description="Base set sizes drawn from the train split (paper: 50, 100, 200); smaller sets lie inside "
        "larger ones.",
    )
    ratios: tuple[float, ...] = Field(
        (0.0, 1.0),
        description="Augmentation ratios generated:base (paper: 1:0, 1:0.5, 1:1, 1:1.5, 1:2; the study and paper "
        "profiles run all five, the CPU default 1:0 and 1:1), written as floats; each pool holds max ratio × base "
        "size shapes.",
    )
    percentile: float = Field(
        75.0,
        ge=0,
        le=99,
        description="Shapes above this percentile of rarity, and separately of graspness, in the base set are "
        "paired (top 25%).",
    )
    first_neighbour: int = Field(
        2,
        ge=1,
        description="N: pair each selected shape with its N-th ... (N+K)-th nearest selected neighbours "
        "(1 = nearest; 2 avoids near-duplicates).",
    )
    extra_neighbours: int = Field(
        3, ge=0, description="K: see first_neighbour. Widened (logged) if a pool runs dry, see alphas."
    )
    alphas: tuple[float, ...] = Field(
        (0.5, 0.3),
        description="Interpolation weights in (0, 0.5]. If a pool runs dry, 0.4, 0.2, 0.1, 0.05 are added, then K "
        "widens, then the percentile drops by 5s (each step logged).",
    )
    n_examples: int = Field(6, ge=1, description="Parent pairs drawn with their child in the picture.")
    decode: DecodeSettings = Field(default_factory=DecodeSettings, description="Decoded grid → mesh.")
    blend: BlendSettings = Field(
        default_factory=BlendSettings,
        description="The blend pool (gqcnn.pools): the targeted pool's pairs interpolated with no network.",
    )
    warp: WarpSettings = Field(
        default_factory=WarpSettings,
        description="The warp pool (gqcnn.pools): each of the targeted pool's pairs becomes a random smooth "
        "deformation of its nearer parent, sized by the ingest rule.",
    )
    primitives: PrimitiveSettings = Field(
        default_factory=PrimitiveSettings,
        description="The primitives pool (gqcnn.pools): random assemblies of 1 to max_parts (5) primitives, no real "
        "parent, sized by the ingest rule.",
    )
    own: OwnGeneratorSettings = Field(
        default_factory=OwnGeneratorSettings,
        description="The own pool (gqcnn.pools): the targeted recipe with an AutoEncoder-Critic trained on the base "
        "set alone (stage train_ae_own), so no geometry beyond the base set enters.",
    )

    @model_validator(mode="before")
    @classmethod
    def _ratios_are_floats(cls, raw: Any) -> Any:
        return floats_written_as_floats(raw, "generate", "ratios")

    def __post_init__(self) -> None:
        if (
            not self.base_sizes
            or any(b < 2 for b in self.base_sizes)
            or len(set(self.base_sizes)) != len(self.base_sizes)
        ):
            raise ValueError(f"generate.base_sizes: must be distinct sizes >= 2; got {list(self.base_sizes)}")
        if not self.ratios or any(r < 0 for r in self.ratios) or max(self.ratios) <= 0:
            raise ValueError(f"generate.ratios: must be ratios >= 0, the largest > 0; got {list(self.ratios)}")
        if not self.alphas or not all(0 < a <= 0.5 for a in self.alphas) or len(set(self.alphas)) != len(self.alphas):
            raise ValueError(f"generate.alphas: must be distinct weights in (0, 0.5]; got {list(self.alphas)}")
