"""The GQ-CNN augmentation experiment's numbers (paper Section IV-C/D): test and validation AP
of every network, pre-declared paired contrasts with t-intervals over seeds and bootstrap
intervals over test objects, the ratio chosen on validation, per-object AP (its words: :mod:`.words`).

A network is (pool, base size B, ratio R) of a training seed (see
:mod:`graspaug.training.networks`). A contrast is a fixed linear combination of networks'
test AP, evaluated per seed (paired: the networks of a seed share initial weights, noise and
validation), then summarized over seeds. The contrasts are declared from params before any
network is read:

* ``real_data``: AP(largest B, 1:0) − AP(smallest B, 1:0), the positive control (more real
  shapes must help);
* ``targeted_vs_none@B``: mean over R > 0 of AP(targeted, B, R) − AP(B, 1:0);
* ``targeted_vs_none_chosen@B``: the same at the ratio chosen on mean validation AP;
* ``warp_vs_none@B``, ``primitives_vs_none@B``, ``procedural_vs_none@B``: the same for the no-network baselines
  when trained, and ``own_vs_none@B`` for the own pool (the targeted recipe, its AE-Critic trained on the base set);
* ``<a>_vs_<b>@B`` for the pool pairs of :data:`PAIRS` whose pools are trained: mean over R > 0 of
  AP(a, B, R) − AP(b, B, R), equal shape counts (``targeted_vs_random``, ``targeted_vs_real``,
  ``recon_vs_real``: what decoding alone costs, ``targeted_vs_recon``: what interpolation and
  selection add to a decoded shape, ``blend_vs_recon``, ``targeted_vs_blend``: what the latent
  space adds over mixing the same parents' signed distance fields; ``warp_vs_real``, ``targeted_vs_warp``,
  ``primitives_vs_real``, ``targeted_vs_primitives``, ``targeted_vs_procedural``: the baselines a researcher tries
  first; ``targeted_vs_own``: what the main AE-Critic's geometry from train shapes beyond the base set adds);
* with ``gqcnn.control_ratios``, a pool's mean runs over its own ratios (:func:`graspaug.training.variants.pool_ratios`)
  and a pair's over the ratios both pools have;
* ``<pool>_vs_real_datapoints@B``: the same pools against real shapes at as many training
  datapoints (:func:`datapoint_matched_contrasts`), since a generated shape yields fewer.

Each contrast is judged by one interval, over seeds and test objects (:func:`evaluate_contrasts`:
:func:`~graspaug.experiments.stats.nested_t_interval`); the share of the real-shape gain that targeted shapes give
has an interval by test inversion over the same resamples (:func:`graspaug.experiments.ap.attribution.combine_draws`).
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.metrics import average_precision_score

from graspaug.errors import DataError
from graspaug.experiments.stats import (
    DIFFERENCE_RANGE,
    ObjectBootstrap,
    contrast,
    headline,
    nested_t_interval,
    percentile_interval,
    t_interval,
)
from graspaug.io.tables import read_table
from graspaug.training.settings import POOLS
from graspaug.training.variants import network_variant, pool_ratios, seed_variants

Key = tuple[str, int, float]  # (pool, base size, ratio); ratio 0 of any pool is ("targeted", B, 0.0)
PAIRS = {  # pool a vs pool b at equal shape counts: what the difference measures
    ("targeted", "random"): "what selecting rare and graspable neighbours adds over random pairs",
    ("targeted", "real"): "generated vs as many more real shapes",
    ("recon", "real"): "what decoding and meshing cost a real shape",
    ("targeted", "recon"): "what interpolation and selection add to a decoded shape",
    ("blend", "recon"): "interpolants made with no network vs decoded real shapes",
    ("targeted", "blend"): "what the learned latent space adds over geometric interpolation of the same pairs",
    ("warp", "real"): "randomly deformed real shapes vs as many more real shapes",
    ("targeted", "warp"): "the paper's method vs deforming the same parents by hand",
    ("primitives", "real"): "random assemblies of primitives vs as many more real shapes",
    ("targeted", "primitives"): "the paper's method vs procedural objects",
    ("targeted", "procedural"): "the paper's method vs the procedural corpus' objects added as they are",
    ("targeted", "own"): "what the AE-Critic's geometry from train shapes beyond the base set adds (own: its AE-Critic "
    "trained on the base set alone)",
}
NONE_CONTRASTS = (
    "warp",
    "primitives",
    "procedural",
    "own",
)  # pools whose own `<pool>_vs_none@B` is declared beside targeted's


def _key(pool: str, base: int, ratio: float) -> Key:
    return ("targeted" if pool != "ceiling" and ratio == 0.0 else pool, int(base), float(ratio))


@dataclass(frozen=True)
class Contrast:
    """``name`` = Σ weight × AP(network) over ``terms``; ``meaning`` says it in words."""

    name: str
    terms: tuple[tuple[float, Key], ...]
    meaning: str
    chosen_on_validation: bool = field(default=False)


def declared_contrasts(
    base_sizes, ratios, augment_base_sizes, chosen: dict[int, float], pools=POOLS, control_ratios=None
) -> list[Contrast]:
    """The experiment's contrasts (module docstring); ``chosen``: base size → ratio chosen on
    validation; ``pools``: the pools trained (``gqcnn.pools``); ``control_ratios``: ``gqcnn.control_ratios``."""
    out, nonzero = [], [float(r) for r in ratios if r > 0]
    small, large = min(base_sizes), max(base_sizes)

    def over(rs) -> str:
        return ", ".join(f"1:{r:g}" for r in rs)

    if large > small:
        out.append(
            Contrast(
                "real_data",
                ((1.0, _key("targeted", large, 0)), (-1.0, _key("targeted", small, 0))),
                f"B = {large} vs B = {small} real shapes, no augmentation (the positive control)",
            )
        )
    for b in augment_base_sizes:
        if not nonzero:
            break
        out.append(
            Contrast(
                f"targeted_vs_none@{b}",
                tuple((1 / len(nonzero), _key("targeted", b, r)) for r in nonzero) + ((-1.0, _key("targeted", b, 0)),),
                f"targeted augmentation vs none at B = {b}, mean over ratios {over(nonzero)}",
            )
        )
        if b in chosen:
            out.append(
                Contrast(
                    f"targeted_vs_none_chosen@{b}",
                    ((1.0, _key("targeted", b, chosen[b])), (-1.0, _key("targeted", b, 0))),
                    f"targeted augmentation at the ratio chosen on validation (1:{chosen[b]:g}) vs none at B = {b}",
                    True,
                )
            )
    for b in augment_base_sizes:
        for pool in (p for p in NONE_CONTRASTS if p in pools):
            rs = pool_ratios(pool, ratios, control_ratios)
            if rs:
                terms = tuple((1 / len(rs), _key(pool, b, r)) for r in rs) + ((-1.0, _key("targeted", b, 0)),)
                words = f"{pool} augmentation vs none at B = {b}, mean over ratios {over(rs)}"
                out.append(Contrast(f"{pool}_vs_none@{b}", terms, words))
        for one, other in PAIRS:
            both = [
                r for r in pool_ratios(one, ratios, control_ratios) if r in pool_ratios(other, ratios, control_ratios)
            ]
            if both and one in pools and other in pools:
                terms = tuple(
                    t for r in both for t in ((1 / len(both), _key(one, b, r)), (-1 / len(both), _key(other, b, r)))
                )
                words = f"{one} vs {other} shapes at B = {b}, equal counts, mean over ratios: {PAIRS[one, other]}"
                out.append(Contrast(f"{one}_vs_{other}@{b}", terms, words))
    return out


def datapoint_matched_contrasts(
    runs: pd.DataFrame, base_sizes, ratios, augment_base_sizes, pools, control_ratios=None
) -> list[Contrast]:
    """Per augmented base size B and pool (but ``real``): ``<pool>_vs_real_datapoints@B``, the pool's
    AP minus the AP that real shapes give at as many training datapoints, mean over ratios R > 0.
    The real-shape curve is AP against training datapoints through the real-shape networks (1:0 at
    every base size, ``real`` at B and every R), linear between neighbouring points; the weights
    come from the datapoint counts (the same in every seed: they are design, not outcome). So a pool is not penalised
    for yielding fewer datapoints per shape. With ``control_ratios``, each pool's mean runs over its own ratios
    (:func:`graspaug.training.variants.pool_ratios`). A ratio whose network lies outside the curve's range, or has no
    count (``runs.train_datapoints``), is left out of the mean and its ``meaning`` says so; a pool with no ratio left
    keeps its contrast with no terms (no value; :func:`evaluate_contrasts`), so no declared contrast disappears."""
    counts = runs.groupby(["pool", "base_size", "ratio"]).train_datapoints.first()
    out = []
    for b in augment_base_sizes:
        real = pool_ratios("real", ratios, control_ratios)
        curve = [("targeted", int(x), 0.0) for x in base_sizes] + [("real", int(b), r) for r in real]
        points = sorted((float(counts[k]), k) for k in curve if k in counts and pd.notna(counts[k]))
        if len(points) < 2 or "real" not in pools:
            continue
        xs = np.array([x for x, _ in points])
        for pool in (p for p in pools if p != "real"):
            terms: list[tuple[float, Key]] = []
            own = pool_ratios(pool, ratios, control_ratios)
            covered = [
                r for r in own if pd.notna(counts.get((pool, int(b), r))) and xs[0] <= counts[pool, b, r] <= xs[-1]
            ]
            for r in covered:
                key, x = (pool, int(b), r), counts[pool, int(b), r]
                hi = min(int(np.searchsorted(xs, x, side="left")), len(xs) - 1)
                lo = max(hi - 1, 0)
                share = 0.0 if xs[hi] == xs[lo] else (x - xs[lo]) / (xs[hi] - xs[lo])
                n = len(covered)
                terms += [(1 / n, key), (-(1 - share) / n, points[lo][1]), (-share / n, points[hi][1])]
            left = [r for r in own if r not in covered]
            outside = (
                f"; 1:{', 1:'.join(f'{r:g}' for r in left)} left out: {'its' if len(left) == 1 else 'their'} training "
                f"datapoints lie outside the real-shape networks' range ({xs[0]:g}–{xs[-1]:g}) or are not recorded"
                if left
                else ""
            )
            words = (
                f"{pool} at B = {b} vs real shapes giving as many training datapoints (the real-shape networks' AP "
                f"interpolated in datapoints), mean over ratios {', '.join(f'1:{r:g}' for r in covered) or 'none'}"
                + outside
            )
            out.append(Contrast(f"{pool}_vs_real_datapoints@{b}", tuple(terms), words))
    return out


def network_folder(seed_dir: Path, key: Key) -> Path:
    """The folder of network ``key`` (pool, B, R) in its seed's folder ``seed_dir``."""
    return Path(seed_dir) / network_variant(*key).name


