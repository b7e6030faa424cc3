"""What the studies over several draws of the data share: a draw's params, its clone of the project, the provenance
of the tables they write to ``results/``."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import yaml

from graspaug.errors import StageError
from graspaug.pipeline.params.model import params_dict, parse_params
from graspaug.pipeline.params.profiles import merge, params_yaml, read_overlay


def draw_params(project: Path, profile: str, data_seed: int, changes: list[str] = ()):
    """The validated params of ``profile`` (``project``/profiles) with ``data_seed`` and ``changes``
    (``key.path=yaml value``, e.g. ``gqcnn.augment_base_sizes=[50]``); a relative ``data.path`` (the real-objects
    profile's ``../shared/corpora/gso300``) is made absolute from ``project``, as a draw runs in a clone elsewhere."""
    overlay = read_overlay(profile, project / "profiles") | {"data_seed": data_seed}
    for change in changes:
        key, _, value = change.partition("=")
        *path, last = key.split(".")
        node = overlay
        for part in path:
            node = node.setdefault(part, {})
        node[last] = yaml.safe_load(value)
    merged = merge(params_dict(), overlay)
    if merged["data"].get("path") and not Path(merged["data"]["path"]).is_absolute():
        merged["data"]["path"] = str((project / merged["data"]["path"]).resolve())
    return parse_params(merged)


def study_env() -> dict[str, str]:
    """The environment of a draw's commands: this interpreter's scripts (``dvc``, ``graspaug``) first on PATH."""
    path = f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"
    return {**os.environ, "DVC_NO_ANALYTICS": "1", "PATH": path}


def checked(command: list[str], cwd: Path, what: str) -> None:
    """Run ``command`` in ``cwd``; a failure is a :class:`StageError` naming ``what`` and the command."""
    done = subprocess.run(command, cwd=cwd, env=study_env())
    if done.returncode != 0:
        raise StageError(f"{what}: `{' '.join(command)}` failed in {cwd} (exit {done.returncode}; its output above)")


def prepare_draw(project: Path, folder: Path, params, header: str, share_cache: bool = True) -> None:
    """Clone ``project``'s HEAD into ``folder`` (once), share ``project``'s DVC cache (``share_cache``) and write
    ``params`` as its params.yaml under ``header``."""
    if not folder.exists():
        checked(["git", "clone", "--quiet", str(project), str(folder)], project, f"draw {params.data_seed}")
    if share_cache:
        cache = subprocess.run(
            [sys.executable, "-m", "dvc", "cache", "dir"], cwd=project, check=True, capture_output=True, text=True
        ).stdout.strip()
        checked([sys.executable, "-m", "dvc", "cache", "dir", "--local", cache], folder, "sharing the DVC cache")
    (folder / "params.yaml").write_text(params_yaml(params, header))


def provenance(project: Path, command: str) -> dict:
    """The ``command`` line, ``project``'s commit and today's date: what ``results/<study>/`` records."""
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=project, capture_output=True, text=True).stdout.strip()
    return {"command": command, "commit": commit, "date": time.strftime("%Y-%m-%d")}
