"""The GQ-CNN experiment's declared contrasts and the report's sentences on scale."""

import json

import numpy as np
import pytest

from graspaug.errors import DataError
from graspaug.experiments import ap
from graspaug.experiments.ap import collect, declared_contrasts
from graspaug.experiments.networks import seed_variants


def test_the_declared_contrasts():
    names = [c.name for c in declared_contrasts([50, 200], [0.0, 0.5, 1.0], [50], {50: 0.5})]
    assert names == [
        "real_data",
        "targeted_vs_none@50",
        "targeted_vs_none_chosen@50",
        "targeted_vs_random@50",
        "targeted_vs_real@50",
    ]
    contrasts = {c.name: c for c in declared_contrasts([50, 200], [0.0, 0.5, 1.0], [50], {50: 0.5})}
    assert dict((k, w) for w, k in contrasts["real_data"].terms) == {
        ("targeted", 200, 0.0): 1.0,
        ("targeted", 50, 0.0): -1.0,
    }
    versus = contrasts["targeted_vs_real@50"].terms
    assert sum(w for w, _ in versus) == pytest.approx(0) and {k[0] for _, k in versus} == {"targeted", "real"}
    assert sum(w for w, _ in contrasts["targeted_vs_none@50"].terms) == pytest.approx(0)
    assert [v.name for v in seed_variants([50, 200], [0.0, 1.0], [50], ceiling=True)] == [
        "targeted/50-0",
        "targeted/200-0",
        "targeted/50-1",
        "random/50-1",
        "real/50-1",
        "ceiling",
    ]


def test_gain_sentences_give_shares_and_call_a_gap_within_the_ceilings_interval_no_gap():
    import pandas as pd

    from graspaug.experiments.ap import gain_sentences

    table = pd.DataFrame(
        [
            ("targeted", 50, 0.0, 0.40, 0.02),
            ("targeted", 50, 1.0, 0.42, 0.02),
            ("targeted", 200, 0.0, 0.495, 0.01),
            ("targeted", 200, 1.0, 0.50, 0.01),
            ("ceiling", 0, 0.0, 0.50, 0.01),
        ],
        columns=["pool", "base_size", "ratio", "test_ap", "test_ap_ci"],
    )
    results = {"targeted_vs_none@50": {"mean": 0.02}, "targeted_vs_real@50": {"mean": -0.06}}  # real shapes: +0.08
    lines = gain_sentences(results, table, {50: 1.0, 200: 1.0}, [50], ceiling_shapes=600)
    assert "give 25% of the gain of the same number of real shapes" in lines[0]
    assert "1:1 closes 20% of the gap" in lines[1]  # (0.42 - 0.40) / (0.50 - 0.40)
    assert "no gap for augmentation to close" in lines[2] and "closes" not in lines[2]  # 0.005 < ±0.01: not "100%"
    assert gain_sentences(results, table, {50: 1.0}, [50], ceiling_shapes=None) == lines[:1]
    below = table.assign(test_ap=table.test_ap.where(table.pool != "ceiling", 0.30))
    assert "below 1:0" in gain_sentences(results, below, {50: 1.0}, [], ceiling_shapes=600)[0]


def test_networks_are_read_from_the_seed_folders_given(tmp_path):
    variants = seed_variants([50], [0.0, 1.0], [], ceiling=False)
    seed_dirs = {3: tmp_path / "s3"}
    folder = seed_dirs[3] / "targeted" / "50-0"
    folder.mkdir(parents=True)
    (folder / "summary.json").write_text(json.dumps({"validation": {"ap": 0.5}, "test": {"ap": 0.4, "roc_auc": 0.7}}))
    np.save(folder / "test_predictions.npy", np.array([0.1, 0.9], dtype=np.float32))
    runs = collect(seed_dirs, variants)
    assert runs.to_dict("records") == [
        {
            "pool": "targeted",
            "base_size": 50,
            "ratio": 0.0,
            "seed": 3,
            "val_ap": 0.5,
            "test_ap": 0.4,
            "test_roc_auc": 0.7,
        }
    ]
    # ratio 0 of any pool is the targeted network
    assert ap.test_predictions(seed_dirs[3], ("random", 50, 0.0)).tolist() == pytest.approx([0.1, 0.9])
    with pytest.raises(DataError, match=r"s3/targeted/50-1/summary.json is missing"):
        collect(seed_dirs, seed_variants([50], [0.0, 1.0], [50], ceiling=False))
