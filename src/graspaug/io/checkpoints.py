"""Network checkpoints: weights plus the settings they were trained with.

A checkpoint is a plain dict (tensors, numbers, strings) so it loads with
``torch.load(..., weights_only=True)``. Loading checks the network settings
against what the caller expects and says what differs.
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from typing import Any

import numpy as np
import torch

from graspaug.errors import CheckpointMismatch
from graspaug.io.atomic import atomic_path
from graspaug.nets.ae_critic import AEConfig, AutoEncoder, Critic

FORMAT = "graspaug.autoencoder/2"  # /2: the critic has no normalization layers
SDF_KEYS = ("output", "truncation")  # in a checkpoint's config only for a decoder of signed distances


def save_autoencoder(
    path: str | os.PathLike, ae: AutoEncoder, critic: Critic | None, train_params: dict[str, Any]
) -> None:
    """Write the AE (and critic) weights with the network config and training params (atomic). An occupancy
    network's config leaves out ``output`` and ``truncation`` (read back as ``occupancy`` and the default
    truncation), so its file is the same, byte for byte, as before a decoder of signed distances existed."""
    config = dataclasses.asdict(ae.cfg)
    if ae.cfg.output == "occupancy":
        config = {k: v for k, v in config.items() if k not in SDF_KEYS}
    state = {
        "format": FORMAT,
        "config": config,
        "train_params": dict(train_params),
        "autoencoder": {k: v.detach().cpu() for k, v in ae.state_dict().items()},
    }
    if critic is not None:
        state["critic"] = {k: v.detach().cpu() for k, v in critic.state_dict().items()}
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        torch.save(state, f)  # a file object: archive names do not depend on the temporary's name


def load_autoencoder(path: str | os.PathLike, expected: AEConfig) -> tuple[AutoEncoder, Critic | None, dict[str, Any]]:
    """Load a checkpoint written by :func:`save_autoencoder`.

    Raises
    ------
    CheckpointMismatch
        naming every setting that differs between the checkpoint and ``expected``.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: no checkpoint (run `dvc repro train_ae`)")
    state = torch.load(path, map_location="cpu", weights_only=True)
    if "critic" in state and state.get("format") != FORMAT:  # the autoencoder's layout is the same in /1
        raise CheckpointMismatch(
            f"{path} holds a critic of format {state.get('format')}, this code reads {FORMAT}; retrain it with `dvc "
            "repro train_ae`"
        )
    saved = AEConfig(**({"output": "occupancy"} | state["config"]))  # no output: an occupancy network's file
    if saved != expected:
        diffs = [
            f"{k}={getattr(saved, k)} (params: {getattr(expected, k)})"
            for k in dataclasses.asdict(saved)
            if getattr(saved, k) != getattr(expected, k)
        ]
        raise CheckpointMismatch(f"{path} was trained with {', '.join(diffs)}; retrain it with `dvc repro train_ae`")
    ae = AutoEncoder(saved)
    ae.load_state_dict(state["autoencoder"])
    critic = None
    if "critic" in state:
        critic = Critic(saved)
        critic.load_state_dict(state["critic"])
    return ae, critic, state["train_params"]


#: /2 adds ``operating_point`` and ``training_range`` (:func:`finish_gqcnn_card`); a /1 card reads with both None.
GQCNN_CARD_FORMAT = "graspaug.gqcnn-card/2"


def gqcnn_card(crop, intrinsics, viewpoints, gripper, label_threshold: float, global_seed: int) -> dict[str, Any]:
    """The part of a GQ-CNN's model card fixed by the rendered data: crop geometry (px), the
    training camera (intrinsics in px, distance in m, tilt in degrees), the gripper (m) and the
    robust-ε label threshold. :func:`finish_gqcnn_card` adds what one network was trained on."""
    from graspaug import __version__

    return {
        "format": GQCNN_CARD_FORMAT,
        "graspaug_version": __version__,
        "crop_size": int(crop.crop_size),
        "out_size": int(crop.out_size),
        "intrinsics": {k: getattr(intrinsics, k) for k in ("width", "height", "fx", "fy", "cx", "cy")},
        "camera_distance": [float(d) for d in viewpoints.distance],
        "camera_tilt_deg": [float(t) for t in viewpoints.tilt_deg],
        "gripper": dataclasses.asdict(gripper),
        "label_threshold": float(label_threshold),
        "global_seed": int(global_seed),
    }


