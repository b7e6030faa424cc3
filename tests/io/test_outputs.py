"""Output folders: a command replaces only the files it wrote, never the user's nor its input."""

from __future__ import annotations

import json
import logging
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import pytest

from graspaug.errors import DataError
from graspaug.io.digest import sha256_of
from graspaug.io.outputs import (
    MARKER,
    check_output_files,
    check_output_folder,
    made_by,
    output_folder,
    owned_files,
)


def _write(out, command: str, files: dict[str, str], **kwargs) -> None:
    with output_folder(out, command, **kwargs) as tmp:
        for name, text in files.items():
            (tmp / name).parent.mkdir(parents=True, exist_ok=True)
            (tmp / name).write_text(text)


def test_a_folder_holding_a_users_file_is_refused_and_kept(tmp_path):
    project = tmp_path / "myproject"
    project.mkdir()
    (project / "notes.txt").write_text("mine")
    with pytest.raises(DataError, match=r"myproject holds notes.txt, which graspaug from-failures did not write"):
        check_output_folder(project, "from-failures")
    assert (project / "notes.txt").read_text() == "mine"
    check_output_folder(project, "from-failures", force=True)  # --force: the user's call


def test_a_rerun_replaces_its_own_files_and_refuses_a_file_added_since(tmp_path):
    """The issue's case: a second run into the folder of the first, after the user added a file there."""
    out = tmp_path / "out_new"
    _write(out, "from-failures", {"index.csv": "1", "meshes/failure_0000.obj": "v", "meshes/failure_0001.obj": "v"})
    assert made_by(out) == "graspaug from-failures"
    assert owned_files(out, "from-failures") == {"index.csv", "meshes/failure_0000.obj", "meshes/failure_0001.obj"}
    _write(out, "from-failures", {"index.csv": "2", "meshes/failure_0000.obj": "w"})  # its own: replaced
    assert (out / "index.csv").read_text() == "2" and not (out / "meshes/failure_0001.obj").exists()
    (out / "my_analysis.txt").write_text("x")
    with pytest.raises(DataError, match=r"out_new holds my_analysis.txt, which graspaug from-failures did not"):
        _write(out, "from-failures", {"index.csv": "3"})
    assert (out / "my_analysis.txt").read_text() == "x" and (out / "index.csv").read_text() == "2"
    _write(out, "from-failures", {"index.csv": "3"}, force=True)  # force writes beside it, never deletes it
    assert (out / "my_analysis.txt").read_text() == "x" and (out / "index.csv").read_text() == "3"
    assert not (out / "meshes").exists() and owned_files(out, "from-failures") == {"index.csv"}
    with pytest.raises(DataError, match="did not write"):  # another command's folder
        check_output_folder(out, "export-model")
    assert sorted(os.listdir(tmp_path)) == ["out_new"]  # no staging folder left


def test_an_older_one_line_marker_vouches_for_no_file(tmp_path):
    (tmp_path / "old").mkdir()
    (tmp_path / "old" / MARKER).write_text("graspaug from-failures\n")
    (tmp_path / "old/index.csv").write_text("1")
    assert made_by(tmp_path / "old") == "graspaug from-failures"
    with pytest.raises(DataError, match="holds index.csv, which"):
        check_output_folder(tmp_path / "old", "from-failures")


def test_a_failure_leaves_the_folder_as_it_was(tmp_path):
    out = tmp_path / "out"
    _write(out, "export-model", {"model.ts": "old", "card.json": "old"})
    with pytest.raises(RuntimeError), output_folder(out, "export-model") as tmp:
        (tmp / "model.ts").write_text("half")
        raise RuntimeError("crash mid-write")
    assert {p.name: p.read_text() for p in out.iterdir() if p.name != MARKER} == {"model.ts": "old", "card.json": "old"}
    with pytest.raises(RuntimeError), output_folder(tmp_path / "new", "export-model") as tmp:
        (tmp / "model.ts").write_text("half")
        raise RuntimeError("crash mid-write")
    assert sorted(os.listdir(tmp_path)) == ["out"]


