"""The GQ-CNN experiment's declared contrasts and the report's sentences on scale."""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from graspaug.errors import DataError
from graspaug.experiments.ap import figures, numbers, words
from graspaug.experiments.ap.numbers import collect, declared_contrasts
from graspaug.experiments.stats import contrast, interval_text, verdict
from graspaug.training.settings import POOLS
from graspaug.training.variants import seed_variants


def test_the_declared_contrasts():
    names = [c.name for c in declared_contrasts([50, 200], [0.0, 0.5, 1.0], [50], {50: 0.5})]
    assert names == [
        "real_data",
        "targeted_vs_none@50",
        "targeted_vs_none_chosen@50",
        "warp_vs_none@50",
        "primitives_vs_none@50",
        "procedural_vs_none@50",
        "own_vs_none@50",
        "targeted_vs_random@50",
        "targeted_vs_real@50",
        "recon_vs_real@50",
        "targeted_vs_recon@50",
        "blend_vs_recon@50",
        "targeted_vs_blend@50",
        "warp_vs_real@50",
        "targeted_vs_warp@50",
        "primitives_vs_real@50",
        "targeted_vs_primitives@50",
        "targeted_vs_procedural@50",
        "targeted_vs_own@50",
    ]
    baseline = {c.name: c for c in declared_contrasts([50, 200], [0.0, 0.5, 1.0], [50], {})}["warp_vs_none@50"]
    assert dict((k, w) for w, k in baseline.terms) == {
        ("warp", 50, 0.5): 0.5,
        ("warp", 50, 1.0): 0.5,
        ("targeted", 50, 0.0): -1.0,
    }
    three_pools = declared_contrasts([50, 200], [0.0, 1.0], [50], {}, ("targeted", "random", "real"))
    assert [c.name for c in three_pools][-2:] == ["targeted_vs_random@50", "targeted_vs_real@50"]
    declared = {c.name: c for c in declared_contrasts([50, 200], [0.0, 0.5, 1.0], [50], {})}
    decoding = {k: w for w, k in declared["recon_vs_real@50"].terms}
    assert decoding == {
        ("recon", 50, 0.5): 0.5,
        ("recon", 50, 1.0): 0.5,
        ("real", 50, 0.5): -0.5,
        ("real", 50, 1.0): -0.5,
    }
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
        "recon/50-1",
        "blend/50-1",
        "warp/50-1",
        "primitives/50-1",
        "procedural/50-1",
        "own/50-1",
        "ceiling",
    ]
    assert "recon/50-1" not in [v.name for v in seed_variants([50], [0.0, 1.0], [50], False, ("targeted", "real"))]


def test_gain_sentences_give_shares_and_call_a_gap_within_the_ceilings_interval_no_gap():
    import pandas as pd

    from graspaug.experiments.ap.words import gain_sentences

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
    real = contrast(0.08, "draws", 4, 1, draws=(0.06, 0.10))
    gain = contrast(0.02, "draws", 4, 1, draws=(0.01, 0.03))
    shares = {"50": {"share": 0.25, "low": 0.1, "high": 0.4, "bounded": True, "gain": gain, "real_gain": real}}
    lines = gain_sentences(shares, table, {50: 1.0, 200: 1.0}, ceiling_shapes=600)
    assert lines[0] == (
        "B = 50: targeted shapes give +25% [+10%, +40%] of the real-shape gain (95% interval by test inversion); "
        "the real shapes' gain +0.0800 [+0.0600, +0.1000] AP, a gain in this draw of the data; targeted's own gain "
        "+0.0200 [+0.0100, +0.0300] AP, a gain in this draw of the data."
    )
    noisy = {"50": shares["50"] | {"low": None, "high": None, "bounded": False}}
    assert (
        "+25% [unbounded] (unbounded: the real shapes' gain is not clearly nonzero)"
        in (gain_sentences(noisy, table, {}, ceiling_shapes=None)[0])
    )
    assert "1:1 closes 20% of the gap" in lines[1]  # (0.42 - 0.40) / (0.50 - 0.40)
    assert "no gap for augmentation to close" in lines[2] and "closes" not in lines[2]  # 0.005 < ±0.01: not "100%"
    assert gain_sentences(shares, table, {50: 1.0}, ceiling_shapes=None) == lines[:1]
    below = table.assign(test_ap=table.test_ap.where(table.pool != "ceiling", 0.30))
    assert "below 1:0" in gain_sentences({}, below, {50: 1.0}, ceiling_shapes=600)[0]


