"""The GQ-CNN augmentation experiment's numbers (paper Section IV-C/D): test and validation AP
of every network, pre-declared paired contrasts with t-intervals over seeds and bootstrap
intervals over test objects, the ratio chosen on validation, per-object AP, the report's text.

A network is (pool, base size B, ratio R) of a training seed (see
:mod:`graspaug.training.networks`). A contrast is a fixed linear combination of networks'
test AP, evaluated per seed (paired: the networks of a seed share initial weights, noise and
validation), then summarized over seeds. The contrasts are declared from params before any
network is read:

* ``real_data``: AP(largest B, 1:0) − AP(smallest B, 1:0), the positive control (more real
  shapes must help);
* ``targeted_vs_none@B``: mean over R > 0 of AP(targeted, B, R) − AP(B, 1:0);
* ``targeted_vs_none_chosen@B``: the same at the ratio chosen on mean validation AP;
* ``<a>_vs_<b>@B`` for the pool pairs of :data:`PAIRS` whose pools are trained: mean over R > 0 of
  AP(a, B, R) − AP(b, B, R), equal shape counts (``targeted_vs_random``, ``targeted_vs_real``,
  ``recon_vs_real``: what decoding alone costs, ``targeted_vs_recon``: what interpolation and
  selection add to a decoded shape, ``blend_vs_recon``, ``targeted_vs_blend``: what the latent
  space adds over mixing the same parents' signed distance fields);
* ``<pool>_vs_real_datapoints@B``: the same pools against real shapes at as many training
  datapoints (:func:`datapoint_matched_contrasts`), since a generated shape yields fewer.

The share of the real-shape gain that targeted shapes give has a Fieller interval over seeds
(:func:`gain_sentences`).
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
    ObjectBootstrap,
    draw_scope,
    draw_verdict,
    fieller_interval,
    headline,
    percentile_interval,
    t_interval,
)
from graspaug.io.tables import read_table
from graspaug.training.settings import POOLS
from graspaug.training.variants import network_variant, seed_variants

Key = tuple[str, int, float]  # (pool, base size, ratio); ratio 0 of any pool is ("targeted", B, 0.0)
PAIRS = {  # pool a vs pool b at equal shape counts: what the difference measures
    ("targeted", "random"): "what selecting rare and graspable neighbours adds over random pairs",
    ("targeted", "real"): "generated vs as many more real shapes",
    ("recon", "real"): "what decoding and meshing cost a real shape",
    ("targeted", "recon"): "what interpolation and selection add to a decoded shape",
    ("blend", "recon"): "interpolants made with no network vs decoded real shapes",
    ("targeted", "blend"): "what the learned latent space adds over geometric interpolation of the same pairs",
}


def _key(pool: str, base: int, ratio: float) -> Key:
    return ("targeted" if pool != "ceiling" and ratio == 0.0 else pool, int(base), float(ratio))


@dataclass(frozen=True)
class Contrast:
    """``name`` = Σ weight × AP(network) over ``terms``; ``meaning`` says it in words."""

    name: str
    terms: tuple[tuple[float, Key], ...]
    meaning: str
    chosen_on_validation: bool = field(default=False)


def declared_contrasts(base_sizes, ratios, augment_base_sizes, chosen: dict[int, float], pools=POOLS) -> list[Contrast]:
    """The experiment's contrasts (module docstring); ``chosen``: base size → ratio chosen on
    validation; ``pools``: the pools trained (``gqcnn.pools``)."""
    out, nonzero = [], [float(r) for r in ratios if r > 0]
    small, large = min(base_sizes), max(base_sizes)
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
                f"targeted augmentation vs none at B = {b}, mean over ratios {', '.join(f'1:{r:g}' for r in nonzero)}",
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
        for one, other in PAIRS:
            if nonzero and one in pools and other in pools:
                terms = tuple(
                    t
                    for r in nonzero
                    for t in ((1 / len(nonzero), _key(one, b, r)), (-1 / len(nonzero), _key(other, b, r)))
                )
                words = f"{one} vs {other} shapes at B = {b}, equal counts, mean over ratios: {PAIRS[one, other]}"
                out.append(Contrast(f"{one}_vs_{other}@{b}", terms, words))
    return out


def datapoint_matched_contrasts(runs: pd.DataFrame, base_sizes, ratios, augment_base_sizes, pools) -> list[Contrast]:
    """Per augmented base size B and pool (but ``real``): ``<pool>_vs_real_datapoints@B``, the pool's
    AP minus the AP that real shapes give at as many training datapoints, mean over ratios R > 0.
    The real-shape curve is AP against training datapoints through the real-shape networks (1:0 at
    every base size, ``real`` at B and every R), linear between neighbouring points; the weights
    come from the datapoint counts (the same in every seed: they are design, not outcome). A
    network outside the curve's range, or without a count (``runs.train_datapoints``), gives no
    contrast. So a pool is not penalised for yielding fewer datapoints per shape."""
    counts = runs.groupby(["pool", "base_size", "ratio"]).train_datapoints.first()
    nonzero, out = [float(r) for r in ratios if r > 0], []
    for b in augment_base_sizes:
        curve = [("targeted", int(x), 0.0) for x in base_sizes] + [("real", int(b), r) for r in nonzero]
        points = sorted((float(counts[k]), k) for k in curve if k in counts and pd.notna(counts[k]))
        if len(points) < 2 or "real" not in pools:
            continue
        xs = np.array([x for x, _ in points])
        for pool in (p for p in pools if p != "real"):
            terms: list[tuple[float, Key]] = []
            for r in nonzero:
                key = (pool, int(b), r)
                x = counts.get(key)
                if x is None or pd.isna(x) or not xs[0] <= x <= xs[-1]:
                    terms = []
                    break
                hi = min(int(np.searchsorted(xs, x, side="left")), len(xs) - 1)
                lo = max(hi - 1, 0)
                share = 0.0 if xs[hi] == xs[lo] else (x - xs[lo]) / (xs[hi] - xs[lo])
                n = len(nonzero)
                terms += [(1 / n, key), (-(1 - share) / n, points[lo][1]), (-share / n, points[hi][1])]
            if terms:
                words = (
                    f"{pool} at B = {b} vs real shapes giving as many training datapoints (the real-shape networks' AP "
                    "interpolated in datapoints), mean over ratios"
                )
                out.append(Contrast(f"{pool}_vs_real_datapoints@{b}", tuple(terms), words))
    return out


def network_folder(seed_dir: Path, key: Key) -> Path:
    """The folder of network ``key`` (pool, B, R) in its seed's folder ``seed_dir``."""
    return Path(seed_dir) / network_variant(*key).name


