import dataclasses
import json

import pydantic
import pytest
import yaml
from typer.testing import CliRunner

from graspaug.pipeline.cli import app
from graspaug.pipeline.params.base import parse_yaml
from graspaug.pipeline.params.model import Params, ParamsError, json_schema, load_params, params_dict, parse_params
from graspaug.pipeline.params.profiles import merge, profile_names, profile_params, profile_yaml
from graspaug.training.settings import TrainSettings


def test_params_yaml_holds_exactly_the_settings_defaults(repo_root):
    """One default per value: params.yaml is what `graspaug profile default` writes from the
    settings classes' fields, key for key."""
    text = (repo_root / "params.yaml").read_text()
    assert yaml.safe_load(text) == params_dict()
    assert load_params(repo_root / "params.yaml") == Params()
    assert text == profile_yaml("default", repo_root / "profiles")


def test_schema_file_is_up_to_date(repo_root):
    assert (repo_root / "params.schema.json").read_text() == json_schema()
    schema = json.loads(json_schema())
    steps = schema["$defs"]["TrainSettings"]["properties"]["max_steps"]
    assert (
        steps["default"] == TrainSettings().max_steps and steps["minimum"] == 1 and "SGD steps" in steps["description"]
    )


@pytest.mark.parametrize(
    ("raw", "message"),
    [
        (
            {"ingest": {"max_facez": 3}},
            "ingest.max_facez: unknown key; allowed here: max_faces, max_file_mb, min_shapes, test_fraction, "
            "min_voxels, surface",
        ),
        ({"colour": 1}, "colour: unknown key; allowed here: seed,"),
        (
            {"sim": {"cell": {"intrinsics": {"fz": 1}}}},
            "sim.cell.intrinsics.fz: unknown key; allowed here: width, height, fx, fy, cx, cy",
        ),
        (
            {"ingest": {"max_faces": "many"}},
            "ingest.max_faces: Input should be a valid integer, unable to parse string as an integer; got 'many'",
        ),
        (
            {"ingest": {"max_faces": 2.5}},
            "ingest.max_faces: Input should be a valid integer, got a number with a fractional part; got 2.5",
        ),
        ({"ingest": {"max_faces": 0}}, "ingest.max_faces: Input should be greater than or equal to 1; got 0"),
        (
            {"ingest": {"test_fraction": 1.5}},
            "ingest.test_fraction: Input should be less than or equal to 0.9; got 1.5",
        ),
        (
            {"ingest": {"surface": {"size_rule": "median"}}},
            "ingest.surface.size_rule: Input should be 'min', 'mid' or 'max'; got 'median'",
        ),
        ({"voxelize": {"resolution": 48}}, "voxelize.resolution: Input should be 16, 32, 64 or 128; got 48"),
        ({"voxelize": {"resolution": 16}}, "ae.net.resolution: must equal voxelize.resolution (16); got 32"),
        ({"device": "tpu"}, "device: Input should be 'auto', 'cpu' or 'cuda'; got 'tpu'"),
        ({"data": {"source": "folder"}}, "data.path: required when data.source is folder"),
        ({"data": 3}, "data: Input should be a dictionary"),
        ({"n_jobs": 0}, "n_jobs: must be >= 1, or -1 for all cores; got 0"),
        ({"executor": "dask"}, "scheduler: required when executor is dask"),
        ({"executor": "ray"}, "executor: Input should be 'joblib' or 'dask'; got 'ray'"),
        ({"ae": {"train": {"lambda": -1}}}, "ae.train.lambda: Input should be greater than or equal to 0; got -1"),
        (
            {"critic_eval": {"alphas": [0.1, 0.104]}},
            "critic_eval.alphas: weights must differ in the first two decimals",
        ),
        ({"critic_eval": {"alphas": [0.1, 1.5]}}, "critic_eval.alphas: must be a non-empty list of weights in [0, 1]"),
        ({"generate": {"ratios": [0, 1.0]}}, "generate.ratios: write every ratio as a float (1.0, not 1)"),
        (
            {"grasps": {"gripper": {"max_width": 0.1}}},
            "sim.sampler.max_width: must equal grasps.gripper.max_width (0.1); got 0.08",
        ),
        ({"render": {"crop": {"out_size": 16}}}, "gqcnn.net.image_size: must equal render.crop.out_size (16); got 32"),
        ({"sim": {"objects": ["mug", "teapot"]}}, "sim.objects: must be distinct names among mug, duck,"),
        ({"sim": {"objects": [], "n_test_objects": 0}}, "sim.objects: no objects to pick"),
        ({"sim": {"base_size": 300}}, "sim.base_size: must be one of gqcnn.augment_base_sizes [50]; got 300"),
        (
            {"sim": {"sampler": {"min_depth_offset": 0.05}}},
            "sim.sampler.max_depth_offset: must be >= min_depth_offset (0.05); got 0.04",
        ),
        ({"sim": {"attempts": 0}}, "sim.attempts: Input should be greater than or equal to 1; got 0"),
        (
            {"ae": {"train": {"precision": "float16"}}},
            "ae.train.precision: Input should be 'auto', 'float32' or 'bfloat16'; got 'float16'",
        ),
        (
            {"gqcnn": {"train": {"precision": "half"}}},
            "gqcnn.train.precision: Input should be 'auto', 'float32' or 'bfloat16'; got 'half'",
        ),
    ],
)
def test_bad_params_name_the_key(raw, message):
    with pytest.raises(ParamsError) as exc:
        parse_params(raw)
    assert str(exc.value).startswith(message)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("precision", ["auto", "float32", "bfloat16"])