CARD_SAMPLING = ("positive_share", "target_positive_share", "drawn_positive_share", "views_datapoints")
"""How a network's batches were drawn, copied from its summary's ``train`` into its card where there: its training
set's positive share, a ``balanced`` network's target share, the share of positives it drew, a ``views`` network's
extra-view datapoints."""


def finish_gqcnn_card(
    card: dict[str, Any] | None,
    summary: dict[str, Any],
    operating_point: dict[str, Any] | None = None,
    training_range: dict[str, Any] | None = None,
) -> dict[str, Any] | None:
    """``card`` plus the training set (pool, base size, ratio, seed, datapoints, steps, kept step, members, and
    ``gqcnn.train.precision`` as ``precision``: None for a summary written before it was recorded) and the
    validation / test AP of ``summary`` (a network's ``summary.json``), the validation ``operating_point``
    (:func:`operating_point`: a threshold on P(success) chosen on validation predictions)
    and the ``training_range`` of its training data (:func:`training_range`: gripper
    depths and object heights, m); either None where not computed. None stays None."""
    if card is None:
        return None
    train = summary["train"]
    return {
        **card,
        "training_set": {
            "pool": summary["pool"],
            "base_size": summary["base_size"],
            "ratio": summary["ratio"],
            "seed": summary["seed"],
            "datapoints": train.get("datapoints"),
            "steps": train.get("steps"),
            "best_step": train.get("best_step"),
            "members": train.get("members", 1),
            "precision": train.get("precision"),
            **{k: train[k] for k in CARD_SAMPLING if k in train},
        },
        "validation_ap": summary["validation"].get("ap"),
        "test_ap": summary["test"].get("ap"),
        "operating_point": None if operating_point is None else dict(operating_point),
        "training_range": None if training_range is None else dict(training_range),
    }


def operating_point(labels: np.ndarray, probability: np.ndarray) -> dict[str, Any] | None:
    """The validation operating point: the threshold t on P(success) that maximises F1 when a grasp
    with P >= t is predicted to succeed, on a network's *validation* predictions (never test data).

    F1 weighs precision and recall of the successes alone, so the many easy failures of a grasp
    dataset (positives are a minority) do not pull the threshold down; below t the network, at its
    best validation trade-off, calls a grasp a failure. Ties go to the lowest threshold (the most
    permissive floor). Candidate thresholds are the distinct predicted probabilities.

    Parameters
    ----------
    labels : (N,) int — 1 = the validation grasp succeeded, 0 = it failed
    probability : (N,) float — the network's P(success) of each validation grasp

    Returns
    -------
    ``{"rule": "max_f1", "threshold", "f1", "precision", "recall", "positive_share", "datapoints"}``
    (threshold in [0, 1]), or None when the labels hold one class only (no trade-off to choose).
    """
    labels = np.asarray(labels).astype(int).ravel()
    probability = np.asarray(probability, dtype=np.float64).ravel()
    if labels.shape != probability.shape:
        raise ValueError(f"operating_point: {len(labels)} labels but {len(probability)} probabilities")
    if not np.all(np.isfinite(probability)):
        raise ValueError("operating_point: the probabilities hold NaN or inf")
    positives = int(labels.sum())
    if positives == 0 or positives == len(labels):
        return None
    order = np.argsort(-probability, kind="stable")
    p, y = probability[order], labels[order]
    last = np.r_[p[1:] != p[:-1], True]  # the last row of each run of equal scores: threshold p keeps rows up to it
    predicted = np.arange(1, len(p) + 1)[last]
    hits = np.cumsum(y)[last]
    f1 = 2 * hits / (predicted + positives)
    best = int(np.flatnonzero(f1 == f1.max())[-1])  # the lowest threshold among ties (scores run high to low)
    return {
        "rule": "max_f1",
        "threshold": float(p[last][best]),
        "f1": float(f1[best]),
        "precision": float(hits[best] / predicted[best]),
        "recall": float(hits[best] / positives),
        "positive_share": float(positives / len(labels)),
        "datapoints": int(len(labels)),
    }


RANGE_SHARE = 0.95  # the share of a network's training datapoints its card's ranges cover (the central part)


