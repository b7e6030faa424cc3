"""The render stage and the Dex-Net export through the real CLI on a small folder corpus."""

import json

import numpy as np
import pandas as pd
import trimesh
from typer.testing import CliRunner

from graspaug.augment.corpus import assign_split
from graspaug.io.dexnet import read_tensor_field
from graspaug.io.gqcnn import GraspImages
from graspaug.pipeline.cli import app
from graspaug.training.gqcnn_data import with_split

from .test_ingest import run_stage

PARAMS = {
    "n_jobs": 1,
    "ingest": {"min_shapes": 2, "test_fraction": 0.34, "surface": {"resolution": 48, "finest_resolution": 48}},
    "grasps": {"sampler": {"n_grasps": 16}, "perturbations": {"n_samples": 5}},
    "render": {"max_poses": 3, "shard_rows": 7, "n_examples": 4},
}


def make_project(tmp_path):
    corpus = tmp_path / "meshes"
    corpus.mkdir()
    trimesh.creation.box(extents=(0.1, 0.06, 0.02)).export(corpus / "plate.stl")
    trimesh.creation.cylinder(radius=0.03, height=0.09).export(corpus / "can.stl")
    trimesh.creation.capsule(height=0.06, radius=0.02).export(corpus / "pill.stl")
    params = {**PARAMS, "data": {"source": "folder", "path": str(corpus)}}
    for stage in ("ingest", "grasps"):
        result = run_stage(tmp_path, stage, params)
        assert result.exit_code == 0, result.output
    # the split as the split stage draws it (the stage refuses 3 shapes: too few for any base set and validation)
    objects = pd.read_parquet(tmp_path / "data/objects.parquet")
    split = assign_split(list(objects.shape_id), PARAMS["ingest"]["test_fraction"], 0)
    objects.assign(split=objects.shape_id.map(split)).to_parquet(tmp_path / "data/shapes.parquet")
    return params


