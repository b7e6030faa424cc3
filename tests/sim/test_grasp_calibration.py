"""Labelled grasps executed in the cell: which are chosen, where the body rests, real pybullet picks, the numbers."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from graspaug.experiments.cell.calibration import (
    ShapeGrasps,
    choose_grasps,
    grasp_on_body,
    placement,
    run_shape,
    summarize,
    summary_line,
)
from graspaug.render.stable_poses import stable_poses
from graspaug.sim.objects import body_origin, everyday_mesh
from graspaug.sim.settings import CellLayout, HandSettings, TrialSettings


def test_choose_grasps_takes_half_positives_from_the_test_split_spread_over_shapes():
    rows = []
    for s in range(6):
        for g in range(10):
            rows.append({"shape_id": f"s{s}", "split": "test", "grasp_id": g, "pose_id": 0, "label": g < 3})
    rows += [{"shape_id": "t0", "split": "train", "grasp_id": g, "pose_id": 0, "label": True} for g in range(10)]
    index = pd.DataFrame(rows)
    chosen = choose_grasps(index, 12, seed=0)
    assert len(chosen) == 12 and chosen.label.sum() == 6
    assert set(chosen.shape_id) == {f"s{s}" for s in range(6)}  # every shape once per label before any twice
    assert (chosen.groupby(["shape_id", "label"]).size() == 1).all()
    pd.testing.assert_frame_equal(chosen, choose_grasps(index, 12, seed=0))
    assert not choose_grasps(index, 12, seed=1).equals(chosen)  # a seeded choice
    few = choose_grasps(index, 50, seed=0)  # 18 positives in all: every one of them, negatives fill in
    assert few.label.sum() == 18 and (~few.label).sum() == 32
    assert len(choose_grasps(index, 100, seed=0)) == 60  # every test datapoint
    assert (index.shape_id[chosen.datapoint].to_numpy() == chosen.shape_id).all()  # its row in the index
    with pytest.raises(ValueError, match="no test-split"):
        choose_grasps(index[index.split == "train"], 4, seed=0)
    tuning = choose_grasps(index, 4, seed=0, split="train")  # the cell's settings are chosen on train datapoints
    assert set(tuning.shape_id) == {"t0"} and len(tuning) == 2 and tuning.label.all()  # t0 has no negatives


def test_a_grasp_follows_the_body_from_its_stable_pose():
    """Put at its placement, the body carries a mesh-frame grasp to where the stable pose puts it."""
    mesh = everyday_mesh("duck")
    pose = stable_poses(mesh).transforms[0]
    origin = body_origin(mesh)
    position, quaternion = placement(pose, origin, clearance=0.0)
    center, axis = mesh.bounds.mean(axis=0), np.array([0.6, 0.0, 0.8])
    table_center, jaw_angle, tilt = grasp_on_body(center, axis, origin, position, quaternion)
    assert np.allclose(table_center, pose[:3, :3] @ center + pose[:3, 3], atol=1e-9)
    table_axis = pose[:3, :3] @ axis
    assert np.isclose(jaw_angle, np.arctan2(table_axis[1], table_axis[0]))
    assert np.isclose(tilt, np.degrees(np.arcsin(abs(table_axis[2]))))
    lifted, _ = placement(pose, origin, clearance=0.001)
    assert np.allclose(lifted - position, [0, 0, 0.001])


def test_executed_grasps_on_a_cube_in_its_stable_pose(cube):
    """Real pybullet: across the cube's middle the Panda lifts it into the bin; the same grasp 6 cm to the
    side closes on air."""
    mesh = everyday_mesh("cube")
    pose = stable_poses(mesh).transforms[0]
    across = pose[:3, :3].T @ np.array([1.0, 0.0, 0.0])  # the table's x axis, in the mesh frame
    middle = mesh.center_mass
    beside = middle + pose[:3, :3].T @ np.array([0.0, 0.06, 0.0])
    rows = pd.DataFrame(
        {
            "datapoint": [10, 11],
            "shape_id": ["cube", "cube"],
            "grasp_id": [0, 1],
            "pose_id": [0, 0],
            "pose_probability": [0.3, 0.3],
            "eps": [0.004, 0.0],
            "collision_free": [True, True],
            "success": [True, False],
            "label": [True, False],
        }
    )
    job = ShapeGrasps(
        "cube",
        cube,
        body_origin(mesh),
        np.stack([pose, pose]),
        np.stack([middle, beside]),
        np.stack([across] * 2),
        rows,
        (1, 2),
    )
    executed = run_shape(job, CellLayout(), HandSettings(), TrialSettings())
    assert [r["outcome"] for r in executed] == ["success", "not_lifted"]
    assert [r["executed_success"] for r in executed] == [True, False]
    assert all(r["settle_shift"] < 0.005 and r["axis_tilt"] < 1.0 for r in executed)  # it rests as placed


def test_summary_of_a_hand_made_table():
    from sklearn.metrics import roc_auc_score

    table = pd.DataFrame(
        {
            "shape_id": ["a", "a", "b", "b", "c", "c", "d", "d"],
            "eps": [0.004, 0.0001, 0.003, 0.001, 0.0025, 0.0005, 0.001, 0.003],
            "collision_free": [True, True, True, False, True, True, False, True],
            "label": [True, False, True, False, True, False, False, True],
            "executed_success": [True, False, True, True, False, False, False, True],
            "outcome": [
                "success",
                "not_lifted",
                "success",
                "success",
                "collision",
                "collision",
                "collision",
                "success",
            ],
        }
    )
    s = summarize(table, n_bootstrap=200, seed=0)
    assert s["n_grasps"] == 8 and s["n_shapes"] == 4 and s["n_positive"] == 4
    assert s["success_positive"]["mean"] == 0.75 and s["success_negative"]["mean"] == 0.25
    assert np.isclose(s["auc_eps"]["mean"], roc_auc_score(table.executed_success, table.eps))
    assert np.isclose(s["auc_label"]["mean"], roc_auc_score(table.executed_success, table.label))
    for name in ("success_positive", "success_negative", "auc_eps", "auc_label"):
        assert s[name]["lo"] <= s[name]["mean"] <= s[name]["hi"]
    assert s["outcomes"]["positive"]["success"] == 3 and s["outcomes"]["negative"]["collision"] == 2
    one_outcome = summarize(table.assign(executed_success=True), n_bootstrap=50, seed=0)
    assert one_outcome["auc_eps"] == {"mean": None, "lo": None, "hi": None}
    assert "ROC AUC of robust eps n/a" in summary_line(one_outcome)
    assert "success 0.750 [" in summary_line(s) and "8 grasps on 4 shapes" in summary_line(s)
