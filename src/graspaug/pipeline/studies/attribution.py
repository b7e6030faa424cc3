"""``graspaug study attribution``: what each pool of generated shapes adds, over several draws of the data (issue #33).

Runs the ``attribution`` profile once per data seed and gives every contrast one interval over draws, training seeds
and test objects. Each draw k is a clone of the project's HEAD in ``workdir``/draw<k> that shares the project's DVC
cache (so the stages no data seed reaches, ingest to ``render@original``, come from the run cache), with params.yaml
written from the profile plus ``data_seed: k`` and any ``--set key=value``; it runs ``dvc repro report`` (the GQ-CNN
experiment, not the robot cell), and adds that draw's per-network, per-test-datapoint tables with the command and
commit that made them to the project's ``results/<results>/`` at once (commit them as they come: ``graspaug results``
recomputes every quoted figure from them). Then :func:`graspaug.experiments.results.combine_attribution` combines
the draws from those tables alone (one interval per contrast: t over the draws' means, or over the seeds with one
draw, with the test objects' bootstrap) and writes ``summary.json`` and ``decomposition.md`` into ``workdir``;
``--combine-only`` does only that, with no clone. A finished draw is not run again (``dvc repro`` finds nothing to
do), and a second draw's clone takes every stage no data seed reaches (ingest to ``render@original``) from the
shared run cache.
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

from graspaug.experiments.ap.attribution import decomposition_markdown
from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.kept import keep_networks
from graspaug.experiments.results import add_attribution_draw, combine_attribution
from graspaug.io.atomic import atomic_paths
from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import params_dict
from graspaug.pipeline.paths import gqcnn_dir
from graspaug.pipeline.studies.draws import (
    checked,
    draw_params,
    failed_draws_error,
    prepare_draw,
    provenance,
    run_on_cluster,
)

log = logging.getLogger(__name__)
KEPT_POOLS = ("targeted", "real")  # with no augmentation (targeted at 1:0), what a user keeps to evaluate


def kept_networks(generate, gqcnn) -> list[tuple[str, int, float]]:
    """The networks a study keeps for its users: at every augmented base size B, none (1:0) and the targeted and
    real pools at each of their nonzero ratios, of the pools the run trains (``gqcnn.pools``)."""
    from graspaug.training.variants import pool_ratios

    out = []
    for b in gqcnn.augment_base_sizes:
        out.append(("targeted", b, 0.0))
        for pool in (p for p in KEPT_POOLS if p in gqcnn.pools):
            out += [(pool, b, float(r)) for r in pool_ratios(pool, generate.ratios, gqcnn.control_ratios) if r > 0]
    return out


def run_draw(project: Path, k: int, clone: Path, params, profile: str) -> int:
    """One draw, on whichever worker runs it: clone ``project`` into ``clone`` (once), write the draw's params, run
    ``dvc repro report``; its wall time (s)."""
    began = time.perf_counter()
    header = f"graspaug params, profile `{profile}` with data_seed {k}: written by `graspaug study attribution`"
    prepare_draw(project, clone, params, header)
    checked(["dvc", "repro", "report"], clone, f"draw {k}")
    return round(time.perf_counter() - began)


def run(
    project: Path,
    draws: list[int],
    workdir: Path,
    profile: str,
    changes: list[str],
    resamples: int,
    combine_only: bool,
    results: str,
    command: str,
    keep: tuple[int, int] | None = None,
    scheduler: str | None = None,
    workers: int = 1,
) -> str:
    """Run (unless ``combine_only``) the draws ``draws`` (data seeds) of ``profile`` in ``workdir``, adding each
    draw's tables to ``project``/results/``results`` as soon as it finishes (``command``: the line recorded with
    them), then combine the draws from those tables alone; the decomposition's markdown (also written to
    ``workdir``/decomposition.md, with summary.json). ``combine_only`` needs no clone: only the results folder.
    ``keep`` (draw, training seed): that seed's networks without augmentation and with the targeted and real pools
    at every augmented B (:data:`KEPT_POOLS`) go to the results folder's ``networks/d<draw>-s<seed>/``. Each draw is
    one task on the Dask cluster at ``scheduler``, or on a LocalCluster of ``workers`` processes; a failed draw is
    named at the end, the others go on (:func:`~graspaug.pipeline.studies.draws.run_on_cluster`)."""
    start = time.perf_counter()
    project, workdir = project.resolve(), workdir.resolve()
    folder = project / "results" / results
    params = {k: draw_params(project, profile, k, changes) for k in draws}
    p = params[draws[0]]

    def finished(k: int, seconds: int) -> None:
        clone = workdir / f"draw{k}"
        networks = {s: clone / f"models/gqcnn/s{s}" for s in p.gqcnn.seeds}
        labels, objects = test_labels(
            read_table(clone / gqcnn_dir("original") / "index.parquet"), networks[p.gqcnn.seeds[0]]
        )
        meta = provenance(clone, command) | {"profile": profile, "n_resamples": resamples, "seed": p.seed}  # its code
        meta["params"] = {k: v for k, v in params_dict(params[k]).items() if k != "data_seed"}
        add_attribution_draw(folder, k, networks, labels, objects, p.generate, p.gqcnn, meta | {"seconds": seconds})
        if keep and keep[0] == k:
            keys = kept_networks(p.generate, p.gqcnn)
            keep_networks(networks[keep[1]], folder / "networks" / f"d{k}-s{keep[1]}", keys)
        log.info("draw %d: done in %d s; its tables are in %s (commit them)", k, seconds, folder)

    jobs = {k: (run_draw, (project, k, workdir / f"draw{k}", params[k], profile)) for k in draws}
    failed = run_on_cluster({} if combine_only else jobs, scheduler, workers, finished)
    if failed:
        raise failed_draws_error(failed, "study attribution")
    result = combine_attribution(folder, draws)
    text = decomposition_markdown(result, p.gqcnn.augment_base_sizes, command)
    workdir.mkdir(parents=True, exist_ok=True)
    with atomic_paths([workdir / "summary.json", workdir / "decomposition.md"]) as (summary, decomposition):
        summary.write_text(json.dumps(result, indent=1))
        decomposition.write_text(text)
    log.info("%.0f s; written to %s/summary.json and decomposition.md", time.perf_counter() - start, workdir)
    return text
