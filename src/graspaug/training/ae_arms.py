"""The ``train_ae`` stage's arms: one training phase of one model, logged to DVCLive per epoch.

An arm is a phase (:func:`~graspaug.training.autoencoder.train_autoencoder` or
:func:`~graspaug.training.autoencoder.train_ae_critic`, given as a function of its epoch callback)
run on one model; :class:`ArmTrainer` logs its epochs, times it and measures its reconstruction IoU.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path

import torch

from graspaug.nets.ae_critic import AutoEncoder, Critic
from graspaug.training.autoencoder import EpochCallback, critic_separation, reconstruction_iou

Phase = Callable[[EpochCallback], float]  # runs a training phase with this epoch callback, returns shapes/s


class ArmTrainer:
    """Trains arms on the ``train`` grids and measures them on the ``test`` grids.

    Parameters
    ----------
    live_dir : folder of the DVCLive logs; arm ``name`` logs to ``live_dir / name``.
    train, test : (N, 1, R, R, R) uint8 grids of the two splits.
    device : where the models run.

    Attributes
    ----------
    summary : ``n_train``, ``n_test`` and per arm ``<name>_iou_test``, ``<name>_iou_train`` (mean IoU, 0..1;
        NaN for an empty split), in the order the arms ran.
    timing : per arm ``<name>_shapes_per_s`` (training throughput) and ``<name>_train_s`` (seconds).
    """

    def __init__(self, live_dir: Path, train: torch.Tensor, test: torch.Tensor, device: torch.device) -> None:
        self.live_dir, self.train, self.test, self.device = Path(live_dir), train, test, device
        self.summary: dict[str, float] = {"n_train": len(train), "n_test": len(test)}
        self.timing: dict[str, float] = {}

    def _logger(
        self, live, model: AutoEncoder, critic: Critic | None, iou_every: int, epochs: int, latest: dict
    ) -> EpochCallback:
        """The epoch callback of one arm: its metrics to ``live``, the test IoU every ``iou_every``-th of the
        ``epochs`` epochs and at the last (kept in ``latest``), and the critic's separation when it has one."""
        test, device = self.test, self.device

        def on_epoch(epoch: int, metrics: dict[str, float]) -> None:
            latest.clear()  # the test IoU of the weights as they are now, when this epoch computed it
            for key, value in metrics.items():
                live.log_metric(key, value)
            # every `iou_every`-th epoch and the last (each costs a pass over the test split)
            if (epoch + 1) % iou_every == 0 or epoch + 1 == epochs:
                latest["iou_test"] = reconstruction_iou(model, test, device)
                live.log_metric("iou_test", latest["iou_test"])
            if critic is not None:  # held-out real grids vs held-out interpolants
                separation = critic_separation(model, critic, test, device)
                live.log_metric("critic_auc", separation["auc"])
                live.log_metric("critic_real", separation["real_mean"])
                live.log_metric("critic_interp", separation["interp_mean"])
            live.next_step()

        return on_epoch

    def fit(
        self, name: str, model: AutoEncoder, critic: Critic | None, phase: Phase, iou_every: int = 1, epochs: int = 0
    ) -> None:
        """Run ``phase`` (training ``model``, and ``critic`` when not None) as arm ``name``, logging every epoch,
        then add its timing and its final weights' test and train IoU to :attr:`timing` and :attr:`summary`.
        ``epochs``: the phase's epoch count (its last epoch measures the test IoU whatever ``iou_every``)."""
        from dvclive import Live

        with Live(str(self.live_dir / name), dvcyaml=False, save_dvc_exp=False) as live:
            t0 = time.perf_counter()
            latest: dict[str, float] = {}
            self.timing[f"{name}_shapes_per_s"] = phase(self._logger(live, model, critic, iou_every, epochs, latest))
            self.timing[f"{name}_train_s"] = time.perf_counter() - t0
        # the last epoch already measured the final weights' test IoU (not with zero epochs)
        self.summary[f"{name}_iou_test"] = (
            latest["iou_test"] if "iou_test" in latest else reconstruction_iou(model, self.test, self.device)
        )
        self.summary[f"{name}_iou_train"] = reconstruction_iou(model, self.train, self.device)


def rounded_summary(summary: dict[str, float]) -> dict[str, float | None]:
    """``summary`` rounded to 5 decimals as floats, NaN (e.g. the IoU of an empty test split; not JSON) as None."""
    return {k: round(float(v), 5) if math.isfinite(v) else None for k, v in summary.items()}


def summary_headline(summary: dict[str, float | None]) -> dict[str, float | None]:
    """The stage's metrics from its :func:`rounded_summary`: the test IoU of each arm (``iou_ae``,
    ``iou_extra``: the λ = 0 control, ``iou_critic``) and the critic's held-out ROC AUC (``auc``)."""
    arms = {"iou_ae": "ae", "iou_extra": "ae_extra", "iou_critic": "ae_critic"}
    return {**{key: summary.get(f"{arm}_iou_test") for key, arm in arms.items()}, "auc": summary.get("critic_auc")}


def fit_ae_critic(
    live_dir: Path, train: torch.Tensor, test: torch.Tensor, net, cfg, device: torch.device, seed: int
) -> tuple[AutoEncoder, Critic, ArmTrainer]:
    """An AutoEncoder of config ``net`` (phase 1, arm ``ae``), then the AE-Critic from it (phase 2, arm
    ``ae_critic``; no λ = 0 control), trained on the ``train`` grids with ``cfg`` (AETrainConfig) as ``train_ae``
    trains them, random numbers from ``seed``; returns (AE, critic, the :class:`ArmTrainer` with their figures)."""
    from graspaug.training.autoencoder import train_ae_critic, train_autoencoder

    torch.manual_seed(seed)
    gen = torch.Generator().manual_seed(seed)
    arms, ae, critic = ArmTrainer(live_dir, train, test, device), AutoEncoder(net), Critic(net)
    arms.fit("ae", ae, None, lambda cb: train_autoencoder(ae, train, cfg, device, gen, cb), 5, cfg.epochs_ae)
    arms.fit("ae_critic", ae, critic, lambda cb: train_ae_critic(ae, critic, train, cfg, device, gen, cb))
    return ae, critic, arms