def test_networks_are_read_from_the_seed_folders_given(tmp_path):
    variants = seed_variants([50], [0.0, 1.0], [], ceiling=False)
    seed_dirs = {3: tmp_path / "s3"}
    folder = seed_dirs[3] / "targeted" / "50-0"
    folder.mkdir(parents=True)
    train = {"datapoints": 3550, "positive_share": 0.02, "steps": 500, "generated_shapes_asked": 0}
    summary = {"validation": {"ap": 0.5}, "test": {"ap": 0.4, "roc_auc": 0.7}, "train": train}
    (folder / "summary.json").write_text(json.dumps(summary))
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
            "train_datapoints": 3550,
            "train_positive_share": 0.02,
            "train_steps": 500,
            "generated_shapes_asked": 0,
            "generated_shapes": None,  # what a summary does not say
        }
    ]
    # ratio 0 of any pool is the targeted network
    assert numbers.test_predictions(seed_dirs[3], ("random", 50, 0.0)).tolist() == pytest.approx([0.1, 0.9])
    with pytest.raises(DataError, match=r"s3/targeted/50-1/summary.json is missing"):
        collect(seed_dirs, seed_variants([50], [0.0, 1.0], [50], ceiling=False))


def _seed_folders(tmp_path, variants, seeds=(0, 1)):
    """Seed folders of hand-made networks (summary, test predictions) and the original corpus's index."""
    import pandas as pd

    rng = np.random.default_rng(0)
    n = 40
    labels = (np.arange(n) % 3 == 0).astype(int)
    index = pd.DataFrame(
        {
            "label": np.concatenate([labels, [0, 1]]),
            "shape_id": [f"s{i % 5}" for i in range(n)] + ["t0", "t1"],
            "split": ["test"] * n + ["train", "train"],
        }
    )
    (tmp_path / "original").mkdir()
    index.to_parquet(tmp_path / "original" / "index.parquet", index=False)
    seed_dirs = {s: tmp_path / f"s{s}" for s in seeds}
    for seed_dir in seed_dirs.values():
        seed_dir.mkdir()
        np.save(seed_dir / "test_rows.npy", np.arange(n))
        roles = {"validation": ["t1"], "real_pool": [], "base": {"10": ["t0"]}}  # the train shapes t0, t1
        (seed_dir / "split.json").write_text(json.dumps(roles))
        for v in variants:
            folder = seed_dir / v.name
            folder.mkdir(parents=True)
            p = rng.random(n).astype(np.float32)
            summary = {"validation": {"ap": float(rng.random())}, "test": {"ap": float(rng.random()), "roc_auc": 0.5}}
            (folder / "summary.json").write_text(json.dumps(summary))
            np.save(folder / "test_predictions.npy", p)
    return seed_dirs, index


