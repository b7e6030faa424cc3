"""Each arm's networks ranked against the cell's outcomes of the executed calibration grasps: the
datapoints found among every seed's test rows, the AUCs sklearn's, the paired contrasts, the
report's section and the metrics files."""

import numpy as np
import pandas as pd
import pytest
from sklearn.metrics import roc_auc_score

from graspaug.errors import DataError
from graspaug.experiments.cell.numbers import cell_ranking, sim_headline
from graspaug.experiments.cell.words import ranking_lines

CHOSEN = {
    "before": ("targeted", 0.0, 50),
    "after": ("targeted", 1.0, 50),
    "more_real": ("targeted", 0.0, 200),
    "antipodal": (None, None, None),
}
FOLDERS = {"before": "targeted/50-0", "after": "targeted/50-1", "more_real": "targeted/200-0"}


def executed_grasps(rng, n_shapes=40, per_shape=4) -> pd.DataFrame:
    """Executed grasps of test datapoints 100, 102, … (rows in the index), four per shape."""
    n = n_shapes * per_shape
    success = rng.random(n) < 0.5
    return pd.DataFrame(
        {
            "datapoint": 100 + 2 * np.arange(n),
            "shape_id": np.repeat([f"s{k:02d}" for k in range(n_shapes)], per_shape),
            "eps": np.where(success, 0.003, 0.001) + rng.normal(0, 0.002, n),
            "label": success ^ (rng.random(n) < 0.2),
            "executed_success": success,
        }
    )


def write_seeds(tmp_path, grasps, rng, seeds=(0, 1, 2)) -> dict:
    """Seed folders as train_gqcnn writes them: every seed's test rows (its own order, more datapoints
    than were executed) and each network's test predictions. more_real ranks outcomes well, before and
    after barely (the same scores: after is before)."""
    seed_dirs = {}
    for seed in seeds:
        folder = tmp_path / f"s{seed}"
        folder.mkdir()
        rows = rng.permutation(np.arange(80, 500))
        np.save(folder / "test_rows.npy", rows)
        success = pd.Series(grasps.executed_success.to_numpy(float), index=grasps.datapoint).reindex(rows).fillna(0.5)
        noise = rng.normal(0, 1, len(rows))
        scores = {"before": 0.3 * success + noise, "more_real": 2.0 * success + noise}
        scores["after"] = scores["before"]
        for arm, name in FOLDERS.items():
            (folder / name).mkdir(parents=True)
            np.save(folder / name / "test_predictions.npy", scores[arm].to_numpy())
        seed_dirs[seed] = folder
    return seed_dirs


def test_networks_are_scored_on_the_executed_grasps_and_paired_by_seed(tmp_path):
    rng = np.random.default_rng(0)
    grasps = executed_grasps(rng)
    seed_dirs = write_seeds(tmp_path, grasps, rng)
    ranking = cell_ranking(grasps, seed_dirs, CHOSEN, n_boot=500, seed=0)
    assert ranking["n_grasps"] == 160 and ranking["n_objects"] == 40
    assert list(ranking["arms"]) == ["before", "after", "more_real"]  # the antipodal arm has no network
    for seed, folder in seed_dirs.items():  # each datapoint's own prediction, found by its row in the index
        where = pd.Index(np.load(folder / "test_rows.npy")).get_indexer(grasps.datapoint)
        p = np.load(folder / "targeted/200-0/test_predictions.npy")[where]
        want = roc_auc_score(grasps.executed_success, p)
        assert ranking["arms"]["more_real"]["per_seed"][str(seed)] == pytest.approx(want, abs=1e-5)
    real, same = ranking["contrasts"]["real_data"], ranking["contrasts"]["after_vs_before"]
    assert real["objects_low"] > 0 and real["seeds_low"] > 0 and real["n_seeds"] == 3
    assert real["mean"] == pytest.approx(
        ranking["arms"]["more_real"]["auc"] - ranking["arms"]["before"]["auc"], abs=1e-4
    )
    assert same["mean"] == same["objects_low"] == same["objects_high"] == 0  # the same network: no difference, no width
    assert ranking["reference"]["label"] == pytest.approx(
        roc_auc_score(grasps.executed_success, grasps.label), abs=1e-5
    )
    assert "network_vs_antipodal" not in ranking["contrasts"]

    text = "\n".join(ranking_lines(ranking))
    assert "The positive control shows on the 160 executed grasps" in text
    assert "- Augmentation shows no change in the networks' ranking of the cell's outcomes (+0.000" in text
    headline = sim_headline({"contrasts": {}, "ranking": ranking})
    assert set(headline) == {"ranking_real_data", "ranking_after_vs_before"}
    assert headline["ranking_real_data"] == {
        "mean": real["mean"],
        "lo": real["objects_low"],
        "hi": real["objects_high"],
    }


def test_a_grasp_that_is_not_a_test_datapoint_of_a_seed_is_named(tmp_path):
    rng = np.random.default_rng(1)
    grasps = executed_grasps(rng, n_shapes=5)
    seed_dirs = write_seeds(tmp_path, grasps, rng, seeds=(0,))
    grasps.loc[3, "datapoint"] = 7  # not among seed 0's test rows
    with pytest.raises(DataError, match="1 executed calibration grasps are not test datapoints of seed 0"):
        cell_ranking(grasps, seed_dirs, CHOSEN, n_boot=100, seed=0)
    held = cell_ranking(grasps.assign(executed_success=True), seed_dirs, CHOSEN, n_boot=100, seed=0)
    assert held["arms"] == held["contrasts"] == {} and held["reference"] is None  # one outcome: nothing to rank
    assert "had the same outcome" in "\n".join(ranking_lines(held))
    assert sim_headline({"contrasts": {}, "ranking": held}) == {}
