"""The experiment's plain data: the pools whose networks it can train (params read them)."""

from __future__ import annotations

FIDELITY_POINTS = 512
"""Surface points per shape for the fidelity stage's Chamfer distances."""

FIDELITY_RESAMPLES = 1000
"""Bootstrap resamples of the fidelity stage's intervals."""

ARMS = ("failure", "random", "real")  # what each round of the lifelong loop adds, at equal counts