SAMPLING_KEYS = ("target_positive_share", "drawn_positive_share", "views_datapoints")
"""What a ``balanced`` or ``views`` network's summary adds (:func:`collect`'s ``train_<key>`` columns, where any
network of the table has one)."""


def _mean(value):
    """A per-member list as its mean; a number as it is."""
    return float(np.mean(value)) if isinstance(value, list) else value


def collect(seed_dirs: Mapping[int, Path], variants) -> pd.DataFrame:
    """One row per network and seed: pool, base_size, ratio, seed, val_ap, test_ap, test_roc_auc,
    train_datapoints, train_positive_share, train_steps, generated_shapes_asked and generated_shapes (the pool's shapes
    it was given: fewer when some did not mesh or yield datapoints; each None when its summary does not say), and
    ``train_<key>`` of :data:`SAMPLING_KEYS` where a network's summary holds it (a ``balanced`` network's target and
    drawn positive shares, a ``views`` network's extra-view datapoints; an ensemble's mean over its members).
    ``seed_dirs``: training seed → the folder of its networks (the seeds in this order)."""
    rows = []
    for seed, seed_dir in seed_dirs.items():
        for v in variants:
            path = network_folder(seed_dir, (v.pool, v.base_size, v.ratio)) / "summary.json"
            if not path.exists():
                raise DataError(f"{path} is missing: run `dvc repro train_gqcnn` first")
            s = json.loads(path.read_text())
            rows.append(
                {
                    "pool": v.pool,
                    "base_size": v.base_size,
                    "ratio": float(v.ratio),
                    "seed": seed,
                    "val_ap": s["validation"]["ap"],
                    "test_ap": s["test"]["ap"],
                    "test_roc_auc": s["test"]["roc_auc"],
                    "train_datapoints": s.get("train", {}).get("datapoints"),
                    "train_positive_share": s.get("train", {}).get("positive_share"),
                    "train_steps": s.get("train", {}).get("steps"),
                    "generated_shapes_asked": s.get("train", {}).get("generated_shapes_asked"),
                    "generated_shapes": s.get("train", {}).get("generated_shapes"),
                    **{f"train_{k}": _mean(s["train"][k]) for k in SAMPLING_KEYS if k in s.get("train", {})},
                }
            )
    return pd.DataFrame(rows)


