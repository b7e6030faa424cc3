"""The exit-code contract of every command (:mod:`graspaug.pipeline.command`): warnings reach the log once each,
and the system failing a command (disk full) is exit 3 naming the cause, not the user's bad input."""

import logging
from pathlib import Path

import numpy as np
import pytest
import typer
from typer.testing import CliRunner

from graspaug.pipeline.cli import app
from graspaug.pipeline.command import Command, is_system_error


def _warning_app() -> typer.Typer:
    """A command (the CLI's :class:`Command`) that makes numpy warn twice with one text and once with another."""
    warner = typer.Typer()

    @warner.command(cls=Command)
    def mean_of_nothing(times: int = 2) -> None:
        for _ in range(times):
            np.mean(np.array([]))  # RuntimeWarning: Mean of empty slice (numpy's own warning)
        np.log(np.array([-1.0]))  # RuntimeWarning: invalid value encountered in log
        logging.getLogger("graspaug.test").info("done")

    return warner


def test_a_third_party_warning_reaches_the_log_once(caplog):
    """Warnings of other packages were all hidden; each distinct one is now logged once, however often raised."""
    caplog.set_level(logging.INFO)
    result = CliRunner().invoke(_warning_app(), ["--times", "5"])
    assert result.exit_code == 0, result.output
    logged = [r.getMessage() for r in caplog.records if r.name == "py.warnings"]
    assert len([m for m in logged if "Mean of empty slice" in m]) == 1, logged
    assert len([m for m in logged if "invalid value encountered in log" in m]) == 1, logged
    assert all(m.startswith("RuntimeWarning: ") for m in logged), logged


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full (every write: no space left)")
def test_a_full_disk_is_exit_3_naming_the_cause(tmp_path):
    """A write that fails with ENOSPC is the system's failure, not bad input: exit 3, the cause named in one line."""
    result = CliRunner().invoke(app, ["schema", "--out", "/dev/full"])
    assert result.exit_code == 3, result.output
    assert "No space left on device" in result.output and "ENOSPC" in result.output, result.output
    assert result.output.count("\n") == 1
    # a missing input stays bad input: exit 2
    missing = CliRunner().invoke(app, ["check-params", "--params", str(tmp_path / "nope.yaml")])
    assert missing.exit_code == 2 and "not found" in missing.output


def test_which_os_errors_are_the_systems():
    import errno

    assert is_system_error(OSError(errno.ENOSPC, "No space left on device"))
    assert is_system_error(PermissionError(errno.EACCES, "Permission denied", "out/grasp.json"))
    assert not is_system_error(FileNotFoundError(errno.ENOENT, "No such file or directory", "in.npy"))
    assert not is_system_error(IsADirectoryError(errno.EISDIR, "Is a directory", "in.npy"))
    assert not is_system_error(FileNotFoundError("data/gqcnn/gen_6: no rendered dataset"))  # a message, no errno
    assert not is_system_error(ValueError("not an OSError"))


def test_usage_errors_are_one_line_and_exit_2():
    """Every usage error of `graspaug` (a bad option value, an unknown option) is one line naming it, exit 2: the
    `--keep-networks` parse error included (it exited 3 as an unexpected error before)."""
    import subprocess
    import sys

    cli = [sys.executable, "-m", "graspaug.pipeline.cli"]
    for args, words in (
        (["study", "attribution", "--keep-networks", "x/y"], "Invalid value for '--keep-networks': 'x/y'"),
        (["evaluate", "--nope"], "No such option: --nope"),
    ):
        done = subprocess.run([*cli, *args], capture_output=True, text=True)
        assert done.returncode == 2 and words in done.stderr, done.stderr
        assert len(done.stderr.strip().splitlines()) == 1, done.stderr


def test_a_study_keeps_only_the_networks_its_run_trains():
    """`--keep-networks` with `gqcnn.pools=[targeted]` keeps none and targeted (no real pool to copy after the run)."""
    from types import SimpleNamespace

    from graspaug.pipeline.studies.attribution import kept_networks

    generate = SimpleNamespace(ratios=(0.0, 1.0))
    only = SimpleNamespace(augment_base_sizes=(50,), pools=("targeted",), control_ratios=None)
    assert kept_networks(generate, only) == [("targeted", 50, 0.0), ("targeted", 50, 1.0)]
    both = SimpleNamespace(augment_base_sizes=(50,), pools=("targeted", "real"), control_ratios=None)
    assert ("real", 50, 1.0) in kept_networks(generate, both)


def test_every_commands_help_keeps_its_placeholders():
    """The help is markdown: a placeholder such as ``d<k>-s0/`` or ``results/<NAME>/`` outside backticks was taken
    for an HTML tag and dropped ("d-s0/ each"). Every command's --help prints every ``<...>`` its texts hold."""
    import re

    import typer
    from typer.testing import CliRunner

    from graspaug.pipeline.cli import app

    def commands(group, path):
        for name, command in group.commands.items():
            if hasattr(command, "commands"):
                yield from commands(command, [*path, name])
            else:
                yield [*path, name], command

    checked = 0
    for path, command in commands(typer.main.get_command(app), []):
        texts = [command.help or "", *(getattr(p, "help", None) or "" for p in command.params)]
        wanted = {m for text in texts for m in re.findall(r"<[\w@.-]+>", text)}
        shown = CliRunner().invoke(app, [*path, "--help"], env={"COLUMNS": "400"})
        assert shown.exit_code == 0, shown.output
        lost = sorted(p for p in wanted if p not in shown.output)
        assert not lost, f"graspaug {' '.join(path)} --help drops {lost}"
        checked += bool(wanted)
    assert checked >= 5  # real-picks, confirm, from-failures, plan, export-dexnet, ... hold placeholders
