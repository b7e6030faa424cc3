"""The report's verdicts on hand-made AP tables: paired per-seed gains against their standard error."""
import pandas as pd

from graspaug.experiments.ap import ap_table, verdicts


def runs_table(rows):
    return pd.DataFrame(rows, columns=["pool", "base_size", "ratio", "seed", "ap"]).assign(accuracy=0.9, roc_auc=0.8)


def test_a_consistent_gain_is_claimed_and_a_noisy_one_is_not():
    rows = []
    for seed, noise in enumerate([0.00, 0.02, -0.02]):
        rows += [("targeted", 50, 0.0, seed, 0.30 + noise), ("targeted", 50, 1.0, seed, 0.34 + noise)]  # +0.04 every seed
        rows += [("targeted", 100, 0.0, seed, 0.30 + noise), ("targeted", 100, 1.0, seed, 0.30 + noise + [0.06, -0.04, 0.01][seed])]
        rows += [("random", 100, 1.0, seed, 0.30 + noise + [0.02, -0.02, 0.0][seed])]
    runs = runs_table(rows)
    table = ap_table(runs)
    assert set(table[table.pool == "random"].ratio) == {0.0, 1.0}  # random shares ratio 0 with targeted
    summary, words = verdicts(runs, table)
    assert summary["50"]["best_ratio"] == 1.0 and summary["50"]["gain"] == 0.04 and summary["50"]["beyond_seed_spread"] is True
    assert summary["50"]["gain_se"] == 0.0 and summary["50"]["seeds"] == 3
    # B = 100: mean gain +0.01, per-seed gains 0.06, -0.04, 0.01 (SE 0.029): within the spread
    assert summary["100"]["best_ratio"] == 1.0 and abs(summary["100"]["gain"] - 0.01) < 1e-9 and summary["100"]["beyond_seed_spread"] is False
    assert "an improvement beyond the seed spread" in words[0] and "not an improvement we can claim" in words[1]
    versus = summary["targeted_vs_random_100"]["1"]
    assert abs(versus["mean"] - 0.01) < 1e-9 and versus["n"] == 3 and versus["beyond_2se"] is False
    assert "targeted has the higher test AP at 1 of 1 ratios" in words[2]


def test_one_seed_makes_no_claim_and_no_gain_is_said_plainly():
    runs = runs_table([("targeted", 50, 0.0, 0, 0.40), ("targeted", 50, 0.5, 0, 0.35), ("targeted", 100, 0.0, 0, 0.30), ("targeted", 100, 0.5, 0, 0.33)])
    summary, words = verdicts(runs, ap_table(runs))
    assert summary["50"]["best_ratio"] == 0.0 and "no augmentation ratio beat" in words[0]
    assert summary["100"]["gain_se"] is None and summary["100"]["beyond_seed_spread"] is False
    assert "with one seed there is no seed spread" in words[1]
