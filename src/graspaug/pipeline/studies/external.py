"""``graspaug study external``: a confirmatory study's kept networks on an external test set (issue #82).

The study's folder (``results/<study>/``, with ``plan.yaml`` and ``networks/d<draw>-s0/``) names its draws and the
arms each draw kept (``objects.json``). The external folder of meshes (``../shared/external/ycb78``) is made into one
test set by the networks' cards, as ``graspaug evaluate`` makes it (:func:`~graspaug.pipeline.stages.evaluate.
card_test_set`, cached), every network predicts every datapoint, and the tables go to ``results/<study>-<set>/``
(:mod:`graspaug.experiments.confirm.external`), from which ``graspaug results`` recomputes every quoted figure.
The contrasts: the plan's control, primary and secondary ones whose arms were kept, then every kept augmented arm
against its base set alone; the first is the positive control of the external set.
"""

from __future__ import annotations

import json
import logging
import time
from pathlib import Path

from graspaug.errors import DataError
from graspaug.experiments.confirm.external import write_external
from graspaug.experiments.confirm.tables import PLAN, column, machine, read_plan

log = logging.getLogger(__name__)


def kept_networks(study: Path) -> tuple[list[int], dict[str, list], dict[tuple[int, str], Path]]:
    """The draws, the arms (name → [pool, B, R]) every draw kept, and (draw, arm) → model.pt of a study's folder."""
    kept = sorted(study.glob("networks/d*-s0/objects.json"), key=lambda p: int(p.parent.name[1:].split("-")[0]))
    if not kept:
        raise DataError(f"{study}: no kept networks (networks/d<draw>-s0/objects.json)")
    draws, arms, models = [], None, {}
    for path in kept:
        draw = int(path.parent.name[1:].split("-")[0])
        these = json.loads(path.read_text())["arms"]
        if arms is not None and these != arms:
            raise DataError(f"{path}: draw {draw} kept other arms ({', '.join(these)}) than the others")
        arms = these
        for arm, (pool, b, r) in these.items():
            model = path.parent / f"{pool}-{b}-{float(r):g}" / "model.pt"
            if not model.is_file():
                raise DataError(f"{model}: draw {draw}'s {arm} network is missing")
            models[(draw, arm)] = model
        draws.append(draw)
    return draws, arms, models


def planned_contrasts(plan: dict, arms: dict) -> dict[str, list[str]]:
    """name → [a, b]: the plan's control, primary and secondary contrasts whose two arms were kept (the control
    first), then each kept augmented arm ``<pool>@B`` against ``none@B``."""
    specs = [plan["control"], plan["primary"], *plan["secondary"]]
    out = {s["name"]: [s["a"], s["b"]] for s in specs if s.get("a") in arms and s.get("b") in arms}
    for arm, (pool, b, r) in arms.items():
        if float(r) > 0 and f"none@{b}" in arms and [arm, f"none@{b}"] not in out.values():
            out[f"{pool}_vs_none@{b}"] = [arm, f"none@{b}"]
    if plan["control"]["name"] not in out:
        raise DataError(f"the plan's control {plan['control']['name']} compares arms that were not kept")
    return out


def predict_on(models: dict, corpus: Path, cache: Path, unit_scale: float = 1.0) -> tuple:
    """Every model of ``models`` (column name → model.pt; their cards must give one test set) on the test set of
    ``corpus``, made by the first model's card as ``graspaug evaluate`` makes it, from or into ``cache``: (labels,
    objects, column → P(success), the cached folder, its ingest counts)."""
    from graspaug.device import resolve_device
    from graspaug.io.checkpoints import read_gqcnn
    from graspaug.io.sources import folder_sources
    from graspaug.pipeline.testsets import Params, card_test_set
    from graspaug.planning.card import ModelCard
    from graspaug.training.gqcnn import predict

    if not corpus.is_dir():
        raise DataError(f"--corpus {corpus}: no such folder")
    sources = folder_sources(corpus, unit_scale, None)
    if not sources:
        raise DataError(f"--corpus {corpus}: no mesh files (.obj .stl .ply .off .glb) in it")
    first = next(iter(models.values()))
    net, raw = read_gqcnn(first)
    card = ModelCard.from_dict(raw, net.config.image_input)
    params, recipe, rules, folder, counts, data, arrays = card_test_set(Params(), card, raw, None, sources, cache)
    device = resolve_device(params.device)
    predictions = {}
    for name, model in models.items():
        net, raw_m = read_gqcnn(model)
        if raw_m.get("test_set_rules") != raw.get("test_set_rules"):
            raise DataError(f"{model}: its card's test-set rules differ from {first}'s; it needs another test set")
        predictions[name] = predict(net.to(device), arrays, device)
        log.info("%s: predicted %d datapoints of %s", name, len(arrays.labels), corpus.name)
    return arrays.labels, data.index["shape_id"].to_numpy(), predictions, folder, counts


def run(study: Path, corpus: Path, out: Path, cache: Path, unit_scale: float, n_resamples: int, command: str) -> str:
    """Predict every kept network of ``study`` on the test set of ``corpus``; write ``out``; the lines to print."""
    from graspaug.experiments.confirm.external import combine_external, external_figures
    from graspaug.io.tables import read_table
    from graspaug.pipeline.studies.draws import provenance

    began, made_by = time.perf_counter(), provenance(Path.cwd(), command)  # the commit that runs, not a later one
    plan = read_plan(study / PLAN)
    draws, arms, models = kept_networks(study)
    contrasts = planned_contrasts(plan, arms)
    named = {column(d, 0, (arms[a][0], int(arms[a][1]), float(arms[a][2]))): m for (d, a), m in models.items()}
    labels, objects, predictions, folder, counts = predict_on(named, corpus, cache, unit_scale)
    held = {o for o, y in zip(objects, labels) if y}
    shapes = read_table(folder / "shapes.parquet").set_index("shape_id")
    meta = made_by | {
        "study": str(study),
        "corpus": str(corpus),
        "test_set": folder.name,
        "arms": arms,
        "draws": draws,
        "contrasts": contrasts,
        "n_resamples": n_resamples,
        "seed": 0,
        "counts": {
            "objects": int(len(set(objects))),
            "objects_with_positive": len(held),
            "datapoints": int(len(labels)),
            "positives": int(labels.sum()),
            "ingest": counts,
        },
        "object_scale": {o: float(shapes.scale[o]) for o in sorted(set(objects))},  # < 1: shrunk by the fit rule
        "seconds": round(time.perf_counter() - began),
        "machine": machine(),
    }
    write_external(out, labels, objects, predictions, meta)
    figures = external_figures(combine_external(out), out.name)
    return "\n".join(f"{k}: {v}" for k, v in figures.items())
