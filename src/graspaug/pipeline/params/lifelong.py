"""The ``lifelong`` section: the loop that generates from the planner's failures, round after round."""

from __future__ import annotations

import re

from graspaug.settings import Field, settings


@settings
class LifelongParams:
    """The lifelong loop: each round scores every validation object by the last round's failure-arm networks, takes
    the worst, generates new shapes from the base shapes nearest to them in latent space, renders their grasps and
    trains the next networks on the union of every round's shapes.

    Three arms add the same number of shapes per round, paired within a training seed: `failure` (parents near the
    worst validation objects), `random` (random pairs of the base set, the same α schedule) and `real` (as many more
    real train shapes, the positive control). Round 0 is the base set alone (the `targeted` B-0 networks of
    `train_gqcnn`). The test split never chooses anything.
    """

    base_size: int = Field(
        50,
        ge=2,
        description="Base size B the loop starts from (one of generate.base_sizes): its 1:0 networks are "
        "round 0 and its base shapes are every generated shape's parents.",
    )
    shapes_per_round: int = Field(
        25, ge=1, description="Shapes each arm adds per round (round r trains on B + r × this many shapes)."
    )
    worst: int = Field(
        10, ge=1, description="Validation objects with the highest mean log loss that anchor the next round."
    )
    per_failure: int = Field(3, ge=1, description="Base shapes anchored near each of those objects (latent space).")
    n_bootstrap: int = Field(2000, ge=100, description="Bootstrap resamples of the test objects and seeds.")
    rounds: dict[str, str] = Field(
        default_factory=dict,
        description="Rounds to run, each round `r<k>` naming the round it follows, `r<k-1>` (DVC needs the previous "
        "round spelled out to link the stages): {} runs round 0 only; `dvc exp run -S '++lifelong.rounds={r1: r0, "
        "r2: r1}'` runs two (the `lifelong` profile).",
    )

    def __post_init__(self) -> None:
        for key, after in self.rounds.items():
            match = re.fullmatch(r"r([1-9][0-9]*)", str(key))
            if match is None or after != f"r{int(match.group(1)) - 1}":
                raise ValueError(f"lifelong.rounds: each entry is r<k>: r<k-1> (k >= 1); got {key}: {after}")
        numbers = sorted(int(k[1:]) for k in self.rounds)
        if numbers != list(range(1, len(numbers) + 1)):
            raise ValueError(f"lifelong.rounds: rounds r1 … r<K> with none missing; got {sorted(self.rounds)}")

    def round_numbers(self) -> list[int]:
        """The rounds to run after round 0, in order."""
        return sorted(int(k[1:]) for k in self.rounds)
