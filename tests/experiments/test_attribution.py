"""Contrasts over data draws × training seeds (graspaug.experiments.ap.attribution) on hand-made networks."""

import json
from types import SimpleNamespace

import numpy as np
import pytest
from sklearn.metrics import average_precision_score

from graspaug.errors import DataError
from graspaug.experiments.ap.attribution import combine_draws, decomposition_markdown, losing_step, recommendation
from graspaug.experiments.stats import contrast, interval_text, verdict
from graspaug.training.variants import seed_variants

GENERATE = SimpleNamespace(base_sizes=[10, 20], ratios=[0.0, 1.0])
GQCNN = SimpleNamespace(
    augment_base_sizes=[10], pools=("targeted", "random", "real", "recon", "blend"), control_ratios=None
)
LABELS = (np.arange(60) % 4 == 0).astype(int)
OBJECTS = np.array([f"o{i % 12}" for i in range(60)])
DATAPOINTS = {"targeted/10-0": 300, "targeted/20-0": 1200, "real/10-1": 600}  # the real-shape curve


def make_draws(tmp_path, draws=(0, 1), seeds=(0, 1), real_noise=0.8):
    """Networks whose test predictions are noise around the labels (SD 0.8; the real pool's ``real_noise``); recon
    predicts exactly as real."""
    rng = np.random.default_rng(0)
    out = {}
    for d in draws:
        out[d] = {}
        for s in seeds:
            seed_dir = tmp_path / f"draw{d}" / f"s{s}"
            predictions = {}
            for v in seed_variants(GENERATE.base_sizes, GENERATE.ratios, GQCNN.augment_base_sizes, False, GQCNN.pools):
                noise = real_noise if v.name == "real/10-1" else 0.8
                p = predictions["real/10-1"] if v.name == "recon/10-1" else LABELS + rng.normal(0, noise, len(LABELS))
                predictions[v.name] = p
                (seed_dir / v.name).mkdir(parents=True)
                np.save(seed_dir / v.name / "test_predictions.npy", p.astype(np.float32))
                summary = {
                    "validation": {"ap": 0.5},
                    "test": {"ap": average_precision_score(LABELS, p), "roc_auc": 0.5},
                    "train": {"datapoints": DATAPOINTS.get(v.name, 450)},
                }
                (seed_dir / v.name / "summary.json").write_text(json.dumps(summary))
            out[d][s] = seed_dir
    return out


def test_combine_draws_gives_every_contrast_one_interval_over_draws_seeds_and_objects(tmp_path):
    draws = make_draws(tmp_path)
    result = combine_draws(draws, LABELS, OBJECTS, GENERATE, GQCNN, n_resamples=300, seed=0)
    contrasts = result["contrasts"]
    assert {"real_data", "recon_vs_real@10", "blend_vs_recon@10", "targeted_vs_blend@10"} <= set(contrasts)
    assert "targeted_vs_none_chosen@10" not in contrasts  # the chosen ratio may differ between draws
    assert {"targeted_vs_real_datapoints@10", "recon_vs_real_datapoints@10"} <= set(contrasts)
    same = contrasts["recon_vs_real@10"]  # recon predicts as real in every draw and seed: exactly zero
    assert same["mean"] == 0 and same["draws_low"] == same["draws_high"] == 0 and same["per_draw"] == [0, 0]
    ap = {  # targeted_vs_blend by hand, from the summaries
        (d, s): json.loads((draws[d][s] / "targeted/10-1/summary.json").read_text())["test"]["ap"]
        - json.loads((draws[d][s] / "blend/10-1/summary.json").read_text())["test"]["ap"]
        for d in draws
        for s in (0, 1)
    }
    step = contrasts["targeted_vs_blend@10"]
    assert step["mean"] == pytest.approx(np.mean(list(ap.values())))
    assert step["per_draw"] == pytest.approx([(ap[d, 0] + ap[d, 1]) / 2 for d in draws], abs=1e-5)
    assert step["n_draws"] == 2 and step["n_seeds"] == 2 and step["draws_low"] < step["draws_high"]
    assert set(result["share"]) == {"10"} and result["draws"] == [0, 1] and result["seeds"] == [0, 1]
    text = decomposition_markdown(result, [10], "graspaug study attribution")
    assert "| `targeted_vs_blend@10` |" in text and "B = 10" in text
    shares = result["shares"]  # every pool but real, as a share of the real pool's gain over no augmentation
    assert set(shares) == {"targeted", "random", "recon", "blend"} and shares["targeted"] == result["share"]
    recon, contrasts = shares["recon"]["10"], result["contrasts"]
    # the real pool is as noisy as the others: its gain's interval holds zero, so every share is unbounded, even
    # that of recon, which predicts exactly as real (the ratio of the resamples was "+100% [+100%, +100%]")
    real = recon["real_gain"]
    assert real["draws_low"] <= 0 <= real["draws_high"]
    assert recon["share"] == pytest.approx(1.0) and not recon["bounded"] and recon["low"] is recon["high"] is None
    real_gain = contrasts["targeted_vs_none@10"]["mean"] - contrasts["targeted_vs_real@10"]["mean"]
    assert recon["gain"]["mean"] == pytest.approx(real_gain) and recon["gain"]["over"] == "draws"
    gain = {  # the blend pool's share by hand: its gain over 1:0 over the real pool's, mean over draws and seeds
        pool: np.mean(
            [
                json.loads((draws[d][s] / f"{pool}/10-1/summary.json").read_text())["test"]["ap"]
                - json.loads((draws[d][s] / "targeted/10-0/summary.json").read_text())["test"]["ap"]
                for d in draws
                for s in (0, 1)
            ]
        )
        for pool in ("blend", "real")
    }
    assert shares["blend"]["10"]["share"] == pytest.approx(gain["blend"] / gain["real"])
    assert "## What to add" in text  # recon gains as real shapes do, but it is a control: never the advice
    assert "| recon (control: the new real shapes themselves, decoded) | +100% [unbounded] |" in text
    assert f"| (the denominator) | {interval_text(real)} AP, {verdict(real)} |" in text
    assert f"the real shapes' gain {interval_text(real)} AP, {verdict(real)}" in text  # beside the share


