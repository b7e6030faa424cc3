"""Does bfloat16 training keep what float32 training gives? Two finished runs of one project that differ only in
``precision`` (``gqcnn.train`` and ``ae.train``), compared on what the choice may look at: validation, never test.

* **GQ-CNNs**: each network's validation AP, member 0 only (the seed's own network: a run of two members pairs with a
  run of one), paired by training seed and network. The rule, fixed before the comparison (the one bfloat16 passed on
  2026-11-25): keep bfloat16 if the mean paired difference (bfloat16 − float32) over the networks whose training data
  the AutoEncoder does not make (:func:`ae_free`: the 1:0 networks, the ``real`` pool's, the ceiling) is above
  ``-0.005`` AP and its 95% t-interval over paired seeds does not lie wholly below zero (no interval: no verdict).
  The networks of generated pools are shown too; their data changes with the AutoEncoder's precision as well.
* **AutoEncoder**: held-out IoU per test shape (paired) and the ``recon`` pool's graspness and datapoints kept of its
  parents (the ``fidelity`` stage's); the rule: bfloat16's figures lie within float32's 95% intervals.
"""

from __future__ import annotations

import pandas as pd

from graspaug.experiments.stats import (
    ObjectBootstrap,
    contrast,
    interval_text,
    mean_interval,
    paired_contrast,
    t_interval,
)

COMPARED = ("float32", "bfloat16")
"""The two runs compared, reference first."""
RULE_MEAN = -0.005
"""The smallest mean paired difference of validation AP (bfloat16 − float32) that keeps bfloat16."""
RECON_KEPT = ("graspness_kept", "datapoints_kept")
"""The recon pool's figures (the ``fidelity`` stage's table) the AutoEncoder's rule reads."""


def ae_free(network: str) -> bool:
    """Whether the AutoEncoder makes none of ``network``'s training data (``pool/B-R``): a 1:0 network, the ``real``
    pool's, the ceiling."""
    return network.endswith("-0") or network.startswith("real/") or network == "ceiling"


def gqcnn_contrasts(networks: pd.DataFrame) -> dict[str, dict]:
    """Per network (``pool/B-R``) and ``pooled`` (each seed's mean over the :func:`ae_free` networks): the paired
    difference bfloat16 − float32 of validation AP as a :func:`~graspaug.experiments.stats.contrast` over seeds,
    with ``float32`` and ``bfloat16`` (mean AP) and ``per_seed``. ``networks``: one row per run, seed and network,
    columns ``precision`` (``float32`` / ``bfloat16``), ``seed``, ``network``, ``val_ap``."""
    wide = networks.pivot_table(index=["network", "seed"], columns="precision", values="val_ap").dropna()
    wide["diff"] = wide["bfloat16"] - wide["float32"]
    out = {}
    groups = [(n, g) for n, g in wide.groupby(level=0)]
    free = wide[[ae_free(n) for n in wide.index.get_level_values(0)]]
    groups.append(("pooled", free.groupby(level=1).mean()))
    for name, g in groups:
        t = t_interval(g["diff"])
        out[name] = contrast(
            t["mean"],
            "seeds",
            t["n_seeds"],
            seeds=(t["low"], t["high"]),
            float32=float(g["float32"].mean()),
            bfloat16=float(g["bfloat16"].mean()),
            per_seed=[round(float(v), 5) for v in g["diff"]],
        )
    return out


def keeps_bfloat16(pooled: dict) -> bool:
    """The GQ-CNN rule on the ``pooled`` contrast of :func:`gqcnn_contrasts`."""
    high = pooled["seeds_high"]
    return pooled["mean"] is not None and pooled["mean"] > RULE_MEAN and high is not None and high >= 0


def ae_contrasts(ious: pd.DataFrame, n_resamples: int = 2000, seed: int = 0) -> dict[str, dict]:
    """Per AutoEncoder (``ae``: ``ae``, ``ae_critic``...): float32's and bfloat16's held-out IoU, each with its 95%
    bootstrap interval over the test shapes, and their paired difference. ``ious``: one row per AutoEncoder and test
    shape, columns ``ae``, ``shape_id``, ``float32``, ``bfloat16`` (IoU)."""
    out = {}
    for ae, rows in ious.groupby("ae", sort=True):
        boot = ObjectBootstrap(rows.shape_id.to_numpy(), n_resamples, seed)
        a, b = rows["float32"].to_numpy(), rows["bfloat16"].to_numpy()
        out[ae] = {
            "float32": mean_interval(a, boot),
            "bfloat16": mean_interval(b, boot),
            "difference": paired_contrast(b, a, boot),
            "shapes": len(rows),
        }
    return out


