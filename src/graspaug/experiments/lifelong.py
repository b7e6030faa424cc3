"""The lifelong loop's choices: which objects the planner fails on, and which training
shapes to generate from.

A round scores every *validation* object by the round's networks (the test split never chooses
anything), takes the worst ones and anchors generation at the training shapes nearest to them in
latent space (:class:`graspaug.generation.FailureStream` pairs each anchor with its neighbours).
The anchors are always training shapes: a validation or test object only points at them.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.metrics import average_precision_score
from sklearn.neighbors import NearestNeighbors

from graspaug.errors import DataError

EPS = 1e-6  # probabilities are clipped to [EPS, 1 − EPS] for the log loss


def object_errors(labels: np.ndarray, probability: np.ndarray, object_ids: np.ndarray) -> pd.DataFrame:
    """How badly a network does on each object's datapoints.

    Parameters
    ----------
    labels : (N,) int — 1 for a positive datapoint
    probability : (N,) float — the network's P(success), or the mean over several networks
    object_ids : (N,) str — the object of each datapoint

    Returns
    -------
    DataFrame indexed by object id: ``datapoints``, ``positives``, ``log_loss`` (mean binary
    cross-entropy, nats; defined for every object) and ``ap`` (average precision; NaN for an
    object whose datapoints are all one class)
    """
    labels, p = np.asarray(labels, dtype=int), np.clip(np.asarray(probability, dtype=float), EPS, 1 - EPS)
    if not (len(labels) == len(p) == len(object_ids)):
        raise DataError(f"object_errors: {len(labels)} labels, {len(p)} probabilities, {len(object_ids)} objects")
    frame = pd.DataFrame(
        {"object": object_ids, "label": labels, "loss": -(labels * np.log(p) + (1 - labels) * np.log1p(-p))}
    )
    frame["p"] = p
    rows = {}
    for obj, group in frame.groupby("object", sort=True):
        both = 0 < group.label.sum() < len(group)
        ap = average_precision_score(group.label, group.p) if both else np.nan
        rows[obj] = {
            "datapoints": len(group),
            "positives": int(group.label.sum()),
            "log_loss": group.loss.mean(),
            "ap": ap,
        }
    return pd.DataFrame.from_dict(rows, orient="index").rename_axis("object")


def validation_errors(seed_dirs: Mapping[int, Path], network: str, index: pd.DataFrame) -> tuple[pd.DataFrame, list]:
    """How badly a trained network does on each *validation* object, over its training seeds.

    Parameters
    ----------
    seed_dirs : training seed → the folder of that seed's networks (``val_rows.npy``, ``split.json``,
        ``<network>/val_predictions.npy``); every seed validates on the same datapoints
    network : the network's folder name, ``<pool>/<B>-<R>`` (e.g. ``targeted/50-0``)
    index : the original corpus's index (columns ``label``, ``shape_id``)

    Returns
    -------
    (errors, validation) — :func:`object_errors` of the mean prediction over seeds, worst first
    (:func:`worst_objects` order), and every validation shape id (those without datapoints too)
    """
    rows, predictions = None, []
    for seed, folder in seed_dirs.items():
        path = Path(folder) / network / "val_predictions.npy"
        if not path.is_file():
            raise DataError(f"no validation predictions of network {network!r} for seed {seed}: {path}")
        seed_rows = np.load(Path(folder) / "val_rows.npy")
        if rows is not None and not np.array_equal(rows, seed_rows):
            raise DataError(f"seed {seed} validates on other datapoints than seed {next(iter(seed_dirs))}")
        rows = seed_rows
        predictions.append(np.load(path))
    if rows is None:
        raise DataError("validation_errors: no training seed")
    errors = object_errors(index.label.to_numpy()[rows], np.mean(predictions, axis=0), index.shape_id.to_numpy()[rows])
    validation = json.loads((Path(next(iter(seed_dirs.values()))) / "split.json").read_text())["validation"]
    return errors.loc[worst_objects(errors, len(errors))], list(validation)


def worst_objects(errors: pd.DataFrame, count: int) -> list[str]:
    """The ``count`` objects of :func:`object_errors` with the highest mean log loss, worst first
    (ties: by object id)."""
    ordered = errors.reset_index().sort_values(["log_loss", "object"], ascending=[False, True], kind="stable")
    return list(ordered.object.head(count))


def failure_anchors(pool_z: np.ndarray, failure_z: np.ndarray, per_failure: int) -> tuple[list[int], list[int]]:
    """Training shapes to generate from: for each failure object (in order, worst first) its
    ``per_failure`` nearest shapes of the training pool in latent space, each shape once.

    Parameters
    ----------
    pool_z : (P, D) — latents of the training pool (the only shapes an anchor can be)
    failure_z : (F, D) — latents of the failure objects (validation objects, or a user's meshes)
    per_failure : int — anchors per failure object

    Returns
    -------
    (anchors, served) : lists of int — the anchors as indices into ``pool_z``, worst failure's
    nearest first, and for each the index of the failure object that chose it
    """
    pool_z, failure_z = np.asarray(pool_z, dtype=float), np.asarray(failure_z, dtype=float)
    if len(pool_z) == 0 or len(failure_z) == 0 or per_failure < 1:
        raise DataError(
            f"failure_anchors: {len(pool_z)} training shapes, {len(failure_z)} failures, "
            f"{per_failure} anchors per failure"
        )
    k = min(per_failure, len(pool_z))
    _, nearest = NearestNeighbors(n_neighbors=k).fit(pool_z).kneighbors(failure_z)
    anchors: list[int] = []
    served: list[int] = []
    for f, row in enumerate(nearest):
        for i in map(int, row):
            if i not in anchors:
                anchors.append(i)
                served.append(f)
    return anchors, served


def disjoint(training: Sequence[str], held_out: Sequence[str]) -> None:
    """Raise a :class:`DataError` naming the shapes if any held-out (validation or test) shape is
    in a training set."""
    if leaked := sorted(set(training) & set(held_out)):
        raise DataError(f"held-out shapes in a training set: {leaked[:5]}{' …' if len(leaked) > 5 else ''}")
