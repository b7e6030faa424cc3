"""How close is a pool of shapes to real shapes, before any network trains on it?

Distribution distances between a pool and held-out real shapes, as 3D generative-model papers
report them (Achlioptas et al. 2018; Yang et al. 2019, PointFlow), on the Chamfer distance between
point clouds sampled from the meshes' surfaces:

* **coverage** (COV): the share of reference shapes that are the nearest reference shape of at
  least one pool shape (higher is better; a pool that covers the references' variety);
* **minimum matching distance** (MMD): the mean over reference shapes of the distance to their
  nearest pool shape (lower is better; fidelity);
* **1-NN accuracy** (1-NNA): leave-one-out accuracy of a 1-nearest-neighbour classifier telling
  pool from reference shapes in their union (0.5 is the ideal: the two sets are
  indistinguishable; 1.0: every shape's nearest neighbour is from its own set). It needs sets of
  equal size.

Chamfer distance here: the mean, over both clouds' points, of the distance to the nearest point
of the other cloud (m, not squared), the clouds centered on their centroids.

Also the round trip's figure (``graspaug study roundtrip-ceiling``, ``bench/paper_scale.py``): how much of each shape's
graspness its reconstruction keeps, labelled as the ``grasps`` stage labels it (:func:`mesh_graspness`,
:func:`paired_graspness_kept`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.spatial import cKDTree

from graspaug.augment.scores import graspness
from graspaug.errors import DataError
from graspaug.experiments.stats import fieller_interval, percentile_interval, t_interval
from graspaug.grasping.labelled import grasps_of_shape
from graspaug.grasping.settings import GraspsSettings
from graspaug.rng import shape_rng

FIDELITY_POINTS = 512
"""Surface points per shape for the fidelity stage's Chamfer distances."""


FIDELITY_RESAMPLES = 1000
"""Bootstrap resamples of the fidelity stage's intervals."""


def surface_cloud(mesh, n_points: int, rng: np.random.Generator) -> np.ndarray:
    """``n_points`` points (n_points, 3) m drawn uniformly by area on ``mesh``'s surface (a trimesh),
    centered on their centroid."""
    import trimesh

    points, _ = trimesh.sample.sample_surface(mesh, n_points, seed=rng)
    return points - points.mean(axis=0)


def chamfer_matrix(a: Sequence[np.ndarray], b: Sequence[np.ndarray]) -> np.ndarray:
    """Chamfer distance (m) between every cloud of ``a`` and every cloud of ``b`` (each (n, 3)):
    (len(a), len(b)), the mean of both directions' nearest-point distances."""
    trees_b = [cKDTree(cloud) for cloud in b]
    trees_a = [cKDTree(cloud) for cloud in a]
    out = np.empty((len(a), len(b)))
    for i, (cloud_a, tree_a) in enumerate(zip(a, trees_a)):
        for j, (cloud_b, tree_b) in enumerate(zip(b, trees_b)):
            out[i, j] = 0.5 * (tree_b.query(cloud_a)[0].mean() + tree_a.query(cloud_b)[0].mean())
    return out


def ratio(numerator: float, denominator: float) -> float:
    """``numerator / denominator``, NaN (undefined) where the denominator is 0 or not finite: a figure undefined on
    some data says so rather than stopping the stage."""
    denominator = float(denominator)
    return float(numerator) / denominator if denominator and np.isfinite(denominator) else np.nan


def coverage_mmd(pool_to_reference: np.ndarray) -> tuple[float, float]:
    """Coverage and minimum matching distance (m) from the Chamfer distances (pool, reference); both NaN without
    pool or reference shapes."""
    d = np.asarray(pool_to_reference, dtype=float)
    if d.size == 0:
        return np.nan, np.nan
    covered = np.unique(d.argmin(axis=1))
    return ratio(len(covered), d.shape[1]), float(d.min(axis=0).mean())


