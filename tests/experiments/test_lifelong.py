"""The lifelong loop's choices (graspaug.experiments.lifelong.numbers, graspaug.augment.candidates.FailureStream) on
hand-made data."""

from collections import Counter

import numpy as np
import pytest

from graspaug.augment.candidates import EXTRA_ALPHAS, FailureStream, neighbour_pairs
from graspaug.errors import DataError
from graspaug.experiments.lifelong.numbers import disjoint, failure_anchors, object_errors, worst_objects
from graspaug.experiments.stats import contrast


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

    from graspaug.experiments.lifelong.numbers import validation_errors

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


def test_rounds_name_the_round_they_follow_and_none_is_missing():
    from graspaug.pipeline.params.model import ParamsError, params_dict, parse_params
    from graspaug.pipeline.params.profiles import merge

    def rounds(value):
        return parse_params(merge(params_dict(), {"lifelong": {"rounds": value}})).lifelong

    assert rounds({"r1": "r0", "r2": "r1"}).round_numbers() == [1, 2] and rounds({}).round_numbers() == []
    for bad in ({"r2": "r1"}, {"r1": "r1"}, {"round1": "r0"}, {"r0": "r-1"}):
        with pytest.raises(ParamsError, match="lifelong.rounds"):
            rounds(bad)


def test_each_round_adds_new_shapes_to_each_arm_and_never_a_pair_and_weight_made_before():
    import pandas as pd
    import trimesh

    from graspaug.augment.candidates import Decoded, candidate_key
    from graspaug.augment.failures import loop_shapes
    from graspaug.augment.pools import BaseSet
    from graspaug.augment.scores import rarity
    from graspaug.pipeline.params.generate import GenerateParams

    box = trimesh.creation.box(extents=(0.04, 0.03, 0.02))
    rng = np.random.default_rng(0)
    z = rng.normal(size=(8, 4)).astype(np.float32)
    base = BaseSet(np.array([f"s{i}" for i in range(8)]), z, rarity(z, 3), rng.random(8), np.full(8, 0.002))
    cfg = GenerateParams(base_sizes=(8,), first_neighbour=1, extra_neighbours=1, alphas=(0.5, 0.3))

    def every_box(batch):
        return [Decoded(c, np.zeros(1, np.uint8), box, None) for c in batch]

    made, keys = None, {"failure": set(), "random": set()}
    for round_ in (1, 2, 3):  # the same anchor every round: its stream must move on
        index, _, kept, _ = loop_shapes(base, [0], ["val_7"], made, 3, cfg, every_box, rng, round_)
        assert list(index.arm) == ["failure"] * 3 + ["random"] * 3 and set(index["round"]) == {round_}
        assert list(index.shape_id[:3]) == [f"r{round_}_f{3 * (round_ - 1) + k:04d}" for k in range(3)]
        assert set(index.parent_a[:3]) == {"s0"} and set(index.failure[:3]) == {"val_7"}
        for arm, rows in index.groupby("arm"):
            new = {candidate_key(a, b, al) for a, b, al in zip(rows.parent_a, rows.parent_b, rows.alpha)}
            assert len(new) == 3 and not new & keys[arm], f"round {round_} repeats a {arm} shape"
            keys[arm] |= new
        made = index if made is None else pd.concat([made, index], ignore_index=True)
    assert len(made) == 18 and made.shape_id.is_unique