def within(value: float, c: dict) -> bool:
    """Whether ``value`` lies within ``c``'s interval (its ``over``), ends included."""
    low, high = c[f"{c['over']}_low"], c[f"{c['over']}_high"]
    return low is not None and high is not None and low <= value <= high


def recon_contrasts(recon: pd.DataFrame) -> dict[str, dict]:
    """The recon pool's :data:`RECON_KEPT` figures per precision (``recon``: one row per precision, the ``fidelity``
    stage's columns ``<figure>``, ``<figure>_lo``, ``<figure>_hi``, and ``precision``), as contrasts over shapes."""
    rows = recon.set_index("precision")
    return {
        f"{figure}/{p}": contrast(
            float(rows.loc[p, figure]), "objects", objects=(rows.loc[p, f"{figure}_lo"], rows.loc[p, f"{figure}_hi"])
        )
        for figure in RECON_KEPT
        for p in COMPARED
    }


def keeps_bfloat16_ae(ae: dict[str, dict], recon: dict[str, dict]) -> bool:
    """The AutoEncoder rule: each AutoEncoder's bfloat16 held-out IoU within float32's interval, and each recon
    figure of bfloat16 within float32's."""
    ious = all(within(r["bfloat16"]["mean"], r["float32"]) for r in ae.values())
    kept = all(within(recon[f"{f}/bfloat16"]["mean"], recon[f"{f}/float32"]) for f in RECON_KEPT)
    return ious and kept


def summarize(networks: pd.DataFrame, ious: pd.DataFrame, recon: pd.DataFrame) -> dict:
    """Every contrast and both verdicts (:mod:`graspaug.experiments.precision`)."""
    gqcnn, ae, kept = gqcnn_contrasts(networks), ae_contrasts(ious), recon_contrasts(recon)
    return {
        "gqcnn": gqcnn,
        "gqcnn_keeps_bfloat16": keeps_bfloat16(gqcnn["pooled"]),
        "ae": ae,
        "recon": kept,
        "ae_keeps_bfloat16": keeps_bfloat16_ae(ae, kept),
    }


def markdown(summary: dict) -> str:
    """The two validation tables and their verdicts."""
    lines = [
        "| GQ-CNN (member 0) | float32 validation AP | bfloat16 | bfloat16 − float32 [95% t over seeds] |",
        "|---|---|---|---|",
    ]
    for name, c in summary["gqcnn"].items():
        label = "pooled: the networks whose data the AutoEncoder does not make" if name == "pooled" else name
        lines.append(f"| {label} | {c['float32']:.3f} | {c['bfloat16']:.3f} | {interval_text(c)} |")
    lines += ["", f"GQ-CNN rule: {'keep' if summary['gqcnn_keeps_bfloat16'] else 'reject'} bfloat16.", ""]
    lines += [
        "| AutoEncoder | float32 held-out IoU | bfloat16 | bfloat16 − float32 [95% over shapes] |",
        "|---|---|---|---|",
    ]
    for name, r in summary["ae"].items():
        f32, bf16, d = (
            interval_text(r[k], spec) for k, spec in zip(COMPARED + ("difference",), (".4f", ".4f", "+.4f"))
        )
        lines.append(f"| {name} | {f32} | {bf16} | {d} |")
    lines += ["", "| recon pool | float32 | bfloat16 |", "|---|---|---|"]
    for figure in ("graspness_kept", "datapoints_kept"):
        f32, bf16 = (interval_text(summary["recon"][f"{figure}/{p}"], ".3f") for p in COMPARED)
        lines.append(f"| {figure.replace('_', ' ')} of parents | {f32} | {bf16} |")
    lines += ["", f"AutoEncoder rule: {'keep' if summary['ae_keeps_bfloat16'] else 'reject'} bfloat16."]
    return "\n".join(lines) + "\n"
