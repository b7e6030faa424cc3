"""The ``critic_eval`` section: the paper's critic study."""

from __future__ import annotations

from graspaug.settings import Field, settings


@settings
class CriticEvalParams:
    """The paper's critic study: outliers of decoded interpolations, AE vs its λ = 0 control vs AE-Critic."""

    n_shapes: int = Field(200, ge=2, description="Random train shapes to draw pairs from (paper: 200).")
    n_pairs: int = Field(
        68, ge=1, description="Random pairs among them; 6 weights each gives 408 shapes per model (paper: ~409)."
    )
    alphas: tuple[float, ...] = Field(
        (0.0, 0.1, 0.2, 0.3, 0.4, 0.5),
        description="Interpolation weights in [0, 1], distinct in their first two decimals.",
    )
    threshold: float = Field(0.5, gt=0, le=1, description="Occupancy threshold of decoded grids.")
    n_examples: int = Field(4, ge=1, description="Interpolation sequences drawn in the picture.")
    n_bootstrap: int = Field(2000, ge=100, description="Bootstrap resamples of the pairs for the 95% intervals.")

    def __post_init__(self) -> None:
        if not self.alphas or not all(0 <= a <= 1 for a in self.alphas):
            raise ValueError(
                f"critic_eval.alphas: must be a non-empty list of weights in [0, 1]; got {list(self.alphas)}"
            )
        if len({f"{a:.2f}" for a in self.alphas}) != len(self.alphas):
            raise ValueError(
                "critic_eval.alphas: weights must differ in the first two decimals (they name the metrics); "
                f"got {list(self.alphas)}"
            )
