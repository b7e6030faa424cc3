"""Why generated shapes help or not: the GQ-CNN experiment's contrasts over several draws of the
data (``data_seed``) crossed with the paired training seeds, each with one interval that covers
draws, seeds and test objects (:func:`graspaug.experiments.stats.nested_t_interval`), and the
decomposition of the gap between generated and real shapes into steps:

    real ─(recon_vs_real: what the decoder loses)→ recon ─(blend_vs_recon)→ blend
         ─(targeted_vs_blend: what the learned latent space adds over geometric interpolation)→ targeted
    targeted_vs_random: what the selection by rarity and graspness adds

A draw is one experiment (its networks by training seed); every draw is tested on the same test
datapoints (the test split is drawn from ``seed``, not ``data_seed``), so one resample of the test
objects serves every draw, seed and network.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.augment.candidates import ratio_count
from graspaug.errors import DataError
from graspaug.experiments.ap.numbers import (
    Contrast,
    collect,
    datapoint_matched_contrasts,
    declared_contrasts,
    test_predictions,
)
from graspaug.experiments.stats import (
    ObjectBootstrap,
    draw_scope,
    interval_text,
    nested_contrast,
    nested_t_interval,
    ratio_interval,
    share_text,
    verdict,
)
from graspaug.training.variants import network_variant, pool_ratios, seed_variants

STEPS = ("recon_vs_real", "blend_vs_recon", "targeted_vs_blend", "targeted_vs_random")


def draw_contrasts(runs: pd.DataFrame, generate, gqcnn) -> list[Contrast]:
    """The contrasts of one draw (``runs``: :func:`graspaug.experiments.ap.numbers.collect`): the declared
    ones without the validation-chosen ratio (it may differ between draws), and the
    datapoint-matched ones (their weights come from the draw's own datapoint counts)."""
    base_sizes, ratios, augment = generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes
    control = gqcnn.control_ratios
    return declared_contrasts(base_sizes, ratios, augment, {}, gqcnn.pools, control) + datapoint_matched_contrasts(
        runs, base_sizes, ratios, augment, gqcnn.pools, control
    )


def combine_draws(
    draws: Mapping[int, Mapping[int, Path]],
    labels: np.ndarray,
    object_ids: np.ndarray,
    generate,
    gqcnn,
    n_resamples: int,
    seed: int,
) -> dict:
    """Every contrast over all draws and seeds.

    Parameters
    ----------
    draws : data seed → (training seed → the folder of that seed's networks); every draw has the
        same training seeds
    labels, object_ids : (N,) — the test datapoints' labels and objects, in the order of every
        network's ``test_predictions.npy``
    generate, gqcnn : the params sections the draws were run with (only ``data_seed`` differs)
    n_resamples : int — resamples of the test objects
    seed : int — seeds them

    Returns
    -------
    dict — ``contrasts``: name → a :func:`~graspaug.experiments.stats.contrast` over ``draws``
    (:func:`nested_t_interval`) with ``per_draw`` (mean over seeds per draw) and ``meaning``; ``shares``: pool →
    augmented base size → the share of the real-shape gain that the pool gives (its mean gain over no augmentation,
    mean over ratios, divided by the real pool's): ``share``, ``low``, ``high``, ``bounded``
    (:func:`~graspaug.experiments.stats.ratio_interval` over the same object resamples; unbounded, ends None, when
    the real gain's interval holds zero), ``gain``, the pool's gain as a contrast over draws (the declared
    ``<pool>_vs_none@B`` where there is one), and ``real_gain``, the denominator as a contrast over draws;
    ``share``: the targeted pool's; ``draws``, ``seeds``. Every interval uses the same object resamples, so a gain
    quoted twice (a contrast, a share's numerator) has one interval.
    """
    seeds = sorted({s for d in draws.values() for s in d})
    if any(sorted(d) != seeds for d in draws.values()):
        raise DataError("every draw needs the same training seeds")
    variants = seed_variants(
        generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes, False, gqcnn.pools, gqcnn.control_ratios
    )
    runs = {d: collect(seed_dirs, variants) for d, seed_dirs in draws.items()}
    predictions = lambda d, s, key: test_predictions(draws[d][s], key)  # noqa: E731
    return combine_runs(runs, predictions, labels, object_ids, generate, gqcnn, n_resamples, seed)


def combine_runs(
    runs: Mapping[int, pd.DataFrame],
    predictions: Callable[[int, int, tuple], np.ndarray],
    labels: np.ndarray,
    object_ids: np.ndarray,
    generate,
    gqcnn,
    n_resamples: int,
    seed: int,
) -> dict:
    """:func:`combine_draws` from the networks' tables rather than their folders (what ``results/attribution/``
    keeps: :mod:`graspaug.experiments.results`): ``runs``: data seed → :func:`collect`'s table of that draw;
    ``predictions(draw, seed, (pool, B, R))``: (N,) the network's P(success) on the test datapoints. The same
    result, figure for figure."""
    seeds = sorted({int(s) for r in runs.values() for s in r.seed})
    per_draw: dict[int, tuple[pd.DataFrame, dict[str, Contrast]]] = {}
    for d, draw_runs in runs.items():
        per_draw[d] = draw_runs, {c.name: c for c in draw_contrasts(draw_runs, generate, gqcnn)}
    draws = list(runs)
    boot = ObjectBootstrap(object_ids, n_resamples, seed)
    names = [n for n in next(iter(per_draw.values()))[1] if all(n in c for _, c in per_draw.values())]
    cache: dict = {}

    def boot_ap(d: int, s: int, key) -> np.ndarray:
        if (d, s, key) not in cache:
            cache[d, s, key] = boot.average_precision(labels, predictions(d, s, key))
        return cache[d, s, key]

    def arrays(terms_of) -> tuple[np.ndarray, np.ndarray]:
        """(draws, seeds) and (draws, seeds, resamples) of Σ weight × AP over ``terms_of(contrasts of a draw)``."""
        f, r = np.zeros((len(draws), len(seeds))), np.zeros((len(draws), len(seeds), n_resamples))
        for i, (d, (runs, contrasts)) in enumerate(per_draw.items()):
            ap = runs.set_index(["pool", "base_size", "ratio", "seed"]).test_ap.astype(float)
            for j, s in enumerate(seeds):
                terms = terms_of(contrasts)  # none: a declared contrast no network gives (no value, NaN)
                f[i, j] = sum(w * ap.get((*k, s), np.nan) for w, k in terms) if terms else np.nan
                r[i, j] = sum(w * boot_ap(d, s, k) for w, k in terms) if terms else np.nan
        return f, r

    def curve_gain(terms) -> dict:  # a real-curve point: its interval and each draw's mean over seeds
        f, r = arrays(lambda _: terms)
        return nested_t_interval(f, r) | {
            "per_draw": [round(float(v), 5) if np.isfinite(v) else None for v in f.mean(1)]
        }

    full, resampled = {}, {}
    for name in names:
        full[name], resampled[name] = arrays(lambda contrasts, name=name: contrasts[name].terms)

    out = {
        name: nested_contrast(
            nested_t_interval(full[name], resampled[name]),
            per_draw=[round(float(v), 5) if np.isfinite(v) else None for v in full[name].mean(axis=1)],
            meaning=per_draw[next(iter(per_draw))][1][name].meaning,
        )
        for name in names
    }
    shares: dict[str, dict[str, dict]] = {}  # pool → base size → the share of the real-shape gain
    real_ratios = pool_ratios("real", generate.ratios, gqcnn.control_ratios)

    def gain(pool: str, b: int, rs) -> tuple[np.ndarray, np.ndarray]:
        """A pool's gain over no augmentation at base size ``b``, mean over ratios ``rs`` (the contrasts' networks)."""
        return arrays(lambda _: [(1 / len(rs), (pool, b, r)) for r in rs] + [(-1.0, ("targeted", b, 0.0))])

    for b in gqcnn.augment_base_sizes if "real" in gqcnn.pools and real_ratios else ():
        for pool in (p for p in gqcnn.pools if p != "real"):
            own = pool_ratios(pool, generate.ratios, gqcnn.control_ratios)
            rs = [r for r in own if r in real_ratios]  # like with like: the ratios both pools were trained at
            if not rs:
                continue
            (f, r), (real_full, real_resampled) = gain(pool, b, rs), gain("real", b, rs)
            real_gain = nested_contrast(nested_t_interval(real_full, real_resampled))  # the share's denominator
            share = ratio_interval(f, r, real_full, real_resampled)
            declared = out.get(f"{pool}_vs_none@{b}") if list(rs) == list(own) else None  # the same terms: one interval
            pool_gain = declared if declared is not None else nested_contrast(nested_t_interval(f, r))
            shares.setdefault(pool, {})[str(b)] = {
                "share": share["share"],
                "low": share["low"],
                "high": share["high"],
                "bounded": share["bounded"],
                "gain": pool_gain,
                "real_gain": real_gain,
                "shapes": float(np.mean([ratio_count(r, b) for r in rs])),  # the pool's shapes = the real ones added
            }
    return {
        "contrasts": out,
        "real_curve": real_curve(runs, curve_gain),
        "share": shares.get("targeted", {}),
        "shares": shares,
        "draws": list(draws),
        "seeds": seeds,
    }


def real_curve(runs: Mapping[int, pd.DataFrame], gain_of: Callable[[list], dict]) -> dict[str, dict]:
    """The real-shape curve: for every count n of real shapes some network trained on (the base sets without
    augmentation, n = B, and the real pool's networks, n = B + R·B), its AP gain over the smallest base set's network
    as a contrast (``gain_of(terms)``: the :func:`nested_t_interval` of those terms, over the same draws, seeds and
    object resamples as every contrast; networks of equal n averaged) with its two SDs (``replicates_sd``: seeds of
    one draw, or draws; ``objects_sd``), the networks it averages (``networks``) and the mean positive
    datapoints a network of n trained on (``positives``, None where the tables do not say). The positive control
    ``real_data`` is the curve's last base set; the exchange rate reads the curve."""
    table = pd.concat(list(runs.values()), ignore_index=True)
    real = table[(table.ratio == 0) | (table.pool == "real")]
    n_real = real.base_size + [
        ratio_count(r, b) if p == "real" else 0 for p, b, r in zip(real.pool, real.base_size, real.ratio)
    ]
    real = real.assign(n=n_real.astype(int))
    smallest = int(real.base_size[real.ratio == 0].min())
    floor = ("targeted", smallest, 0.0)
    out = {}
    for n, rows in real.groupby("n", sort=True):
        keys = sorted({(p, int(b), float(r)) for p, b, r in zip(rows.pool, rows.base_size, rows.ratio)})
        keys = [("targeted", b, 0.0) if r == 0 else (p, b, r) for p, b, r in keys]
        keys = list(dict.fromkeys(keys))
        positives = None
        if "train_positive_share" in rows and rows.train_positive_share.notna().all():
            positives = round(float((rows.train_datapoints * rows.train_positive_share).mean()), 1)
        raw = None if n == smallest else gain_of([(1 / len(keys), k) for k in keys] + [(-1.0, floor)])
        names = [network_variant(*k).name for k in keys]
        out[str(n)] = {
            "n": int(n),
            "networks": names,
            "gain": None if raw is None else nested_contrast(raw, per_draw=raw.get("per_draw")),
            "replicates_sd": None if raw is None else raw["replicates_sd"],  # the seeds' (one draw) or draws' SD
            "objects_sd": None if raw is None else raw["objects_sd"],
            "positives": positives,
        }
    return out


def curve_lines(curve: Mapping[str, dict]) -> list[str]:
    """The real-shape curve (:func:`real_curve`) as a markdown table: n real shapes, its networks, the AP gain over
    the smallest base set with its 95% interval and verdict, the seeds' SD of that gain, positives per network."""
    lines = [
        "| real shapes | networks | AP gain over the fewest [95%] | seed (or draw) SD | positives per network |",
        "|---|---|---|---|---|",
    ]
    for c in curve.values():
        g = c["gain"]
        gain = "(the floor)" if g is None else f"{interval_text(g)}, {verdict(g)}"
        sd = "-" if c["replicates_sd"] is None else f"{c['replicates_sd']:.4f}"
        positives = "-" if c["positives"] is None else f"{c['positives']:.0f}"
        lines.append(f"| {c['n']} | {', '.join(f'`{n}`' for n in c['networks'])} | {gain} | {sd} | {positives} |")
    return lines


def losing_step(contrasts: Mapping[str, dict], base_size: int) -> str:
    """One sentence: which step of the decomposition (:data:`STEPS`) at ``base_size`` loses the most
    of the real-shape gain, if any step's interval lies below zero."""
    steps = {s: contrasts.get(f"{s}@{base_size}") for s in STEPS}
    below = {
        s: c
        for s, c in steps.items()
        if c and c["mean"] is not None and c["draws_high"] is not None and c["draws_high"] < 0
    }
    if not below:
        shown = [s for s, c in steps.items() if c]
        return (
            f"At B = {base_size} no step ({', '.join(shown) or 'none measured'}) loses AP with its interval below zero."
        )
    worst = min(below, key=lambda s: below[s]["mean"])
    c = below[worst]
    over = f"{c['n_draws']} draws × {c['n_seeds']} seeds" if c["n_draws"] > 1 else f"{c['n_seeds']} seeds of one draw"
    return (
        f"At B = {base_size} the step that loses most is `{worst}`: {c['mean']:+.4f} AP "
        f"[{c['draws_low']:+.4f}, {c['draws_high']:+.4f}] over {over} and the test objects, {verdict(c)}."
    )


def decomposition_markdown(result: dict, augment_base_sizes: Sequence[int], command: str) -> str:
    """The attribution report: every contrast with its interval over draws, seeds and objects, the
    share of the real-shape gain, and per base size the step that loses it. One draw (the ``report``
    stage) says which, and that its intervals do not cover other draws
    (:func:`~graspaug.experiments.stats.draw_scope`)."""
    if len(result["draws"]) > 1:
        design = (
            f"Draws (data_seed) {result['draws']} × training seeds {result['seeds']}; every interval is a 95% "
            "t-interval over the draws' means (seeds within draws) combined with the bootstrap over test objects."
        )
    else:
        design = (
            f"{draw_scope(result['draws'][0], result['seeds'], 'ap')} Every interval is a 95% t-interval over the "
            "seeds combined with the bootstrap over the test objects (none with one seed)."
        )
    lines = [
        "# Why generated shapes help or not: the gap to real shapes, step by step",
        "",
        design + " Command: `" + command + "`.",
        "",
        "| contrast | mean | 95% interval | per draw | meaning |",
        "|---|---|---|---|---|",
    ]
    for name, c in result["contrasts"].items():
        interval = "-" if c["draws_low"] is None else f"[{c['draws_low']:+.4f}, {c['draws_high']:+.4f}]"
        per_draw = ", ".join("-" if v is None else f"{v:+.4f}" for v in c["per_draw"])
        mean = "-" if c["mean"] is None else f"{c['mean']:+.4f}"
        lines.append(f"| `{name}` | {mean} | {interval} | {per_draw} | {c['meaning']} |")
    lines += ["", "## What it says", ""]
    lines += [f"- {share_sentence('targeted', b, s)}" for b, s in result["share"].items()]
    lines += [f"- {losing_step(result['contrasts'], b)}" for b in augment_base_sizes]
    if result.get("real_curve"):
        lines += ["", "## The real-shape curve: AP gain with more real shapes", "", *curve_lines(result["real_curve"])]
    if result.get("shares"):
        lines += ["", "## What to add: each pool's share of the real-shape gain", "", *recommendation(result)]
        lines += [
            "",
            "## The exchange rate: what a pool's shapes are worth in real shapes",
            "",
            *exchange_lines(result),
        ]
    return "\n".join(lines) + "\n"


def exchange_rate(s: dict) -> dict:
    """How many real shapes a pool's shapes are worth at one base size, from its share of the real-shape gain (an
    entry of :func:`combine_runs`'s ``shares``): ``worth`` = share × ``shapes``, the real shapes that the share's
    denominator adds (as many as the pool's shapes), with the share's interval scaled alike (``low``, ``high``;
    None when unbounded: the real shapes' own gain is not clearly nonzero), ``bounded`` and ``shapes``. It reads
    the real-shape curve as a line between B and B + ``shapes`` real shapes: a worth above ``shapes`` is an
    extrapolation beyond that segment."""
    shapes = s.get("shapes")
    if s.get("share") is None or not shapes:
        return {"worth": None, "low": None, "high": None, "bounded": False, "shapes": shapes}
    scale = lambda v: None if v is None else float(v) * shapes  # noqa: E731
    return {
        "worth": scale(s["share"]),
        "low": scale(s["low"]) if s["bounded"] else None,
        "high": scale(s["high"]) if s["bounded"] else None,
        "bounded": bool(s["bounded"]),
        "shapes": shapes,
    }


def exchange_text(rate: dict) -> str:
    """An :func:`exchange_rate` in words: ``N [lo, hi]`` real shapes (``N [unbounded]``; ``n/a`` without one)."""
    if rate["worth"] is None:
        return "n/a"
    if not rate["bounded"]:
        return f"{rate['worth']:+.0f} [unbounded]"
    return f"{rate['worth']:+.0f} [{rate['low']:+.0f}, {rate['high']:+.0f}]"


def exchange_lines(result: dict) -> list[str]:
    """The exchange-rate table of a result (:func:`combine_runs`): per pool, what its shapes at each augmented base
    size are worth in real shapes, with the 95% interval of its share."""
    shares = result.get("shares", {})
    sizes = sorted({b for by_size in shares.values() for b in by_size}, key=int)
    if not sizes:
        return []
    lines = [
        "| pool | " + " | ".join(f"B = {b}: its shapes are worth (real shapes) [95%]" for b in sizes) + " |",
        "|---|" + "---|" * len(sizes),
    ]
    for pool, by_size in shares.items():
        cells = []
        for b in sizes:
            s = by_size.get(b)
            cells.append("-" if s is None else f"{exchange_text(exchange_rate(s))} for {s['shapes']:.0f}")
        lines.append(f"| {pool} | " + " | ".join(cells) + " |")
    return lines + [
        "",
        "N of a pool's shapes are worth W real shapes when they raise AP as much as W more real shapes would, read "
        "off the line between B and B + N real shapes (W = its share × N; the interval is the share's, by test "
        "inversion; unbounded when the real shapes' own gain is not clearly nonzero; W above N extrapolates).",
    ]


def share_sentence(pool: str, base_size, s: dict) -> str:
    """One sentence: ``pool``'s share of the real-shape gain at ``base_size`` (an entry of :func:`combine_draws`'s
    ``shares``) beside its denominator, the real shapes' own gain, and the pool's own gain, each with its interval
    and verdict."""
    real, gain = s["real_gain"], s["gain"]
    share = share_text(s)
    why = "" if s["bounded"] else " (unbounded: the real shapes' gain is not clearly nonzero)"
    return (
        f"B = {base_size}: {pool} shapes give {share}{why} of the real-shape gain (95% interval by test inversion); "
        f"the real shapes' gain {interval_text(real)} AP, {verdict(real)}; {pool}'s own gain "
        f"{interval_text(gain)} AP, {verdict(gain)}."
    )


CONTROLS = {"recon": "control: the new real shapes themselves, decoded"}
"""Pools that need the very real shapes they stand in for: measured, never recommended."""


def recommendation(result: dict) -> list[str]:
    """A markdown table (one line each): per pool of ``result["shares"]`` (:func:`combine_draws`), its share of the
    real-shape gain at every augmented base size with its 95% interval, ordered by the share at the smallest base
    size, and what the pool's own gain over no augmentation says at each base size (``gain``, a contrast over draws,
    in :func:`~graspaug.experiments.stats.verdict`'s words); then, per base size, a sentence a user can act on,
    naming no pool of :data:`CONTROLS`."""

    def text(s: dict | None) -> str:
        if not s or s["share"] is None:
            return "-"
        return share_text(s)

    def says(s: dict | None) -> str:  # the pool's own gain over no augmentation, in the one verdict's words
        return "n/a" if not s or s["gain"]["mean"] is None else verdict(s["gain"])

    def own(s: dict | None) -> str:  # that gain, its interval and its verdict
        return "n/a" if not s or s["gain"]["mean"] is None else f"{interval_text(s['gain'])} AP, {verdict(s['gain'])}"

    shares = result["shares"]
    sizes = sorted({b for by_size in shares.values() for b in by_size}, key=int)

    def at_first(pool: str) -> float:
        share = shares[pool].get(sizes[0], {}).get("share")
        return -np.inf if share is None else share

    order = sorted(shares, key=at_first, reverse=True)
    lines = [
        "| pool | "
        + " | ".join(f"B = {b}: share [95%]" for b in sizes)
        + " | "
        + " | ".join(f"its own gain at B = {b}" for b in sizes)
        + " |",
        "|---|" + "---|" * (2 * len(sizes)),
    ]
    real = {b: next(iter(shares.values()))[b]["real_gain"] for b in sizes}
    lines.append(  # the denominator of every share, beside them
        "| real (as many more real shapes: every share's denominator) | "
        + " | ".join("(the denominator)" for b in sizes)
        + " | "
        + " | ".join(f"{interval_text(real[b])} AP, {verdict(real[b])}" for b in sizes)
        + " |"
    )
    lines += [
        f"| {p}{f' ({CONTROLS[p]})' if p in CONTROLS else ''} | "
        + " | ".join(text(shares[p].get(b)) for b in sizes)
        + " | "
        + " | ".join(own(shares[p].get(b)) for b in sizes)
        + " |"
        for p in order
    ]
    advice = []
    for b in sizes:
        gaining = [p for p in order if says(shares[p].get(b)).startswith("a gain")]
        pools, controls = [p for p in gaining if p not in CONTROLS], [f"`{p}`" for p in gaining if p in CONTROLS]
        if pools:
            best = max(pools, key=lambda p: -np.inf if shares[p][b]["share"] is None else shares[p][b]["share"])
            share = shares[best][b]
            most = (
                f"; {best} adds the most, {share_text(share)} of as many real shapes' gain"
                if share["bounded"]
                else f"; {best}'s share of the real-shape gain is unbounded (that gain is not clearly nonzero)"
            )
            advice.append(f"At B = {b} the pools that add AP with an interval above zero: {', '.join(pools)}{most}.")
        else:
            but = (
                f" (only the control {', '.join(controls)} does, and it needs the new real shapes)" if controls else ""
            )
            none = "no generated or procedural pool tried here adds AP with an interval above zero"
            advice.append(f"At B = {b}, add real shapes: {none}{but}.")
    return lines + [
        "",
        "A share is the pool's AP gain over no augmentation divided by as many real shapes' gain, its 95% interval by "
        "test inversion over the same resamples (unbounded when the real shapes' gain is not clearly nonzero). "
        + " ".join(advice),
    ]
