"""The lifelong loop's choices (graspaug.experiments.lifelong, graspaug.generation.FailureStream) on hand-made data."""

from collections import Counter

import numpy as np
import pytest

from graspaug.errors import DataError
from graspaug.experiments.lifelong import disjoint, failure_anchors, object_errors, worst_objects
from graspaug.generation import EXTRA_ALPHAS, FailureStream, neighbour_pairs


def test_object_errors_rank_the_object_the_network_gets_wrong_first():
    labels = np.array([1, 0, 1, 0, 1, 1, 0, 0])
    good = np.array([0.9, 0.1, 0.8, 0.2])  # object a: right
    bad = np.array([0.2, 0.3, 0.9, 0.6])  # object b: a positive at 0.2, a negative at 0.9
    objects = np.array(["a"] * 4 + ["b"] * 4)
    errors = object_errors(labels, np.r_[good, bad], objects)
    assert errors.loc["a", "log_loss"] == pytest.approx(-np.mean(np.log([0.9, 0.9, 0.8, 0.8])))
    assert errors.loc["a", "ap"] == 1.0 and errors.loc["b", "ap"] < 1.0
    assert errors.datapoints.tolist() == [4, 4] and errors.positives.tolist() == [2, 2]
    assert worst_objects(errors, 1) == ["b"] and worst_objects(errors, 5) == ["b", "a"]
    one_class = object_errors(np.array([1, 1]), np.array([1.0, 0.5]), np.array(["c", "c"]))
    assert np.isnan(one_class.loc["c", "ap"]) and np.isfinite(one_class.loc["c", "log_loss"])  # clipped at 1
    with pytest.raises(DataError, match="2 labels, 1 probabilities"):
        object_errors(np.array([1, 0]), np.array([0.5]), np.array(["a", "a"]))


def test_failure_anchors_are_the_training_shapes_nearest_each_failure_worst_first():
    pool = np.array([[0.0, 0], [1, 0], [10, 0], [11, 0], [20, 0]])
    failures = np.array([[10.4, 0], [0.2, 0]])  # worst first: near shapes 2 and 3, then near 0 and 1
    assert failure_anchors(pool, failures, 2) == ([2, 3, 0, 1], [0, 0, 1, 1])
    assert failure_anchors(pool, np.array([[10.4, 0], [10.6, 0]]), 2) == ([2, 3], [0, 0])  # each shape once
    assert failure_anchors(pool, failures, 9)[0] == [2, 3, 1, 4, 0]  # at most the pool
    with pytest.raises(DataError, match="0 training shapes"):
        failure_anchors(pool[:0], failures, 1)
    with pytest.raises(DataError, match="0 failures"):
        failure_anchors(pool, failures[:0], 1)


def test_a_held_out_shape_in_a_training_set_is_named():
    disjoint(["a", "b"], ["c"])
    with pytest.raises(DataError, match=r"\['b'\]"):
        disjoint(["a", "b"], ["b", "c"])


def test_the_failure_stream_pairs_only_anchors_with_their_neighbours_and_shares_the_weight_schedule():
    rng = np.random.default_rng(0)
    z = rng.normal(size=(12, 4))
    anchors = [7, 2]
    stream = FailureStream(z, anchors, first=1, extra=2, alphas=[0.5, 0.3])
    pairs = neighbour_pairs(z, 1, 2, anchors)
    assert all(a in anchors for a, _ in pairs) and pairs[0][0] == 7  # rank 1 of the worst anchor first
    items = stream.take(0, 2 * len(pairs))
    assert [(c.a, c.b) for c in items[: len(pairs)]] == pairs and {c.selected_by for c in items} == {"failure"}
    assert Counter(c.alpha for c in items) == {0.5: len(pairs), 0.3: len(pairs)}  # each weight equally often
    more = stream.take(0, 3 * len(pairs))  # dry: the next weight first
    assert len(more) == 3 * len(pairs) and stream.notes[0].startswith(f"alpha {EXTRA_ALPHAS[0]} added")
    assert stream.take(0, 2 * len(pairs)) == items  # what was handed out stays where it was
    everything = stream.take(0, 10_000)  # widened to every neighbour and weight, then exhausted
    assert len({(frozenset((c.a, c.b)), c.alpha) for c in everything}) == len(everything)
    assert any(n.startswith("K widened") for n in stream.notes)


def _seed_folders(tmp_path, predictions: dict[int, list[float]], rows=(0, 1, 2, 3)):
    import json

    folders = {}
    for seed, p in predictions.items():
        folder = tmp_path / f"s{seed}"
        (folder / "targeted/6-0").mkdir(parents=True)
        np.save(folder / "targeted/6-0/val_predictions.npy", np.array(p, np.float32))
        np.save(folder / "val_rows.npy", np.array(rows))
        (folder / "split.json").write_text(json.dumps({"validation": ["a", "b", "c"]}))
        folders[seed] = folder
    return folders


def test_validation_errors_average_the_seeds_predictions_and_rank_worst_first(tmp_path):
    import pandas as pd

    from graspaug.experiments.lifelong import validation_errors

    index = pd.DataFrame({"shape_id": ["a", "a", "b", "b", "t"], "label": [1, 0, 1, 0, 1]})
    folders = _seed_folders(tmp_path, {0: [0.9, 0.1, 0.1, 0.9], 1: [0.7, 0.3, 0.3, 0.5]})
    errors, validation = validation_errors(folders, "targeted/6-0", index)
    assert list(errors.index) == ["b", "a"] and validation == ["a", "b", "c"]  # b: its labels the wrong way round
    expected = object_errors(np.array([1, 0, 1, 0]), np.array([0.8, 0.2, 0.2, 0.7]), np.array(["a", "a", "b", "b"]))
    assert errors.loc["a", "log_loss"] == pytest.approx(expected.loc["a", "log_loss"])
    with pytest.raises(DataError, match="no validation predictions of network 'random/6-1' for seed 0"):
        validation_errors(folders, "random/6-1", index)
    other = _seed_folders(tmp_path / "other", {1: [0.5] * 4}, rows=(0, 1, 2, 4))
    with pytest.raises(DataError, match="seed 1 validates on other datapoints"):
        validation_errors({0: folders[0], 1: other[1]}, "targeted/6-0", index)
