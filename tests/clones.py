"""A user's clone of the repository in a temporary folder, and the commands the slow tests run in it."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import yaml

#: The commands of the package under test (graspaug, dvc) in the interpreter's own folder.
BIN = Path(sys.executable).parent


def copy_repo(src: Path, dst: Path) -> None:
    """The files a user's clone has (tracked by git), without outputs or caches."""
    listed = subprocess.run(
        ["git", "ls-files", "-co", "--exclude-standard"], cwd=src, capture_output=True, text=True, check=True
    )
    for rel in listed.stdout.splitlines():
        if not (src / rel).is_file():
            continue
        (dst / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src / rel, dst / rel)


def run(cmd, cwd, env):
    result = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
    assert result.returncode == 0, f"{cmd} failed:\n{result.stdout}\n{result.stderr}"
    return result


def clone_env(cache: Path) -> dict[str, str]:
    """The environment of the commands run in a clone: the interpreter's commands first on the path, a git identity
    (a user's clone has commits: DVCLive and ``dvc exp`` need one), and the cell's convex decompositions cached in
    ``cache`` (``$GRASPAUG_CACHE``), never in the user's ``~/.cache``."""
    return {
        **os.environ,
        "DVC_NO_ANALYTICS": "1",
        "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}",
        "GRASPAUG_CACHE": str(cache),
        **{f"GIT_{who}_NAME": "test" for who in ("AUTHOR", "COMMITTER")},
        **{f"GIT_{who}_EMAIL": "test@example.com" for who in ("AUTHOR", "COMMITTER")},
    }


def tiny_clone(src: Path, work: Path, cache: Path, edit: Callable[[dict], None] | None = None) -> dict[str, str]:
    """A clone of ``src`` in ``work`` on the tiny profile, applied the documented way (``graspaug profile tiny``),
    ``edit`` (if given) changing its params in place, committed; the environment to run commands in it."""
    work.mkdir(parents=True, exist_ok=True)
    copy_repo(src, work)
    env = clone_env(cache)
    run([str(BIN / "graspaug"), "profile", "tiny"], work, env)
    if edit is not None:
        params = yaml.safe_load((work / "params.yaml").read_text())
        edit(params)
        (work / "params.yaml").write_text(yaml.safe_dump(params, sort_keys=False))
    for cmd in (["git", "init", "-q"], ["git", "add", "-A"], ["git", "commit", "-q", "-m", "clone"]):
        run(cmd, work, env)
    return env
