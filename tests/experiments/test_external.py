"""A confirmatory study's kept networks on an external test set (issue #82): the two readouts, paired by draw, and
the committed YCB table made again from the kept networks where ../shared/external/ycb78 is at hand."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from graspaug.errors import DataError
from graspaug.experiments.confirm.external import combine_external, external_figures, write_external
from graspaug.experiments.confirm.numbers import per_object_ap
from graspaug.experiments.confirm.tables import column
from graspaug.experiments.stats import weighted_average_precision

ROOT = Path(__file__).resolve().parents[2]
YCB = ROOT.parent / "shared" / "external" / "ycb78"
COMMITTED = ROOT / "results" / "real-objects-confirm-ycb78"
ARMS = {"none@50": ["targeted", 50, 0.0], "none@150": ["targeted", 150, 0.0], "targeted@50": ["targeted", 50, 1.0]}


def _folder(tmp_path, effect: float, draws=(10, 11, 12, 13)) -> Path:
    """An external folder of 30 objects: none@150 beats none@50 by ``effect`` in the scores' signal, each draw with
    its own noise; targeted@50 equals none@50 but for draw noise."""
    rng = np.random.default_rng(3)
    objects = np.repeat([f"o{i:02d}" for i in range(30)], 40)
    labels = rng.random(len(objects)) < 0.1
    labels[::40] = True  # every object holds a positive
    predictions = {}
    for d in draws:
        base = labels + rng.normal(0, 1.0, len(labels))
        for arm, key in ARMS.items():
            signal = effect if arm == "none@150" else 0.0
            predictions[column(d, 0, (key[0], key[1], key[2]))] = (
                base + signal * labels + rng.normal(0, 0.1, len(labels))
            )
    meta = {
        "arms": ARMS,
        "draws": list(draws),
        "contrasts": {"real_data": ["none@150", "none@50"], "targeted_vs_none@50": ["targeted@50", "none@50"]},
        "n_resamples": 200,
        "seed": 0,
        "counts": {
            "objects": 30,
            "objects_with_positive": 30,
            "datapoints": len(labels),
            "positives": int(labels.sum()),
        },
    }
    write_external(tmp_path / "ext", labels, objects, predictions, meta)
    return tmp_path / "ext"


def test_both_readouts_pair_by_draw_and_the_control_shows_only_when_it_is_there(tmp_path):
    strong = combine_external(_folder(tmp_path / "a", effect=2.0))
    for readout in ("pooled", "per_object"):
        control = strong["contrasts"][readout]["real_data"]
        assert control["shows"] and control["positive_draws"] == 4 and control["low"] > 0
        null = strong["contrasts"][readout]["targeted_vs_none@50"]
        assert null["low"] < 0 < null["high"]
    flat = combine_external(_folder(tmp_path / "b", effect=0.0))
    assert not flat["contrasts"]["pooled"]["real_data"]["shows"]
    figures = external_figures(strong, "x")
    assert figures["x/pooled/control/verdict"] == "shows" and figures["x/pooled/real_data/draws"].startswith("4 of 4")
    # the pooled value of a draw is the AP over every datapoint, the per-object one the mean of the objects' APs
    test, p = (
        pd.read_parquet(tmp_path / "a/ext/test.parquet"),
        pd.read_parquet(tmp_path / "a/ext/predictions-d10.parquet"),
    )
    col = p[column(10, 0, ("targeted", 150, 0.0))].to_numpy()
    y, ones = test.label.to_numpy().astype(bool), np.ones(len(test))
    a150, a50 = (
        weighted_average_precision(y, col, ones),
        weighted_average_precision(y, p[column(10, 0, ("targeted", 50, 0.0))].to_numpy(), ones),
    )
    assert strong["contrasts"]["pooled"]["real_data"]["per_draw"][0] == pytest.approx(a150 - a50)
    objects = per_object_ap(y, test.object.to_numpy(), col)
    assert len(objects) == 30 and objects.between(0, 1).all()


def test_a_missing_network_or_file_is_named(tmp_path):
    folder = _folder(tmp_path, effect=1.0)
    p = pd.read_parquet(folder / "predictions-d12.parquet").drop(columns=[column(12, 0, ("targeted", 50, 1.0))])
    p.to_parquet(folder / "predictions-d12.parquet")
    with pytest.raises(DataError, match=r"draw 12's targeted@50"):
        combine_external(folder)
    (folder / "test.parquet").unlink()
    with pytest.raises(DataError, match="lacks test.parquet"):
        combine_external(folder)


@pytest.mark.skipif(not YCB.is_dir() or not COMMITTED.is_dir(), reason="needs ../shared/external/ycb78")
def test_the_committed_ycb_table_is_what_the_kept_networks_predict(tmp_path):
    """Two YCB objects and draw 10's kept networks, made again from nothing: the datapoints and predictions of the
    committed table for those objects, to float32."""
    meta = json.loads((COMMITTED / "meta.json").read_text())
    test = pd.read_parquet(COMMITTED / "test.parquet")
    objects = ["025_mug", "077_rubiks_cube"]
    corpus = tmp_path / "ycb"
    corpus.mkdir()
    for name in objects:
        shutil.copy(YCB / f"{name}.stl", corpus)
    study = tmp_path / "study"
    (study / "networks").mkdir(parents=True)
    shutil.copy(ROOT / "results/real-objects-confirm/plan.yaml", study)
    shutil.copytree(ROOT / "results/real-objects-confirm/networks/d10-s0", study / "networks/d10-s0")
    env = {**os.environ, "DVC_NO_ANALYTICS": "1"}
    out = tmp_path / "out"
    cmd = [str(Path(sys.executable).parent / "graspaug"), "study", "external", str(study), "--corpus", str(corpus)]
    done = subprocess.run([*cmd, "--out", str(out), "--cache", str(tmp_path / "cache")], env=env, capture_output=True)
    # one draw: no interval over draws, which the figures cannot print; the tables are what is compared
    assert (out / "predictions-d10.parquet").is_file(), done.stderr.decode()[-2000:]
    again, made = pd.read_parquet(out / "test.parquet"), pd.read_parquet(out / "predictions-d10.parquet")
    committed = pd.read_parquet(COMMITTED / "predictions-d10.parquet")
    for name in objects:
        ids = [o for o in set(test.object) if o.endswith(name) or name in o]
        assert ids, f"{name} not in the committed test set"
        mine, theirs = again.object.str.contains(name).to_numpy(), test.object.isin(ids).to_numpy()
        assert mine.sum() == theirs.sum() and again.label[mine].sum() == test.label[theirs].sum()
        for key in meta["arms"].values():
            c = column(10, 0, (key[0], int(key[1]), float(key[2])))
            np.testing.assert_allclose(np.sort(made[c][mine]), np.sort(committed[c][theirs]), atol=1e-5)


def test_a_plans_external_set_is_read_with_its_own_control_and_holm(tmp_path):
    """A plan's ``test_sets`` entry: the set's readout per draw, the plan's tests in order, gated by the set's own
    control, and the nested p agreeing with its interval."""
    import yaml

    from graspaug.experiments.confirm.tables import external_result, external_sets
    from graspaug.experiments.confirm.words import confirm_figures

    folder = _folder(tmp_path, effect=2.0)
    test = pd.read_parquet(folder / "test.parquet")
    predictions = pd.concat([pd.read_parquet(folder / f"predictions-d{d}.parquet") for d in (10, 11, 12, 13)], axis=1)
    test.to_parquet(folder / "test-ycb78.parquet")
    for d in (10, 11, 12, 13):
        predictions[[c for c in predictions if c.startswith(f"{d}/")]].to_parquet(
            folder / f"predictions-ycb78-d{d}-s0.parquet"
        )
    plan = yaml.safe_load((ROOT / "results/real-objects-confirm/plan.yaml").read_text())
    plan |= {"draws": [10, 11, 12, 13], "arms": ARMS, "secondary": [{"name": "t", "a": "targeted@50", "b": "none@50"}]}
    plan["control"] = {"name": "real_data", "a": "none@150", "b": "none@50"}
    plan["exploratory"] = "no verdict: none@150 - targeted@50"
    plan["test_sets"] = {
        "heldout": {"readout": "pooled"},
        "ycb78": {"corpus": "x", "readout": "per_object", "resamples": 300},
    }
    assert list(external_sets(plan)) == ["ycb78"]
    r = external_result(folder, plan, "ycb78")
    assert r["readout"] == "per_object" and r["control"]["shows"] and r["control"]["p"] < 0.05 < r["primary"]["p"]
    assert r["primary"]["verdict"] == "not shown" and r["secondary"]["t"]["verdict"] == "not shown"
    assert (r["control"]["low"] > 0) == (r["control"]["p"] < 0.05)
    figures = confirm_figures({"status": "complete", "complete": True, "external": {"ycb78": r}} | _heldout(r), "s")
    assert figures["s/ycb78/control/verdict"] == "shows" and figures["s/ycb78/primary/verdict"] == "not shown"
    # the plan's exploratory contrast on the external set: the same nested interval, no verdict
    explored = r["exploratory"]["none@150-targeted@50"]
    assert explored["mean"] > 0 and "verdict" not in explored and (explored["low"] > 0) == (explored["p"] < 0.05)
    assert figures["s/ycb78/exploratory/none@150-targeted@50"].startswith(f"{explored['mean']:+.4f}")
    assert float(figures["s/ycb78/ap/none@150"]) == pytest.approx(r["arms"]["none@150"], abs=1e-4)
    (folder / "predictions-ycb78-d12-s0.parquet").unlink()
    with pytest.raises(DataError, match="draw 12's ycb78 predictions are missing"):
        external_result(folder, plan, "ycb78")


def _heldout(r: dict) -> dict:
    """A held-out result shaped as :func:`combine_confirm` gives it (the external one stands in for it)."""
    return {k: r[k] for k in ("control", "primary", "secondary", "sentence")}