def test_both_networks_take_every_precision(precision):
    params = parse_params({"ae": {"train": {"precision": precision}}, "gqcnn": {"train": {"precision": precision}}})
    assert params.ae.train.precision == params.gqcnn.train.precision == precision


def test_ints_are_accepted_for_floats_and_null_for_optionals():
    params = parse_params({"ingest": {"surface": {"size_m": 1}}, "data": {"limit": None}})
    assert params.ingest.surface.size_m == 1.0 and isinstance(params.ingest.surface.size_m, float)
    assert params.data.limit is None


def test_params_and_sections_are_frozen():
    with pytest.raises(pydantic.ValidationError):
        Params().seed = 3
    with pytest.raises(dataclasses.FrozenInstanceError):
        Params().gqcnn.train.max_steps = 3


def test_sections_are_the_library_settings():
    """No adapters: a section is the object the library takes."""
    from graspaug.grasping.antipodal import AntipodalSettings
    from graspaug.nets.gqcnn import GQCNNConfig
    from graspaug.sim.scene import CellLayout
    from graspaug.training.gqcnn import NoiseSettings

    params = Params()
    assert isinstance(params.grasps.sampler, AntipodalSettings) and isinstance(params.gqcnn.net, GQCNNConfig)
    assert isinstance(params.sim.cell, CellLayout) and isinstance(params.gqcnn.train.noise, NoiseSettings)
    assert params.gqcnn.train.noise == NoiseSettings()


def test_cli_bad_params_exit_2_with_one_line(tmp_path):
    bad = tmp_path / "params.yaml"
    bad.write_text(yaml.safe_dump({"voxelize": {"resolution": 7}}))
    result = CliRunner().invoke(app, ["voxelize", "--params", str(bad)])
    assert result.exit_code == 2
    lines = [line for line in result.output.splitlines() if line.strip()]
    assert lines == ["error: voxelize.resolution: Input should be 16, 32, 64 or 128; got 7"]


