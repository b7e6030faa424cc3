"""The ``generate`` stage's work on one base set: its inputs (:class:`BaseSet`), its pools (targeted, random and the
controls) filled by the batch runners of :mod:`graspaug.augment.decode`, and their tables, metrics and picture data.

Base sets, candidate streams and pool rules, which the GQ-CNN experiment imports too, are
:mod:`graspaug.augment.candidates`; the shapes made near a planner's failures (the ``from-failures`` stream, the
lifelong loop's rounds) are :mod:`graspaug.augment.failures`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from graspaug.augment.candidates import (
    BASE_SEED,
    Candidate,
    Decoded,
    FollowStream,
    PoolExhausted,
    PrimitiveStream,
    ProceduralStream,
    RandomStream,
    ReconStream,
    TargetedStream,
    decode_each,
    draw_base_sets,
    fill_pool,
    pool_size,
)
from graspaug.augment.embedding import tsne_2d
from graspaug.augment.pool_tables import base_scores_table, pool_summary, pool_tables
from graspaug.augment.scores import rarity
from graspaug.augment.settings import GenerateSettings
from graspaug.errors import DataError

LOW_YIELD = 0.95  # a pool keeping a smaller share of its decodes is warned about
REJECT_COLUMNS = ["pool", "parent_a", "parent_b", "alpha", "selected_by", "reason"]


def base_ids(shapes: pd.DataFrame, base_sizes: Sequence[int], base_size: int, seed: int) -> np.ndarray:
    """The (``base_size``,) shape ids of the base set of ``base_size``, one of ``base_sizes``
    (``generate.base_sizes``), drawn from the train split of ``shapes`` (the ingested shape table)
    by :func:`graspaug.augment.candidates.draw_base_sets` with the global ``seed``; a
    :class:`graspaug.errors.DataError` if the size is not listed or the train split is too small."""
    if base_size not in base_sizes:
        raise DataError(f"base size {base_size} is not in generate.base_sizes {list(base_sizes)}")
    n_train = int((shapes.split == "train").sum())
    if n_train < max(base_sizes):
        raise DataError(f"generate.base_sizes: {max(base_sizes)} is larger than the {n_train} train shapes")
    return draw_base_sets(shapes, base_sizes, seed)[base_size]


@dataclass(frozen=True)
class BaseSet:
    """One base set's inputs to generation, B shapes in base-set order.

    ids : (B,) str — shape ids
    z : (B, d) float32 — AE-Critic latents
    rarity : (B,) float — rarity R, eq. (4), relative to this base set
    graspness : (B,) float — share of successful grasps
    pitch : (B,) float — voxel pitch, m (the shape's metric scale)
    """

    ids: np.ndarray
    z: np.ndarray
    rarity: np.ndarray
    graspness: np.ndarray
    pitch: np.ndarray


def base_set(ids: np.ndarray, latents: pd.DataFrame, scores: pd.DataFrame, voxels, k: int) -> BaseSet:
    """The :class:`BaseSet` of shapes ``ids`` (B,) from the latents table (``shape_id``, ``z``),
    the scores table (``shape_id``, ``graspness``), the corpus' ``voxels`` (VoxelSet: ``shape_id``,
    ``pitch`` in m) and the rarity's ``k`` neighbours."""
    latent = latents.set_index("shape_id").z
    graspness = scores.set_index("shape_id").graspness
    pitch_of = dict(zip(voxels.shape_id, voxels.pitch))
    z = np.stack(latent.loc[ids].to_numpy()).astype(np.float32)
    base_rarity = rarity(z, k)  # relative to this base set
    return BaseSet(ids, z, base_rarity, graspness.loc[ids].to_numpy(), np.array([pitch_of[s] for s in ids]))


Pools = dict[str, tuple[list[Decoded], list[Decoded]]]
# what generate makes, in index order
GENERATED_POOLS = ("targeted", "random", "recon", "blend", "warp", "primitives", "procedural", "own")
FOLLOWERS = ("blend", "warp")  # the controls that follow the targeted pool's candidates (its parents and weights)
PRIMITIVE_TRIES = 20  # the primitives stream holds this many assemblies per shape needed
Runner = Callable[[list[Candidate]], list[Decoded]]


@dataclass(frozen=True)
class ReconSource:
    """What the ``recon`` pool reconstructs: ``shapes``, the real pool's shapes in its order (a
    :class:`BaseSet`: ids, latents, pitches), and ``run_batch``, :func:`.decode.mesh_batches` over them."""

    shapes: BaseSet
    run_batch: Callable[[list[Candidate]], list[Decoded]]


