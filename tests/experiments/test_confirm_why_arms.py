"""The confirmatory tables take the why study's arms (issue #82): `balanced` and `views` networks go through a
draw's predictions, its networks table (with their target and drawn positive shares and extra-view counts) and the
plan's combined result as any other pool's."""

import json

import numpy as np
import pandas as pd
import pytest
import yaml

from graspaug.experiments.confirm.tables import add_confirm_draw, column, combine_confirm
from graspaug.experiments.confirm.words import confirm_figures

PLAN = {
    "format": "graspaug.confirm-plan/1",
    "question": "Why does the targeted pool help?",
    "profile": "why",
    "draws": [0, 1, 2],
    "seeds": [0],
    "arms": {
        "none@50": ["targeted", 50, 0.0],
        "targeted@50": ["targeted", 50, 1.0],
        "balanced@50": ["balanced", 50, 1.0],
        "views@50": ["views", 50, 1.0],
    },
    "training_rule": "8,000 steps",
    "statistic": "t over draws",
    "alpha": 0.05,
    "control": {"name": "targeted_vs_none@50", "a": "targeted@50", "b": "none@50"},
    "primary": {"name": "targeted_vs_balanced@50", "a": "targeted@50", "b": "balanced@50"},
    "secondary": [{"name": "targeted_vs_views@50", "a": "targeted@50", "b": "views@50"}],
    "power": {},
    "exploratory": "Named, no verdict: balanced@50 - none@50, views@50 - none@50 (and none@50 - other@50: no arm).",
    "words": {
        "uninformative": "uninformative",
        "raises": "raises AP by {mean}",
        "lowers": "lowers AP by {mean}",
        "not_shown": "not shown: {mean}",
    },
}


def _seed_dir(folder, draw, labels):
    """A draw's seed-0 folder with a summary and test predictions for every arm of the plan (better with targeted)."""
    rng = np.random.default_rng(draw)
    for arm, (pool, b, r) in PLAN["arms"].items():
        net = folder / f"{pool}/{b}-{r:g}" if r else folder / f"targeted/{b}-0"
        net.mkdir(parents=True)
        skill = 1.5 if arm == "targeted@50" else 0.5 + 0.1 * draw
        p = 1 / (1 + np.exp(-(skill * (2 * labels - 1) + rng.standard_normal(len(labels)))))
        np.save(net / "test_predictions.npy", p.astype(np.float32))
        train = {"datapoints": 900, "positive_share": 0.2, "steps": 8000, "generated_shapes_asked": 0}
        train |= {"target_positive_share": 0.31, "drawn_positive_share": 0.3101} if pool == "balanced" else {}
        train |= {"views_datapoints": 450} if pool == "views" else {}
        summary = {"validation": {"ap": 0.5}, "test": {"ap": 0.5, "roc_auc": 0.6}, "train": train}
        (net / "summary.json").write_text(json.dumps(summary))
    return folder


def test_balanced_and_views_arms_go_through_a_draw_and_the_combined_result(tmp_path):
    folder = tmp_path / "results/why-x"
    folder.mkdir(parents=True)
    (folder / "plan.yaml").write_text(yaml.safe_dump(PLAN))
    labels = np.tile([0, 0, 1, 0, 1], 40)
    objects = np.repeat([f"o{k}" for k in range(20)], 10)
    for draw in PLAN["draws"]:
        seed_dir = _seed_dir(tmp_path / f"d{draw}/s0", draw, labels)
        meta = {"params": {"gqcnn.networks": "the plan's"}, "command": "test", "commit": "x", "date": "d", "seconds": 1}
        add_confirm_draw(folder, PLAN, draw, {0: seed_dir}, labels, objects, meta, {})
    predictions = pd.read_parquet(folder / "predictions-d1-s0.parquet")
    assert column(1, 0, ("balanced", 50, 1.0)) == "1/0/balanced/50-1" and "1/0/views/50-1" in predictions
    networks = pd.read_parquet(folder / "networks.parquet")
    balanced = networks[networks.pool == "balanced"]
    assert len(balanced) == 3 and (balanced.train_target_positive_share == 0.31).all()
    assert (balanced.train_drawn_positive_share == 0.3101).all()
    assert (networks[networks.pool == "views"].train_views_datapoints == 450).all()
    result = combine_confirm(folder)
    assert result["complete"] and result["primary"]["mean"] > 0 and "targeted_vs_views@50" in result["secondary"]
    assert {r["pool"] for r in result["train_steps"]} == {"targeted", "balanced", "views"}
    # the plan's exploratory contrasts: over draws with the plan's interval, no verdict; each arm's mean AP
    assert list(result["exploratory"]) == ["balanced@50-none@50", "views@50-none@50"]
    balanced = result["exploratory"]["balanced@50-none@50"]
    per_draw = [v["balanced@50"] - v["none@50"] for v in result["per_draw_ap"].values()]
    assert balanced["mean"] == pytest.approx(np.mean(per_draw)) and "verdict" not in balanced
    assert result["arms"]["targeted@50"] > result["arms"]["none@50"]
    figures = confirm_figures(result, "why-x")
    views = result["exploratory"]["views@50-none@50"]
    assert figures["why-x/exploratory/views@50-none@50"].startswith(f"{views['mean']:+.4f} [")
    assert "why-x/exploratory/balanced@50-none@50/verdict" not in figures and "why-x/ap/views@50" in figures
