"""What the studies over several draws of the data share: a draw's params, its clone of the project, the provenance
of the tables they write to ``results/``."""

from __future__ import annotations

import logging
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


#: Dask settings of the local cluster a study starts: a draw's task only waits on its ``dvc repro`` for an hour, so
#: the worker's statistical profiler (a sample every 10 ms), the 20 ms event-loop tick and the half-second system and
#: memory monitors are overhead on the cores the draws need: 8.0 CPU seconds a minute with Dask's defaults, 0.81 lean
#: (9.9x less, ``bench/dask_overhead.py``, 2 cores, 2026-12-07).
LEAN_DASK = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.admin.tick.interval": "1s",
    "distributed.worker.memory.monitor-interval": "2s",
}


def run_on_cluster(jobs: dict, scheduler: str | None, workers: int, finished) -> dict[int, str]:
    """Run ``jobs`` (draw → (function, args)), each as one task on a Dask cluster: the scheduler at ``scheduler``
    (workers that see the project and the DVC cache at the same paths), or a ``distributed.LocalCluster`` of
    ``workers`` processes of one thread each, with :data:`LEAN_DASK`'s settings. ``finished(draw, result)`` runs
    here, in this process, as each draw ends (so one process writes ``results/``); a draw that fails is logged with
    its reason and the others go on. Returns draw → the reason of each failed draw (empty: all finished). Without
    ``distributed`` installed the draws run here, one after another."""
    log = logging.getLogger(__name__)
    failed: dict[int, str] = {}

    def done(draw, call):
        try:
            result = call()
        except Exception as exc:  # one failed draw must not stop the others: it is named at the end
            failed[draw] = f"{type(exc).__name__}: {exc}"
            log.error("draw %d failed: %s", draw, failed[draw])
            return
        finished(draw, result)

    if not jobs:
        return failed
    try:
        import dask
        from distributed import Client, LocalCluster, as_completed
    except ImportError:  # pragma: no cover - the dev extras install it
        log.warning("distributed is not installed: the draws run here, one after another")
        for draw, (function, args) in jobs.items():
            done(draw, lambda: function(*args))
        return failed
    with dask.config.set(LEAN_DASK if scheduler is None else {}):  # a cluster of the user's keeps its own settings
        cluster = None
        if scheduler is None:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
        try:
            with Client(scheduler or cluster) as client:
                log.info("draws %s on the Dask cluster at %s", sorted(jobs), client.scheduler.address)
                futures = {
                    client.submit(f, *a, key=f"draw-{d}-{time.time_ns()}", pure=False): d for d, (f, a) in jobs.items()
                }
                for future in as_completed(futures):
                    done(futures[future], future.result)
        finally:
            if cluster is not None:
                cluster.close()
    return failed


def failed_draws_error(failed: dict[int, str], what: str) -> StageError:
    """The error a study ends with when draws failed: each named with its reason."""
    reasons = "; ".join(f"draw {d}: {why}" for d, why in sorted(failed.items()))
    return StageError(f"{what}: {len(failed)} draw(s) failed, the others finished ({reasons})")
