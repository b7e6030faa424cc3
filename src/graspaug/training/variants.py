"""The networks of the GQ-CNN experiment, by name: a :class:`Variant` is (pool, base size B,
ratio R), and its name is its folder in its training seed's folder (plain data, no I/O).

Pools: ``targeted`` / ``random`` (interpolants), ``recon`` (the real pool's shapes decoded by the
AutoEncoder alone), ``real`` (more real train shapes) and the ``ceiling`` (every train shape
outside validation; no base size or ratio). Ratio 0 of any pool but the ceiling is the base set
alone: the ``targeted`` network (:func:`network_variant`).

Two arms add no shapes (:data:`SAMPLED_POOLS`): ``balanced`` at (B, R), the B base shapes alone with batches drawn
so that their positive share is that of targeted at (B, R); ``views`` at (B, R), the B base shapes with as many more
datapoints, from extra camera views of themselves, as targeted at (B, R) adds. A seed's networks are the matrix of
:func:`seed_variants`, or an explicit list (``gqcnn.networks``, :func:`listed_variants`).
"""

from __future__ import annotations

from dataclasses import dataclass

from graspaug.errors import DataError
from graspaug.training.settings import POOLS, check_networks


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


def pool_ratios(pool: str, ratios, control_ratios=None) -> tuple[float, ...]:
    """The nonzero ratios at which ``pool`` gets networks: every nonzero one of ``ratios`` (``generate.ratios``) for
    the targeted pool, and for the others too unless ``control_ratios`` (``gqcnn.control_ratios``) names theirs."""
    nonzero = tuple(float(r) for r in ratios if r > 0)
    if pool == "targeted" or control_ratios is None:
        return nonzero
    return tuple(r for r in nonzero if r in {float(c) for c in control_ratios})


def seed_variants(base_sizes, ratios, augment_base_sizes, ceiling: bool, pools=POOLS, control_ratios=None) -> list:
    """Every network of a seed (a list of :class:`Variant`): 1:0 at every base size; each of ``pools`` (in
    :data:`POOLS` order) at each of its :func:`pool_ratios` at ``augment_base_sizes``; the ceiling."""
    out = [Variant("targeted", b, 0.0) for b in base_sizes]
    out += [
        Variant(p, b, r)
        for p in POOLS
        if p in pools
        for b in augment_base_sizes
        for r in pool_ratios(p, ratios, control_ratios)
    ]
    return out + ([Variant("ceiling")] if ceiling else [])


def listed_variants(networks) -> list[Variant]:
    """The networks of an explicit list of (pool, B, R) (``gqcnn.networks``), in its order, ratio 0 of any pool as
    the targeted network (:func:`network_variant`)."""
    return [network_variant(str(p), int(b), float(r)) for p, b, r in networks]


def seed_networks(networks, base_sizes, ratios, augment_base_sizes, ceiling: bool, pools=POOLS, control_ratios=None):
    """Every network of a seed: those of the explicit list ``networks`` (``gqcnn.networks``, checked by
    :func:`check_networks`: a :class:`~graspaug.errors.DataError` naming the key) and the ceiling, or with an
    empty list the matrix of :func:`seed_variants`."""
    if not networks:
        return seed_variants(base_sizes, ratios, augment_base_sizes, ceiling, pools, control_ratios)
    problem = check_networks(networks, base_sizes, ratios, augment_base_sizes, pools, control_ratios)
    if problem:
        raise DataError(problem)
    return listed_variants(networks) + ([Variant("ceiling")] if ceiling else [])
