"""``graspaug export-dexnet`` of a generated corpus: one pool alone (``--pool``), or every pool labelled."""

import json

import numpy as np
import pandas as pd
from typer.testing import CliRunner

from graspaug.io.atomic import atomic_path
from graspaug.io.dexnet import read_tensor_field
from graspaug.io.gqcnn import write_grasp_images
from graspaug.pipeline.cli import app
from graspaug.pipeline.paths import gqcnn_dir


def write_generated_dataset(root, pools=("targeted", "random"), per_pool=6):
    """A rendered corpus ``gen_6`` in the render stage's format: ``per_pool`` datapoints of each pool, two shapes
    each, depth crops of a flat table 0.7 m away with one shape's step."""
    rows = []
    for p, pool in enumerate(pools):
        for i in range(per_pool):
            rows.append(
                {
                    "shape_id": f"g6_{pool}_{i % 2:03d}",
                    "origin": "generated",
                    "split": "train",
                    "base_size": 6,
                    "pool": pool,
                    "order": i % 2,
                    "grasp_id": i,
                    "pose_id": 0,
                    "image_id": i // 2,
                    "center_u": 320.0 + i,
                    "center_v": 240.0 + p,
                    "angle": 0.1 * i,
                    "z": 0.68,
                    "width_px": 20.0,
                    "collision_free": i % 3 != 0,
                    "eps": 0.001 * i,
                    "success": 0.001 * i > 0.002,
                }
            )
    index = pd.DataFrame(rows).astype({"pool": "string"})
    index["label"] = index.collision_free & index.success
    images = np.full((len(index), 32, 32), 0.7, np.float32)
    images[:, 8:24, 8:24] -= 0.01 * (1 + np.arange(len(index)))[:, None, None]  # each crop its own
    info = {"corpus": "gen_6", "intrinsics": {"cx": 319.5, "cy": 239.5}, "grasps_threshold": 0.002}
    with atomic_path(root / gqcnn_dir("gen_6"), directory=True) as folder:
        write_grasp_images(folder, images, index, shard_rows=5)
        (folder / "dataset.json").write_text(json.dumps(info))
    return index, images


def test_export_dexnet_pool_exports_only_that_pool(tmp_path, monkeypatch):
    index, images = write_generated_dataset(tmp_path)
    monkeypatch.chdir(tmp_path)
    result = CliRunner().invoke(app, ["export-dexnet", "gen_6", "targeted_only", "--pool", "targeted"])
    assert result.exit_code == 0, result.output
    assert "6 datapoints (gen_6, pool targeted)" in result.output
    config = json.loads((tmp_path / "targeted_only/config.json").read_text())
    assert config["pool"] == "targeted" and config["pools"] == ["targeted"] and config["num_datapoints"] == 6
    assert config["source"] == "graspaug render (gen_6, pool targeted)"
    targeted = (index.pool == "targeted").to_numpy()
    depth = read_tensor_field(tmp_path / "targeted_only", "depth_ims_tf_table")[..., 0]
    np.testing.assert_array_equal(depth, images[targeted])
    assert set(np.array(config["obj_ids"])) == {"g6_targeted_000", "g6_targeted_001"}
    np.testing.assert_allclose(
        read_tensor_field(tmp_path / "targeted_only", "robust_ferrari_canny_raw"), index.eps[targeted]
    )
    assert not (tmp_path / "targeted_only/tensors/pool_labels_00000.npz").exists()

    # every pool: each datapoint says which
    result = CliRunner().invoke(app, ["export-dexnet", "gen_6", "both"])
    assert result.exit_code == 0, result.output
    config = json.loads((tmp_path / "both/config.json").read_text())
    assert config["pool"] == "all" and config["pools"] == ["random", "targeted"] and config["num_datapoints"] == 12
    labels = read_tensor_field(tmp_path / "both", "pool_labels")
    np.testing.assert_array_equal(np.array(config["pools"])[labels], index.pool.to_numpy(dtype=object))

    # a pool the corpus does not hold: one line naming it and the pools there are, nothing written
    result = CliRunner().invoke(app, ["export-dexnet", "gen_6", "nope", "--pool", "blend"])
    assert result.exit_code == 2 and result.output.count("\n") == 1, result.output
    assert "--pool blend: not a pool of gen_6; its pools: random, targeted" in result.output
    assert not (tmp_path / "nope").exists()