def test_predictions(seed_dir: Path, key: Key) -> np.ndarray:
    """(N,) P(success) of network ``key`` (pool, B, R) of the seed in ``seed_dir`` on the test datapoints."""
    return np.load(network_folder(seed_dir, key) / "test_predictions.npy")


def test_rows(seed_dir: Path) -> np.ndarray:
    """(N,) the test datapoints' rows in the original corpus's index (the seed in ``seed_dir``)."""
    return np.load(Path(seed_dir) / "test_rows.npy")


def test_labels(index: pd.DataFrame, seed_dir: Path) -> tuple[np.ndarray, np.ndarray]:
    """The test datapoints' labels (N,) and objects (N,): the rows of the seed in ``seed_dir``
    (:func:`test_rows`) in the original corpus's ``index`` (columns ``label``, ``shape_id``)."""
    rows = test_rows(seed_dir)
    return index.label.to_numpy()[rows], index.shape_id.to_numpy()[rows]


def ceiling_shapes(seed_dir: Path) -> int:
    """How many train shapes the ceiling trains on: every rendered train shape outside validation, the base sets
    and the real pool of the seed's ``split.json`` (in ``seed_dir``)."""
    roles = json.loads((Path(seed_dir) / "split.json").read_text())
    return len(set(roles["real_pool"]).union(*map(set, roles["base"].values())))