def training_range(images: np.ndarray, z: np.ndarray) -> dict[str, Any]:
    """The range of what a network was trained on, from its training datapoints.

    Parameters
    ----------
    images : (N, S, S) float — the training depth crops, m (the camera's depth of each crop pixel)
    z : (N,) float — the training gripper depths, m (camera z of each grasp center)

    Returns
    -------
    ``{"gripper_depth": [low, high], "object_height": [low, high], "share": 0.95, "datapoints": N}`` in m:
    the central ``share`` of the training datapoints (2.5th to 97.5th percentile), not the extremes, which
    a few tall stable poses decide (the default corpus's train crops: relief 2.1 cm at the 2.5th
    percentile, 6.0 cm median, 8.5 cm at the 97.5th, 34 cm largest). A crop's object height is its
    depth relief, the deepest pixel (the table) minus the nearest (the object's top): the height above
    the table of what the network saw beside the grasp; a lower bound where a crop shows no table (its
    table pixels are at most a centimetre deeper at a 5° tilt). Empty data gives None ranges.
    """
    images = np.asarray(images)
    z = np.asarray(z, dtype=np.float64).ravel()
    if len(images) != len(z):
        raise ValueError(f"training_range: {len(images)} crops but {len(z)} gripper depths")
    if len(z) == 0:
        return {"gripper_depth": None, "object_height": None, "datapoints": 0}
    flat = images.reshape(len(images), -1)
    relief = flat.max(axis=1).astype(np.float64) - flat.min(axis=1)
    tail = 50 * (1 - RANGE_SHARE)  # percent below and above the range

    def central(values: np.ndarray) -> list[float]:
        return [round(float(v), 5) for v in np.percentile(values, [tail, 100 - tail])]

    return {
        "gripper_depth": central(z),
        "object_height": central(relief),
        "share": RANGE_SHARE,
        "datapoints": int(len(z)),
    }


def save_gqcnn(path: str | os.PathLike, net, summary: dict[str, Any], card: dict[str, Any] | None) -> None:
    """Write a GQ-CNN checkpoint (atomic): its config, weights, training summary and model card;
    for a :class:`~graspaug.nets.gqcnn.GQCNNEnsemble` also its number of members."""
    state = {
        "config": dataclasses.asdict(net.config),
        "state_dict": {k: v.detach().cpu() for k, v in net.state_dict().items()},
        "summary": summary,
        "card": card,
    }
    from graspaug.nets.gqcnn import GQCNNEnsemble

    if isinstance(net, GQCNNEnsemble):
        state["members"] = len(net.members)
    with atomic_path(path) as tmp, open(tmp, "wb") as f:
        torch.save(state, f)


def _unreadable(path: Path, exc: Exception) -> str:
    """Why ``torch.load`` could not read ``path``, in the user's words: what the file looks like (not a zip archive:
    no PyTorch save; a truncated archive; a pickle of objects other than tensors and plain values), never torch's
    advice to turn ``weights_only`` off (which would run code from the file)."""
    import zipfile

    if not zipfile.is_zipfile(path):
        return "not the zip archive torch.save writes: a corrupt, truncated or other kind of file"
    if type(exc).__name__ == "UnpicklingError":
        return "a PyTorch save holding objects other than tensors and plain values, which graspaug does not load"
    return f"a damaged PyTorch archive: {type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else 'truncated'}"


def read_gqcnn(path: str | os.PathLike):
    """A trained GQ-CNN (a :class:`~graspaug.nets.gqcnn.GQCNNEnsemble` for a checkpoint of
    several members) on the CPU in eval mode, and its model card (a dict; None for a
    checkpoint written before cards existed)."""
    from graspaug.nets.gqcnn import GQCNN, GQCNNConfig, GQCNNEnsemble

    path = Path(path)
    if path.is_dir():
        inside = sorted(p.relative_to(path).as_posix() for p in path.rglob("model.pt"))[:2]
        hint = f": it holds {' and '.join(inside)}" if inside else ""
        raise CheckpointMismatch(f"model {path}: a folder, not a model.pt file{hint}")
    if not path.is_file():
        raise FileNotFoundError(f"model {path}: no such file (a trained GQ-CNN is a model.pt file)")
    if path.stat().st_size == 0:
        raise CheckpointMismatch(f"model {path}: the file is empty")
    try:
        saved = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - torch raises many types for a file that is no checkpoint
        raise CheckpointMismatch(f"model {path}: not a checkpoint ({_unreadable(path, exc)})") from None
    if not isinstance(saved, dict) or "state_dict" not in saved or "config" not in saved:
        raise CheckpointMismatch(f"model {path}: not a GQ-CNN checkpoint of graspaug (no config and state_dict)")
    config = GQCNNConfig(
        **{"image_input": "depth", **saved["config"]}
    )  # checkpoints older than the option saw the depth crop
    members = saved.get("members")  # only an ensemble's checkpoint has it
    net = GQCNN(config) if members is None else GQCNNEnsemble([GQCNN(config) for _ in range(int(members))])
    net.load_state_dict(saved["state_dict"])
    return net.eval(), saved.get("card")