def one_nn_accuracy(pool_pool: np.ndarray, reference_reference: np.ndarray, pool_reference: np.ndarray) -> float:
    """Leave-one-out 1-NN accuracy on the union of a pool and a reference set of the same size, from
    their Chamfer distances within the pool (P, P), within the reference (P, P) and across (P, P)."""
    pp, rr, pr = (np.asarray(m, dtype=float) for m in (pool_pool, reference_reference, pool_reference))
    if not (pp.shape == rr.shape == pr.shape and pp.shape[0] == pp.shape[1]):
        raise ValueError(f"1-NNA needs square matrices of one size; got {pp.shape}, {rr.shape}, {pr.shape}")
    n = len(pp)
    full = np.block([[pp, pr], [pr.T, rr]])
    np.fill_diagonal(full, np.inf)
    nearest = full.argmin(axis=1)
    own = np.r_[np.zeros(n, bool), np.ones(n, bool)]
    return float((own[nearest] == own).mean())


def distribution_distances(pool: Sequence[np.ndarray], reference: Sequence[np.ndarray]) -> dict[str, float]:
    """``coverage``, ``mmd`` (m) and ``one_nna`` of a pool of clouds against reference clouds of the same count."""
    pr = chamfer_matrix(pool, reference)
    coverage, mmd = coverage_mmd(pr)
    one_nna = one_nn_accuracy(chamfer_matrix(pool, pool), chamfer_matrix(reference, reference), pr)
    return {"coverage": coverage, "mmd": mmd, "one_nna": one_nna}


@dataclass(frozen=True)
class PoolShapes:
    """One pool's shapes, one row each (:func:`pool_shapes`).

    Attributes
    ----------
    ids : (n,) shape ids
    clouds : n arrays (P, 3) m — surface points (:func:`surface_cloud`)
    extents : (n, 3) m — each shape's bounding-box extents, sorted
    graspness : (n,) — the share of the shape's sampled grasps with robust ε above the threshold
    parents : (n,) — the parents' graspness mixed as the child mixes them, (1 − α) g_a + α g_b
        (NaN for a real shape)
    datapoints, positives : (n,) int — the shape's rendered datapoints and its positive ones
    parent_datapoints : (n,) — the parents' rendered datapoints mixed as the child mixes them (NaN for a real
        shape or one with no real parent)
    distinct_parents : int or None — parents of the pool's shapes, counted once (None: real shapes)
    alphas : dict — α → how many shapes (empty for real shapes)
    """

    ids: list[str]
    clouds: list[np.ndarray]
    extents: np.ndarray
    graspness: np.ndarray
    parents: np.ndarray
    datapoints: np.ndarray
    positives: np.ndarray
    parent_datapoints: np.ndarray | None = None
    distinct_parents: int | None = None
    alphas: dict = field(default_factory=dict)


