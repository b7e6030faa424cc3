"""Output folders: a command replaces only what it made, never its input."""

from __future__ import annotations

import pytest

from graspaug.errors import DataError
from graspaug.io.atomic import atomic_path
from graspaug.io.outputs import MARKER, check_output_files, check_output_folder, made_by, mark


def test_a_folder_holding_a_users_file_is_refused_and_kept(tmp_path):
    project = tmp_path / "myproject"
    project.mkdir()
    (project / "notes.txt").write_text("mine")
    with pytest.raises(DataError, match=r"myproject already holds files that graspaug from-failures did not write"):
        check_output_folder(project, "from-failures")
    assert (project / "notes.txt").read_text() == "mine"
    check_output_folder(project, "from-failures", force=True)  # --force: the user's call


def test_a_folder_the_command_made_is_replaced_and_another_commands_is_not(tmp_path):
    out = tmp_path / "out"
    with atomic_path(out, directory=True) as tmp:
        mark(tmp, "from-failures")
        (tmp / "index.csv").write_text("shape_id\n")
    assert made_by(out) == "graspaug from-failures" and (out / MARKER).is_file()
    check_output_folder(out, "from-failures")  # its own: replaced
    with pytest.raises(DataError, match="did not write"):
        check_output_folder(out, "export-model")
    check_output_folder(tmp_path / "new", "from-failures")  # missing: made
    (tmp_path / "empty").mkdir()
    check_output_folder(tmp_path / "empty", "from-failures")


@pytest.mark.parametrize(("out", "word"), [("missed", "is"), ("missed/out", "lies inside"), (".", "holds")])
def test_an_output_inside_or_around_an_input_is_refused_even_with_force(tmp_path, out, word):
    missed = tmp_path / "missed"
    missed.mkdir()
    (missed / "mug.obj").write_text("v 0 0 0\n")
    with pytest.raises(DataError, match=f"{word} the input folder"):
        check_output_folder(tmp_path / out, "from-failures", inputs=[missed], force=True)
    assert (missed / "mug.obj").exists()


def test_a_file_as_output_folder_is_refused(tmp_path):
    (tmp_path / "plan").write_text("x")
    with pytest.raises(DataError, match="is a file"):
        check_output_folder(tmp_path / "plan", "from-failures")
    with pytest.raises(DataError, match="is a file; give a folder"):
        check_output_files(tmp_path / "plan", ["grasp.json"], "plan", "graspaug plan")


def test_files_a_command_wrote_are_replaced_and_others_are_not(tmp_path):
    (tmp_path / "grasp.json").write_text('{"written_by": "graspaug plan"}')
    check_output_files(tmp_path, ["grasp.json", "grasp.png"], "plan", "graspaug plan")
    (tmp_path / "grasp.json").write_text('{"mine": 1}')
    with pytest.raises(DataError, match="already holds grasp.json, not written by graspaug plan"):
        check_output_files(tmp_path, ["grasp.json", "grasp.png"], "plan", "graspaug plan")
    check_output_files(tmp_path, ["grasp.json"], "plan", "graspaug plan", force=True)