def test_a_share_of_a_clear_real_gain_holds_its_estimate_and_its_gains_are_the_contrasts(tmp_path):
    draws = make_draws(tmp_path, draws=(0, 1, 2), seeds=(0, 1, 2), real_noise=0.1)  # real predicts the labels well
    result = combine_draws(draws, LABELS, OBJECTS, GENERATE, GQCNN, n_resamples=300, seed=0)
    recon, blend = result["shares"]["recon"]["10"], result["shares"]["blend"]["10"]
    assert recon["real_gain"]["draws_low"] > 0
    assert (recon["share"], recon["low"], recon["high"], recon["bounded"]) == pytest.approx((1.0, 1.0, 1.0, True))
    assert blend["bounded"] and blend["low"] <= blend["share"] <= blend["high"]
    declared = result["contrasts"]["blend_vs_recon@10"]  # one set of resamples: a difference of gains adds up
    assert blend["gain"]["mean"] - recon["gain"]["mean"] == pytest.approx(declared["mean"], abs=1e-9)
    assert result["shares"]["targeted"]["10"]["gain"] == result["contrasts"]["targeted_vs_none@10"]


def test_every_draw_needs_the_same_training_seeds(tmp_path):
    draws = make_draws(tmp_path, seeds=(0, 1))
    draws[1] = {0: draws[1][0]}
    with pytest.raises(DataError, match="the same training seeds"):
        combine_draws(draws, LABELS, OBJECTS, GENERATE, GQCNN, n_resamples=10, seed=0)


def test_the_losing_step_is_the_most_negative_with_its_interval_below_zero():
    c = {
        "recon_vs_real@50": contrast(-0.03, "draws", 4, 3, draws=(-0.05, -0.01)),
        "targeted_vs_blend@50": contrast(-0.05, "draws", 4, 3, draws=(-0.09, 0.01)),
    }
    assert "`recon_vs_real`: -0.0300 AP [-0.0500, -0.0100] over 3 draws × 4 seeds" in losing_step(c, 50)
    assert losing_step(c, 50).endswith("a loss over 3 draws of the data.")
    assert losing_step({}, 50).startswith("At B = 50 no step (none measured)")


def test_one_draw_gives_intervals_over_seeds_and_objects_and_says_they_miss_other_draws(tmp_path):
    """The report stage's decomposition: one run is one draw of the data."""
    draws = make_draws(tmp_path, draws=(0,), seeds=(0, 1, 2))
    result = combine_draws(draws, LABELS, OBJECTS, GENERATE, GQCNN, n_resamples=300, seed=0)
    step = result["contrasts"]["targeted_vs_blend@10"]
    assert step["n_draws"] == 1 and step["n_seeds"] == 3 and step["draws_low"] < step["mean"] < step["draws_high"]
    text = decomposition_markdown(result, [10], "dvc repro report")
    assert "One draw of the data" in text and "does not cover other draws" in text and "Draws (data_seed)" not in text
    assert "`data_seed` = 0 and training seeds [0, 1, 2]" in text and "graspaug study attribution --draws 0 1 2" in text
    c = {"recon_vs_real@50": contrast(-0.03, "draws", 4, 1, draws=(-0.05, -0.01))}
    assert "over 4 seeds of one draw and the test objects, a loss in this draw of the data." in losing_step(c, 50)


