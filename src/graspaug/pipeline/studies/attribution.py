"""``graspaug study attribution``: why generated shapes add nothing, over several draws of the data (issue #33).

Runs the ``attribution`` profile once per data seed and gives every contrast one interval over draws, training seeds
and test objects. Each draw k is a clone of the project's HEAD in ``workdir``/draw<k> that shares the project's DVC
cache (so the stages no data seed reaches, ingest to ``render@original``, come from the run cache), with params.yaml
written from the profile plus ``data_seed: k`` and any ``--set key=value``; it runs ``dvc repro report`` (the GQ-CNN
experiment, not the robot cell). Then :func:`graspaug.experiments.ap.attribution.combine_draws` combines the draws'
networks (t over the draws' means, with the test objects' bootstrap) and writes ``summary.json`` and
``decomposition.md`` into ``workdir``, and the per-network, per-test-datapoint tables with the command and commit
that made them into the project's ``results/<results>/`` (commit them: ``graspaug results`` recomputes every quoted
figure from them). A finished draw is not run again (``dvc repro`` finds nothing to do).
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

from graspaug.errors import DataError
from graspaug.experiments.ap.attribution import combine_draws, decomposition_markdown
from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.results import write_attribution
from graspaug.io.atomic import atomic_paths
from graspaug.io.tables import read_table
from graspaug.pipeline.paths import gqcnn_dir
from graspaug.pipeline.studies.draws import checked, draw_params, prepare_draw, provenance

log = logging.getLogger(__name__)


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
) -> str:
    """Run (unless ``combine_only``) and combine the draws ``draws`` (data seeds) of ``profile`` in ``workdir``;
    the decomposition's markdown (also written to ``workdir``/decomposition.md). ``command``: the line recorded
    with the tables in ``project``/results/``results``."""
    start = time.perf_counter()
    project, workdir = project.resolve(), workdir.resolve()
    params = {k: draw_params(project, profile, k, changes) for k in draws}
    folders = {k: workdir / f"draw{k}" for k in draws}
    for k in draws:
        if not combine_only:
            header = f"graspaug params, profile `{profile}` with data_seed {k}: written by `graspaug study attribution`"
            prepare_draw(project, folders[k], params[k], header)
            checked(["dvc", "repro", "report"], folders[k], f"draw {k}")
        log.info("draw %d: done (%.0f s)", k, time.perf_counter() - start)
    p = params[draws[0]]
    networks = {k: {s: folders[k] / f"models/gqcnn/s{s}" for s in p.gqcnn.seeds} for k in draws}
    tests = [
        test_labels(read_table(f / gqcnn_dir("original") / "index.parquet"), networks[k][p.gqcnn.seeds[0]])
        for k, f in folders.items()
    ]
    labels, objects = tests[0]
    if any((t[0] != labels).any() or (t[1] != objects).any() for t in tests):
        raise DataError("the draws were tested on different datapoints: they must share seed and the test split")
    result = combine_draws(networks, labels, objects, p.generate, p.gqcnn, resamples, p.seed)
    meta = provenance(project, command) | {"profile": profile, "draws": draws, "n_resamples": resamples, "seed": p.seed}
    write_attribution(project / "results" / results, networks, labels, objects, p.generate, p.gqcnn, meta)
    text = decomposition_markdown(result, p.gqcnn.augment_base_sizes, command)
    with atomic_paths([workdir / "summary.json", workdir / "decomposition.md"]) as (summary, decomposition):
        summary.write_text(json.dumps(result, indent=1))
        decomposition.write_text(text)
    log.info("%.0f s; written to %s/summary.json and decomposition.md", time.perf_counter() - start, workdir)
    return text