def test_evaluate_networks_is_the_report_chain_step_by_step(tmp_path):
    from types import SimpleNamespace

    import pandas as pd

    generate = SimpleNamespace(base_sizes=[10, 20], ratios=[0.0, 1.0])
    gqcnn = SimpleNamespace(
        augment_base_sizes=[10], ceiling=True, val_shapes=1, pools=("targeted", "recon", "real"), control_ratios=None
    )
    variants = seed_variants(generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes, gqcnn.ceiling, gqcnn.pools)
    seed_dirs, index = _seed_folders(tmp_path, variants)
    ev = numbers.evaluate_networks(seed_dirs, tmp_path / "original", generate, gqcnn, seed=5, n_resamples=50)

    runs = collect(seed_dirs, variants)
    chosen = numbers.choose_ratios(runs, gqcnn.augment_base_sizes)
    contrasts = declared_contrasts(generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes, chosen, gqcnn.pools)
    assert [c.name for c in contrasts][-3:] == ["targeted_vs_real@10", "recon_vs_real@10", "targeted_vs_recon@10"]
    rows = numbers.test_rows(seed_dirs[0])
    labels, object_ids = index.label.to_numpy()[rows], index.shape_id.to_numpy()[rows]
    results = numbers.evaluate_contrasts(contrasts, runs, seed_dirs, labels, object_ids, n_resamples=50, seed=5)
    per_object, by_network = numbers.per_object_aps(seed_dirs, variants, labels, object_ids)
    assert ev.chosen == chosen and ev.contrasts == results
    pd.testing.assert_frame_equal(ev.table, numbers.network_table(runs, per_object))
    assert ev.by_network.keys() == by_network.keys() and np.array_equal(ev.labels, labels)
    assert np.array_equal(ev.object_ids, object_ids)
    assert ev.ceiling_shapes == 2 - 1  # the train shapes t0, t1 but one validation shape

    # issue #62 item 7: one interval and one verdict per contrast, the same in report.md and decomposition.md
    from graspaug.experiments.ap.attribution import combine_draws, decomposition_markdown

    steps = combine_draws({0: seed_dirs}, labels, object_ids, generate, gqcnn, 50, 5)
    one = results["targeted_vs_real@10"]
    assert one["over"] == "draws" and one["n_draws"] == 1  # seeds × objects: judged by its nested interval
    same = steps["contrasts"]["targeted_vs_real@10"]  # the same resamples: equal up to the report's rounding
    assert [one[k] for k in ("mean", "draws_low", "draws_high")] == pytest.approx(
        [same[k] for k in ("mean", "draws_low", "draws_high")], abs=1e-5
    )
    text = words.report_markdown(ev.table, results, chosen, [], list(seed_dirs), 0.3, "Words.", 0)
    decomposition = decomposition_markdown(steps, [10], "dvc repro report")
    quoted = interval_text(one)
    rows = [line for line in text.splitlines() if "`targeted_vs_real@10`" in line]
    assert len(rows) == 2 and all(quoted in row for row in rows)  # the table and its sentence: one interval
    assert sum(verdict(one) in row for row in rows) == 2 and "t-interval" not in text.split("## What the")[1]
    assert f"[{one['draws_low']:+.4f}, {one['draws_high']:+.4f}]" in decomposition
    # the share of the real-shape gain: one function (stats.ratio_interval via combine_draws) for the report, the
    # decomposition and the multi-draw study, so report.md's sentence is the decomposition's, word for word
    sentence = words.gain_sentences(steps["share"], ev.table, chosen, ceiling_shapes=None)[0]
    assert f"- {sentence}" in decomposition and "of the real-shape gain (95% interval by test inversion)" in sentence
    assert "the real shapes' gain " in sentence  # beside its denominator

    predictions = figures.compared_predictions(seed_dirs[0], 10, 1.0, ceiling=True)
    assert list(predictions) == ["B = 10, 1:0", "B = 10, 1:1", "ceiling"]
    np.testing.assert_array_equal(
        predictions["B = 10, 1:1"], numbers.test_predictions(seed_dirs[0], ("targeted", 10, 1.0))
    )
    assert list(figures.compared_predictions(seed_dirs[0], 10, 1.0, ceiling=False)) == ["B = 10, 1:0", "B = 10, 1:1"]


def test_the_augmentation_set_is_the_targeted_pools_first_rows():
    import pandas as pd

    from graspaug.augment.candidates import ratio_count

    generated = pd.DataFrame({"pool": ["targeted"] * 6 + ["random"] * 6, "order": list(range(6)) * 2})
    chosen = figures.augmentation_set(generated, 4, 0.5)
    assert (chosen.pool == "targeted").all() and list(chosen.order) == list(range(ratio_count(0.5, 4)))


def test_the_pr_roc_figure_draws_the_compared_networks(tmp_path):
    from types import SimpleNamespace

    from graspaug.experiments.ap.figures import draw_pr_roc

    generate, gqcnn = SimpleNamespace(base_sizes=[10], ratios=[0.0, 1.0]), SimpleNamespace(augment_base_sizes=[10])
    variants = seed_variants(generate.base_sizes, generate.ratios, gqcnn.augment_base_sizes, ceiling=False)
    seed_dirs, index = _seed_folders(tmp_path, variants, seeds=(0,))
    labels = index.label.to_numpy()[numbers.test_rows(seed_dirs[0])]
    draw_pr_roc(labels, seed_dirs[0], 0, 10, 1.0, False, tmp_path / "pr_roc.png")
    assert (tmp_path / "pr_roc.png").stat().st_size > 0


