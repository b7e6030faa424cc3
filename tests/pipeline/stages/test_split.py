"""The split stage on a folder of 12 meshes with the tiny profile (issue #84: the README's own-meshes path with 12
meshes stopped at `generate@6` with exit 3, a "bug", after every expensive stage before it had run)."""

import pandas as pd
import trimesh

from graspaug.pipeline.params.model import params_dict
from graspaug.pipeline.params.profiles import profile_params

from .test_ingest import run_stage


def twelve_meshes(folder):
    """Boxes and cans of 12 proportions (distinct once sized, so no duplicate: 9 train, 3 test at 0.2663)."""
    folder.mkdir()
    for k in range(6):
        trimesh.creation.box(extents=(0.10, 0.06, 0.02 + 0.012 * k)).export(folder / f"box_{k}.stl")
        trimesh.creation.cylinder(radius=0.015 + 0.006 * k, height=0.08).export(folder / f"can_{k}.stl")


def test_too_few_shapes_for_the_settings_stop_the_split_in_one_line(tmp_path, repo_root):
    twelve_meshes(tmp_path / "meshes")
    params = params_dict(profile_params("tiny", repo_root / "profiles"))
    params["data"] |= {"source": "folder", "path": "meshes"}
    assert run_stage(tmp_path, "ingest", params).exit_code == 0
    assert len(pd.read_parquet(tmp_path / "data/objects.parquet")) == 12

    refused = run_stage(tmp_path, "split", params)
    assert refused.exit_code == 2, refused.output
    said = [line for line in refused.output.splitlines() if line.startswith("error:")]
    assert len(said) == 1 and "Traceback" not in refused.output
    assert said[0].startswith("error: too few shapes: 12 kept by ingest (9 train, 3 test at ingest.test_fraction")
    assert "14 train (generate.base_sizes up to 6 + gqcnn.val_shapes 2 + 6 for the real pool" in said[0]
    assert "at least 19 in all" in said[0] and not (tmp_path / "data/shapes.parquet").exists()

    # what the line says to lower: base sets of 2 and 3 need 3 + 2 + 3 train shapes, which 9 hold
    params["generate"]["base_sizes"], params["gqcnn"]["augment_base_sizes"] = [2, 3], [3]
    accepted = run_stage(tmp_path, "split", params)
    assert accepted.exit_code == 0, accepted.output
    assert pd.read_parquet(tmp_path / "data/shapes.parquet").split.value_counts().to_dict() == {"train": 9, "test": 3}
