import pandas as pd

from graspaug.grasping.labelled import grasps_headline, grasps_summary


def test_summary_counts_shapes_without_grasps_and_shares():
    table = pd.DataFrame(
        {"shape_id": ["a", "a", "a", "c"], "eps": [0.0, 0.01, 0.02, 0.03], "eps_mean": [0.0, 0.001, 0.003, 0.004]}
    )
    table["success"] = table.eps_mean > 0.002
    summary = grasps_summary(table, ["a", "b", "c"])
    assert summary == {
        "n_shapes": 3,
        "n_grasps": 4,
        "shapes_without_grasps": 1,
        "grasps_per_shape_mean": 1.33,
        "success_share": 0.5,
        "eps_mean_median": 0.002,
        "nominal_force_closure_share": 0.75,
    }
    assert grasps_headline(summary) == {"shapes": 3, "positive": 0.5}


def test_summary_of_a_corpus_without_grasps_has_no_shares():
    empty = pd.DataFrame({"shape_id": [], "eps": [], "eps_mean": [], "success": []})
    summary = grasps_summary(empty, ["a"])
    assert summary["shapes_without_grasps"] == 1 and summary["success_share"] is None
    assert summary["eps_mean_median"] is None and summary["nominal_force_closure_share"] is None