KILLED_WRITER = textwrap.dedent("""
    import os, signal, sys
    from graspaug.io.outputs import output_folder
    with output_folder(sys.argv[1], "from-failures") as tmp:
        (tmp / "index.csv").write_text("half")
        os.kill(os.getpid(), signal.SIGKILL)
""")


def test_a_killed_writer_leaves_nothing_under_the_final_name_and_the_next_run_cleans_up(tmp_path):
    result = subprocess.run([sys.executable, "-c", KILLED_WRITER, str(tmp_path / "out")])
    assert result.returncode == -signal.SIGKILL
    assert not (tmp_path / "out").exists() and len(list(tmp_path.glob(".out.tmp-*"))) == 1
    _write(tmp_path / "out", "from-failures", {"index.csv": "whole"})
    assert sorted(os.listdir(tmp_path)) == ["out"] and (tmp_path / "out/index.csv").read_text() == "whole"


def test_a_symlinked_output_folder_is_refused_even_with_force(tmp_path):
    (tmp_path / "real").mkdir()
    (tmp_path / "real/keep.txt").write_text("mine")
    (tmp_path / "link").symlink_to(tmp_path / "real")
    for force in (False, True):
        with pytest.raises(DataError, match=r"link is a symbolic link \(to .*real\)"):
            check_output_folder(tmp_path / "link", "from-failures", force=force)
    assert (tmp_path / "real/keep.txt").read_text() == "mine" and (tmp_path / "link").is_symlink()


@pytest.mark.parametrize(("out", "word"), [("missed", "is"), ("missed/out", "lies inside"), (".", "holds")])
def test_an_output_inside_or_around_an_input_is_refused_even_with_force(tmp_path, out, word):
    missed = tmp_path / "missed"
    missed.mkdir()
    (missed / "mug.obj").write_text("v 0 0 0\n")
    with pytest.raises(DataError, match=f"{word} the input "):
        check_output_folder(tmp_path / out, "from-failures", inputs=[missed, None], force=True)
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


def test_a_manifest_name_that_leaves_the_folder_is_not_trusted(tmp_path):
    """The issue's case: ``"../precious.txt"`` in the manifest was deleted by a rerun."""
    (tmp_path / "precious.txt").write_text("mine")
    out = tmp_path / "out"
    _write(out, "from-failures", {"index.csv": "1"})
    manifest = json.loads((out / MARKER).read_text())
    manifest["files"] |= {"../precious.txt": sha256_of(tmp_path / "precious.txt"), "/etc/hostname": None}
    (out / MARKER).write_text(json.dumps(manifest))
    assert owned_files(out, "from-failures") == {"index.csv"}
    _write(out, "from-failures", {"index.csv": "2"})
    assert (tmp_path / "precious.txt").read_text() == "mine" and (out / "index.csv").read_text() == "2"


def test_a_folder_replaced_by_a_symbolic_link_is_never_written_or_emptied_through(tmp_path):
    """The issue's case: a subfolder the last run wrote, replaced by a link, had its target's file deleted."""
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "failure_0000.obj").write_text("mine")
    out = tmp_path / "out"
    _write(out, "from-failures", {"index.csv": "1", "meshes/failure_0000.obj": "v"})
    shutil.rmtree(out / "meshes")
    (out / "meshes").symlink_to(elsewhere)
    assert owned_files(out, "from-failures") == {"index.csv"}
    _write(out, "from-failures", {"index.csv": "2"}, force=True)  # the link is the user's: kept, not followed
    assert (elsewhere / "failure_0000.obj").read_text() == "mine" and (out / "meshes").is_symlink()
    with pytest.raises(DataError, match=r"holds meshes as a symbolic link .* nothing was written"):
        _write(out, "from-failures", {"index.csv": "3", "meshes/failure_0000.obj": "w"}, force=True)
    assert (elsewhere / "failure_0000.obj").read_text() == "mine" and (out / "index.csv").read_text() == "2"
    assert json.loads((out / MARKER).read_text())["files"].keys() == {"index.csv"}  # old and new not listed together


