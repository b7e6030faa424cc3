import json
import math

import torch

from graspaug.nets.ae_critic import AEConfig, AutoEncoder, Critic
from graspaug.training.ae_arms import ArmTrainer, rounded_summary, summary_headline

CPU = torch.device("cpu")


def test_an_arm_logs_its_epochs_and_measures_its_weights(tmp_path):
    torch.manual_seed(0)
    cfg = AEConfig(resolution=16, z_dim=8, base_width=4, top_width=8, output="occupancy")
    grids = (torch.rand(6, 1, 16, 16, 16) > 0.5).to(torch.uint8)
    arms = ArmTrainer(tmp_path / "live", grids[:4], grids[4:], CPU)

    def phase(on_epoch):
        for epoch in range(3):
            on_epoch(epoch, {"loss_recon": 1.0 / (epoch + 1)})
        return 12.5

    arms.fit("ae", AutoEncoder(cfg), None, phase, iou_every=2, epochs=3)
    arms.fit("ae_critic", AutoEncoder(cfg), Critic(cfg), phase)
    arm_keys = [f"{arm}_iou_{split}" for arm in ("ae", "ae_critic") for split in ("test", "train")]
    assert list(arms.summary) == ["n_train", "n_test", *arm_keys]
    assert arms.summary["n_train"] == 4 and 0.0 <= arms.summary["ae_iou_test"] <= 1.0
    assert arms.timing["ae_shapes_per_s"] == 12.5 and arms.timing["ae_train_s"] >= 0.0
    iou = (tmp_path / "live/ae/plots/metrics/iou_test.tsv").read_text().splitlines()
    assert [line.split("\t")[0] for line in iou[1:]] == ["1", "2"]  # epochs 2 and 3 (the last)
    assert (tmp_path / "live/ae_critic/plots/metrics/critic_auc.tsv").is_file()


def test_rounded_summary_is_json_without_nan():
    out = rounded_summary({"n": 3, "iou": 0.1234567, "empty": float("nan")})
    assert out == {"n": 3.0, "iou": 0.12346, "empty": None}
    assert json.loads(json.dumps(out)) == out and not any(isinstance(v, float) and math.isnan(v) for v in out.values())


def test_the_headline_is_the_test_iou_of_each_arm_and_the_critics_auc():
    summary = {"n_train": 8.0, "ae_iou_test": 0.8, "ae_iou_train": 0.81, "ae_extra_iou_test": 0.85}
    summary |= {"ae_critic_iou_test": 0.84, "ae_critic_iou_train": 0.9, "critic_auc": None}
    assert summary_headline(summary) == {"iou_ae": 0.8, "iou_extra": 0.85, "iou_critic": 0.84, "auc": None}
