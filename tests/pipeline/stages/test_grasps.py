"""The grasps stage through the real CLI on a small folder corpus."""

import json
import logging

import pandas as pd
import trimesh

from .test_ingest import run_stage

PARAMS = {
    "n_jobs": 1,
    "data": {"source": "folder", "path": None},
    "ingest": {"min_shapes": 2, "surface": {"resolution": 48, "finest_resolution": 48}},
    # a 3 cm gripper: it fits across the plate (2 cm) but not the cube (6 cm)
    "grasps": {"sampler": {"n_grasps": 12}, "perturbations": {"n_samples": 5}, "gripper": {"max_width": 0.03}},
    "sim": {"sampler": {"max_width": 0.03}},
}


def test_grasps_stage_writes_labelled_grasps_and_explains_empty_shapes(tmp_path, caplog):
    corpus = tmp_path / "meshes"
    corpus.mkdir()
    trimesh.creation.box(extents=(0.06, 0.06, 0.06)).export(corpus / "cube.stl")
    trimesh.creation.box(extents=(0.1, 0.06, 0.02)).export(corpus / "plate.stl")
    params = {**PARAMS, "data": {"source": "folder", "path": str(corpus)}}
    assert run_stage(tmp_path, "ingest", params).exit_code == 0

    with caplog.at_level(logging.WARNING):
        result = run_stage(tmp_path, "grasps", params)
    assert result.exit_code == 0, result.output
    table = pd.read_parquet(tmp_path / "data/grasps/original.parquet")
    assert set(table.shape_id) == {"f_plate"}  # the cube gets no rows ...
    assert (
        "f_cube has no grasp: its oriented bounding box's smallest side, 0.060 m, is wider than the 0.03 m opening"
        in caplog.text
    )
    assert len(table) == 12 and list(table.grasp_id) == list(range(12))
    for column in ("center_x", "axis_z", "p1_y", "n2_x", "width", "eps", "eps_mean", "eps_std", "success"):
        assert column in table
    assert table.width.between(0.02 - 1e-9, 0.03).all()
    assert (table.success == (table.eps_mean > 0.002)).all()
    assert (table.eps_mean >= 0).all() and (table.eps_std >= 0).all()
    summary = json.loads((tmp_path / "reports/grasps/original.json").read_text())
    assert summary["n_grasps"] == 12 and summary["shapes_without_grasps"] == 1
    metrics = json.loads((tmp_path / "metrics/grasps/original.json").read_text())
    assert metrics == {"shapes": 2, "positive": summary["success_share"]}  # the headline only

    first = table.copy()
    assert run_stage(tmp_path, "grasps", {**params, "n_jobs": 2}).exit_code == 0
    # same params, same table, whatever the number of worker processes
    pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / "data/grasps/original.parquet"), first)


def test_unknown_corpus_is_a_clear_error(tmp_path):
    from typer.testing import CliRunner

    from graspaug.pipeline.cli import app

    (tmp_path / "params.yaml").write_text("seed: 0\n")
    result = CliRunner().invoke(app, ["grasps", "--corpus", "nope", "--params", str(tmp_path / "params.yaml")])
    assert result.exit_code == 2  # bad input (the exit-code contract of graspaug --help)
    assert "unknown corpus 'nope'; known: original, gen_<base size>" in result.output