def choose_ratios(runs: pd.DataFrame, base_sizes) -> dict[int, float]:  # base sizes with augmented networks
    """Per base size, the nonzero ratio with the highest mean validation AP of the targeted networks."""
    out = {}
    for b in base_sizes:
        rows = (
            runs[(runs.pool == "targeted") & (runs.base_size == b) & (runs.ratio > 0)]
            .groupby("ratio")
            .val_ap.mean()
            .dropna()
        )
        if len(rows):
            out[int(b)] = float(rows.idxmax())
    return out


@dataclass(frozen=True)
class Evaluation:
    """Every network of every seed evaluated (:func:`evaluate_networks`): ``chosen`` (base size →
    ratio chosen on validation AP), ``contrasts`` (:func:`evaluate_contrasts`), ``table``
    (:func:`network_table`), ``by_network`` (:func:`per_object_aps`), the test labels (N,) and
    ``ceiling_shapes`` (:func:`ceiling_shapes`)."""

    chosen: dict[int, float]
    contrasts: dict
    table: pd.DataFrame
    by_network: dict[tuple, pd.Series]
    labels: np.ndarray
    object_ids: np.ndarray
    ceiling_shapes: int


def evaluate_networks(
    seed_dirs: Mapping[int, Path], original: Path, generate, gqcnn, seed: int, n_resamples: int = 1000
) -> Evaluation:
    """Read every network of every seed (:func:`~graspaug.training.variants.seed_variants` of the
    ``generate`` and ``gqcnn`` params) in its seed's folder (``seed_dirs``: training seed → folder;
    a missing network is a :class:`DataError`), choose the ratios on validation AP, evaluate the
    declared contrasts (``n_resamples`` bootstrap resamples of the test objects, seeded by the
    global ``seed``) on the test datapoints of the first seed in the original corpus's dataset
    folder ``original`` (its ``index.parquet``), and tabulate AP and per-object AP per network."""
    base_sizes, ratios, augment_base_sizes = generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes
    variants = seed_variants(base_sizes, ratios, augment_base_sizes, gqcnn.ceiling, gqcnn.pools, gqcnn.control_ratios)
    runs = collect(seed_dirs, variants)
    chosen = choose_ratios(runs, augment_base_sizes)
    contrasts = declared_contrasts(base_sizes, ratios, augment_base_sizes, chosen, gqcnn.pools, gqcnn.control_ratios)
    contrasts += datapoint_matched_contrasts(
        runs, base_sizes, ratios, augment_base_sizes, gqcnn.pools, gqcnn.control_ratios
    )
    index = read_table(Path(original) / "index.parquet")
    labels, object_ids = test_labels(index, seed_dirs[next(iter(seed_dirs))])
    results = evaluate_contrasts(contrasts, runs, seed_dirs, labels, object_ids, n_resamples=n_resamples, seed=seed)
    per_object, by_network = per_object_aps(seed_dirs, variants, labels, object_ids)
    table = network_table(runs, per_object)
    return Evaluation(
        chosen, results, table, by_network, labels, object_ids, ceiling_shapes(seed_dirs[next(iter(seed_dirs))])
    )