@dataclass(frozen=True)
class OwnSource:
    """What the ``own`` pool is made from: ``shapes``, the base set as its own AutoEncoder-Critic (trained on the base
    set alone) sees it (a :class:`BaseSet`: the same ids, graspness and pitches; that AE's latents and the rarity
    among them), and ``run_batch``, :func:`.decode.mesh_batches` over them with that AE."""

    shapes: BaseSet
    run_batch: Callable[[list[Candidate]], list[Decoded]]


def targeted_stream(shapes: BaseSet, cfg: GenerateSettings) -> TargetedStream:
    """The targeted recipe's candidates on ``shapes``: its rare, and separately graspable, shapes paired with their
    N-th … (N+K)-th latent neighbours at ``cfg.alphas`` (widened as :class:`TargetedStream` says)."""
    return TargetedStream(
        shapes.z, shapes.rarity, shapes.graspness, cfg.percentile, cfg.first_neighbour, cfg.extra_neighbours, cfg.alphas
    )


def fill_pools(
    base: BaseSet,
    cfg: GenerateSettings,
    seed: int,
    run_batch: Runner,
    pools: Sequence[str] = ("targeted", "random"),
    recon: ReconSource | None = None,
    controls: dict[str, Runner] | None = None,
    procedural: int = 0,
    control_ratios: Sequence[float] | None = None,
    own: OwnSource | None = None,
) -> tuple[Pools, TargetedStream, int, TargetedStream | None]:
    """Fill each of ``pools`` (of :data:`GENERATED_POOLS`; the targeted one always) to
    ``pool_size(cfg.ratios, B)`` kept shapes (the pools but targeted: ``pool_size(control_ratios, B)`` when
    ``control_ratios`` is given, ``gqcnn.control_ratios``): ``targeted`` and ``random`` (seeded by
    ``[seed, BASE_SEED, B]``) with ``run_batch`` (:func:`.decode.mesh_batches` over the base set),
    ``recon`` from ``recon`` (the real pool's first shapes, each decoded once from its own latent: a shape that
    does not mesh is dropped, not replaced, so the recon pool of ratio R is the real pool's set of R less its
    failures, and never runs out), and the
    no-network pools with their runner in ``controls``: ``blend`` (:func:`.decode.blend_batches`) and
    ``warp`` (:func:`.decode.warp_batches`) on the targeted pool's candidates (its kept ones first: the same
    parents and weights), ``primitives`` (:func:`.decode.primitive_batches`) on assemblies 0, 1, … of
    :class:`PrimitiveStream` (:data:`PRIMITIVE_TRIES` per shape needed), ``procedural``
    (:func:`.decode.procedural_batches`) on objects 0, 1, … of its shuffled corpus (``procedural``: how many), and
    ``own``: the targeted recipe (:func:`targeted_stream`, the same settings) on ``own`` (:class:`OwnSource`: the
    base set's latents and rarity under its own AutoEncoder-Critic, decoded by it).

    Returns (pools: name → (kept, rejected) Decoded lists, in :data:`GENERATED_POOLS` order, the
    targeted stream as widened, shapes per pool, the own pool's stream as widened or None); a
    :class:`graspaug.errors.DataError` if a pool's candidates run out first, or a pool is asked for without its
    source or runner.
    """
    base_size = len(base.ids)
    needed = pool_size(cfg.ratios, base_size)
    control = needed if control_ratios is None else pool_size(control_ratios, base_size)  # the other pools' size
    targeted = targeted_stream(base, cfg)
    if "recon" in pools and recon is None:
        raise DataError(f"generate {base_size}: the recon pool needs the real pool's shapes")
    if "own" in pools and own is None:
        raise DataError(f"generate {base_size}: the own pool needs the base set's own AutoEncoder-Critic")
    own_stream = targeted_stream(own.shapes, cfg) if own and "own" in pools else None
    controls = controls or {}
    for name in ("blend", "warp", "primitives", "procedural"):
        if name in pools and name not in controls:
            raise DataError(f"generate {base_size}: the {name} pool needs its runner (the base set's meshes)")
    if "procedural" in pools and procedural < control:
        raise DataError(
            f"generate {base_size}, procedural pool: {control} shapes needed, the procedural corpus holds {procedural} "
            "objects outside this experiment's corpus (the pool adds pybullet's random_urdfs to a corpus of your own; "
            "with data.source: pybullet it has nothing to add)"
        )
    streams = {
        "targeted": (targeted, run_batch),
        "random": (RandomStream(base_size, cfg.alphas, np.random.default_rng([seed, BASE_SEED, base_size])), run_batch),
        "recon": (ReconStream(len(recon.shapes.ids)), recon.run_batch) if recon else None,
        "primitives": (PrimitiveStream(PRIMITIVE_TRIES * control), controls.get("primitives")),
        "procedural": (ProceduralStream(procedural), controls.get("procedural")),
        "own": (own_stream, own.run_batch) if own_stream else None,
    }
    out = {}
    for name in (p for p in GENERATED_POOLS if p == "targeted" or p in pools):
        if name in FOLLOWERS:
            streams[name] = (FollowStream([d.candidate for d in out["targeted"][0]], targeted), controls[name])
        stream, runner = streams[name]
        if name == "recon":  # the real pool's first shapes, each decoded once: a failed decode is a gap, not replaced
            out[name] = decode_each(stream, min(control, len(recon.shapes.ids)), runner)
            continue
        try:
            out[name] = fill_pool(stream, needed if name == "targeted" else control, runner)
        except PoolExhausted as exc:
            raise DataError(f"generate {base_size}, {name} pool: {exc}") from None
    return out, targeted, needed, own_stream


