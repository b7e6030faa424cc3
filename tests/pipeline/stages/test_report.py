"""The report's words and table on hand-made numbers: an interval above zero is a gain, one
that includes zero is not, one seed claims nothing; the ratio is chosen on validation."""

import numpy as np
import pandas as pd
import pytest

from graspaug.experiments.ap.numbers import choose_ratios, network_table
from graspaug.experiments.ap.words import verdict


def contrast(values, boot=(0.01, 0.03)):
    from graspaug.experiments.stats import contrast as stats_contrast
    from graspaug.experiments.stats import t_interval

    t = t_interval(values)
    sd = float(np.std(values, ddof=1)) if len(values) > 1 else None
    return stats_contrast(
        t["mean"], "seeds", t["n_seeds"], seeds=(t["low"], t["high"]), objects=boot, sd=sd, meaning="m"
    )


def test_a_consistent_gain_is_claimed_and_a_noisy_one_is_not():
    assert "a gain in this draw of the data" in verdict("real_data", contrast([0.04, 0.05, 0.045]))
    noisy = verdict("targeted_vs_none@50", contrast([0.06, -0.04, 0.01], boot=(-0.02, 0.03)))
    assert "[-0.1142, +0.1342]" in noisy and "no effect we can claim" in noisy  # one interval, holding zero
    assert noisy.count("[") == 1  # the objects-only interval is not quoted beside it
    assert "a loss in this draw of the data" in verdict(
        "targeted_vs_real@50", contrast([-0.03, -0.04, -0.035], boot=(-0.05, -0.02))
    )
    assert "one seed, no interval" in verdict("x", contrast([0.05]))


def test_the_ratio_is_chosen_on_validation_not_test():
    runs = pd.DataFrame(
        [
            ("targeted", 50, r, s, v, t, 0.8)
            for s in (0, 1)
            for r, v, t in ((0.0, 0.30, 0.30), (0.5, 0.33, 0.28), (1.0, 0.31, 0.40))
        ],
        columns=["pool", "base_size", "ratio", "seed", "val_ap", "test_ap", "test_roc_auc"],
    )
    assert choose_ratios(runs, [50]) == {50: 0.5}  # best validation AP, although 1:1 has the best test AP
    per_object = runs[["pool", "base_size", "ratio", "seed"]].assign(per_object_ap=0.5)
    table = network_table(runs, per_object)
    assert list(table.ratio) == [0.0, 0.5, 1.0] and (table.n_seeds == 2).all()
    assert table.test_ap_ci.iloc[0] == pytest.approx(0.0) and table.per_object_ap.iloc[0] == 0.5