def collect(seed_dirs: Mapping[int, Path], variants) -> pd.DataFrame:
    """One row per network and seed: pool, base_size, ratio, seed, val_ap, test_ap, test_roc_auc,
    train_datapoints (None when its summary does not say).
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


def ceiling_shapes(index: pd.DataFrame, val_shapes: int) -> int:
    """How many train shapes the ceiling trains on: the train shapes of the original corpus's
    ``index`` but the ``val_shapes`` validation shapes."""
    return len(index[index.split == "train"].shape_id.unique()) - val_shapes


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
    variants = seed_variants(base_sizes, ratios, augment_base_sizes, gqcnn.ceiling, gqcnn.pools)
    runs = collect(seed_dirs, variants)
    chosen = choose_ratios(runs, augment_base_sizes)
    contrasts = declared_contrasts(base_sizes, ratios, augment_base_sizes, chosen, gqcnn.pools)
    contrasts += datapoint_matched_contrasts(runs, base_sizes, ratios, augment_base_sizes, gqcnn.pools)
    index = read_table(Path(original) / "index.parquet")
    labels, object_ids = test_labels(index, seed_dirs[next(iter(seed_dirs))])
    results = evaluate_contrasts(contrasts, runs, seed_dirs, labels, object_ids, n_resamples=n_resamples, seed=seed)
    per_object, by_network = per_object_aps(seed_dirs, variants, labels, object_ids)
    table = network_table(runs, per_object)
    return Evaluation(chosen, results, table, by_network, labels, object_ids, ceiling_shapes(index, gqcnn.val_shapes))


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
    """Per contrast: mean over seeds, 95% t-interval over seeds, SD of the per-seed values, and
    a 95% bootstrap interval resampling test objects (the same resamples for every network).
    ``seed_dirs``: training seed → the folder of its networks; ``labels``, ``object_ids`` (N,):
    the test datapoints' labels and objects."""
    seeds = list(seed_dirs)
    boot = ObjectBootstrap(object_ids, n_resamples, seed)
    ap = runs.set_index(["pool", "base_size", "ratio", "seed"]).test_ap.astype(float)  # None (one class) → NaN
    cache: dict = {}

    def boot_ap(key: Key, s: int) -> np.ndarray:
        if (key, s) not in cache:
            cache[key, s] = boot.average_precision(labels, test_predictions(seed_dirs[s], key))
        return cache[key, s]

    out = {}
    for c in contrasts:
        per_seed = [sum(w * ap.get((*k, s), np.nan) for w, k in c.terms) for s in seeds]
        summary = t_interval(per_seed)
        resampled = np.mean([sum(w * boot_ap(k, s) for w, k in c.terms) for s in seeds], axis=0)
        low, high = percentile_interval(resampled)
        finite = [v for v in per_seed if np.isfinite(v)]
        out[c.name] = {
            **{k: (round(v, 5) if isinstance(v, float) else v) for k, v in summary.items()},
            "sd": round(float(np.std(finite, ddof=1)), 5) if len(finite) > 1 else None,
            "boot_low": None if low is None else round(low, 5),
            "boot_high": None if high is None else round(high, 5),
            "per_seed": [round(float(v), 5) if np.isfinite(v) else None for v in per_seed],
            "meaning": c.meaning,
        }
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
    """Per network: test AP mean and 95% t half-width over seeds, validation AP mean, per-object mean AP."""
    rows = []
    merged = runs.merge(per_object, on=["pool", "base_size", "ratio", "seed"], how="left")
    for (pool, base, ratio), g in merged.groupby(["pool", "base_size", "ratio"], sort=False):
        t = t_interval(g.test_ap.astype(float))
        half = np.nan if t["ci_high"] is None else t["ci_high"] - t["mean"]
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
    """The experiment's metrics from its :func:`ap_metrics` report: per declared contrast its mean and
    95% t-interval over seeds (:func:`~graspaug.experiments.stats.headline`), one metrics file each."""
    return {name: headline(c) for name, c in report["contrasts"].items()}


