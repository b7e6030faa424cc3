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
