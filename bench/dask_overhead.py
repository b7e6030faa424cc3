"""The CPU a study's local Dask cluster spends beside its draws: two workers of one thread each (as
``graspaug study … --workers 2`` starts them) wait on a ``sleep`` subprocess, as a draw's task waits on its
``dvc repro``; the CPU time of this process (scheduler and client) and of the worker processes over that wait,
with Dask's default settings (the reference) and with
:data:`graspaug.pipeline.studies.draws.LEAN_DASK`. Prints each and their ratio.

    python bench/dask_overhead.py [--seconds 60]
"""

from __future__ import annotations

import argparse
import json
import subprocess

import dask
import psutil
from distributed import Client, LocalCluster

from graspaug.pipeline.studies.draws import LEAN_DASK


def _wait(seconds: float) -> float:
    subprocess.run(["sleep", str(seconds)], check=True)
    return seconds


def _cpu(processes: list[psutil.Process]) -> float:
    return sum(sum(p.cpu_times()[:2]) for p in processes if p.is_running())


def overhead(settings: dict, seconds: float) -> float:
    """CPU seconds the cluster's processes spend while two tasks wait ``seconds`` on a subprocess."""
    with dask.config.set(settings):
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
        try:
            with Client(cluster) as client:
                me = psutil.Process()
                processes = [me, *me.children(recursive=True)]
                before = _cpu(processes)
                client.gather([client.submit(_wait, seconds, pure=False) for _ in range(2)])
                return _cpu(processes) - before
        finally:
            cluster.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0)
    args = parser.parse_args()
    default, lean = overhead({}, args.seconds), overhead(LEAN_DASK, args.seconds)
    print(
        json.dumps(
            {
                "wait_seconds": args.seconds,
                "cpu_seconds_dask_defaults": round(default, 2),
                "cpu_seconds_lean": round(lean, 2),
                "ratio": round(default / max(lean, 1e-9), 1),
            }
        )
    )


if __name__ == "__main__":
    main()