def test_a_network_without_a_test_ap_gives_no_mean_and_valid_json(tmp_path):
    """A tiny run's network may have no test AP: the decomposition says so with None, never NaN."""
    draws = make_draws(tmp_path, draws=(0,), seeds=(0, 1))
    summary = draws[0][1] / "blend/10-1/summary.json"
    data = json.loads(summary.read_text())
    data["test"]["ap"] = None
    summary.write_text(json.dumps(data))
    result = combine_draws(draws, LABELS, OBJECTS, GENERATE, GQCNN, n_resamples=50, seed=0)
    step = result["contrasts"]["blend_vs_recon@10"]
    assert step["mean"] is None and step["per_draw"] == [None]
    json.loads(json.dumps(result, allow_nan=False))  # strict JSON
    text = decomposition_markdown(result, [10], "dvc repro report")
    assert "| `blend_vs_recon@10` | - |" in text


def _share(share: float, gain_low: float, gain_high: float) -> dict:
    gain = contrast((gain_low + gain_high) / 2, "draws", 4, 3, draws=(gain_low, gain_high))
    real = contrast(0.02, "draws", 4, 3, draws=(0.01, 0.03))
    return {"share": share, "low": share - 0.2, "high": share + 0.2, "bounded": True, "gain": gain, "real_gain": real}


def test_the_advice_names_the_pools_that_gain_and_never_the_recon_control():
    shares = {
        "recon": {"50": _share(0.9, 0.01, 0.03)},  # gains as the real shapes it decodes do
        "warp": {"50": _share(0.5, 0.002, 0.02)},
        "primitives": {"50": _share(-0.5, -0.03, -0.01)},
    }
    lines = recommendation({"shares": shares})
    assert lines[2] == (  # the denominator of every share, beside them
        "| real (as many more real shapes: every share's denominator) | (the denominator) "
        "| +0.0200 [+0.0100, +0.0300] AP, a gain over 3 draws of the data |"
    )
    assert lines[3].startswith("| recon (control: the new real shapes themselves, decoded) | +90% [+70%, +110%] |")
    assert [line.split(" |")[0] for line in lines[4:6]] == ["| warp", "| primitives"]  # ordered by share
    assert lines[-1].endswith(
        "pools that add AP with an interval above zero: warp; warp adds the most, +50% [+30%, +70%] of as many real "
        "shapes' gain."
    )
    shares["warp"]["50"] = _share(0.5, -0.01, 0.02)  # now only the control gains
    advice = recommendation({"shares": shares})[-1]
    assert (
        "At B = 50, add real shapes: no generated or procedural pool" in advice and "the control `recon` does" in advice
    )


def test_the_advice_reads_every_base_size():
    shares = {
        "targeted": {"50": _share(-0.2, -0.02, 0.01), "100": _share(0.8, 0.001, 0.02)},  # gains at B = 100 only
        "warp": {"50": _share(-0.8, -0.02, -0.001), "100": _share(-0.4, -0.02, 0.01)},
    }
    lines = recommendation({"shares": shares})
    assert lines[0] == (
        "| pool | B = 50: share [95%] | B = 100: share [95%] | its own gain at B = 50 | its own gain at B = 100 |"
    )
    assert lines[3].startswith(
        "| targeted | -20% [-40%, +0%] | +80% [+60%, +100%] | -0.0050 [-0.0200, +0.0100] AP, no effect we can claim "
        "over 3 draws of the data | +0.0105 [+0.0010, +0.0200] AP, a gain"
    )
    assert lines[-1].endswith(
        "At B = 50, add real shapes: no generated or procedural pool tried here adds AP with an interval above zero. "
        "At B = 100 the pools that add AP with an interval above zero: targeted; targeted adds the most, +80% [+60%, "
        "+100%] of as many real shapes' gain."
    )


def test_an_exchange_rate_is_the_share_times_the_real_shapes_added_and_unbounded_with_it():
    from graspaug.experiments.ap.attribution import exchange_rate, exchange_text

    gain = {"mean": 0.01}
    bounded = {"share": 0.4, "low": 0.1, "high": 0.9, "bounded": True, "gain": gain, "real_gain": gain, "shapes": 50.0}
    assert exchange_rate(bounded) == {"worth": 20.0, "low": 5.0, "high": 45.0, "bounded": True, "shapes": 50.0}
    assert exchange_text(exchange_rate(bounded)) == "+20 [+5, +45]"
    unbounded = bounded | {"low": None, "high": None, "bounded": False}
    assert exchange_text(exchange_rate(unbounded)) == "+20 [unbounded]"
    assert exchange_text(exchange_rate(bounded | {"share": None})) == "n/a"