def test_render_writes_shards_index_metrics_and_a_dexnet_export(tmp_path, monkeypatch):
    params = make_project(tmp_path)
    result = run_stage(tmp_path, "render", params)
    assert result.exit_code == 0, result.output
    folder = tmp_path / "data/gqcnn/original"
    data = GraspImages.open(folder)
    index, grasps = data.index, pd.read_parquet(tmp_path / "data/grasps/original.parquet")
    shapes = pd.read_parquet(tmp_path / "data/shapes.parquet")
    assert len(data) > 7 and index.split.isna().all()  # the original objects' renders hold no split ...
    index = with_split(index, shapes)  # ... the split stage's table does
    assert set(index.split) == {"train", "test"}
    assert sorted(p.name for p in folder.glob("images_*.npy"))[0] == "images_00000.npy"
    assert len(list(folder.glob("images_*.npy"))) == int(np.ceil(len(data) / 7))  # shards of 7 rows
    images = data.images()
    assert images.shape == (len(data), 32, 32) and images.dtype == np.float32 and np.isfinite(images).all()
    assert np.all((images > 0.4) & (images < 0.8))  # depths of a camera 0.65-0.75 m above the table
    # each row is its grasp: ε and success from the grasps table, label = collision free and success
    merged = index.merge(grasps, on=["shape_id", "grasp_id"], suffixes=("", "_grasp"))
    assert len(merged) == len(index)
    np.testing.assert_allclose(merged.eps, merged.eps_mean)
    assert (index.label == (index.collision_free & (index.eps > 0.002))).all()
    assert (index.split == index.shape_id.map(shapes.set_index("shape_id").split)).all()
    assert index.origin.eq("original").all() and index.base_size.isna().all() and index.pool.isna().all()
    assert str(index.pool.dtype) == "string"  # the same column type as in generated corpora
    np.testing.assert_array_equal(data.read("labels"), index.label.to_numpy())
    np.testing.assert_allclose(data.read("z"), index.z, rtol=1e-6)
    np.testing.assert_allclose(data.read("eps"), index.eps, rtol=1e-6)
    rows = np.array([len(data) - 1, 0, 3])
    np.testing.assert_array_equal(data.images(rows), images[rows])  # reads across shards, in order
    summary = json.loads((tmp_path / "reports/render/original/summary.json").read_text())
    assert summary["n_datapoints"] == len(data) and summary["shapes_rendered"] + summary["shapes_skipped"] == 3
    assert summary["positive_share"] == round(float(index.label.mean()), 4)
    metrics = json.loads((tmp_path / "metrics/render/original.json").read_text())
    assert metrics == {
        "shapes": summary["shapes_rendered"],
        "datapoints": len(data),
        "positive": summary["positive_share"],
    }
    assert (tmp_path / "reports/render/original/examples.png").stat().st_size > 10_000

    # same params, same dataset
    first = images.copy()
    assert run_stage(tmp_path, "render", {**params, "n_jobs": 2}).exit_code == 0
    np.testing.assert_array_equal(GraspImages.open(folder).images(), first)

    # Dex-Net's tensor layout, read back
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "export"
    result = CliRunner().invoke(app, ["export-dexnet", "original", str(out), "--rows-per-file", "5"])
    assert result.exit_code == 0, result.output
    config = json.loads((out / "config.json").read_text())
    assert config["datapoints_per_file"] == 5 and config["num_datapoints"] == len(data)
    assert config["fields"]["depth_ims_tf_table"] == {"dtype": "float32", "height": 32, "width": 32, "channels": 1}
    assert (out / "tensors/depth_ims_tf_table_00000.npz").exists()
    assert len(list((out / "tensors").glob("hand_poses_*.npz"))) == int(np.ceil(len(data) / 5))
    assert np.load(out / "tensors/hand_poses_00000.npz")["arr_0"].shape == (5, 7)
    np.testing.assert_array_equal(read_tensor_field(out, "depth_ims_tf_table")[..., 0], images)
    hand_poses = read_tensor_field(out, "hand_poses")
    np.testing.assert_allclose(
        hand_poses[:, [0, 1, 2, 3, 6]], index[["center_v", "center_u", "z", "angle", "width_px"]], rtol=1e-6
    )
    np.testing.assert_allclose(hand_poses[:, 4], index.center_v - 239.5, atol=1e-4)
    # Dex-Net's convention: the metric is 0 for colliding grasps, so `metric > threshold` is our label
    metric = read_tensor_field(out, "robust_ferrari_canny")
    np.testing.assert_allclose(metric, np.where(index.collision_free, index.eps, 0.0), rtol=1e-6)
    np.testing.assert_array_equal(metric > 0.002, index.label)
    np.testing.assert_allclose(read_tensor_field(out, "robust_ferrari_canny_raw"), index.eps, rtol=1e-6)
    np.testing.assert_array_equal(read_tensor_field(out, "collision_free"), index.collision_free.astype(np.uint8))
    image_labels = read_tensor_field(out, "image_labels")
    assert len(np.unique(image_labels)) == index.groupby(["shape_id", "pose_id", "image_id"]).ngroups
    obj_ids = np.array(config["obj_ids"])
    np.testing.assert_array_equal(obj_ids[read_tensor_field(out, "obj_labels")], index.shape_id)
    pose_ids = np.array(config["pose_ids"])
    np.testing.assert_array_equal(
        pose_ids[read_tensor_field(out, "pose_labels")], index.shape_id + ":" + index.pose_id.astype(str)
    )

    (out / "notes.txt").write_text("mine")  # a file of the user's in the folder: refused, and kept
    again = CliRunner().invoke(app, ["export-dexnet", "original", str(out)])
    assert again.exit_code == 2 and "holds notes.txt, which graspaug export-dexnet did not write" in again.output
    assert (out / "notes.txt").read_text() == "mine"
    (out / "notes.txt").unlink()  # its own folder: its files replaced
    assert CliRunner().invoke(app, ["export-dexnet", "original", str(out)]).exit_code == 0
    assert len(list((out / "tensors").glob("hand_poses_*.npz"))) == int(np.ceil(len(data) / 1000))
    missing = CliRunner().invoke(app, ["export-dexnet", "gen_50", str(tmp_path / "other")])
    assert missing.exit_code == 2 and "no rendered dataset" in missing.output
    assert not (tmp_path / "other").exists()