def per_object_ap(labels: np.ndarray, probability: np.ndarray, shape_ids: np.ndarray) -> pd.Series:
    """AP per test object (those with both classes among their datapoints)."""
    frame = pd.DataFrame({"label": labels.astype(int), "p": probability, "shape_id": shape_ids})
    values = {
        s: average_precision_score(g.label, g.p) for s, g in frame.groupby("shape_id") if 0 < g.label.sum() < len(g)
    }
    return pd.Series(values, dtype=float)


def evaluate_contrasts(
    contrasts: list[Contrast],
    runs: pd.DataFrame,
    seed_dirs: Mapping[int, Path],
    labels: np.ndarray,
    object_ids: np.ndarray,
    n_resamples: int,
    seed: int,
) -> dict:
    """Per contrast, a :func:`~graspaug.experiments.stats.contrast` judged by ONE interval, the one that covers both
    sources of variance: the 95% interval over the training seeds and the test objects (``draws_low``,
    ``draws_high``, ``over`` ``draws`` with ``n_draws`` 1: :func:`~graspaug.experiments.stats.nested_t_interval` on
    this one draw, with the object resamples :func:`graspaug.experiments.ap.attribution.combine_draws` uses, so the
    decomposition quotes the same interval; none with one seed). A contrast without terms (declared, but no network
    can give it: :func:`datapoint_matched_contrasts`) has no value and says why in its ``meaning``. Secondary, never
    judged: the 95% t-interval over seeds (``seeds_*``; None where it leaves [−1, 1]: too few seeds), the bootstrap
    over test objects alone (``objects_*``), the SD of the per-seed values. ``seed_dirs``: training seed → the folder
    of its networks; ``labels``, ``object_ids`` (N,): the test datapoints' labels and objects."""
    seeds = list(seed_dirs)
    boot = ObjectBootstrap(object_ids, n_resamples, seed)
    ap = runs.set_index(["pool", "base_size", "ratio", "seed"]).test_ap.astype(float)  # None (one class) → NaN
    cache: dict = {}

    def boot_ap(key: Key, s: int) -> np.ndarray:
        if (key, s) not in cache:
            cache[key, s] = boot.average_precision(labels, test_predictions(seed_dirs[s], key))
        return cache[key, s]

    out = {}
    r5 = lambda v: None if v is None else round(float(v), 5)  # noqa: E731
    for c in contrasts:
        per_seed = [sum(w * ap.get((*k, s), np.nan) for w, k in c.terms) if c.terms else np.nan for s in seeds]
        summary = t_interval(per_seed, bounds=DIFFERENCE_RANGE)
        no_value = np.full(n_resamples, np.nan)
        resampled = np.array([sum(w * boot_ap(k, s) for w, k in c.terms) if c.terms else no_value for s in seeds])
        low, high = percentile_interval(resampled.mean(axis=0))
        nested = nested_t_interval(np.array([per_seed]), resampled[None])
        finite = [v for v in per_seed if np.isfinite(v)]
        out[c.name] = contrast(
            r5(summary["mean"]),
            "draws",
            summary["n_seeds"],
            seeds=(r5(summary["low"]), r5(summary["high"])),
            objects=(r5(low), r5(high)),
            draws=(r5(nested["low"]), r5(nested["high"])),
            sd=round(float(np.std(finite, ddof=1)), 5) if len(finite) > 1 else None,
            per_seed=[round(float(v), 5) if np.isfinite(v) else None for v in per_seed],
            meaning=c.meaning,
            **({"recon_shapes": recon_shapes(runs, c)} if c.name.startswith("recon_vs_real@") else {}),
        )
    return out


