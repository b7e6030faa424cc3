import dataclasses

import pytest
import yaml
from typer.testing import CliRunner

from graspaug.cli import app
from graspaug.config import Params, ParamsError, load_params, parse_params


def test_repo_params_load_and_match_the_dataclass_defaults(repo_root):
    params = load_params(repo_root / "params.yaml")
    assert isinstance(params, Params)
    # params.yaml states every default explicitly, so --help and the file agree
    assert params == Params()


@pytest.mark.parametrize(
    ("raw", "message"),
    [
        ({"ingest": {"max_facez": 3}}, "ingest.max_facez: unknown key; allowed here: max_faces,"),
        ({"colour": 1}, "colour: unknown key"),
        ({"ingest": {"max_faces": "many"}}, "ingest.max_faces: expected int, got 'many'"),
        ({"ingest": {"max_faces": 2.5}}, "ingest.max_faces: expected int, got 2.5"),
        ({"ingest": {"max_faces": True}}, "ingest.max_faces: expected int, got True"),
        ({"ingest": {"max_faces": 0}}, "ingest.max_faces: must be >= 1; got 0"),
        ({"ingest": {"test_fraction": 1.5}}, "ingest.test_fraction: must be <= 0.9; got 1.5"),
        ({"voxelize": {"resolution": 48}}, "voxelize.resolution: must be one of 16, 32, 64, 128; got 48"),
        ({"device": "tpu"}, "device: must be one of auto, cpu, cuda; got 'tpu'"),
        ({"data": {"source": "folder"}}, "data.path: required when data.source is folder"),
        ({"data": 3}, "data.: expected a mapping"),
        ({"n_jobs": 0}, "n_jobs: must be >= 1, or -1 for all cores; got 0"),
        ({"executor": "dask"}, "scheduler: required when executor is dask"),
        ({"executor": "ray"}, "executor: must be one of joblib, dask; got 'ray'"),
        ({"ae": {"lambda": -1}}, "ae.lambda: must be >= 0; got -1"),
        ({"critic_eval": {"alphas": [0.1, 0.104]}}, "critic_eval.alphas: weights must differ in the first two decimals"),
        ({"critic_eval": {"alphas": [0.1, 1.5]}}, "critic_eval.alphas: must be a non-empty list of weights in [0, 1]"),
        ({"sim": {"objects": ["mug", "teapot"]}}, "sim.objects: must be distinct names among mug, duck,"),
        ({"sim": {"objects": [], "n_test_objects": 0}}, "sim.objects: no objects to pick"),
        ({"sim": {"base_size": 300}}, "sim.base_size: must be one of generate.base_sizes [50, 100, 200]; got 300"),
        ({"sim": {"min_depth_offset": 0.05}}, "sim.max_depth_offset: must be >= sim.min_depth_offset (0.05); got 0.04"),
        ({"sim": {"attempts": 0}}, "sim.attempts: must be >= 1; got 0"),
    ],
)
def test_bad_params_name_the_key(raw, message):
    with pytest.raises(ParamsError) as exc:
        parse_params(raw)
    assert str(exc.value).startswith(message)
    assert "\n" not in str(exc.value)


def test_ints_are_accepted_for_floats_and_null_for_optionals():
    params = parse_params({"ingest": {"size_m": 1}, "data": {"limit": None}})
    assert params.ingest.size_m == 1.0 and isinstance(params.ingest.size_m, float)
    assert params.data.limit is None


def test_params_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        Params().seed = 3


def test_cli_bad_params_exit_2_with_one_line(tmp_path):
    bad = tmp_path / "params.yaml"
    bad.write_text(yaml.safe_dump({"voxelize": {"resolution": 7}}))
    result = CliRunner().invoke(app, ["voxelize", "--params", str(bad)])
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert lines == ["error: voxelize.resolution: must be one of 16, 32, 64, 128; got 7"]


def test_cli_help_lists_stages_and_explains_params():
    runner = CliRunner()
    top = runner.invoke(app, ["--help"])
    assert top.exit_code == 0
    for stage in ("ingest", "voxelize"):
        assert stage in top.output
    sub = runner.invoke(app, ["ingest", "--help"])
    assert sub.exit_code == 0
    for key in ("max_faces", "surface_resolution", "size_rule", "test_fraction", "source"):
        assert key in sub.output


def test_paper_profile_loads_with_the_paper_sizes(repo_root):
    params = load_params(repo_root / "profiles/paper.yaml")
    assert params.voxelize.resolution == 64
    assert (params.ae.base_width, params.ae.top_width, params.ae.z_dim) == (64, 512, 128)
    assert params.ingest.test_fraction == pytest.approx(363 / 1363, abs=1e-4)
    assert (len(params.sim.objects), params.sim.n_test_objects, params.sim.attempts) == (8, 0, 10)  # 8 objects x 10 attempts


def test_study_profile_is_the_defaults_with_three_seeds(repo_root):
    import dataclasses

    study, default = load_params(repo_root / "profiles/study.yaml"), load_params(repo_root / "params.yaml")
    assert study.gqcnn.seeds == (0, 1, 2) and default.gqcnn.seeds == (0,)
    assert dataclasses.replace(study, gqcnn=dataclasses.replace(study.gqcnn, seeds=(0,))) == default
    paper = load_params(repo_root / "profiles/paper.yaml")
    assert (paper.gqcnn.filters, paper.gqcnn.fc) == (64, 1024) and len(paper.gqcnn.seeds) >= 3