@dataclass(frozen=True)
class GeneratedSet:
    """A base set's generated shapes, ready to write.

    index : one row per kept shape in pool order (:func:`graspaug.augment.pool_tables.pool_tables` columns
        plus ``rarity_vs_base``, the rarity of its latent against the base set; NaN for the warp and primitives
        pools, whose shapes have no latent; the own pool's ``z`` and rarity are in its own AutoEncoder-Critic's
        latent space, against the base set's latents there)
    rejects : one row per rejected decode (:data:`REJECT_COLUMNS`)
    base_table : the base set with its scores (:func:`graspaug.augment.pool_tables.base_scores_table`)
    kept : the kept decodes (Decoded, with their meshes in m), in ``index`` order
    summary : the ``generate`` summary (:func:`.pool_tables.pool_summary`; metrics: ``generate_headline``)
    kept_share : pool name → share of its decodes that were kept
    examples : the decodes to picture (:func:`example_decodes`)
    notes : how the targeted stream was widened, in order
    warnings : one message per pool whose kept share is below :data:`LOW_YIELD`
    """

    index: pd.DataFrame
    rejects: pd.DataFrame
    base_table: pd.DataFrame
    kept: list[Decoded]
    summary: dict
    kept_share: dict[str, float]
    examples: list[Decoded]
    notes: list[str]
    warnings: list[str]


def generated_set(
    base: BaseSet,
    pools: Pools,
    targeted: TargetedStream,
    needed: int,
    k: int,
    n_examples: int,
    recon_shapes: BaseSet | None = None,
    procedural_ids: Sequence[str] = (),
    own: tuple[BaseSet, TargetedStream] | None = None,
) -> GeneratedSet:
    """The :class:`GeneratedSet` of ``pools`` (:func:`fill_pools`: the pools, the targeted stream
    and the shapes per pool) for ``base``; ``k``: the rarity's neighbours; ``n_examples``: targeted
    decodes to picture; ``recon_shapes``: the shapes the recon pool reconstructs; ``procedural_ids``: the
    procedural pool's objects in stream order; ``own``: the base set under its own AutoEncoder-Critic and the own
    pool's stream."""
    base_size = len(base.ids)
    sources = {name: (base.ids, base.z) for name in pools}
    if recon_shapes is not None:
        sources["recon"] = (recon_shapes.ids, recon_shapes.z)
    if "warp" in pools:  # a warp is its parent deformed: the parent's latent is not the warp's
        sources["warp"] = (base.ids, np.full_like(base.z, np.nan))
    if "primitives" in pools:  # assembly k of the stream: no real parent, no latent
        n = PRIMITIVE_TRIES * needed
        sources["primitives"] = (
            np.array([f"assembly_{i:04d}" for i in range(n)]),
            np.full((n, base.z.shape[1]), np.nan),
        )
    if "procedural" in pools:  # object k of the shuffled procedural corpus: not a parent of this corpus, no latent
        sources["procedural"] = (np.asarray(procedural_ids), np.full((len(procedural_ids), base.z.shape[1]), np.nan))
    own_shapes, own_stream = own if own is not None and "own" in pools else (None, None)
    if own_shapes is not None:  # the own AE's latents: their own space, whose size may differ
        sources["own"] = (own_shapes.ids, own_shapes.z)
    rows, reject_rows = pool_tables(sources, pools, base_size)
    index = pd.DataFrame(rows)
    mine = (index.pool == "own").to_numpy()
    index["rarity_vs_base"] = np.nan
    z = list(index.z)
    index.loc[~mine, "rarity_vs_base"] = latent_rarity(base.z, k, _stacked(z, ~mine, base.z.shape[1]))
    if own_shapes is not None:
        index.loc[mine, "rarity_vs_base"] = latent_rarity(own_shapes.z, k, _stacked(z, mine, own_shapes.z.shape[1]))
    base_table = base_scores_table(base.ids, base.rarity, base.graspness, targeted.percentile)
    summary, kept_share = pool_summary(base_size, needed, pools, targeted, index, reject_rows, own_stream)
    return GeneratedSet(
        index,
        pd.DataFrame(reject_rows, columns=REJECT_COLUMNS),
        base_table,
        [d for kept, _ in pools.values() for d in kept],
        summary,
        kept_share,
        example_decodes(pools, n_examples),
        targeted.notes + [f"own pool: {note}" for note in (own_stream.notes if own_stream else [])],
        [
            f"only {100 * share:.1f}% of the {name} pool's decodes were usable meshes"
            for name, share in kept_share.items()
            if share < LOW_YIELD
        ],
    )


