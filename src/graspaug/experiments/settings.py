"""The experiment's plain data: the pools whose networks it can train (params read them)."""

from __future__ import annotations

POOLS = ("targeted", "random", "real", "recon", "blend")
"""Pools of augmented networks, in report order: ``targeted`` / ``random`` (interpolants of the
base set's rare-and-graspable neighbours / of random pairs), ``real`` (more real train shapes, the
positive control), ``recon`` (the real pool's shapes decoded from their own latents) and ``blend``
(the targeted pool's pairs and weights interpolated with no network: mixed signed distance fields)."""

FIDELITY_POINTS = 512
"""Surface points per shape for the fidelity stage's Chamfer distances."""

FIDELITY_RESAMPLES = 1000
"""Bootstrap resamples of the fidelity stage's intervals."""

ARMS = ("failure", "random", "real")  # what each round of the lifelong loop adds, at equal counts