def gain_sentences(
    results: dict, table: pd.DataFrame, chosen: dict[int, float], augment_base_sizes, ceiling_shapes: int | None
) -> list[str]:
    """The report's sentences on scale: per augmented base size, targeted augmentation's gain as
    a share of the same number of real shapes' gain (mean over ratios), and, with the ceiling
    (``ceiling_shapes`` train shapes; None without it), the share of the gap from 1:0 to the
    ceiling that the chosen ratio closes. A gap within the ceiling's 95% t half-width is
    reported as no gap rather than as a share of noise. The share of the real-shape gain has a Fieller
    interval over seeds (:func:`~graspaug.experiments.stats.fieller_interval`); the ceiling's share none."""
    out = []
    for b in augment_base_sizes:
        t, r = results.get(f"targeted_vs_none@{b}"), results.get(f"targeted_vs_real@{b}")
        real_gain = (
            t["mean"] - r["mean"] if t and r and None not in (t["mean"], r["mean"]) else 0.0
        )  # mean over R of AP(real, B, R) - AP(B, 1:0)
        if real_gain:
            gain = np.array([np.nan if v is None else v for v in t["per_seed"]], dtype=float)
            real = gain - np.array([np.nan if v is None else v for v in r["per_seed"]], dtype=float)
            ok = np.isfinite(gain) & np.isfinite(real)
            share = fieller_interval(gain[ok], real[ok])
            interval = (
                f"95% Fieller interval over seeds [{share['ci_low']:.0%}, {share['ci_high']:.0%}]"
                if share["bounded"]
                else "the real-shape gain is not clearly nonzero over seeds, so its Fieller interval is unbounded"
            )
            out.append(
                f"At B = {b}, generated shapes give {t['mean'] / real_gain:.0%} of the gain of the same number of "
                f"real shapes ({t['mean']:+.4f} vs {real_gain:+.4f} AP, mean over ratios; {interval})."
            )
    nets = table.set_index(["pool", "base_size", "ratio"])
    if ceiling_shapes is None or ("ceiling", 0, 0.0) not in nets.index:
        return out
    top, half = nets.test_ap[("ceiling", 0, 0.0)], np.nan_to_num(nets.test_ap_ci[("ceiling", 0, 0.0)])
    for b, ratio in chosen.items():
        none, best = nets.test_ap.get(("targeted", b, 0.0)), nets.test_ap.get(("targeted", b, ratio))
        if none is None or best is None or not np.isfinite(top - none) or not np.isfinite(best):
            continue
        head = f"B = {b}: the ceiling (all {ceiling_shapes} train shapes outside validation) reaches {top:.4f}"
        if abs(top - none) <= half:
            out.append(
                f"{head}, within its 95% interval (±{half:.4f}) of 1:0 ({none:.4f}): no gap for augmentation to close "
                "at this budget."
            )
        elif top < none:
            out.append(
                f"{head}, below 1:0 ({none:.4f}): at this budget more shapes do not raise AP beyond B = {b}; no gap "
                "to close."
            )
        else:
            out.append(
                f"{head}; 1:{ratio:g} closes {(best - none) / (top - none):.0%} of the gap from 1:0 ({none:.4f})."
            )
    return out