def test_a_file_the_user_saved_over_is_theirs_and_kept(tmp_path, caplog):
    """The issue's case: a file of the command's name holding the user's bytes was deleted by a rerun."""
    out = tmp_path / "out"
    _write(out, "from-failures", {"index.csv": "1", "summary.txt": "ours"})
    (out / "summary.txt").write_text("my own notes")
    with pytest.raises(DataError, match="holds summary.txt, which graspaug from-failures did not write"):
        _write(out, "from-failures", {"index.csv": "2"})
    with caplog.at_level(logging.INFO, logger="graspaug.io.outputs"):
        _write(out, "from-failures", {"index.csv": "2"}, force=True)
    assert (out / "summary.txt").read_text() == "my own notes" and (out / "index.csv").read_text() == "2"
    assert "kept" in caplog.text and "summary.txt" in caplog.text and "yours now" in caplog.text
    assert owned_files(out, "from-failures") == {"index.csv"}


def test_an_output_at_or_above_the_working_folder_or_the_project_is_refused(tmp_path, monkeypatch):
    project = tmp_path / "project"
    (project / "reports").mkdir(parents=True)
    monkeypatch.chdir(project / "reports")
    for out in (".", "..", str(tmp_path)):
        with pytest.raises(DataError, match="the working folder"):
            check_output_folder(out, "evaluate", force=True)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(DataError, match=r"output folder project is the project \("):
        check_output_folder("project", "evaluate", force=True, homes=[("the project", project)])
    check_output_folder("project/reports/evaluate", "evaluate", homes=[("the project", project)])  # inside: fine


def test_a_model_file_or_a_cache_inside_the_output_is_refused(tmp_path):
    (tmp_path / "o/cache").mkdir(parents=True)
    (tmp_path / "m.pt").write_text("x")
    with pytest.raises(DataError, match="holds the input .*cache"):
        check_output_folder(tmp_path / "o", "evaluate", inputs=[tmp_path / "o/cache"], force=True)
    with pytest.raises(DataError, match="holds the input .*m.pt"):
        check_output_folder(tmp_path, "evaluate", inputs=[tmp_path / "m.pt"], force=True)


def _checked_as(uid: int | None, outs: list[Path]) -> list[str]:
    """check_output_folder of each of ``outs`` in a forked child running as user ``uid`` (None: as this one)."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: drop to the user, check, report one line per folder
        lines = []
        try:
            if uid is not None:
                os.setgid(uid)
                os.setuid(uid)
            for out in outs:
                try:
                    check_output_folder(out, "evaluate", force=True)
                    lines.append(f"accepted {out}")
                except DataError as exc:
                    lines.append(f"refused {exc}")
        finally:
            os.write(write, "\n".join(lines).encode())
            os._exit(0)
    os.close(write)
    with os.fdopen(read) as pipe:
        text = pipe.read()
    os.waitpid(pid, 0)
    return text.splitlines()


def test_a_folder_that_cannot_be_written_is_refused_before_any_work():
    """As a user who may not write there (root may write anywhere: the check runs as ``nobody``)."""
    with tempfile.TemporaryDirectory() as top:
        top = Path(top)
        (top / "ro").mkdir()
        (top / "ok").mkdir()
        os.chmod(top, 0o755)
        os.chmod(top / "ro", 0o555)
        os.chmod(top / "ok", 0o777)
        lines = _checked_as(65534 if os.geteuid() == 0 else None, [top / "ro", top / "ro/new", top / "ok/new"])
    assert lines[0].startswith(f"refused the output folder {top / 'ro'} cannot be written")
    assert lines[1].startswith(f"refused the output folder {top / 'ro/new'} cannot be written: {top / 'ro'} refuses")
    assert lines[2] == f"accepted {top / 'ok/new'}"


def test_an_output_folder_under_a_file_blames_the_path_given(tmp_path):
    """``--out afile/sub``: the user's path and the file in its way are named, not an internal probe file."""
    from graspaug.io.outputs import check_output_folder

    (tmp_path / "afile").write_text("a file, not a folder")
    for out in (tmp_path / "afile" / "sub", tmp_path / "afile" / "sub" / "deeper"):
        with pytest.raises(DataError) as refused:
            check_output_folder(out, "evaluate")
        assert str(out) in str(refused.value) and f"{tmp_path / 'afile'} is a file" in str(refused.value)
        assert "probe" not in str(refused.value)
