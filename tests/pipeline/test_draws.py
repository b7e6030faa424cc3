"""A study's draws on a real local Dask cluster (:func:`graspaug.pipeline.studies.draws.run_on_cluster`): each draw a
task on workers with the lean settings, its result handed back here as it ends, a failed draw named while the others
finish."""

import dask
import pytest

from graspaug.pipeline.studies.draws import LEAN_DASK, run_on_cluster

pytest.importorskip("distributed")


def _settings_seen_by_the_worker(draw: int) -> dict:
    if draw < 0:
        raise ValueError(f"draw {draw} cannot run")
    return {key: dask.config.get(key) for key in LEAN_DASK}


def test_draws_run_on_lean_workers_and_a_failed_draw_is_named():
    finished = {}
    failed = run_on_cluster(
        {d: (_settings_seen_by_the_worker, (d,)) for d in (1, 2, -3)}, None, 2, lambda d, r: finished.update({d: r})
    )
    assert sorted(finished) == [1, 2] and all(seen == LEAN_DASK for seen in finished.values())
    assert failed == {-3: "ValueError: draw -3 cannot run"}
    assert dask.config.get("distributed.worker.profile.enabled") is True  # this process's settings come back