def verdict(name: str, c: dict) -> str:
    """One sentence: does the contrast's interval exclude zero, by both intervals; the words scoped to
    the run's one draw of the data (:func:`~graspaug.experiments.stats.draw_verdict`)."""
    if c["mean"] is None:
        return f"`{name}` ({c['meaning']}): no value (a test set with one class?)."
    if c["ci_low"] is None:
        return f"`{name}` ({c['meaning']}): {c['mean']:+.4f} with one seed, no interval; not evidence either way."
    t_side = "above zero" if c["ci_low"] > 0 else ("below zero" if c["ci_high"] < 0 else "includes zero")
    b_side = (
        "above zero" if (c["boot_low"] or 0) > 0 else ("below zero" if (c["boot_high"] or 0) < 0 else "includes zero")
    )
    word = draw_verdict(c["ci_low"], c["ci_high"])
    return (
        f"`{name}` ({c['meaning']}): {c['mean']:+.4f} AP, 95% t-interval over {c['n_seeds']} seeds "
        f"[{c['ci_low']:+.4f}, {c['ci_high']:+.4f}] "
        f"({t_side}), bootstrap over test objects [{c['boot_low']:+.4f}, {c['boot_high']:+.4f}] ({b_side}): {word}."
    )


def improvement_panels(
    base_set: pd.DataFrame,
    generated: pd.DataFrame,
    generated_graspness: np.ndarray,
    test_rarity: np.ndarray,
    test_graspness: np.ndarray,
    improvement: np.ndarray,
) -> list[dict]:
    """Fig. 8's two panels (rarity against the base set, graspness): bin edges, the selected and
    generated shapes' scores, and the mean per-object AP change of the test objects per bin."""
    panels = []
    for name, selected, made, test_values in (
        (
            "rarity (against the base set)",
            base_set.rarity[base_set.selected_by_rarity],
            generated.rarity_vs_base,
            test_rarity,
        ),
        (
            "graspness",
            base_set.graspness[base_set.selected_by_graspness],
            pd.Series(generated_graspness),
            test_graspness,
        ),
    ):
        values = np.concatenate([selected, made, test_values])
        edges = np.linspace(
            0.0 if name == "graspness" else float(np.min(values)), float(np.quantile(values, 0.99)) + 1e-9, 9
        )
        test_values = np.clip(test_values, edges[0], edges[-1])
        bins = np.clip(np.digitize(test_values, edges) - 1, 0, len(edges) - 2)
        means = [float(improvement[bins == b].mean()) if (bins == b).any() else np.nan for b in range(len(edges) - 1)]
        panels.append(
            {
                "name": name,
                "edges": edges,
                "selected": np.asarray(selected),
                "generated": np.asarray(made),
                "improvement": means,
                "objects": [int((bins == b).sum()) for b in range(len(edges) - 1)],
            }
        )
    return panels


def compared_predictions(seed_dir: Path, base_size: int, ratio: float, ceiling: bool) -> dict[str, np.ndarray]:
    """The test predictions (N,) P(success) of the networks the robot trials compare, by label, of the
    seed in ``seed_dir``: targeted at 1:0 and 1:``ratio`` for ``base_size``, and the ceiling when
    trained (``ceiling``)."""
    compared = {
        f"B = {base_size}, 1:0": ("targeted", base_size, 0.0),
        f"B = {base_size}, 1:{ratio:g}": ("targeted", base_size, ratio),
        "ceiling": ("ceiling", 0, 0.0),
    }
    return {name: test_predictions(seed_dir, key) for name, key in compared.items() if ceiling or key[0] != "ceiling"}


