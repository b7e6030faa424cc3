"""The networks of the GQ-CNN experiment, by name: a :class:`Variant` is (pool, base size B,
ratio R), and its name is its folder in its training seed's folder (plain data, no I/O).

Pools: ``targeted`` / ``random`` (interpolants), ``recon`` (the real pool's shapes decoded by the
AutoEncoder alone), ``real`` (more real train shapes) and the ``ceiling`` (every train shape
outside validation; no base size or ratio). Ratio 0 of any pool but the ceiling is the base set
alone: the ``targeted`` network (:func:`network_variant`).
"""

from __future__ import annotations

from dataclasses import dataclass

from graspaug.training.settings import POOLS


@dataclass(frozen=True, order=True)
class Variant:
    """One network of a seed: ``pool`` (one of :data:`POOLS`, or ceiling), base size, ratio."""

    pool: str
    base_size: int = 0
    ratio: float = 0.0

    @property
    def name(self) -> str:
        """``<pool>/<B>-<R>`` (R as ``%g``: ``50-0.5``, ``200-1``), or ``ceiling``: the network's folder
        in its seed's folder."""
        return "ceiling" if self.pool == "ceiling" else f"{self.pool}/{self.base_size}-{float(self.ratio):g}"


def network_variant(pool: str, base_size: int, ratio: float) -> Variant:
    """The network trained for (pool, B, R): ratio 0 of any pool but the ceiling is the targeted network."""
    return Variant("targeted" if pool != "ceiling" and float(ratio) == 0.0 else pool, base_size, ratio)


def seed_variants(base_sizes, ratios, augment_base_sizes, ceiling: bool, pools=POOLS) -> list[Variant]:
    """Every network of a seed: 1:0 at every base size; each of ``pools`` (in :data:`POOLS` order)
    at every nonzero ratio of ``augment_base_sizes``; the ceiling."""
    out = [Variant("targeted", b, 0.0) for b in base_sizes]
    out += [Variant(p, b, float(r)) for p in POOLS if p in pools for b in augment_base_sizes for r in ratios if r > 0]
    return out + ([Variant("ceiling")] if ceiling else [])
