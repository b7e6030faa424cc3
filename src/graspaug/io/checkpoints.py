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

import torch

from graspaug.errors import CheckpointMismatch
from graspaug.io.atomic import atomic_path
from graspaug.nets.ae_critic import AEConfig, AutoEncoder, Critic

FORMAT = "graspaug.autoencoder/2"  # /2: the critic has no normalization layers


def save_autoencoder(
    path: str | os.PathLike, ae: AutoEncoder, critic: Critic | None, train_params: dict[str, Any]
) -> None:
    """Write the AE (and critic) weights with the network config and training params (atomic)."""
    state = {
        "format": FORMAT,
        "config": dataclasses.asdict(ae.cfg),
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
    saved = AEConfig(**state["config"])
    if saved != expected:
        diffs = [
            f"{k}={getattr(saved, k)} (params: {getattr(expected, k)})"
            for k in state["config"]
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


GQCNN_CARD_FORMAT = "graspaug.gqcnn-card/1"


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


def finish_gqcnn_card(card: dict[str, Any] | None, summary: dict[str, Any]) -> dict[str, Any] | None:
    """``card`` plus the training set (pool, base size, ratio, seed, datapoints, steps, kept step, members, and
    ``gqcnn.train.precision`` as ``precision``: None for a summary written before it was recorded) and the
    validation / test AP of ``summary`` (a network's ``summary.json``); None stays None."""
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
        },
        "validation_ap": summary["validation"].get("ap"),
        "test_ap": summary["test"].get("ap"),
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


def read_gqcnn(path: str | os.PathLike):
    """A trained GQ-CNN (a :class:`~graspaug.nets.gqcnn.GQCNNEnsemble` for a checkpoint of
    several members) on the CPU in eval mode, and its model card (a dict; None for a
    checkpoint written before cards existed)."""
    from graspaug.nets.gqcnn import GQCNN, GQCNNConfig, GQCNNEnsemble

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"model {path}: no such file (a trained GQ-CNN is a model.pt file)")
    if path.stat().st_size == 0:
        raise CheckpointMismatch(f"model {path}: the file is empty")
    try:
        saved = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - torch raises many types for a file that is no checkpoint
        why = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else 'truncated'}"
        raise CheckpointMismatch(f"model {path}: not a readable PyTorch checkpoint ({why})") from None
    if not isinstance(saved, dict) or "state_dict" not in saved or "config" not in saved:
        raise CheckpointMismatch(f"model {path}: not a GQ-CNN checkpoint of graspaug (no config and state_dict)")
    config = GQCNNConfig(
        **{"image_input": "depth", **saved["config"]}
    )  # checkpoints older than the option saw the depth crop
    members = saved.get("members")  # only an ensemble's checkpoint has it
    net = GQCNN(config) if members is None else GQCNNEnsemble([GQCNN(config) for _ in range(int(members))])
    net.load_state_dict(saved["state_dict"])
    return net.eval(), saved.get("card")
