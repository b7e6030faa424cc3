"""The ``generate`` stage's work on one base set: decode candidates to meshes with the AE-Critic,
fill the targeted and random pools, and assemble their tables, metrics and picture data.

Kept apart from :mod:`graspaug.augment.candidates` (base sets, candidate streams, pool rules), which the
GQ-CNN experiment imports too, so that decoder and meshing code is code of ``generate`` alone.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from graspaug.augment.candidates import (
    BASE_SEED,
    Candidate,
    CandidateStream,
    Decoded,
    FailureStream,
    FollowStream,
    PoolExhausted,
    PrimitiveStream,
    ProceduralStream,
    RandomStream,
    ReconStream,
    TargetedStream,
    candidate_key,
    draw_base_sets,
    fill_pool,
    pool_size,
)
from graspaug.augment.embedding import tsne_2d
from graspaug.augment.pool_tables import base_scores_table, pool_summary, pool_tables
from graspaug.augment.scores import rarity
from graspaug.augment.settings import GenerateSettings
from graspaug.errors import DataError

log = logging.getLogger(__name__)
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
GENERATED_POOLS = ("targeted", "random", "recon", "blend", "warp", "primitives", "procedural")
FOLLOWERS = ("blend", "warp")  # the controls that follow the targeted pool's candidates (its parents and weights)
PRIMITIVE_TRIES = 20  # the primitives stream holds this many assemblies per shape needed
Runner = Callable[[list[Candidate]], list[Decoded]]


@dataclass(frozen=True)
class ReconSource:
    """What the ``recon`` pool reconstructs: ``shapes``, the real pool's shapes in its order (a
    :class:`BaseSet`: ids, latents, pitches), and ``run_batch``, :func:`.decode.mesh_batches` over them."""

    shapes: BaseSet
    run_batch: Callable[[list[Candidate]], list[Decoded]]


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
) -> tuple[Pools, TargetedStream, int]:
    """Fill each of ``pools`` (of :data:`GENERATED_POOLS`; the targeted one always) to
    ``pool_size(cfg.ratios, B)`` kept shapes (the pools but targeted: ``pool_size(control_ratios, B)`` when
    ``control_ratios`` is given, ``gqcnn.control_ratios``): ``targeted`` and ``random`` (seeded by
    ``[seed, BASE_SEED, B]``) with ``run_batch`` (:func:`.decode.mesh_batches` over the base set),
    ``recon`` from ``recon`` (the real pool's shapes, each decoded from its own latent), and the
    no-network pools with their runner in ``controls``: ``blend`` (:func:`.decode.blend_batches`) and
    ``warp`` (:func:`.decode.warp_batches`) on the targeted pool's candidates (its kept ones first: the same
    parents and weights), ``primitives`` (:func:`.decode.primitive_batches`) on assemblies 0, 1, … of
    :class:`PrimitiveStream` (:data:`PRIMITIVE_TRIES` per shape needed), ``procedural``
    (:func:`.decode.procedural_batches`) on objects 0, 1, … of its shuffled corpus (``procedural``: how many).

    Returns (pools: name → (kept, rejected) Decoded lists, in :data:`GENERATED_POOLS` order, the
    targeted stream as widened, shapes per pool); a :class:`graspaug.errors.DataError` if a pool's
    candidates run out first, or a pool is asked for without its source or runner.
    """
    base_size = len(base.ids)
    needed = pool_size(cfg.ratios, base_size)
    control = needed if control_ratios is None else pool_size(control_ratios, base_size)  # the other pools' size
    targeted_stream = TargetedStream(
        base.z, base.rarity, base.graspness, cfg.percentile, cfg.first_neighbour, cfg.extra_neighbours, cfg.alphas
    )
    if "recon" in pools and recon is None:
        raise DataError(f"generate {base_size}: the recon pool needs the real pool's shapes")
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
        "targeted": (targeted_stream, run_batch),
        "random": (RandomStream(base_size, cfg.alphas, np.random.default_rng([seed, BASE_SEED, base_size])), run_batch),
        "recon": (ReconStream(len(recon.shapes.ids)), recon.run_batch) if recon else None,
        "primitives": (PrimitiveStream(PRIMITIVE_TRIES * control), controls.get("primitives")),
        "procedural": (ProceduralStream(procedural), controls.get("procedural")),
    }
    out = {}
    for name in (p for p in GENERATED_POOLS if p == "targeted" or p in pools):
        if name in FOLLOWERS:
            streams[name] = (FollowStream([d.candidate for d in out["targeted"][0]], targeted_stream), controls[name])
        stream, runner = streams[name]
        try:
            out[name] = fill_pool(stream, needed if name == "targeted" else control, runner)
        except PoolExhausted as exc:
            raise DataError(f"generate {base_size}, {name} pool: {exc}") from None
    return out, targeted_stream, needed


@dataclass(frozen=True)
class GeneratedSet:
    """A base set's generated shapes, ready to write.

    index : one row per kept shape in pool order (:func:`graspaug.augment.pool_tables.pool_tables` columns
        plus ``rarity_vs_base``, the rarity of its latent against the base set; NaN for the warp and primitives
        pools, whose shapes have no latent)
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
) -> GeneratedSet:
    """The :class:`GeneratedSet` of ``pools`` (:func:`fill_pools`: the pools, the targeted stream
    and the shapes per pool) for ``base``; ``k``: the rarity's neighbours; ``n_examples``: targeted
    decodes to picture; ``recon_shapes``: the shapes the recon pool reconstructs; ``procedural_ids``: the
    procedural pool's objects in stream order."""
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
    rows, reject_rows = pool_tables(sources, pools, base_size)
    index = pd.DataFrame(rows)
    index["rarity_vs_base"] = latent_rarity(base.z, k, np.stack(index.z.to_numpy()))
    base_table = base_scores_table(base.ids, base.rarity, base.graspness, targeted.percentile)
    summary, kept_share = pool_summary(base_size, needed, pools, targeted, index, reject_rows)
    return GeneratedSet(
        index,
        pd.DataFrame(reject_rows, columns=REJECT_COLUMNS),
        base_table,
        [d for kept, _ in pools.values() for d in kept],
        summary,
        kept_share,
        example_decodes(pools, n_examples),
        targeted.notes,
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
) -> GeneratedSet:
    """:func:`fill_pools` then :func:`generated_set` (``k``: the rarity's neighbours; ``procedural_ids``: the
    procedural pool's objects in stream order; ``control_ratios``: the ratios of the pools but targeted)."""
    filled, targeted, needed = fill_pools(
        base, cfg, seed, run_batch, pools, recon, controls, len(procedural_ids), control_ratios
    )
    recon_shapes = recon.shapes if recon else None
    return generated_set(base, filled, targeted, needed, k, cfg.n_examples, recon_shapes, procedural_ids)


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
    ones that have a latent (``index.z`` not NaN: not the warp and primitives pools), and each point's group
    (``base`` or ``generated (<selected_by>)``)."""
    z = np.stack(index.z.to_numpy())
    known = np.isfinite(z).all(axis=1)  # a primitive assembly has no latent
    xy = tsne_2d(np.concatenate([base.z, z[known]]), perplexity, seed)
    groups = ["base"] * len(base.ids) + [f"generated ({s})" for s in index.selected_by[known]]
    return xy, groups


def stream_shapes(
    pool: BaseSet,
    stream: CandidateStream,
    name: str,
    count: int,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    first_order: int = 0,
    prefix: str = "",
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """``count`` kept shapes of ``stream`` (candidates indexing ``pool``), decoded by ``run_batch``
    (:func:`~graspaug.augment.decode.mesh_batches` over ``pool``), as pool ``name``.

    Returns (index, rejects, kept, notes): ``index`` one row per kept shape (the columns of
    :func:`graspaug.augment.pool_tables.pool_tables`; ``order`` counts from ``first_order``, ``shape_id`` is
    ``<prefix><order>``), ``rejects`` (:data:`REJECT_COLUMNS`), the kept decodes (meshes in m) in
    ``index`` order and how the stream was widened; a :class:`DataError` if the candidates run out first.
    """
    try:
        kept, rejected = fill_pool(stream, count, run_batch)
    except PoolExhausted as exc:
        raise DataError(f"{name} pool: {exc}") from None
    rows, reject_rows = pool_tables({name: (pool.ids, pool.z)}, {name: (kept, rejected)}, len(pool.ids))
    index = pd.DataFrame(rows)
    index["order"] += first_order
    index["shape_id"] = [f"{prefix}{order:04d}" for order in index.order]
    return index, pd.DataFrame(reject_rows, columns=REJECT_COLUMNS), kept, stream.notes


def failure_shapes(
    pool: BaseSet,
    anchors: Sequence[int],
    failures: Sequence[str],
    count: int,
    cfg: GenerateSettings,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    used: Iterable[tuple[frozenset, float]] = (),
    first_order: int = 0,
    prefix: str = "failure_",
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """``count`` shapes generated from training shapes near objects a planner fails on.

    Parameters
    ----------
    pool : the training shapes (a :class:`BaseSet`) the anchors index
    anchors : indices into ``pool``, most failing first
        (:func:`graspaug.experiments.lifelong.numbers.failure_anchors`)
    failures : (len(anchors),) — the name of the failure object each anchor is nearest to
    count : shapes to keep
    cfg : the ``generate`` params: neighbours (``first_neighbour``, ``extra_neighbours``) and ``alphas``
    run_batch : :func:`~graspaug.augment.decode.mesh_batches` over ``pool``
    used, first_order, prefix : candidates (:func:`.candidates.candidate_key` of ``pool`` indices) not to
        make again, and the ids (:func:`stream_shapes`): the lifelong loop's later rounds

    Returns
    -------
    :func:`stream_shapes`'s (index, rejects, kept, notes), ``index`` with the column ``failure`` (the failure object
    each shape's anchor ``parent_a`` serves)
    """
    failing = FailureStream(pool.z, anchors, cfg.first_neighbour, cfg.extra_neighbours, cfg.alphas)
    stream = FollowStream([], failing, used)
    index, rejects, kept, notes = stream_shapes(pool, stream, "failure", count, run_batch, first_order, prefix)
    served = dict(zip(anchors, failures))
    index["failure"] = [served[d.candidate.a] for d in kept]
    rejects["failure"] = rejects.parent_a.map({pool.ids[a]: name for a, name in served.items()})
    return index, rejects, kept, notes


def failure_summary(failures: Sequence[str], served: Sequence[str], index: pd.DataFrame, rejects: pd.DataFrame):
    """One row per failure object (in the order of ``failures``): its ``anchors`` (how many entries of
    ``served``, the failure each anchor serves, name it), the ``shapes`` kept and decodes ``rejected`` for it
    (``index`` and ``rejects`` of :func:`failure_shapes`), and ``why`` in words when it got no shape.
    """
    anchors = pd.Series(list(served), dtype=object).value_counts()
    made, rejected = index.failure.value_counts(), rejects.failure.value_counts()
    reasons = rejects.groupby("failure").reason.agg(
        lambda r: "; ".join(f"{k}: {v}" for k, v in r.value_counts().items())
    )
    rows = []
    for name in failures:
        n_anchors, n_made, n_rejected = int(anchors.get(name, 0)), int(made.get(name, 0)), int(rejected.get(name, 0))
        if n_made:
            why = ""
        elif not n_anchors:
            why = "no anchor: its nearest train shapes already anchor failures listed before it"
        elif n_rejected:
            why = f"every decode near it was rejected ({reasons[name]})"
        else:
            why = "the requested count was reached before its anchors were used (raise --count)"
        rows.append(
            {
                "failure": name,
                "anchors": n_anchors,
                "shapes": n_made,
                "rejected": n_rejected,
                "reject_reasons": reasons.get(name, ""),
                "why_none": why,
            }
        )
    return pd.DataFrame(rows, columns=["failure", "anchors", "shapes", "rejected", "reject_reasons", "why_none"])


def log_failure_summary(summary: pd.DataFrame, notes: Sequence[str], out) -> None:
    """Log how the stream was widened (``notes``), one line per failure object of ``summary``
    (:func:`failure_summary`; a warning naming one that got no shape) and the total written to ``out``."""
    for note in notes:
        log.info("from-failures: %s", note)
    for row in summary.itertuples():
        shapes, decodes = ("shape" if row.shapes == 1 else "shapes"), ("decode" if row.rejected == 1 else "decodes")
        line = f"{row.failure}: {row.shapes} {shapes}, {row.rejected} {decodes} rejected {row.why_none}".rstrip()
        log.log(logging.WARNING if row.why_none else logging.INFO, "from-failures: %s", line)
    served = int((summary.shapes > 0).sum())
    log.info(
        "from-failures: %d shapes for %d of %d failure objects in %s", summary.shapes.sum(), served, len(summary), out
    )


def random_shapes(
    pool: BaseSet,
    count: int,
    cfg: GenerateSettings,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    rng: np.random.Generator,
    used: Iterable[tuple[frozenset, float]] = (),
    first_order: int = 0,
    prefix: str = "random_",
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """``count`` shapes of random pairs of ``pool`` in an order drawn from ``rng``, the weights cycling through
    ``cfg.alphas`` as every pool's do; ``used``, ``first_order``, ``prefix`` and the result as
    :func:`failure_shapes`."""
    stream = FollowStream([], RandomStream(len(pool.ids), cfg.alphas, rng), used)
    return stream_shapes(pool, stream, "random", count, run_batch, first_order, prefix)


def loop_shapes(
    base: BaseSet,
    anchors: Sequence[int],
    failures: Sequence[str],
    made: pd.DataFrame | None,
    count: int,
    cfg: GenerateSettings,
    run_batch: Callable[[list[Candidate]], list[Decoded]],
    rng: np.random.Generator,
    round_: int,
) -> tuple[pd.DataFrame, pd.DataFrame, list[Decoded], list[str]]:
    """One round of the lifelong loop's generated arms: ``count`` ``failure`` shapes (:func:`failure_shapes` from
    ``anchors``, base-set indices near the ``failures`` they serve) and ``count`` ``random`` ones
    (:func:`random_shapes` drawn by ``rng``), none a pair and weight an earlier round of its arm made.

    ``made``: the earlier rounds' shapes (this function's index; None in round 1). Returns (index, rejects, kept,
    notes): ``index`` with ``arm`` (= ``pool``), ``round`` = ``round_``, ``order`` counting on from the earlier
    rounds of the arm and ``shape_id`` ``r<round>_<f|r><order>``; the rest as :func:`stream_shapes`.
    """
    position = {shape_id: i for i, shape_id in enumerate(base.ids)}
    made = made if made is not None else pd.DataFrame(columns=["arm", "parent_a", "parent_b", "alpha"])

    def earlier(arm: str) -> tuple[list, int]:
        rows = made[made.arm == arm]
        keys = [
            candidate_key(position[a], position[b], al) for a, b, al in zip(rows.parent_a, rows.parent_b, rows.alpha)
        ]
        return keys, len(rows)

    used, first = earlier("failure")
    failing = failure_shapes(base, anchors, failures, count, cfg, run_batch, used, first, f"r{round_}_f")
    used, first = earlier("random")
    random = random_shapes(base, count, cfg, run_batch, rng, used, first, f"r{round_}_r")
    index = pd.concat([failing[0], random[0]], ignore_index=True)
    index["arm"], index["round"] = index.pool, round_
    rejects = pd.concat([failing[1], random[1]], ignore_index=True)
    return index, rejects, failing[2] + random[2], failing[3] + random[3]