def test_cli_help_lists_stages_and_explains_params():
    runner = CliRunner()
    top = runner.invoke(app, ["--help"])
    assert top.exit_code == 0
    for stage in ("ingest", "voxelize", "profile", "schema"):
        assert stage in top.output
    sub = runner.invoke(app, ["ingest", "--help"])
    assert sub.exit_code == 0
    for key in ("max_faces", "ingest.surface.resolution", "size_rule", "test_fraction", "data.source"):
        assert key in sub.output
    version = runner.invoke(app, ["--version"])
    assert version.exit_code == 0 and version.output.startswith("graspaug ")


def test_every_overlay_names_only_real_keys(repo_root):
    folder = repo_root / "profiles"
    assert set(profile_names(folder)) >= {"default", "tiny", "study", "paper"}
    for name in profile_names(folder):
        profile_params(name, folder)  # raises on an unknown key or a bad value
    with pytest.raises(ParamsError, match=r"gqcnn\.train\.stepz: unknown key"):
        merge(params_dict(), {"gqcnn": {"train": {"stepz": 3}}})


def test_profiles_are_small_overlays(repo_root):
    folder = repo_root / "profiles"
    study, paper, tiny = (profile_params(n, folder) for n in ("study", "paper", "tiny"))
    assert (
        len(study.gqcnn.seeds) >= 5 and study.generate.base_sizes == (50, 100, 200) and len(study.generate.ratios) == 5
    )
    assert set(study.gqcnn.augment_base_sizes) == set(study.generate.base_sizes)  # the paper's 15 cells, three pools
    assert yaml.safe_load((folder / "study.yaml").read_text()).keys() == {"generate", "gqcnn", "sim"}
    per_seed = (len(study.sim.objects) + study.sim.n_test_objects) * study.sim.attempts
    assert per_seed >= 400  # paired attempts per network arm and training seed (issue 18)
    assert paper.voxelize.resolution == paper.ae.net.resolution == 64
    assert (paper.ae.net.base_width, paper.ae.net.top_width, paper.ae.net.z_dim) == (64, 512, 128)
    assert (paper.gqcnn.net.filters, paper.gqcnn.net.fc) == (64, 1024) and len(paper.gqcnn.seeds) >= 3
    assert (len(paper.sim.objects), paper.sim.n_test_objects, paper.sim.attempts) == (8, 0, 10)
    assert tiny.data.limit == 20 and tiny.voxelize.resolution == 16
    # the default decodes signed distances, and so does tiny (the test suite runs it); the paper's own decoder stays
    assert profile_params("default", folder).ae.net.output == tiny.ae.net.output == "sdf"
    assert paper.ae.net.output == "occupancy"


def test_profile_command_writes_a_complete_params_file(repo_root, tmp_path):
    out = tmp_path / "params.yaml"
    result = CliRunner().invoke(app, ["profile", "study", "--out", str(out), "--profiles", str(repo_root / "profiles")])
    assert result.exit_code == 0, result.output
    assert load_params(out) == profile_params("study", repo_root / "profiles")
    assert (
        yaml.safe_load(out.read_text())["gqcnn"]["train"]["max_steps"] == TrainSettings().max_steps
    )  # every key written, for DVC
    missing = CliRunner().invoke(app, ["profile", "nope", "--out", str(out), "--profiles", str(repo_root / "profiles")])
    assert missing.exit_code == 2 and "profile 'nope' not found" in missing.output


def test_profile_keeps_hand_edits_unless_forced(repo_root, tmp_path):
    """`graspaug profile` overwrites a file some profile wrote, but refuses one with hand edits, naming the keys."""
    out, profiles = tmp_path / "params.yaml", ["--profiles", str(repo_root / "profiles")]
    assert CliRunner().invoke(app, ["profile", "tiny", "--out", str(out), *profiles]).exit_code == 0
    assert CliRunner().invoke(app, ["profile", "default", "--out", str(out), *profiles]).exit_code == 0  # unedited
    edited = out.read_text().replace("\nseed: 0", "\nseed: 7", 1)
    assert edited != out.read_text()
    out.write_text(edited)
    refused = CliRunner().invoke(app, ["profile", "tiny", "--out", str(out), *profiles])
    assert refused.exit_code == 2 and "seed: 7" in refused.output and refused.output.count("\n") == 1
    assert out.read_text() == edited  # nothing lost
    forced = CliRunner().invoke(app, ["profile", "tiny", "--out", str(out), "--force", *profiles])
    assert forced.exit_code == 0 and load_params(out) == profile_params("tiny", repo_root / "profiles")


