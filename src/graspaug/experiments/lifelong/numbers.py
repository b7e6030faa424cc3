"""The lifelong loop's choices and numbers: which objects the planner fails on, which training
shapes to generate from, and what each round's arms gain.

A round scores every *validation* object by the round's networks (the test split never chooses
anything), takes the worst ones and anchors generation at the training shapes nearest to them in
latent space (:class:`graspaug.augment.candidates.FailureStream` pairs each anchor with its neighbours).
The anchors are always training shapes: a validation or test object only points at them."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd
from sklearn.metrics import average_precision_score
from sklearn.neighbors import NearestNeighbors

from graspaug.errors import DataError
from graspaug.experiments.stats import (
    ObjectBootstrap,
    nested_contrast,
    nested_t_interval,
    ratio_interval,
)
from graspaug.training.variants import Variant

ARMS = ("failure", "random", "real")  # what each round of the lifelong loop adds, at equal counts


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


ARM_CONTRASTS = {  # name → (arm a, arm b): AP(a) − AP(b) at one round, paired within a training seed
    "failure_vs_random": ("failure", "random"),
    "failure_vs_real": ("failure", "real"),
    "real_data": ("real", "none"),
    "failure_vs_none": ("failure", "none"),
    "random_vs_none": ("random", "none"),
}


def arm_variant(arm: str, base_size: int, added: int) -> Variant:
    """The network of ``arm`` after ``added`` shapes on a base set of ``base_size``: ``<arm>/<B>-<added / B>``
    (arm ``none``: the base set alone, the ``targeted`` B-0 network)."""
    if arm == "none" or added == 0:
        return Variant("targeted", base_size, 0.0)
    return Variant(arm, base_size, added / base_size)


def arm_contrasts(
    networks: Mapping[int, Mapping[int, Mapping[str, Path]]],
    labels: np.ndarray,
    object_ids: np.ndarray,
    n_resamples: int,
    seed: int,
) -> dict:
    """Every arm's test AP and the :data:`ARM_CONTRASTS` of one round, over data draws × training seeds × test
    objects (:func:`graspaug.experiments.stats.nested_t_interval`; one draw: seeds × objects).

    Parameters
    ----------
    networks : data seed → training seed → arm (``none``, ``failure``, ``random``, ``real``) → the network's
        folder (``test_predictions.npy``) or its (N,) predictions themselves (:func:`network_predictions`; what
        ``results/lifelong/`` keeps); every draw has the same seeds and arms
    labels, object_ids : (N,) — the test datapoints' labels and objects, in the predictions' order
    n_resamples, seed : resamples of the objects, and their seed

    Returns
    -------
    dict — ``ap``: arm → a :func:`~graspaug.experiments.stats.contrast` over ``draws``; ``contrasts``: name → the
    same; ``share``: the share of the real shapes' gain that failure-targeted shapes give
    (:func:`~graspaug.experiments.stats.ratio_interval` over the same object resamples: ``share``, ``low``, ``high``,
    ``bounded``; unbounded when ``real_data``'s interval holds zero), ``draws``, ``seeds``. Every interval uses the
    same object resamples.
    """
    draws = list(networks)
    seeds = sorted(networks[draws[0]])
    arms = list(networks[draws[0]][seeds[0]])
    boot = ObjectBootstrap(object_ids, n_resamples, seed)
    full = np.zeros((len(arms), len(draws), len(seeds)))
    resampled = np.zeros((len(arms), len(draws), len(seeds), n_resamples))
    for i, d in enumerate(draws):
        if sorted(networks[d]) != seeds:
            raise DataError(f"draw {d} has training seeds {sorted(networks[d])}, not {seeds}")
        for j, s in enumerate(seeds):
            for a, arm in enumerate(arms):
                p = network_predictions(networks[d][s][arm])
                full[a, i, j] = average_precision_score(labels, p)
                resampled[a, i, j] = boot.average_precision(labels, p)

    at = {arm: a for a, arm in enumerate(arms)}
    rounded = lambda d: {k: (round(v, 5) if isinstance(v, float) else v) for k, v in d.items()}  # noqa: E731
    out = {
        "ap": {arm: rounded(nested_contrast(nested_t_interval(full[a], resampled[a]))) for arm, a in at.items()},
        "contrasts": {
            name: rounded(
                nested_contrast(nested_t_interval(full[at[a]] - full[at[b]], resampled[at[a]] - resampled[at[b]]))
            )
            for name, (a, b) in ARM_CONTRASTS.items()
            if a in at and b in at
        },
        "draws": draws,
        "seeds": seeds,
    }
    if {"none", "failure", "real"} <= set(at):
        share = ratio_interval(
            full[at["failure"]] - full[at["none"]],
            resampled[at["failure"]] - resampled[at["none"]],
            full[at["real"]] - full[at["none"]],
            resampled[at["real"]] - resampled[at["none"]],
        )
        out["share"] = rounded(share)  # beside it in every report: its denominator, contrasts["real_data"]
    return out


def network_predictions(network) -> np.ndarray:
    """(N,) a network's P(success) on the test datapoints: ``network`` is its folder (``test_predictions.npy``) or
    the predictions themselves (an array)."""
    if isinstance(network, (str, Path)):
        return np.load(Path(network) / "test_predictions.npy")
    return np.asarray(network, dtype=float)


def failure_history(previous: pd.DataFrame | None, round_: int, chosen: Sequence[str]) -> pd.DataFrame:
    """The objects chosen as failures so far: ``previous`` (None at round 0) plus one row per object of
    ``chosen`` (worst first) at ``round_``: ``round``, ``object``, ``rank`` (0: the worst)."""
    rows = pd.DataFrame({"round": round_, "object": list(chosen), "rank": range(len(chosen))})
    return rows if previous is None else pd.concat([previous, rows], ignore_index=True)


def persistent_failures(history: pd.DataFrame) -> pd.DataFrame:
    """Objects of a :func:`failure_history` by how many rounds chose them (most first, then by mean rank):
    ``object``, ``rounds`` (count), ``first`` and ``last`` round, ``mean_rank``."""
    grouped = history.groupby("object").agg(
        rounds=("round", "size"), first=("round", "min"), last=("round", "max"), mean_rank=("rank", "mean")
    )
    return grouped.sort_values(["rounds", "mean_rank"], ascending=[False, True]).reset_index()


def followed_failures(before: pd.DataFrame, after: Mapping[str, pd.DataFrame], chosen: Sequence[str]) -> pd.DataFrame:
    """How the objects ``chosen`` as failures by the last round fare now: one row per object with its
    ``log_loss`` and ``ap`` before (``before``: :func:`object_errors` of the network that chose them) and under
    each arm's network now (``after``: arm → its :func:`object_errors`), as ``<arm>_log_loss`` / ``<arm>_ap``."""
    out = before.loc[list(chosen), ["datapoints", "log_loss", "ap"]].add_prefix("before_")
    for arm, errors in after.items():
        out[f"{arm}_log_loss"] = errors.log_loss.reindex(out.index).to_numpy()
        out[f"{arm}_ap"] = errors.ap.reindex(out.index).to_numpy()
    return out


GAINS = {"failure": "failure_vs_none", "random": "random_vs_none", "real": "real_data"}  # arm → its gain over round 0


def curve_rows(round_: int, result: dict) -> pd.DataFrame:
    """The rows a round appends to the loop's curve, from :func:`arm_contrasts`'s ``result`` at ``round_``: per arm
    its test AP (``figure`` ``ap``) and its paired gain over round 0 (``figure`` ``gain``, :data:`GAINS`; 0 at
    round 0), each as ``round``, ``arm``, ``figure``, ``mean``, ``draws_low``, ``draws_high``."""
    keys = ("mean", "draws_low", "draws_high")
    rows = [{"round": round_, "arm": arm, "figure": "ap", **{k: c[k] for k in keys}} for arm, c in result["ap"].items()]
    for arm, name in GAINS.items():
        gain = {k: 0.0 for k in keys} if round_ == 0 else result["contrasts"].get(name)
        if gain is not None:
            rows.append({"round": round_, "arm": arm, "figure": "gain", **{k: gain[k] for k in keys}})
    return pd.DataFrame(rows)


def round_networks(start: Mapping[int, Path], seed_dirs: Mapping[int, Path], variants: Sequence[Variant]) -> dict:
    """Training seed → arm → network folder of one round, for :func:`arm_contrasts`: ``none`` (the round-0
    network's folder per seed, ``start``) and each arm's variant (in ``ARMS`` order) in its seed's folder."""
    return {
        s: {"none": Path(start[s])} | {a: Path(seed_dirs[s]) / v.name for a, v in zip(ARMS, variants)}
        for s in seed_dirs
    }
