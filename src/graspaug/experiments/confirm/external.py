"""A confirmatory study's networks read on an external test set (issue #82): the same kept networks of every draw,
one fixed set of objects from another source (``../shared/external/ycb78``), in a folder of its own beside the
study's (``results/<study>-<set>/``), so that the plan's folder holds only what the plan named.

* ``test.parquet`` — the external datapoints (``label``, ``object``), one test set for every draw;
* ``predictions-d<draw>.parquet`` — each of that draw's networks' P(success) of every datapoint, one float32 column
  per network, ``<draw>/<seed>/<pool>/<B>-<R>`` (:func:`~graspaug.experiments.confirm.tables.column`): a file a draw,
  each well under git's comfortable size;
* ``meta.json`` — the arms (name → pool, B, R), the draws, the contrasts (name → [a, b]; the first one the positive
  control), the bootstrap's resamples and seed, the counts, the command, commit, date, wall time and machine.

Two readouts, each a contrast's mean over the draws with the interval of
:func:`~graspaug.experiments.stats.nested_t_interval` (draws as replicates, one seed each, plus the objects'
bootstrap; the draws are paired by draw, never by position):

* ``pooled``: AP over every datapoint (the study's own statistic);
* ``per_object``: the mean over the objects that hold a positive of each object's own AP, so a few objects with
  most positives do not decide it. Which readout a claim reads is fixed by a plan before its data; on a study that
  did not plan it, it is exploratory.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.confirm.numbers import network_values
from graspaug.experiments.confirm.tables import column
from graspaug.experiments.stats import nested_t_interval

FILES = ("test.parquet", "meta.json")  # and predictions-d<draw>.parquet, one a draw
READOUTS = ("pooled", "per_object")


def combine_external(folder: Path) -> dict:
    """The external readouts of a folder (module docstring): per arm its mean AP over the draws, per contrast its
    nested interval, per-draw values and the count of draws it is positive in, for both readouts; the counts."""
    folder = Path(folder)
    missing = [f for f in FILES if not (folder / f).is_file()]
    if missing:
        raise DataError(f"{folder}: lacks {', '.join(missing)} (an external check's folder holds {', '.join(FILES)})")
    meta = json.loads((folder / "meta.json").read_text())
    test = pd.read_parquet(folder / "test.parquet")
    labels, objects = test.label.to_numpy().astype(bool), test.object.to_numpy()
    draws, seed, n = [int(d) for d in meta["draws"]], int(meta.get("seed", 0)), int(meta["n_resamples"])
    missing = [f"predictions-d{d}.parquet" for d in draws if not (folder / f"predictions-d{d}.parquet").is_file()]
    if missing:
        raise DataError(f"{folder}: lacks {', '.join(missing)} (each draw's predictions)")
    predictions = pd.concat([pd.read_parquet(folder / f"predictions-d{d}.parquet") for d in draws], axis=1)
    values: dict[str, dict[str, list]] = {r: {} for r in READOUTS}
    for arm, key in meta["arms"].items():
        rows = {r: [] for r in READOUTS}
        for d in draws:
            name = column(d, 0, (key[0], int(key[1]), float(key[2])))
            if name not in predictions:
                raise DataError(f"{folder}/predictions-d{d}.parquet: no column {name!r} (draw {d}'s {arm} network)")
            for r, v in network_values(labels, objects, predictions[name].to_numpy(), n, seed).items():
                rows[r].append(v)
        for r in READOUTS:
            values[r][arm] = rows[r]
    positives = pd.Series(labels).groupby(objects).sum().sort_values(ascending=False, kind="stable")
    top4 = float(positives.iloc[:4].sum() / max(positives.sum(), 1))
    out = {"draws": draws, "counts": meta["counts"] | {"top4_share": top4}, "contrasts": {}, "arms": {}}
    for r in READOUTS:
        out["arms"][r] = {arm: float(np.mean([v[0] for v in vs])) for arm, vs in values[r].items()}
        pairs = meta["contrasts"].items()
        out["contrasts"][r] = {name: _contrast(values[r][a], values[r][b]) for name, (a, b) in pairs}
    control = next(iter(meta["contrasts"]))
    out["subsets"] = {}
    for subset, keep in subsets(labels, objects, meta.get("object_scale")).items():
        rows = {arm: [] for arm in meta["arms"]}
        for arm, key in meta["arms"].items():
            for d in draws:
                p = predictions[column(d, 0, (key[0], int(key[1]), float(key[2])))].to_numpy()
                rows[arm].append(network_values(labels[keep], objects[keep], p[keep], n, seed)["pooled"])
        a, b = meta["contrasts"][control]
        out["subsets"][subset] = _contrast(rows[a], rows[b]) | {"objects": int(len(set(objects[keep])))}
    for r in READOUTS:
        c = out["contrasts"][r][control]
        c["shows"] = c["low"] is not None and c["low"] > 0
    out["control"] = control
    return out


def subsets(labels: np.ndarray, objects: np.ndarray, scale: Mapping[str, float] | None) -> dict[str, np.ndarray]:
    """The datapoints of the subsets the control is also read on, exploratory (chosen after looking at the pooled
    one): ``without_top4`` (all but the four objects holding the most positives), and where the objects' fit scales
    are known, ``real_size`` (objects kept at their real size) and ``fitted`` (shrunk to fit the gripper)."""
    positives = pd.Series(labels).groupby(objects).sum().sort_values(ascending=False, kind="stable")
    out = {"without_top4": ~np.isin(objects, positives.index[:4])}
    if scale:
        fitted = np.array([scale[o] < 1.0 for o in objects])
        out |= {"real_size": ~fitted, "fitted": fitted}
    return out


def _contrast(a: list, b: list) -> dict:
    """Arm a − arm b, paired by draw: the nested interval over the draws (one seed each) and the objects."""
    full = np.array([[x[0] - y[0]] for x, y in zip(a, b)])  # (D, 1)
    resampled = np.stack([x[1] - y[1] for x, y in zip(a, b)])[:, None, :]  # (D, 1, R)
    c = nested_t_interval(full, resampled)
    per_draw = full[:, 0]
    return c | {"per_draw": [float(v) for v in per_draw], "positive_draws": int((per_draw > 0).sum())}


def external_figures(result: Mapping, study: str) -> dict[str, str]:
    """The figures a document quotes: ``<study>/counts``; per readout (``pooled``, ``per_object``)
    ``<study>/<readout>/<contrast>`` (``mean [low, high]``), its ``/draws`` (``k of D draws positive``), the
    control's ``<study>/<readout>/control/verdict`` (shows / does not show) and ``<study>/<readout>/arm/<arm>``."""
    c = result["counts"]
    out = {
        f"{study}/counts": f"{c['objects']} objects with datapoints ({c['objects_with_positive']} with a positive), "
        f"{c['datapoints']:,} datapoints, {c['positives']:,} positive",
        f"{study}/top4_share": f"{c['top4_share']:.0%}",
    }
    for subset, x in result.get("subsets", {}).items():
        interval = f"{x['mean']:+.4f} [{x['low']:+.4f}, {x['high']:+.4f}]" if x["low"] is not None else "n/a"
        out[f"{study}/subset/{subset}/control"] = f"{interval} on {x['objects']} objects"
    for r in READOUTS:
        for name, x in result["contrasts"][r].items():
            no_interval = f"{x['mean']:+.4f} (no interval: {len(x['per_draw'])} draw)"
            interval = no_interval if x["low"] is None else f"{x['mean']:+.4f} [{x['low']:+.4f}, {x['high']:+.4f}]"
            out[f"{study}/{r}/{name}"] = interval
            out[f"{study}/{r}/{name}/draws"] = f"{x['positive_draws']} of {len(x['per_draw'])} draws positive"
        shows = result["contrasts"][r][result["control"]]["shows"]
        out[f"{study}/{r}/control/verdict"] = "shows" if shows else "does not show"
        out |= {f"{study}/{r}/arm/{arm}": f"{v:.4f}" for arm, v in result["arms"][r].items()}
    return out


def write_external(folder: Path, labels, objects, predictions: Mapping[str, np.ndarray], meta: Mapping) -> None:
    """Write an external check's folder (module docstring): the test datapoints, the predictions, ``meta.json``
    last (a folder without it is an unfinished one)."""
    from graspaug.experiments.kept import write_predictions
    from graspaug.io.atomic import atomic_path

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "meta.json").unlink(missing_ok=True)
    test = pd.DataFrame({"label": np.asarray(labels, dtype=np.int8), "object": np.asarray(objects)})
    with atomic_path(folder / "test.parquet") as tmp:
        test.to_parquet(tmp, index=False)
    for draw in sorted({k.split("/", 1)[0] for k in predictions}, key=int):
        columns = {k: np.asarray(v, dtype=np.float32) for k, v in predictions.items() if k.split("/", 1)[0] == draw}
        write_predictions(columns, folder / f"predictions-d{draw}.parquet")
    with atomic_path(folder / "meta.json") as tmp:
        tmp.write_text(json.dumps(dict(meta), indent=1) + "\n")
