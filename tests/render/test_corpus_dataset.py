"""A corpus's dataset tables (graspaug.render.corpus_dataset) without rendering."""

import numpy as np
import pandas as pd

from graspaug.render.corpus_dataset import (
    datapoints_table,
    example_crops,
    render_headline,
    render_summary,
    with_pool_columns,
)


def index_parts():
    parts = []
    for i, split in enumerate(["train", "train", "test"]):
        label = np.array([True, False, i == 0, False])
        parts.append(
            pd.DataFrame(
                {
                    "shape_id": f"s{i}",
                    "split": split,
                    "base_size": None,
                    "pool": None,
                    "order": None,
                    "z": 0.7,
                    "width_px": 40.0,
                    "eps": np.where(label, 0.003, 0.001),
                    "collision_free": np.array([True, True, True, False]),
                    "success": label,
                    "label": label,
                }
            )
        )
    return parts


def test_pool_columns_have_one_type_for_every_corpus():
    shapes = with_pool_columns(pd.DataFrame({"shape_id": ["a", "b"]}))
    assert [str(shapes[c].dtype) for c in ("base_size", "order", "pool")] == ["Int64", "Int64", "string"]
    index = datapoints_table(index_parts())
    assert len(index) == 12
    assert [str(index[c].dtype) for c in ("base_size", "order", "pool")] == ["Int64", "Int64", "string"]


def test_summary_and_examples():
    parts = index_parts()
    index = datapoints_table(parts)
    summary = render_summary(4, parts, [{"shape_id": "s3", "reason": "no grasps"}], index, 120, [2, 3, 4])
    assert summary["shapes_rendered"] == 3 and summary["shapes_skipped"] == 1 and summary["n_datapoints"] == 12
    assert summary["positive_share"] == round(4 / 12, 4) and summary["stable_poses_per_shape_mean"] == 3.0
    assert summary["by_split"] == {
        "test": {"datapoints": 4, "positives": 1, "shapes": 1},
        "train": {"datapoints": 8, "positives": 3, "shapes": 2},
    }
    assert summary["rays_per_datapoint"] == 10.0
    assert render_headline(summary) == {"shapes": 3, "datapoints": 12, "positive": round(4 / 12, 4)}
    chosen, titles, jaws = example_crops(index, 6, 0, 3)
    labels = index.label.to_numpy()[chosen]
    assert len(chosen) == 6 and labels[:3].all() and not labels[3:].any()  # positives first, each group sorted
    assert list(chosen[:3]) == sorted(chosen[:3]) and list(chosen[3:]) == sorted(chosen[3:])
    assert titles[0].startswith("+ s") and all(t.startswith("- ") for t in titles[3:])
    assert any(t.endswith(" hit") for t in titles) == (~index.collision_free.to_numpy()[chosen]).any()
    np.testing.assert_allclose(jaws, 40.0 / 2 / 3)
    again, _, _ = example_crops(index, 6, 0, 3)
    np.testing.assert_array_equal(again, chosen)  # seeded