def recon_shapes(runs: pd.DataFrame, c: Contrast) -> list[dict]:
    """Per recon network of contrast ``c`` (its terms of pool ``recon``), how many of the real shapes it decodes
    meshed: ``ratio``, ``meshed`` (``generated_shapes``), ``asked`` (``generated_shapes_asked``), from the first seed
    that records them in ``runs`` (:func:`collect`; every seed of a draw trains on the same pool); empty when no
    summary records them."""
    out = []
    for _, (pool, base, ratio) in c.terms:
        rows = runs[(runs.pool == pool) & (runs.base_size == base) & (runs.ratio == ratio)] if pool == "recon" else []
        if "generated_shapes" in runs and len(rows) and rows.generated_shapes.notna().any():
            row = rows[rows.generated_shapes.notna()].iloc[0]
            out.append({"ratio": ratio, "meshed": int(row.generated_shapes), "asked": int(row.generated_shapes_asked)})
    return out


def per_object_aps(
    seed_dirs: Mapping[int, Path], variants, labels: np.ndarray, object_ids: np.ndarray
) -> tuple[pd.DataFrame, dict[tuple, pd.Series]]:
    """Per network and seed, the AP per test object (:func:`per_object_ap`): a table of their means
    (pool, base_size, ratio, seed, per_object_ap) and (pool, B, R, seed) → AP per object (by object id)."""
    per_object, by_network = [], {}
    for seed, seed_dir in seed_dirs.items():
        for v in variants:
            ap = per_object_ap(labels, test_predictions(seed_dir, (v.pool, v.base_size, v.ratio)), object_ids)
            per_object.append(
                {
                    "pool": v.pool,
                    "base_size": v.base_size,
                    "ratio": float(v.ratio),
                    "seed": seed,
                    "per_object_ap": ap.mean(),
                }
            )
            by_network[v.pool, v.base_size, float(v.ratio), seed] = ap
    return pd.DataFrame(per_object), by_network