def pool_shapes(
    meshes: Mapping[str, object],
    graspness: Mapping[str, float],
    rendered: pd.DataFrame,
    n_points: int,
    seed: int,
    parents: pd.DataFrame | None = None,
    parent_counts: Mapping[str, int] | None = None,
) -> PoolShapes:
    """A pool's :class:`PoolShapes` from its meshes.

    Parameters
    ----------
    meshes : shape id → trimesh, in pool order
    graspness : shape id → graspness (a shape missing here had no sampled grasp: 0)
    rendered : the pool's rendered datapoints (columns ``shape_id``, ``label``)
    n_points : surface points per shape; each shape's points come from its own stream of ``seed``
    parents : for generated shapes, their rows of the generated index (``shape_id``, ``parent_a``,
        ``parent_b``, ``alpha``), the parents' graspness looked up in ``graspness``
    parent_counts : real shape id → its rendered datapoints, the parents' looked up here
    """
    ids = list(meshes)
    counts = rendered.groupby("shape_id").label.agg(["size", "sum"]).reindex(ids, fill_value=0)
    mixed, mixed_counts, distinct, alphas = np.full(len(ids), np.nan), np.full(len(ids), np.nan), None, {}
    if parents is not None:
        p = parents.set_index("shape_id").loc[ids]
        alpha = p.alpha.to_numpy(float)

        def mix(of: Mapping[str, float]) -> np.ndarray:  # a parent figure mixed as the child mixes its parents
            a, b = (p[c].map(lambda s: of.get(s, 0.0)).to_numpy(float) for c in ("parent_a", "parent_b"))
            return (1 - alpha) * a + alpha * b

        mixed = mix(graspness)
        if parent_counts is not None:
            mixed_counts = mix(parent_counts)
        distinct = len(set(p.parent_a) | set(p.parent_b))
        alphas = {f"{a:g}": int(n) for a, n in p.alpha.value_counts().sort_index().items()}
    return PoolShapes(
        ids=ids,
        clouds=[surface_cloud(meshes[s], n_points, shape_rng(seed, s, "fidelity")) for s in ids],
        extents=np.sort([np.asarray(meshes[s].extents, float) for s in ids], axis=1).reshape(-1, 3),
        graspness=np.array([graspness.get(s, 0.0) for s in ids], float),
        parents=mixed,
        datapoints=counts["size"].to_numpy(int),
        positives=counts["sum"].to_numpy(int),
        parent_datapoints=mixed_counts,
        distinct_parents=distinct,
        alphas=alphas,
    )


def resampled_distances(pp: np.ndarray, rr: np.ndarray, pr: np.ndarray, i: np.ndarray, j: np.ndarray) -> dict:
    """``coverage``, ``mmd`` (m) and ``one_nna`` of pool shapes ``i`` against reference shapes ``j``
    (index arrays of one length, drawn with replacement) from the full Chamfer matrices within the
    pool ``pp``, within the reference ``rr`` and across ``pr``. Copies of one shape are not each
    other's neighbours: a resample scores as its distinct shapes would, not better."""
    i, j = np.asarray(i), np.asarray(j)
    if len(i) != len(j):
        raise ValueError(f"1-NNA needs sets of one size; got {len(i)} pool and {len(j)} reference shapes")
    across = pr[np.ix_(i, j)]
    coverage = float(np.isin(j, j[across.argmin(axis=1)]).mean())
    within_pool = np.where(i[:, None] == i[None, :], np.inf, pp[np.ix_(i, i)])
    within_reference = np.where(j[:, None] == j[None, :], np.inf, rr[np.ix_(j, j)])
    return {
        "coverage": coverage,
        "mmd": coverage_mmd(across)[1],
        "one_nna": one_nn_accuracy(within_pool, within_reference, across),
    }


FIGURES = (
    "graspness",
    "graspness_kept",
    "positive_share",
    "datapoints_per_shape",
    "datapoints_kept",
    "coverage",
    "mmd",
    "one_nna",
)
"""The figures of :func:`fidelity_table`, each with its interval."""

UNDEFINED = {
    "graspness_kept": "the parents' graspness is 0",
    "positive_share": "no datapoints",
    "datapoints_kept": "the parents have no datapoints",
}
"""Why a figure of :func:`fidelity_table` can be undefined on the shapes drawn (a ratio over 0)."""


def _shape_figures(pool: PoolShapes, i: np.ndarray) -> dict:
    """The shape figures of ``pool`` over its shapes ``i``: NaN where undefined on them (:data:`UNDEFINED`), None
    where the pool has no such figure (real shapes keep no parents' figures)."""
    graspness = float(pool.graspness[i].mean())
    counts = pool.parent_datapoints
    return {
        "graspness": graspness,
        "graspness_kept": ratio(graspness, np.mean(pool.parents[i])) if np.isfinite(pool.parents).all() else None,
        "positive_share": ratio(pool.positives[i].sum(), pool.datapoints[i].sum()),
        "datapoints_per_shape": float(pool.datapoints[i].mean()),
        "datapoints_kept": (
            ratio(pool.datapoints[i].sum(), counts[i].sum())
            if counts is not None and np.isfinite(counts).all()
            else None
        ),
    }