def test_a_yaml_syntax_error_names_its_line(tmp_path):
    bad = tmp_path / "params.yaml"
    bad.write_text("seed: 0\ngqcnn:\n  seeds: [0, 1\n  members: 3\n")
    with pytest.raises(ParamsError, match=r"params.yaml: not valid YAML at line \d+, column \d+"):
        load_params(bad)


def test_a_duplicated_key_is_refused_naming_the_key_and_its_line(tmp_path, repo_root):
    """YAML forbids a key given twice in one mapping; PyYAML keeps the second value silently and DVC calls the file
    corrupted, so check-params (and every stage's params load) refuses it, naming the key and both lines."""
    lines = (repo_root / "params.yaml").read_text().split("\n")
    at = next(i for i, line in enumerate(lines) if line.strip().startswith("size_m:"))
    indent = lines[at][: len(lines[at]) - len(lines[at].lstrip())]
    lines.insert(at + 1, f"{indent}size_m: 0.5")  # the same key again, in the same mapping
    bad = tmp_path / "params.yaml"
    bad.write_text("\n".join(lines))
    result = CliRunner().invoke(app, ["check-params", "--params", str(bad)])
    assert result.exit_code == 2, result.output
    assert f"duplicate key ingest.surface.size_m at line {at + 2} (first at line {at + 1})" in result.output
    assert result.output.count("\n") == 1
    with pytest.raises(ParamsError, match="duplicate key ingest.surface.size_m"):
        load_params(bad)
    # the same key in two mappings is no duplicate; nor is a merge key
    assert parse_yaml("a: {x: 1}\nb: {x: 2}\nc: &c {y: 1}\nd:\n  <<: *c\n  y: 2\n") == {
        "a": {"x": 1},
        "b": {"x": 2},
        "c": {"y": 1},
        "d": {"y": 2},
    }


def test_control_ratios_must_be_ratios_of_generate(repo_root):
    """gqcnn.control_ratios names ratios of generate.ratios (1:1 of 0, 0.5, 1, 2)."""
    chosen = {"generate": {"ratios": [0.0, 0.5, 1.0, 2.0]}, "gqcnn": {"control_ratios": [1.0]}}
    assert parse_params(merge(params_dict(), chosen)).gqcnn.control_ratios == (1.0,)
    real_objects = profile_params("real_objects", repo_root / "profiles")
    assert real_objects.ingest.surface.size == "fit" and "procedural" in real_objects.gqcnn.pools
    assert real_objects.render.images_per_pose == 5 and real_objects.generate.base_sizes == (50, 100, 150)
    with pytest.raises(ParamsError, match=r"gqcnn\.control_ratios: must be among generate\.ratios"):
        parse_params(merge(params_dict(), {"gqcnn": {"control_ratios": [3.0]}}))
    with pytest.raises(ParamsError, match=r"gqcnn\.control_ratios"):
        parse_params(merge(params_dict(), {"gqcnn": {"control_ratios": [0.0]}}))


def test_a_draw_of_the_real_objects_profile_reads_the_corpus_from_the_project(repo_root):
    """A draw runs in a clone elsewhere: the profile's relative corpus path is made absolute from the project."""
    from pathlib import Path

    from graspaug.pipeline.studies.draws import draw_params

    params = draw_params(repo_root, "real_objects", 2)
    assert params.data_seed == 2 and Path(params.data.path).is_absolute()
    assert Path(params.data.path) == (repo_root / "../shared/corpora").resolve()
    assert draw_params(repo_root, "attribution", 0).data.path is None