def test_render_params_are_checked(tmp_path):
    (tmp_path / "params.yaml").write_text("render:\n  viewpoints:\n    tilt_deg: [5.0, 1.0]\n")
    result = CliRunner().invoke(app, ["render", "--params", str(tmp_path / "params.yaml")])
    assert (
        result.exit_code == 2
        and "render.viewpoints: camera tilt range must lie in [0, 90) degrees and be ordered" in result.output
    )
    (tmp_path / "params.yaml").write_text("render:\n  crop:\n    out_size: 40\n")
    result = CliRunner().invoke(app, ["render", "--params", str(tmp_path / "params.yaml")])
    assert (
        result.exit_code == 2
        and "render.crop: crop_size (96) must be a positive multiple of out_size (40)" in result.output
    )
    (tmp_path / "params.yaml").write_text("render:\n  crop:\n    out_size: 16\n")
    result = CliRunner().invoke(app, ["train-gqcnn", "--params", str(tmp_path / "params.yaml")])  # reads both sections
    assert (
        result.exit_code == 2 and "gqcnn.net.image_size: must equal render.crop.out_size (16); got 32" in result.output
    )


def test_a_mesh_that_cannot_be_rendered_is_skipped_with_its_reason(tmp_path):
    from graspaug.grasping.gripper import ParallelJawGripper
    from graspaug.render.dataset import RenderSettings
    from graspaug.render.dataset import render_file as render_one

    flat = trimesh.Trimesh(vertices=[[0, 0, 0], [0.05, 0, 0], [0, 0.05, 0]], faces=[[0, 1, 2]])  # no volume, no hull
    flat.export(tmp_path / "flat.ply")
    data, reason = render_one(
        tmp_path / "flat.ply",
        "flat",
        np.zeros((1, 3)),
        np.array([[1.0, 0, 0]]),
        RenderSettings(),
        ParallelJawGripper(),
        0,
    )
    assert data is None and reason.startswith("rendering failed: ")
    data, reason = render_one(
        tmp_path / "missing.ply",
        "missing",
        np.zeros((1, 3)),
        np.array([[1.0, 0, 0]]),
        RenderSettings(),
        ParallelJawGripper(),
        0,
    )
    assert data is None and reason.startswith("mesh could not be read")


def test_render_views_renders_the_originals_from_other_views_and_nothing_at_zero(tmp_path):
    """render-views (the why study's `views` networks): the same shapes and grasps as render@original seen from new
    camera views, `gqcnn.extra_views` per pose; at 0 (every other profile) an empty corpus."""
    params = make_project(tmp_path)
    assert run_stage(tmp_path, "render", params).exit_code == 0
    assert run_stage(tmp_path, "render-views", params).exit_code == 0
    empty = GraspImages.open(tmp_path / "data/gqcnn/views")
    assert len(empty) == 0 and json.loads((tmp_path / "data/gqcnn/views/dataset.json").read_text())["extra_views"] == 0
    result = run_stage(tmp_path, "render-views", {**params, "gqcnn": {"extra_views": 2}})
    assert result.exit_code == 0, result.output
    original = GraspImages.open(tmp_path / "data/gqcnn/original").index
    views = GraspImages.open(tmp_path / "data/gqcnn/views").index
    assert set(views.shape_id) == set(original.shape_id) and set(views.grasp_id) <= set(original.grasp_id)
    per_pose = views.groupby(["shape_id", "pose_id"]).image_id.nunique()
    assert per_pose.max() == 2  # two views of each pose, where the original has one
    assert original.groupby(["shape_id", "pose_id"]).image_id.nunique().max() == 1
    assert not set(views.camera_height.round(6)) & set(original.camera_height.round(6))  # new camera seeds
    timing = json.loads((tmp_path / "reports/timing/render/views.json").read_text())
    assert timing["datapoints"] == len(views) and timing["extra_views"] == 2
