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

from graspaug.io.atomic import atomic_path
from graspaug.nets.ae_critic import AEConfig, AutoEncoder, Critic
from graspaug.errors import CheckpointMismatch

FORMAT = "graspaug.autoencoder/2"  # /2: the critic has no normalization layers


def save_autoencoder(path: str | os.PathLike, ae: AutoEncoder, critic: Critic | None, train_params: dict[str, Any]) -> None:
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
        raise CheckpointMismatch(f"{path} holds a critic of format {state.get('format')}, this code reads {FORMAT}; retrain it with `dvc repro train_ae`")
    saved = AEConfig(**state["config"])
    if saved != expected:
        diffs = [f"{k}={getattr(saved, k)} (params: {getattr(expected, k)})" for k in state["config"] if getattr(saved, k) != getattr(expected, k)]
        raise CheckpointMismatch(f"{path} was trained with {', '.join(diffs)}; retrain it with `dvc repro train_ae`")
    ae = AutoEncoder(saved)
    ae.load_state_dict(state["autoencoder"])
    critic = None
    if "critic" in state:
        critic = Critic(saved)
        critic.load_state_dict(state["critic"])
    return ae, critic, state["train_params"]


def load_gqcnn(path: str | os.PathLike):
    """A trained GQ-CNN from ``models/gqcnn/<pool>/<B>-<R>-s<seed>/model.pt``, on the CPU, in eval mode."""
    from graspaug.nets.gqcnn import GQCNN, GQCNNConfig

    saved = torch.load(path, map_location="cpu", weights_only=True)
    net = GQCNN(GQCNNConfig(**saved["config"]))
    net.load_state_dict(saved["state_dict"])
    return net.eval()