def augmentation_set(generated: pd.DataFrame, base_size: int, ratio: float) -> pd.DataFrame:
    """The rows of the generated index ``generated`` (of base size ``base_size``) that the targeted
    network at 1:``ratio`` trains on: the targeted pool's first ``ratio_count(ratio, base_size)``."""
    from graspaug.augment.candidates import ratio_count

    return generated[(generated.pool == "targeted") & (generated.order < ratio_count(ratio, base_size))]


def score_panels(
    improvement: pd.Series,
    base_set: pd.DataFrame,
    generated: pd.DataFrame,
    grasps: pd.DataFrame,
    latents: pd.DataFrame,
    scores: pd.DataFrame,
    k: int,
) -> tuple[list[dict], np.ndarray]:
    """Fig. 8's panels (:func:`improvement_panels`) of the per-object AP change ``improvement`` (by test
    object): the test objects' rarity against the base set (as the selected shapes', ``k`` neighbours)
    and graspness. ``base_set``: the base set with its scores; ``generated``: the augmentation set's
    rows of the generated index; ``grasps``: the generated shapes' grasps (``shape_id``, ``success``);
    ``latents``, ``scores``: by shape id. Also returns the generated shapes' graspness (share of
    successful grasps, 0 without grasps)."""
    from graspaug.augment.scores import rarity

    generated_graspness = grasps.groupby("shape_id").success.mean().reindex(generated.shape_id).fillna(0.0).to_numpy()
    z_base = np.stack(latents.loc[base_set.shape_id, "z"].to_numpy())
    test_rarity = (
        rarity(z_base, min(k, len(z_base) - 1), query=np.stack(latents.loc[improvement.index, "z"].to_numpy()))
        if len(improvement)
        else np.zeros(0)
    )
    panels = improvement_panels(
        base_set,
        generated,
        generated_graspness,
        np.asarray(test_rarity),
        scores.loc[improvement.index, "graspness"].to_numpy(),
        improvement.to_numpy(),
    )
    return panels, generated_graspness


def improvement_data(
    by_network: dict[tuple, pd.Series],
    seeds,
    base_size: int,
    ratio: float,
    base_set: pd.DataFrame,
    generated: pd.DataFrame,
    grasps: pd.DataFrame,
    latents: pd.DataFrame,
    scores: pd.DataFrame,
    k: int,
) -> tuple[pd.Series, pd.DataFrame, list[dict], np.ndarray]:
    """Fig. 8's data: the per-object AP change of 1:``ratio`` over 1:0 at ``base_size``
    (:func:`object_improvement`), the augmentation set (:func:`augmentation_set` of the generated
    index ``generated``), its panels and the generated shapes' graspness (:func:`score_panels`;
    the test objects' rarity against the base set, as the selected shapes', ``k`` neighbours)."""
    improvement = object_improvement(by_network, base_size, ratio, seeds)
    augmentation = augmentation_set(generated, base_size, ratio)
    panels, generated_graspness = score_panels(improvement, base_set, augmentation, grasps, latents, scores, k)
    return improvement, augmentation, panels, generated_graspness