def _undefined(figure: str, point, samples: list) -> str | None:
    """What :func:`fidelity_table` says of a ``figure`` undefined at its ``point`` value or on some resamples
    (``samples``: its values over them), None when it is defined everywhere or does not apply."""
    missing = sum(v is not None and not np.isfinite(v) for v in samples)
    if point is None or figure not in UNDEFINED:
        return None
    if not np.isfinite(point):
        return f"{figure}: {UNDEFINED[figure]}"
    if missing:
        return f"{figure}: {UNDEFINED[figure]} in {missing} of {len(samples)} resamples (left out of its interval)"
    return None


def fidelity_table(
    pools: Mapping[str, PoolShapes], reference: Sequence[np.ndarray], n_resamples: int, rng: np.random.Generator
) -> pd.DataFrame:
    """How close each pool is to real shapes, before any training, with 95% intervals.

    Each pool gets :data:`FIGURES`: its graspness and (generated pools) the share of its parents'
    graspness it keeps, the share of positive rendered datapoints, datapoints per shape and (pools with real
    parents) the share of its parents' datapoints it keeps (both ratios of paired means over the same
    resampled shapes), and
    coverage / MMD / 1-NNA against the ``reference`` clouds (held-out real shapes) on the first m
    shapes of each (m: the smaller count). Intervals: percentile bootstrap, ``n_resamples`` times
    drawing the pool's shapes and (for the distances) m pool and m reference shapes with
    replacement.

    Returns
    -------
    DataFrame — one row per pool: ``pool``, ``shapes``, ``distinct_parents``, ``alphas``, the median
    sorted extents ``extent_small``/``extent_middle``/``extent_large`` (m), per figure its value
    and ``<figure>_lo``/``<figure>_hi`` (NaN or None where undefined: a ratio over 0, e.g. the parents' graspness
    0 on every shape), and ``undefined``: which figures were undefined, and why, on the pool or on how many
    resamples ("" when none was)
    """
    rr_full = chamfer_matrix(reference, reference)
    rows = []
    for name, pool in pools.items():
        n, m = len(pool.ids), min(len(pool.ids), len(reference))
        if m < 2:
            raise DataError(f"fidelity: pool {name!r} has {n} shapes and the reference {len(reference)}; need 2 each")
        pp, pr = chamfer_matrix(pool.clouds, pool.clouds), chamfer_matrix(pool.clouds, reference)
        point = _shape_figures(pool, np.arange(n)) | resampled_distances(pp, rr_full, pr, np.arange(m), np.arange(m))
        samples = []
        for _ in range(n_resamples):
            shapes, i, j = rng.integers(0, n, n), rng.integers(0, n, m), rng.integers(0, len(reference), m)
            samples.append(_shape_figures(pool, shapes) | resampled_distances(pp, rr_full, pr, i, j))
        row = {"pool": name, "shapes": n, "distinct_parents": pool.distinct_parents, "alphas": json.dumps(pool.alphas)}
        row |= dict(zip(("extent_small", "extent_middle", "extent_large"), np.median(pool.extents, axis=0).tolist()))
        notes = []
        for figure in FIGURES:
            values = [s[figure] for s in samples]
            low, high = percentile_interval(np.array(values, dtype=float))
            row |= {figure: point[figure], f"{figure}_lo": low, f"{figure}_hi": high}
            notes.append(_undefined(figure, point[figure], values))
        rows.append(row | {"undefined": "; ".join(n for n in notes if n)})
    return pd.DataFrame(rows)


HEADLINE = ("graspness_kept", "positive_share", "datapoints_per_shape", "datapoints_kept", "one_nna")
"""The figures of :func:`fidelity_table` that go to metrics files (the rest: the report's table)."""


