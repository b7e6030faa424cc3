"""``graspaug study confirm``: the draws of a committed confirmatory plan (issue #74).

The plan (``results/<name>/plan.yaml``, :func:`graspaug.experiments.confirm.tables.read_plan`) names the profile,
the draws (data seeds) and the training seeds of each draw. The study refuses to run from a plan that git does not
hold unchanged, or whose profile now gives other params than the plan recorded (``params_sha256``). Each draw is one
task on a Dask cluster (:func:`~graspaug.pipeline.studies.draws.run_on_cluster`): a clone of the project's HEAD in
``workdir``/draw<k> sharing its DVC cache, with the profile's params and ``data_seed: k``, runs ``dvc repro
train_gqcnn@<s>`` for each planned seed (the per-object stages come from the run cache: with ``independent_draws``
a draw redraws only its split and what follows it). As each draw ends its tables go into the plan's folder at once
(:func:`~graspaug.experiments.confirm.tables.add_confirm_draw`; commit them as they come), and a failed draw is
named while the others go on. A draw already in the folder is not run again. Once every planned draw is in,
:func:`~graspaug.experiments.confirm.tables.combine_confirm` reads the plan's tests.
"""

from __future__ import annotations

import hashlib
import json
import logging
import time
from pathlib import Path

from graspaug.errors import DataError
from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.confirm.tables import (
    BASE_OBJECTS,
    PLAN,
    add_confirm_draw,
    arm_key,
    base_objects,
    check_base_objects,
    check_plan_history,
    column,
    combine_confirm,
    external_sets,
    read_plan,
)
from graspaug.experiments.confirm.words import confirm_figures
from graspaug.io.tables import read_table
from graspaug.pipeline.params.model import params_dict
from graspaug.pipeline.paths import OBJECTS_TABLE, SHAPES_TABLE, gqcnn_dir
from graspaug.pipeline.studies.draws import (
    checked,
    draw_params,
    failed_draws_error,
    prepare_draw,
    provenance,
    run_on_cluster,
)

log = logging.getLogger(__name__)


def params_digest(params) -> str:
    """SHA-256 (first 16 hex digits) of a draw's params but ``data_seed`` and the corpus path (which differs by
    machine): what a plan records so that a later edit of its profile is caught."""
    values = {k: v for k, v in params_dict(params).items() if k != "data_seed"}
    values["data"] = {k: v for k, v in values["data"].items() if k != "path"}
    return hashlib.sha256(json.dumps(values, sort_keys=True).encode()).hexdigest()[:16]


def run_draw(project: Path, draw: int, clone: Path, params, seeds: list[int]) -> dict:
    """One draw, on whichever worker runs it: clone ``project`` into ``clone`` (once), write the draw's params, run
    ``dvc repro train_gqcnn@<s>`` for every seed of ``seeds``; the clone and the wall time (s)."""
    began = time.perf_counter()
    header = f"graspaug params of the confirmatory draw data_seed {draw}: written by `graspaug study confirm`"
    prepare_draw(project, clone, params, header)
    checked(["dvc", "repro", *[f"train_gqcnn@{s}" for s in seeds]], clone, f"draw {draw}")
    return {"clone": str(clone), "seconds": round(time.perf_counter() - began)}


def draw_roles(clone: Path, seed: int, objects) -> dict:
    """The draw's objects by role, as the kept networks' ``objects.json`` records them: its base sets, validation
    and test objects (shape ids), and each test object's source file (relative to the corpus folder, e.g.
    ``gso100/Name.obj``) with the scale ingest gave it, so a test object can be loaded again from the corpora."""
    roles = json.loads((clone / "models" / "gqcnn" / f"s{seed}" / "split.json").read_text())
    test = sorted(set(objects))
    shapes = read_table(clone / SHAPES_TABLE).set_index("shape_id")
    sources = {s: {"source": str(shapes.source[s]).split(":", 1)[-1], "scale": float(shapes.scale[s])} for s in test}
    return {"base": roles["base"], "validation": list(roles["validation"]), "test": test, "test_sources": sources}


def draw_external(project: Path, plan: dict, spec: dict, draw: int, seed_dirs: dict) -> tuple:
    """One draw's networks on a plan's external test set (``spec``: its ``corpus``, relative to the project or
    absolute): (labels, objects, seed → column → P(success)); the test set is made once and cached in the project's
    ``.graspaug-cache/evaluate`` (the same for every draw: the networks' cards give the same rules)."""
    from graspaug.experiments.ap.numbers import network_folder
    from graspaug.pipeline.studies.external import predict_on

    corpus = Path(spec["corpus"])
    corpus = corpus if corpus.is_absolute() else (project / corpus).resolve()
    keys = {arm: arm_key(plan, arm) for arm in plan["arms"]}
    by_seed, labels, objects = {}, None, None
    for s, seed_dir in seed_dirs.items():
        models = {column(draw, s, k): network_folder(seed_dir, k) / "model.pt" for k in keys.values()}
        labels, objects, by_seed[s], _, _ = predict_on(models, corpus, project / ".graspaug-cache" / "evaluate")
    return labels, objects, by_seed


