"""Every report names the profile and corpus that made it (issue #62, 12): read from the params file itself."""

from __future__ import annotations

import pandas as pd

from graspaug.pipeline.params.base import load
from graspaug.pipeline.params.profiles import profile_yaml
from graspaug.pipeline.provenance import report_header
from graspaug.pipeline.stages import report


def test_a_tiny_run_says_so_loudly(repo_root):
    text = profile_yaml("tiny", repo_root / "profiles")
    shapes = pd.DataFrame({"split": ["train"] * 13 + ["test"] * 5})
    header = report_header(text, shapes)
    first = header.splitlines()[0]
    assert "profile `tiny` (params.yaml = the defaults + profiles/tiny.yaml)" in first
    assert "pybullet_data/random_urdfs, the first 20 files; 18 shapes kept (13 train, 5 test)" in first
    assert "**Profile `tiny` is a smoke test" in header and "its numbers mean nothing" in header
    default = report_header(profile_yaml("default", repo_root / "profiles"))
    assert "profile `default` (params.yaml = the defaults)" in default and "mean nothing" not in default


def test_an_edited_value_is_not_passed_off_as_the_profile(repo_root):
    text = profile_yaml("default", repo_root / "profiles")
    edited = text.replace("\ndata_seed: 0", "\ndata_seed: 3", 1)
    assert edited != text
    assert "values edited since" in report_header(edited)
    assert "values edited since" not in report_header(text)
    assert "edited" not in report_header(text.replace("# Edit values", "# A comment; edit values"))  # not a value
    assert "names no profile" in report_header("data_seed: 0\n")
    assert "built in code" in report_header(None)


def test_loaded_params_carry_their_file(repo_root, tmp_path):
    path = tmp_path / "params.yaml"
    path.write_text(profile_yaml("tiny", repo_root / "profiles"))
    params = load(path, report.Params)
    assert "profile `tiny`" in report_header(params.file_text)
    assert params == report.Params.model_validate(params.model_dump(by_alias=True))  # the text is not a value