def generate_pools(
    base: BaseSet,
    cfg: GenerateSettings,
    seed: int,
    run_batch: Runner,
    k: int,
    pools: Sequence[str] = ("targeted", "random"),
    recon: ReconSource | None = None,
    controls: dict[str, Runner] | None = None,
    procedural_ids: Sequence[str] = (),
    control_ratios: Sequence[float] | None = None,
    own: OwnSource | None = None,
) -> GeneratedSet:
    """:func:`fill_pools` then :func:`generated_set` (``k``: the rarity's neighbours; ``procedural_ids``: the
    procedural pool's objects in stream order; ``control_ratios``: the ratios of the pools but targeted; ``own``: the
    own pool's source)."""
    filled, targeted, needed, own_stream = fill_pools(
        base, cfg, seed, run_batch, pools, recon, controls, len(procedural_ids), control_ratios, own
    )
    recon_shapes, mine = recon.shapes if recon else None, (own.shapes, own_stream) if own_stream else None
    return generated_set(base, filled, targeted, needed, k, cfg.n_examples, recon_shapes, procedural_ids, mine)


def _stacked(z: list[np.ndarray], rows: np.ndarray, width: int) -> np.ndarray:
    """The latents ``z`` of ``rows`` (a mask) stacked (n, ``width``), (0, ``width``) for none."""
    picked = [z[i] for i in np.flatnonzero(rows)]
    return np.stack(picked) if picked else np.zeros((0, width), np.float32)


def latent_rarity(z_base: np.ndarray, k: int, z: np.ndarray) -> np.ndarray:
    """Rarity (G,) of latents ``z`` (G, d) against the base latents ``z_base`` (B, d) with ``k`` neighbours; NaN for
    a row with no latent (NaN)."""
    out = np.full(len(z), np.nan)
    known = np.isfinite(z).all(axis=1)
    if known.any():
        out[known] = rarity(z_base, k, query=z[known])
    return out


def example_decodes(pools: Pools, n_examples: int) -> list[Decoded]:
    """The decodes to picture: the targeted pool's first ``n_examples`` kept, then the random pool's first 2."""
    return pools["targeted"][0][:n_examples] + pools.get("random", ([], []))[0][:2]


def tsne_groups(base: BaseSet, index: pd.DataFrame, perplexity: float, seed: int) -> tuple[np.ndarray, list[str]]:
    """(xy (B + G, 2), groups (B + G,)): the t-SNE of the base latents followed by the G generated
    ones that have a latent in the base latents' space (``index.z`` not NaN: not the warp and primitives pools; not
    the own pool, whose latents are its own AutoEncoder-Critic's), and each point's group
    (``base`` or ``generated (<selected_by>)``)."""
    shared = (index.pool != "own").to_numpy()
    index = index[shared]
    z = np.stack(index.z.to_numpy()) if len(index) else np.zeros((0, base.z.shape[1]))
    known = np.isfinite(z).all(axis=1)  # a primitive assembly has no latent
    xy = tsne_2d(np.concatenate([base.z, z[known]]), perplexity, seed)
    groups = ["base"] * len(base.ids) + [f"generated ({s})" for s in index.selected_by[known]]
    return xy, groups