def test_arm_contrasts_pair_the_arms_within_a_seed_and_say_when_the_real_data_gain_shows(tmp_path):
    from graspaug.experiments.lifelong.figures import curve_series
    from graspaug.experiments.lifelong.numbers import arm_contrasts, arm_variant, curve_rows

    rng = np.random.default_rng(1)
    objects = np.repeat([f"o{i}" for i in range(40)], 10)
    labels = rng.integers(0, 2, size=len(objects))
    noise = {s: rng.normal(size=len(labels)) for s in (0, 1, 2)}
    skill = {"none": 0.5, "failure": 0.6, "random": 0.6, "real": 1.5}  # more real data: a much better network
    networks = {}
    for s in (0, 1, 2):
        for arm, k in skill.items():
            folder = tmp_path / f"s{s}" / arm
            folder.mkdir(parents=True)
            np.save(folder / "test_predictions.npy", 1 / (1 + np.exp(-(k * (2 * labels - 1) + noise[s]))))
            networks.setdefault(s, {})[arm] = folder
    out = arm_contrasts({0: networks}, labels, objects, 300, 0)
    c = out["contrasts"]
    assert c["real_data"]["draws_low"] > 0 and c["failure_vs_real"]["draws_high"] < 0  # the control shows
    assert c["failure_vs_random"]["mean"] == pytest.approx(0.0, abs=1e-12)  # the same network: nothing, exactly
    assert c["failure_vs_random"]["draws_low"] <= 0 <= c["failure_vs_random"]["draws_high"]
    assert out["ap"]["real"]["mean"] > out["ap"]["none"]["mean"] and 0 < out["share"]["share"] < 0.5
    share = out["share"]  # the real gain is clearly positive: a bounded share that holds its estimate
    assert share["bounded"] and share["low"] <= share["share"] <= share["high"]
    assert (share["denominator_low"], share["denominator_high"]) == pytest.approx(  # one set of resamples
        (c["real_data"]["draws_low"], c["real_data"]["draws_high"]), abs=1e-5
    )
    assert arm_variant("none", 50, 0).name == "targeted/50-0"
    assert arm_variant("failure", 50, 25).name == "failure/50-0.5"
    import pandas as pd

    curve = pd.concat([curve_rows(0, {"ap": {"none": out["ap"]["none"]}, "contrasts": {}}), curve_rows(1, out)])
    rounds, series, bands = curve_series(curve, ["failure", "real"])
    assert rounds == [0, 1] and series["real"] == [out["ap"]["none"]["mean"], out["ap"]["real"]["mean"]]
    assert bands["failure"][0][0] == out["ap"]["none"]["draws_low"]  # every arm starts from the base set alone
    rounds, series, bands = curve_series(curve, ["failure", "real"], "gain")  # paired: from 0, real_data for real
    assert (
        series["real"] == [0.0, c["real_data"]["mean"]] and bands["failure"][1][1] == c["failure_vs_none"]["draws_high"]
    )


def test_failure_history_counts_the_rounds_an_object_stays_a_failure():
    import pandas as pd

    from graspaug.experiments.lifelong.numbers import failure_history, followed_failures, persistent_failures

    history = failure_history(failure_history(failure_history(None, 0, ["a", "b"]), 1, ["b", "c"]), 2, ["b", "a"])
    top = persistent_failures(history)
    assert list(top.object) == ["b", "a", "c"] and list(top.rounds) == [3, 2, 1] and top.first.tolist() == [0, 0, 1]
    before = pd.DataFrame({"datapoints": [4, 6], "log_loss": [1.0, 2.0], "ap": [0.5, 0.2]}, index=["a", "b"])
    now = pd.DataFrame({"log_loss": [0.5], "ap": [0.9]}, index=["b"])
    followed = followed_failures(before, {"failure": now}, ["b", "a"])
    assert list(followed.index) == ["b", "a"] and followed.loc["b", "failure_ap"] == 0.9
    assert np.isnan(followed.loc["a", "failure_ap"]) and followed.loc["b", "before_ap"] == 0.2


def test_a_rounds_verdicts_are_scoped_to_its_one_draw_of_the_data():
    import pandas as pd

    from graspaug.experiments.lifelong.words import round_markdown

    c = contrast(-0.02, "draws", 4, 1, draws=(-0.03, -0.01))
    result = {"ap": {"failure": contrast(0.3, "draws", 4, 1, draws=(0.2, 0.4))}, "contrasts": {"failure_vs_real": c}}
    persistent = pd.DataFrame({"object": ["o1"], "rounds": [1]})
    text = round_markdown(1, result | {"draws": [0]}, None, persistent, {"design": "D.", "command": "c"})
    assert "| `failure_vs_real@r1` | -0.0200 [-0.0300, -0.0100] | a loss in this draw of the data |" in text
    share = {"share": 1.5, "low": None, "high": None, "bounded": False}  # a real gain not clearly nonzero
    real = contrast(0.001, "draws", 4, 1, draws=(-0.01, 0.012))
    failure = contrast(0.0015, "draws", 4, 1, draws=(-0.01, 0.013))
    both = {"real_data": real, "failure_vs_none": failure}
    text = round_markdown(
        1, result | {"share": share, "contrasts": both}, None, persistent, {"design": "", "command": ""}
    )
    assert (
        "give: +150% [unbounded] (95% interval by test inversion; unbounded when the real shapes' gain is not "
        "clearly nonzero), beside its denominator, the real shapes' gain `real_data` +0.0010 [-0.0100, +0.0120] AP "
        "(no effect we can claim in this draw of the data)"
    ) in text
    result["contrasts"]["failure_vs_real"] = c | {"n_draws": 3}
    text = round_markdown(1, result | {"draws": [0, 1, 2]}, None, persistent, {"design": "D.", "command": "c"})
    assert "| a loss over 3 draws of the data |" in text