def latent_map(
    latents: pd.DataFrame,
    scores: pd.DataFrame,
    generated: pd.DataFrame,
    generated_graspness: np.ndarray,
    base_size: int,
    perplexity: float,
    seed: int,
) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Fig. 1: t-SNE (N, 2) of the original train shapes' and the generated shapes' latents, their
    graspness (N,) and group names. ``latents`` (``shape_id``, ``split``, ``z``), ``scores`` (by
    shape id): of the original shapes; ``generated``: the augmentation set of base size ``base_size``."""
    from sklearn.manifold import TSNE

    train = latents[latents.split == "train"]
    z = np.concatenate([np.stack(train.z.to_numpy()), np.stack(generated.z.to_numpy())])
    graspness = np.concatenate([scores.loc[train.shape_id, "graspness"].to_numpy(), generated_graspness])
    groups = ["original train"] * len(train) + [f"generated (B = {base_size}, targeted)"] * len(generated)
    xy = TSNE(
        n_components=2, perplexity=min(perplexity, (len(z) - 1) / 3), init="pca", random_state=seed
    ).fit_transform(z)
    return xy, graspness, groups


def _fmt(v, digits: int = 4) -> str:
    return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else f"{v:.{digits}f}"


def training_words(t, members: int = 1) -> str:
    """The training budget of ``gqcnn.train`` (a TrainSettings) and ``gqcnn.members`` in words, for the report."""
    what = (
        "Each network"
        if members == 1
        else f"Each network is an ensemble of {members} GQ-CNNs (their mean P(success)); each member"
    )
    return (
        f"{what} trains {t.epochs:g} passes over its own training set ({t.min_steps}-{t.max_steps} steps of "
        f"{t.batch_size}), "
        f"the learning rate annealed to {t.final_lr:g} of its start, and keeps the weights with the best validation AP."
    )


def report_markdown(
    table: pd.DataFrame,
    contrasts: dict,
    chosen: dict[int, float],
    extras: list[str],
    seeds,
    positive_share: float,
    train_words: str,
    data_seed: int,
) -> str:
    """report.md: the network table, the contrasts with intervals, the verdicts in words (scoped to the
    draw of the data ``data_seed``: :func:`~graspaug.experiments.stats.draw_scope`), the figures."""
    lines = [
        "# GQ-CNN augmentation experiment",
        "",
        "Every number is test Average Precision on every test-split grasp of the original corpus, over training "
        f"seeds {list(seeds)} of one draw of the data (`data_seed` = {data_seed}); "
        f"± is the 95% t-interval half-width over seeds. {train_words} A predictor without skill has AP = the "
        "positive share, "
        f"{positive_share:.4f}. Ratios are chosen on validation AP (train shapes no network trains on), never on the "
        "test set. "
        "Paper (Fig. 7): best ratios 1:0.5, 1:1.5, 1:2 for B = 50, 100, 200.",
        "",
        "| pool | B | ratio | test AP | per-object AP | validation AP | ROC AUC |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in table.itertuples():
        ratio = "all" if r.pool == "ceiling" else f"1:{r.ratio:g}"
        base = "-" if r.pool == "ceiling" else str(r.base_size)
        ci = "" if not np.isfinite(r.test_ap_ci) else f" ± {r.test_ap_ci:.4f}"
        lines.append(
            f"| {r.pool} | {base} | {ratio} | {_fmt(r.test_ap)}{ci} | {_fmt(r.per_object_ap)} | {_fmt(r.val_ap)} | "
            f"{_fmt(r.test_roc_auc)} |"
        )
    lines += [
        "",
        "## Contrasts (declared before any network was read)",
        "",
        "| contrast | mean | 95% t-interval | SD over seeds | 95% bootstrap (objects) |",
        "|---|---|---|---|---|",
    ]
    for name, c in contrasts.items():
        lines.append(
            f"| `{name}` | {_fmt(c['mean'])} | [{_fmt(c['ci_low'])}, {_fmt(c['ci_high'])}] | {_fmt(c['sd'])} | "
            f"[{_fmt(c['boot_low'])}, {_fmt(c['boot_high'])}] |"
        )
    excluding = [n for n, c in contrasts.items() if c["ci_low"] is not None and (c["ci_low"] > 0 or c["ci_high"] < 0)]
    lines += [
        "",
        "## What the numbers say",
        "",
        draw_scope(data_seed, seeds, "ap"),
        "",
        "- Contrasts whose t-interval excludes zero: "
        f"{', '.join(f'`{n}`' for n in excluding) if excluding else 'none'}.",
    ]
    lines += [f"- {verdict(n, c)}" for n, c in contrasts.items()]
    if chosen:
        lines.append(
            "- Ratios chosen on validation AP: " + ", ".join(f"B = {b}: 1:{r:g}" for b, r in chosen.items()) + "."
        )
    lines += [f"- {e}" for e in extras]
    lines += [
        "",
        "![AP vs ratio](ap_vs_ratio.png)",
        "",
        "![Per-object improvement](improvement_by_score.png)",
        "",
        "![t-SNE](tsne_graspness.png)",
        "",
    ]
    return "\n".join(lines)
