"""The sim stage's comparison and its words, on hand-made trial tables."""
import numpy as np
import pandas as pd

from graspaug.sim.experiment import compare, rate_summary, report_text


def trials_table(outcomes: dict[tuple[int, str], list[bool]]) -> pd.DataFrame:
    """(seed, arm) → successes per attempt of one object."""
    rows = [{"seed": seed, "arm": arm, "object": "cube", "attempt": i, "success": ok, "outcome": "success" if ok else "not_lifted"}
            for (seed, arm), oks in outcomes.items() for i, ok in enumerate(oks)]
    return pd.DataFrame(rows)


def metrics_for(trials: pd.DataFrame) -> dict:
    pooled = compare(trials)
    seeds = sorted(set(trials.seed))
    return {
        "setup": {"base_size": 200, "objects": 1, "attempts": int(trials.attempt.max() + 1), "camera_height": 0.65, "model_seeds": seeds},
        "arms": {"before": {"ratio": 0.0, **pooled["before"]}, "after": {"ratio": 1.0, **pooled["after"]}},
        "difference": pooled["difference"], "paired": pooled["paired"], "same_network": False,
        "per_seed": {str(s): compare(trials[trials.seed == s]) for s in seeds},
        "per_object": {"cube": {"kind": "everyday", **{arm: rate_summary(trials.success[trials.arm == arm]) for arm in ("before", "after")}}},
    }


def test_a_clear_loss_is_called_worse_with_its_numbers():
    trials = trials_table({(0, "before"): [True] * 20, (0, "after"): [True] * 5 + [False] * 15})
    metrics = metrics_for(trials)
    assert metrics["difference"] == -0.75 and metrics["paired"]["only_before"] == 15 and metrics["paired"]["p_value"] < 0.001
    text = report_text(metrics, trials)
    assert "fell after augmentation (1.00 → 0.25, -0.75)" in text and "worse, beyond chance" in text
    assert "one training seed" in text


def test_a_small_gain_is_not_claimed():
    trials = trials_table({(0, "before"): [True] * 7 + [False] * 3, (0, "after"): [True] * 8 + [False] * 2})
    text = report_text(metrics_for(trials), trials)
    assert "rose after augmentation" in text and "no evidence either way" in text and "helped" not in text


def test_seeds_that_disagree_are_reported():
    trials = trials_table({(0, "before"): [True] * 10, (0, "after"): [False] * 10,
                           (1, "before"): [False] * 10, (1, "after"): [True] * 10})
    metrics = metrics_for(trials)
    assert metrics["difference"] == 0.0 and metrics["per_seed"]["0"]["difference"] == -1.0 and metrics["per_seed"]["1"]["difference"] == 1.0
    assert metrics["paired"]["only_before"] == 10 and metrics["paired"]["only_after"] == 10 and np.isclose(metrics["paired"]["p_value"], 1.0)
    text = report_text(metrics, trials)
    assert "| 0 | 10/10 | 0/10 | -1.00 |" in text and "sign of the difference changes with the training seed" in text