def test_datapoint_matched_contrasts_interpolate_the_real_shape_curve_in_datapoints():
    import pandas as pd

    from graspaug.experiments.ap.numbers import datapoint_matched_contrasts

    rows = [  # (pool, B, R, training datapoints): real shapes at 3,000 / 6,000 / 12,000 datapoints
        ("targeted", 50, 0.0, 3000),
        ("targeted", 200, 0.0, 12000),
        ("real", 50, 1.0, 6000),
        ("targeted", 50, 1.0, 4500),  # halfway between B = 50 alone and 1:1 real
        ("recon", 50, 1.0, 9000),  # halfway between 1:1 real and B = 200
        ("random", 50, 1.0, 2000),  # below the curve: no contrast
    ]
    runs = pd.DataFrame(rows, columns=["pool", "base_size", "ratio", "train_datapoints"]).assign(seed=0)
    out = {c.name: c for c in datapoint_matched_contrasts(runs, [50, 200], [0.0, 1.0], [50], POOLS)}
    assert set(out) == {f"{p}_vs_real_datapoints@50" for p in POOLS if p != "real"}  # declared: none disappears
    assert out["random_vs_real_datapoints@50"].terms == () and out["warp_vs_real_datapoints@50"].terms == ()
    assert "mean over ratios none; 1:1 left out: its training datapoints lie outside" in (
        out["random_vs_real_datapoints@50"].meaning
    )
    weights = lambda c: {k: w for w, k in c.terms if w}  # noqa: E731
    assert weights(out["targeted_vs_real_datapoints@50"]) == pytest.approx(
        {("targeted", 50, 1.0): 1.0, ("targeted", 50, 0.0): -0.5, ("real", 50, 1.0): -0.5}
    )
    assert weights(out["recon_vs_real_datapoints@50"]) == pytest.approx(
        {("recon", 50, 1.0): 1.0, ("real", 50, 1.0): -0.5, ("targeted", 200, 0.0): -0.5}
    )
    assert datapoint_matched_contrasts(runs, [50, 200], [0.0, 1.0], [50], ("targeted", "recon")) == []  # no real pool


def test_a_ratio_outside_the_real_pools_datapoints_is_left_out_of_its_contrast_and_said_on_the_real_objects_pools():
    """Issue #67: on the real_objects profile of a94c689 targeted had 1:0.5, 1:1, 1:2 and real 1:1 (control_ratios);
    targeted 1:2 gives more datapoints than any real-shape network, and targeted_vs_real_datapoints@B vanished."""
    import pandas as pd

    from graspaug.experiments.ap.numbers import datapoint_matched_contrasts, evaluate_contrasts
    from graspaug.experiments.ap.words import verdict
    from graspaug.training.variants import seed_variants

    gen = {"base_sizes": [50, 100], "ratios": [0.0, 0.5, 1.0, 2.0]}  # the real_objects profile of a94c689
    gq = {"augment_base_sizes": [50, 100], "pools": ["targeted", "random", "real", "recon", "procedural"]}
    gq["control_ratios"] = [1.0]
    variants = seed_variants(
        gen["base_sizes"], gen["ratios"], gq["augment_base_sizes"], False, gq["pools"], gq["control_ratios"]
    )
    per_shape = {"targeted": 40, "random": 40, "recon": 45, "procedural": 30}  # a real shape gives 60 datapoints
    runs = pd.DataFrame(
        [
            (v.pool, v.base_size, v.ratio, 60 * v.base_size + per_shape.get(v.pool, 60) * round(v.ratio * v.base_size))
            for v in variants
        ],
        columns=["pool", "base_size", "ratio", "train_datapoints"],
    ).assign(seed=0, test_ap=0.5)
    found = datapoint_matched_contrasts(
        runs, gen["base_sizes"], gen["ratios"], gq["augment_base_sizes"], gq["pools"], gq["control_ratios"]
    )
    out = {c.name: c for c in found}
    for b in gq["augment_base_sizes"]:
        assert {f"{p}_vs_real_datapoints@{b}" for p in gq["pools"] if p != "real"} <= set(out)
        targeted = out[f"targeted_vs_real_datapoints@{b}"]
        assert {k[2] for _, k in targeted.terms if k[0] == "targeted" and k[2] > 0} == {0.5, 1.0}  # on what it covers
        assert "mean over ratios 1:0.5, 1:1; 1:2 left out" in targeted.meaning
    # a pool with no ratio in range keeps its contrast: no value, and the report says why
    none = dataclasses.replace(out["targeted_vs_real_datapoints@50"], terms=(), meaning="m; 1:2 left out: outside")
    c = evaluate_contrasts([none], runs, {0: Path("unused")}, np.array([0, 1]), np.array(["a", "b"]), 10, 0)
    assert c[none.name]["mean"] is None and c[none.name]["draws_low"] is None
    assert verdict(none.name, c[none.name]).startswith(
        "`targeted_vs_real_datapoints@50` (m; 1:2 left out: outside): no"
    )