def fidelity_headline(table: pd.DataFrame) -> dict[str, dict]:
    """Metrics files from :func:`fidelity_table`: ``<pool>_<figure>`` → ``mean``, ``lo``, ``hi`` (its
    95% interval) for each figure of :data:`HEADLINE` a pool has (real and primitive shapes have no parents, so no
    graspness or datapoints kept)."""

    def value(v):
        return None if v is None or not np.isfinite(v) else round(float(v), 4)

    return {
        f"{row.pool}_{f}": {"mean": value(row[f]), "lo": value(row[f"{f}_lo"]), "hi": value(row[f"{f}_hi"])}
        for _, row in table.iterrows()
        for f in HEADLINE
        if value(row[f]) is not None
    }


def mesh_graspness(path: Path, shape_id: str, grasps: GraspsSettings, seed: int) -> tuple[float, int]:
    """The share of positive grasps (0–1) of the mesh file ``path`` and how many grasps were labelled, as the
    ``grasps`` stage labels shape ``shape_id`` (:func:`~graspaug.grasping.labelled.grasps_of_shape` with its settings
    ``grasps`` and ``seed``); 0 where no grasp was found."""
    table, _ = grasps_of_shape(path, shape_id, grasps, seed)
    score, count = graspness(table.success.to_numpy(), np.zeros(len(table), dtype=np.int64), 1)
    return float(score[0]), int(count[0])


def paired_graspness_kept(after: np.ndarray, before: np.ndarray) -> dict:
    """Paired graspness (shares of positive grasps, finite, 0–1) ``after`` / ``before`` (n,) of the same n shapes: the
    ratio of means ``kept`` with its Fieller 95% interval (``kept_low``, ``kept_high``; None when unbounded) and the
    mean ``difference`` with its 95% t half-width. Unlike the pools' ``graspness_kept`` figure (a child against its
    mixed parents, bootstrapped), a shape here is compared with itself."""
    ratio, diff = fieller_interval(after, before), t_interval(after - before)
    return {
        "graspness_before": float(before.mean()),
        "graspness_after": float(after.mean()),
        "kept": ratio["ratio"],
        "kept_low": ratio["low"],
        "kept_high": ratio["high"],
        "difference": diff["mean"],
        "difference_half_width": None if diff["high"] is None else diff["high"] - diff["mean"],
    }


HELDOUT_WHEN = ("before", "after")


def heldout_summary(per_shape: pd.DataFrame) -> dict:
    """What an AutoEncoder keeps of held-out shapes, from the per-shape table ``graspaug study heldout-fidelity``
    writes (one row per shape: ``meshed``, ``graspness_*``, ``datapoints_*``, ``positives_*``, ``stable_poses_*``,
    ``grasps_rendered_*`` before and after): paired figures over the shapes whose reconstruction meshed: graspness
    kept (Fieller 95%), datapoints kept (Fieller 95%), mean datapoints, the datapoints' positive share (pooled),
    stable poses and grasps rendered, before and after."""
    meshed = per_shape[per_shape.meshed.astype(bool)]
    before, after = meshed.datapoints_before.to_numpy(float), meshed.datapoints_after.to_numpy(float)
    dp = fieller_interval(after, before)
    return {
        "shapes": len(per_shape),
        "meshed": len(meshed),
        **paired_graspness_kept(meshed.graspness_after.to_numpy(float), meshed.graspness_before.to_numpy(float)),
        "datapoints_before": float(before.mean()),
        "datapoints_after": float(after.mean()),
        "datapoints_kept": dp["ratio"],
        "datapoints_kept_low": dp["low"],
        "datapoints_kept_high": dp["high"],
        "positive_before": ratio(meshed.positives_before.sum(), before.sum()),  # pooled, as the dataset's share
        "positive_after": ratio(meshed.positives_after.sum(), after.sum()),  # NaN: no datapoints
    } | {
        f"{k}_{w}": float(np.nanmean(meshed[f"{k}_{w}"]))
        for k in ("stable_poses", "grasps_rendered")
        for w in HELDOUT_WHEN
    }