def run(
    project: Path,
    plan_path: Path,
    workdir: Path,
    draws: list[int] | None,
    scheduler: str | None,
    workers: int,
    combine_only: bool,
    command: str,
) -> str:
    """Run the plan's draws not yet in its folder (or only ``draws``, each of the plan's), add each one's tables as it
    finishes, then combine; the text to print (the progress, or the plan's result)."""
    project, workdir = project.resolve(), workdir.resolve()
    plan_path = (project / plan_path) if not plan_path.is_absolute() else plan_path
    plan, folder = read_plan(plan_path), plan_path.parent
    problems = check_plan_history(folder)
    if problems:
        raise DataError(f"{plan_path}: {'; '.join(problems)}")
    planned = [int(d) for d in plan["draws"]]
    chosen = planned if draws is None else draws
    extra = sorted(set(chosen) - set(planned))
    if extra:
        raise DataError(
            f"--draws {extra}: not in the plan's draws {planned}; a draw beyond the plan is exploratory (run it with "
            "`graspaug study attribution` into a results folder of its own and report it apart)"
        )
    done = combine_confirm(folder)["draws_done"]
    todo = [] if combine_only else [d for d in chosen if d not in done]
    params = {d: draw_params(project, plan["profile"], d) for d in todo}
    for d, p in params.items():
        if sorted(p.gqcnn.seeds) != sorted(plan["seeds"]):
            raise DataError(f"profile {plan['profile']}: gqcnn.seeds {list(p.gqcnn.seeds)}, the plan {plan['seeds']}")
        if plan.get("params_sha256") and params_digest(p) != plan["params_sha256"]:
            raise DataError(
                f"profile {plan['profile']} now gives other params than the plan recorded (params_sha256 "
                f"{plan['params_sha256']}, now {params_digest(p)}): the plan is fixed; a new design is a new plan"
            )

    def finished(draw: int, result: dict) -> None:
        clone = Path(result["clone"])
        seed_dirs = {s: clone / "models" / "gqcnn" / f"s{s}" for s in sorted(plan["seeds"])}
        first = seed_dirs[min(seed_dirs)]
        labels, objects = test_labels(read_table(clone / gqcnn_dir("original") / "index.parquet"), first)
        meta = provenance(clone, command) | {"seconds": result["seconds"], "plan": PLAN}
        meta["params"] = {k: v for k, v in params_dict(params[draw]).items() if k not in ("data_seed", "data")}
        roles = draw_roles(clone, min(seed_dirs), objects)
        sets = external_sets(plan).items()
        external = {name: draw_external(project, plan, spec, draw, seed_dirs) for name, spec in sets}
        add_confirm_draw(folder, plan, draw, seed_dirs, labels, objects, meta, roles, external)
        log.info("draw %d: done in %d s; its tables are in %s (commit them)", draw, result["seconds"], folder)

    jobs = {d: (run_draw, (project, d, workdir / f"draw{d}", params[d], sorted(plan["seeds"]))) for d in todo}
    failed = run_on_cluster(jobs, scheduler, workers, finished)
    result = combine_confirm(folder)
    figures = confirm_figures(result, folder.name)
    text = "\n".join(f"{k}: {v}" for k, v in figures.items())
    if failed:
        raise failed_draws_error(failed, f"study confirm ({result['status']})")
    return text


def count_objects(project: Path, plan_path: Path, clone: Path) -> str:
    """Write the plan folder's base-set counts (:data:`BASE_OBJECTS`, :func:`base_objects`): each planned draw's
    base sets on actual counts, from ``clone``'s objects table and rendered originals (a finished draw of the plan, or
    any clone whose ingest and renders are the draws'), split and drawn by the plan's profile; refused unless every
    committed 1:0 network trained on exactly the datapoints counted for it. The text to print."""
    import pandas as pd

    project, clone = project.resolve(), clone.resolve()
    plan_path = (project / plan_path) if not plan_path.is_absolute() else plan_path
    plan, folder = read_plan(plan_path), plan_path.parent
    for needed in (clone / OBJECTS_TABLE, clone / gqcnn_dir("original") / "index.parquet"):
        if not needed.is_file():
            raise DataError(f"--count-objects {clone}: no {needed.relative_to(clone)} (a finished draw's clone)")
    if not (folder / "networks.parquet").is_file():
        raise DataError(f"{folder}: no networks.parquet, so no draw to count (run the plan's draws first)")
    draws = sorted(set(int(d) for d in pd.read_parquet(folder / "networks.parquet").draw))
    params = draw_params(project, plan["profile"], draws[0])
    counts = base_objects(
        read_table(clone / OBJECTS_TABLE),
        clone / gqcnn_dir("original"),
        draws,
        list(params.generate.base_sizes),
        params.ingest.test_fraction,
        params.gqcnn.val_shapes,
        params.seed,
        params.independent_draws,
    )
    check_base_objects(counts, pd.read_parquet(folder / "networks.parquet"))
    tmp = folder / f".{BASE_OBJECTS}.tmp"
    counts.to_parquet(tmp, index=False)
    tmp.replace(folder / BASE_OBJECTS)
    return counts.to_string(index=False)