def test_the_report_scopes_its_verdicts_to_its_one_draw_of_the_data():
    """One run's intervals cover its draw of the data and its training seeds: report.md says which, that
    other draws are not covered and where they are combined, and calls a loss a loss in this draw."""
    loss = contrast(
        -0.034, "draws", 4, seeds=(-0.055, -0.014), objects=(-0.05, -0.02), draws=(-0.06, -0.01), sd=0.013, meaning="m"
    )
    table = pd.DataFrame(
        [("targeted", 50, 0.0, 0.3, 0.01, 0.3, 0.3, 0.8, 4)],
        columns=["pool", "base_size", "ratio", "test_ap", "test_ap_ci", "per_object_ap", "val_ap", "test_roc_auc", "n"],
    )
    text = words.report_markdown(table, {"targeted_vs_random@50": loss}, {}, [], [0, 1, 2, 3], 0.3, "Words.", 1)
    assert "over training seeds [0, 1, 2, 3] of one draw of the data (`data_seed` = 1)" in text
    assert "does not cover other draws" in text and "`graspaug study attribution --draws 0 1 2`" in text
    assert "Over three draws of the data" in text
    assert "a loss in this draw of the data" in text and "a real loss" not in text
    assert "a real gain" not in words.verdict("x", loss | {"mean": 0.03, "draws_low": 0.01, "draws_high": 0.05})
    assert "`targeted_vs_random@50` (m): -0.0340 [-0.0600, -0.0100] AP, a loss in this draw of the data." in text
    two = loss | {"seeds_low": None, "seeds_high": None, "n_seeds": 2}  # a t-interval past [-1, 1]: none
    assert "| too few seeds |" in words.report_markdown(table, {"x": two}, {}, [], [0, 1], 0.3, "Words.", 1)


def test_control_ratios_give_the_other_pools_their_own_ratios_and_pairs_the_ratios_both_have():
    """The real-objects design: targeted at the paper's 1:0.5, 1:1 and 1:2, the other pools at 1:1 only; the
    declared contrasts compare like with like, and the issue's contrasts are all declared."""
    pools = ("targeted", "random", "real", "recon", "procedural")
    ratios, control = [0.0, 0.5, 1.0, 2.0], (1.0,)
    names = [v.name for v in seed_variants([50, 100], ratios, [50, 100], False, pools, control)]
    assert names.count("targeted/50-0.5") == 1 and "targeted/100-2" in names
    assert "real/100-1" in names and "real/100-2" not in names and "procedural/50-0.5" not in names
    assert len(names) == 2 + 2 * 3 + 2 * 4  # 1:0 at both sizes, targeted at 3 ratios, 4 controls at 1:1
    declared = {c.name: c for c in declared_contrasts([50, 100], ratios, [50, 100], {}, pools, control)}
    for b in (50, 100):
        for name in ("targeted_vs_none", "targeted_vs_real", "recon_vs_real", "procedural_vs_none"):
            assert f"{name}@{b}" in declared
        assert f"targeted_vs_procedural@{b}" in declared
    assert "real_data" in declared
    assert {k[2] for _, k in declared["targeted_vs_none@100"].terms} == {0.0, 0.5, 1.0, 2.0}
    assert {k for _, k in declared["targeted_vs_real@100"].terms} == {("targeted", 100, 1.0), ("real", 100, 1.0)}
    assert {k for _, k in declared["procedural_vs_none@50"].terms} == {("procedural", 50, 1.0), ("targeted", 50, 0.0)}
    for c in declared.values():
        assert sum(w for w, _ in c.terms) == pytest.approx(0)
    # without control ratios every pool runs at every ratio, as before
    every = [v.name for v in seed_variants([50, 100], ratios, [50, 100], False, pools)]
    assert "procedural/50-0.5" in every and len(every) == 2 + 2 * 3 * 5
