"""The tables of the generated pools: ``index.parquet`` and ``rejects.parquet`` rows, a base size's summary and
headline, the pools' makeup, and the base set's scores table (what ``generate`` writes beside the meshes)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from graspaug.augment.candidates import Decoded, TargetedStream, above_percentile

ID_LETTERS = {
    "targeted": "t",
    "random": "r",
    "recon": "c",
    "blend": "b",
    "warp": "w",
    "primitives": "p",
    "procedural": "x",
    "own": "o",
    "failure": "f",
}  # gen_<B>_<letter><order>


def pool_tables(
    sources: dict[str, tuple[np.ndarray, np.ndarray]],
    pools: dict[str, tuple[list[Decoded], list[Decoded]]],
    base_size: int,
) -> tuple[list[dict], list[dict]]:
    """Rows of ``index.parquet`` (one per kept shape, pools in the order of ``pools``, each in pool
    order) and of ``rejects.parquet`` for the pools (name → (kept, rejected)) of base size
    ``base_size``; ``sources``: pool name → (shape ids (P,), latents (P, d)) its candidates' parent
    indices point into (the base set; the real pool for ``recon``)."""
    rows, rejects = [], []
    for pool, (kept, rejected) in pools.items():
        ids, z = sources[pool]
        for position, d in enumerate(kept):
            c, m = d.candidate, d.mesh
            order = c.a if pool == "recon" else position  # recon: the real pool's position (a failed decode a gap)
            rows.append(
                {
                    "shape_id": f"gen_{base_size}_{ID_LETTERS[pool]}{order:04d}",
                    "base_size": base_size,
                    "pool": pool,
                    "order": order,
                    "parent_a": ids[c.a],
                    "parent_b": ids[c.b],
                    "alpha": c.alpha,
                    "selected_by": c.selected_by,
                    "z": ((1 - c.alpha) * z[c.a] + c.alpha * z[c.b]).astype(np.float32),
                    "faces": len(m.faces),
                    "vertices": len(m.vertices),
                    "watertight": bool(m.is_watertight),
                    "one_piece": len(m.split(only_watertight=False)) == 1,
                    "volume": float(m.volume),
                    "extent_x": m.extents[0],
                    "extent_y": m.extents[1],
                    "extent_z": m.extents[2],
                    "split": "train",
                    "origin": "generated",
                }
            )
        rejects += [
            {
                "pool": pool,
                "parent_a": ids[d.candidate.a],
                "parent_b": ids[d.candidate.b],
                "alpha": d.candidate.alpha,
                "selected_by": d.candidate.selected_by,
                "reason": d.reason,
            }
            for d in rejected
        ]
    return rows, rejects


def pool_summary(
    base_size: int,
    needed: int,
    pools: dict,
    targeted: TargetedStream,
    index,
    reject_rows: list[dict],
    own: TargetedStream | None = None,
) -> tuple[dict, dict[str, float]]:
    """The ``generate`` stage's metrics for the pools (name → (kept, rejected) Decoded lists), and
    each pool's share of usable decodes. Every pool gets ``kept``, ``tried``, ``kept_share`` and
    its :func:`pool_makeup`; the targeted pool also how its stream was widened, and so does the own pool (``own``: its
    stream, the targeted recipe on the own AutoEncoder-Critic's latents)."""

    reasons = pd.Series([r["reason"].split(":")[0] for r in reject_rows], dtype=object)
    kept_share = {name: len(kept) / max(1, len(kept) + len(rejected)) for name, (kept, rejected) in pools.items()}
    summary: dict = {"base_size": base_size, "pool_size": needed}
    for name, (kept, rejected) in pools.items():
        summary[name] = {
            "kept": len(kept),
            "tried": len(kept) + len(rejected),
            "kept_share": round(kept_share[name], 4),
            **pool_makeup(index[index.pool == name]),
        }
    for name, stream in (("targeted", targeted), ("own", own)):
        if stream is None or name not in summary:
            continue
        rows = index[index.pool == name]
        summary[name] |= {
            "by_rarity": int((rows.selected_by == "rarity").sum()),
            "by_graspness": int((rows.selected_by == "graspness").sum()),
            "k_used": stream.extra,
            "alphas_used": stream.alphas,
            "percentile_used": stream.percentile,
            "widening": stream.notes,
        }
    summary["rejects"] = {str(k): int(v) for k, v in reasons.value_counts().sort_index().items()}
    summary["kept_watertight_one_piece_share"] = round(float((index.watertight & index.one_piece).mean()), 4)
    return summary, kept_share


def pool_makeup(rows) -> dict:
    """What a pool's kept shapes (their ``index.parquet`` rows: ``parent_a``, ``parent_b``, ``alpha``) are
    made of: ``distinct_parents`` (base shapes that parent at least one; for ``primitives``, its assemblies) and
    ``alphas`` (weight → shapes)."""
    parents = set(rows.parent_a) | set(rows.parent_b)
    counts = rows.alpha.value_counts().sort_index()
    return {"distinct_parents": len(parents), "alphas": {f"{a:g}": int(n) for a, n in counts.items()}}


def generate_headline(summary: dict) -> dict[str, float | int]:
    """The stage's metrics from its :func:`pool_summary`: generated ``shapes`` kept (every pool) and the
    share of decoded shapes kept (``kept``)."""
    pools = [v for v in summary.values() if isinstance(v, dict) and "tried" in v]
    kept, tried = sum(p["kept"] for p in pools), sum(p["tried"] for p in pools)
    return {"shapes": kept, "kept": round(kept / tried, 4) if tried else None}


def base_scores_table(base: np.ndarray, rarity: np.ndarray, graspness: np.ndarray, percentile: float):
    """``base.parquet``: the base set's shape ids, rarity (against the base set), graspness and
    whether each was selected by rarity and by graspness at ``percentile`` (the one finally used)."""

    rare, graspable = set(above_percentile(rarity, percentile)), set(above_percentile(graspness, percentile))
    return pd.DataFrame(
        {
            "shape_id": base,
            "rarity": rarity,
            "graspness": graspness,
            "selected_by_rarity": [i in rare for i in range(len(base))],
            "selected_by_graspness": [i in graspable for i in range(len(base))],
        }
    )
