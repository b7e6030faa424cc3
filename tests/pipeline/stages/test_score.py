"""The score tables (graspaug.augment.score_tables) and their handling of corpora without grasps."""

import numpy as np
import pandas as pd
import pytest

from graspaug.augment.score_tables import (
    example_shapes,
    histogram_bars,
    histogram_table,
    score_headline,
    score_summary,
    shape_scores,
)
from graspaug.augment.scores import rarity
from graspaug.errors import DataError


def tables(seed=0):
    rng = np.random.default_rng(seed)
    ids = [f"s{i:02d}" for i in range(12)]
    split = ["train"] * 8 + ["test"] * 4
    shapes = pd.DataFrame({"shape_id": ids, "split": split})
    z = rng.normal(size=(12, 4))
    latents = pd.DataFrame({"shape_id": ids[::-1], "split": split[::-1], "z": list(z[::-1])})  # other order
    grasps = pd.DataFrame({"shape_id": ["s00", "s00", "s03", "s09", "zz"], "success": [True, False, True, False, True]})
    return shapes, latents, grasps, z


def test_scores_follow_the_shapes_and_score_test_shapes_against_train():
    shapes, latents, grasps, z = tables()
    scores = shape_scores(shapes, latents, grasps, k=3)
    assert list(scores.shape_id) == list(shapes.shape_id)
    np.testing.assert_allclose(scores.rarity[:8], rarity(z[:8], 3))
    np.testing.assert_allclose(scores.rarity[8:], rarity(z[:8], 3, query=z[8:]))
    np.testing.assert_allclose(scores.graspness, [0.5, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0])
    assert list(scores.n_grasps[[0, 3, 9]]) == [2, 1, 1] and list(scores.n_success[[0, 3, 9]]) == [1, 1, 0]
    assert scores.n_grasps.sum() == 4  # the grasp of an unknown shape is ignored
    assert example_shapes(scores) == ["s00", "s03"]  # lowest (0.5) and highest (1.0) among train shapes with grasps


def test_no_grasps_and_missing_latents():
    shapes, latents, grasps, _ = tables()
    scores = shape_scores(shapes, latents, grasps.iloc[:0], k=3)
    assert (scores.graspness == 0).all() and example_shapes(scores) == []
    with pytest.raises(DataError, match="have no latent"):
        shape_scores(shapes, latents.iloc[1:], grasps, k=3)


def test_histogram_bars_and_summary():
    shapes, latents, grasps, _ = tables()
    scores = shape_scores(shapes, latents, grasps, k=3)
    counts, edges = histogram_bars(histogram_table(scores.graspness.to_numpy(), 4, 0.0, 1.0))
    np.testing.assert_array_equal(counts, [10, 0, 1, 1])
    np.testing.assert_allclose(edges, [0, 0.25, 0.5, 0.75, 1])
    summary = score_summary(scores[scores.split == "train"])
    assert summary["n_train"] == 8 and summary["train_shapes_without_success"] == 6
    assert summary["graspness_train_mean"] == round(1.5 / 8, 4)
    assert score_headline(summary) == {"shapes": 8, "graspness": round(1.5 / 8, 4)}


def test_empty_grasp_picture_is_still_a_picture(tmp_path):
    from graspaug.plots import grasps_on_shapes

    grasps_on_shapes([], [], [], [], tmp_path / "empty.png", vmax=0.004, threshold=0.002)
    assert (tmp_path / "empty.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
