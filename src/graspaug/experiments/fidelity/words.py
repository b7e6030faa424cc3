"""The fidelity experiment in words: report.md's table of every pool's figures with their intervals, and the round
trip's table of graspness kept."""

from __future__ import annotations

import numpy as np
import pandas as pd


def fidelity_markdown(table: pd.DataFrame, base_size: int, reference_count: int) -> str:
    """The fidelity table in words and numbers: value [95% interval] per pool and figure; a figure undefined on the
    pool's shapes (a ratio over 0) reads "undefined: why", one undefined on some resamples is named under the table,
    and one that does not apply to the pool reads "-"."""

    def notes(row) -> dict[str, str]:
        text = row.get("undefined")
        text = text if isinstance(text, str) else ""
        return {note.split(": ", 1)[0]: note.split(": ", 1)[1] for note in text.split("; ") if note}

    def number(v) -> bool:
        return v is not None and not pd.isna(v) and np.isfinite(v)

    def cell(row, f: str, digits: int) -> str:
        v, lo, hi = row[f], row[f"{f}_lo"], row[f"{f}_hi"]
        if not number(v):
            return f"undefined: {notes(row)[f]}" if f in notes(row) else "-"
        interval = f"[{lo:.{digits}f}, {hi:.{digits}f}]" if number(lo) and number(hi) else "[undefined]"
        return f"{v:.{digits}f} {interval}"

    lines = [
        f"# Fidelity of the pools at B = {base_size}, before any training",
        "",
        f"Each pool against {reference_count} held-out real shapes (test split; Chamfer distance on surface points). "
        "Intervals: 95% percentile bootstrap over the pool's shapes and the reference shapes. 1-NNA 0.5 is "
        "indistinguishable from real shapes, 1.0 fully separable; the `real` pool is the control. Kept of parents: "
        "the pool's mean over its parents' (mixed by α as the child mixes them; a recon shape's parent is itself), "
        "graspness and rendered datapoints.",
        "",
        "| pool | shapes | parents | graspness | kept of parents | positive share | datapoints / shape "
        "| datapoints kept of parents | COV | MMD (mm) | 1-NNA | median extents (cm) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for _, row in table.iterrows():
        mmd = "-" if pd.isna(row.mmd) else f"{1e3 * row.mmd:.2f} [{1e3 * row.mmd_lo:.2f}, {1e3 * row.mmd_hi:.2f}]"
        extents = " / ".join(f"{100 * row[e]:.1f}" for e in ("extent_small", "extent_middle", "extent_large"))
        parents = "-" if row.distinct_parents is None or pd.isna(row.distinct_parents) else int(row.distinct_parents)
        lines.append(
            f"| {row.pool} | {row.shapes} | {parents} | {cell(row, 'graspness', 3)} | {cell(row, 'graspness_kept', 2)} "
            f"| {cell(row, 'positive_share', 3)} | {cell(row, 'datapoints_per_shape', 1)} "
            f"| {cell(row, 'datapoints_kept', 2)} | {cell(row, 'coverage', 2)} "
            f"| {mmd} | {cell(row, 'one_nna', 2)} | {extents} |"
        )
    undefined = [f"- {row.pool}: {row['undefined']}." for _, row in table.iterrows() if notes(row)]
    if undefined:
        lines += ["", "Undefined figures (a ratio over 0 on the shapes drawn):", *undefined]
    return "\n".join(lines) + "\n"


def paired_graspness_kept_markdown(rows: pd.DataFrame) -> str:
    """A table of graspness kept, one row per ``variant``, from rows of
    :func:`~graspaug.experiments.fidelity.numbers.paired_graspness_kept` with ``variant``, ``shapes`` and ``meshed``."""

    def number(value, spec):
        return "n/a" if value is None or not np.isfinite(value) else format(value, spec)

    lines = [
        "| variant | shapes | meshed | graspness before → after | kept [95% Fieller] | after − before ± 95% t |",
        "|---|---:|---:|---|---|---|",
    ]
    for r in rows.itertuples():
        kept = f"{number(r.kept, '.1%')} [{number(r.kept_low, '.1%')}, {number(r.kept_high, '.1%')}]"
        diff = f"{number(r.difference, '+.3f')} ± {number(r.difference_half_width, '.3f')}"
        graspness_text = f"{r.graspness_before:.3f} → {r.graspness_after:.3f}"
        lines.append(f"| {r.variant} | {r.shapes} | {r.meshed} | {graspness_text} | {kept} | {diff} |")
    return "\n".join(lines)
