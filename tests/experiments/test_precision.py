"""The precision study's rules (graspaug.experiments.precision) on tables whose answer is known."""

import numpy as np
import pandas as pd
import pytest

from graspaug.experiments.precision import ae_contrasts, ae_free, gqcnn_contrasts, keeps_bfloat16, within


def networks(differences: dict[str, list[float]]) -> pd.DataFrame:
    """float32 AP 0.45 everywhere, bfloat16 that plus each network's per-seed difference."""
    rows = []
    for network, diffs in differences.items():
        for seed, d in enumerate(diffs):
            rows.append({"precision": "float32", "seed": seed, "network": network, "val_ap": 0.45})
            rows.append({"precision": "bfloat16", "seed": seed, "network": network, "val_ap": 0.45 + d})
    return pd.DataFrame(rows)


def test_only_the_networks_the_autoencoder_does_not_feed_are_pooled():
    names = ("targeted/50-0", "real/50-1", "ceiling", "targeted/50-1", "recon/50-1")
    assert [ae_free(n) for n in names] == [True, True, True, False, False]
    # a generated pool far below float32 does not move the pooled verdict: its data changed with the AutoEncoder
    c = gqcnn_contrasts(networks({"targeted/50-0": [0.01, 0.0, 0.005, 0.0], "recon/50-1": [-0.1] * 4}))
    assert c["pooled"]["mean"] == pytest.approx(0.00375) and c["recon/50-1"]["mean"] == pytest.approx(-0.1)
    assert keeps_bfloat16(c["pooled"])


@pytest.mark.parametrize(
    ("diffs", "keep"),
    [
        ([0.002, -0.004, 0.001, 0.003], True),  # about zero: kept
        ([-0.006, -0.004, -0.008, -0.005], False),  # mean below -0.005
        ([-0.004, -0.0041, -0.0042, -0.0039], False),  # mean above -0.005 but the interval wholly below zero
        ([-0.004], False),  # one seed: no interval, no verdict to keep
    ],
)
def test_the_gqcnn_rule_keeps_bfloat16_only_near_float32(diffs, keep):
    c = gqcnn_contrasts(networks({"targeted/50-0": diffs, "targeted/200-0": diffs}))
    assert keeps_bfloat16(c["pooled"]) is keep


def test_held_out_iou_is_paired_over_shapes_and_judged_against_float32s_interval():
    rng = np.random.default_rng(0)
    f32 = rng.uniform(0.7, 0.95, 200)
    shapes = [f"s{i}" for i in range(200)]
    ious = pd.DataFrame({"ae": "ae", "shape_id": shapes, "float32": f32, "bfloat16": f32 - 0.002})
    r = ae_contrasts(ious, n_resamples=500)["ae"]
    assert r["difference"]["mean"] == pytest.approx(-0.002)
    # every shape lost exactly 0.002: the paired interval is that point, far narrower than either mean's interval
    assert r["difference"]["objects_low"] == pytest.approx(-0.002) == r["difference"]["objects_high"]
    assert within(r["bfloat16"]["mean"], r["float32"]) and not within(r["float32"]["mean"] - 0.1, r["float32"])