def object_improvement(by_network: dict[tuple, pd.Series], base_size: int, ratio: float, seeds) -> pd.Series:
    """Per test object with an AP at both ratios: targeted AP at ``ratio`` minus at 1:0 for base size
    ``base_size``, mean over ``seeds`` (``by_network``: :func:`per_object_aps`)."""
    changes = [by_network["targeted", base_size, ratio, s] - by_network["targeted", base_size, 0.0, s] for s in seeds]
    return pd.concat(changes, axis=1).mean(axis=1).dropna()


def network_table(runs: pd.DataFrame, per_object: pd.DataFrame) -> pd.DataFrame:
    """Per network: test AP mean and 95% t half-width over seeds (NaN where the interval would leave AP's range
    [0, 1]: too few seeds), validation AP mean, per-object mean AP."""
    rows = []
    merged = runs.merge(per_object, on=["pool", "base_size", "ratio", "seed"], how="left")
    for (pool, base, ratio), g in merged.groupby(["pool", "base_size", "ratio"], sort=False):
        t = t_interval(g.test_ap.astype(float), bounds=(0.0, 1.0))
        half = np.nan if t["high"] is None else t["high"] - t["mean"]
        rows.append(
            {
                "pool": pool,
                "base_size": base,
                "ratio": ratio,
                "test_ap": np.nan if t["mean"] is None else t["mean"],
                "test_ap_ci": half,
                "val_ap": g.val_ap.astype(float).mean(),
                "per_object_ap": g.per_object_ap.mean(),
                "test_roc_auc": g.test_roc_auc.mean(),
                "n_seeds": t["n_seeds"],
            }
        )
    return pd.DataFrame(rows)


def ratio_curves(table: pd.DataFrame) -> pd.DataFrame:
    """Test AP by ratio (rows) and curve ``<pool>_<B>`` (columns) of the :func:`network_table`, the ceiling left out."""
    curves = table[table.pool != "ceiling"].assign(curve=lambda t: t.pool + "_" + t.base_size.astype(str))
    return curves.pivot(index="ratio", columns="curve", values="test_ap").reset_index()


def ap_metrics(contrasts: dict, table: pd.DataFrame, chosen: dict[int, float], positive_share: float, seeds) -> dict:
    """The experiment's report (its metrics: :func:`ap_headline`): the contrasts (:func:`evaluate_contrasts`),
    test / validation / per-object AP per pool, base size and ratio (of the :func:`network_table`; None where
    not finite), the ratio chosen on validation AP per base size, the test set's positive share."""
    columns = ["test_ap", "test_ap_ci", "per_object_ap", "val_ap"]

    def value(v):
        return None if v is None or not np.isfinite(v) else round(float(v), 5)

    networks = {
        pool: {
            str(b): {
                f"{r:g}": {k: value(v) for k, v in row.items()} for r, row in g.set_index("ratio")[columns].iterrows()
            }
            for b, g in frame.groupby("base_size")
        }
        for pool, frame in table.groupby("pool")
    }
    return {
        "contrasts": contrasts,
        "networks": networks,
        "chosen_ratio": {str(b): r for b, r in chosen.items()},
        "summary": {str(b): {"best_ratio": r, "chosen_on": "validation AP"} for b, r in chosen.items()},
        "test_positive_share": round(positive_share, 5),
        "seeds": seeds,
    }


def ap_headline(report: dict) -> dict[str, dict]:
    """The experiment's metrics from its :func:`ap_metrics` report: per declared contrast its mean and the one
    interval it is judged by, the 95% interval over seeds × test objects
    (:func:`~graspaug.experiments.stats.headline`), one metrics file each."""
    return {name: headline(c) for name, c in report["contrasts"].items()}
