"""``graspaug evaluate MODEL… --corpus DIR``: trained GQ-CNNs tested on any folder of meshes. No DVC stage: a user's
command whose adapter sits here as it knows the file names.

The folder is ingested as the pipeline ingests (``ingest`` params, real size kept: ``ingest.surface.size: real``),
grasps sampled and labelled by the ``grasps`` params with the models' gripper and label threshold, datapoints rendered
by the ``render`` params with the models' camera (their model card); the params are the built-in defaults unless
``--params FILE`` names a file, wherever the command runs. The test set is cached
(:func:`~graspaug.experiments.evaluate.testset.cached_test_set`). Writes into ``out`` through its manifest
(:mod:`graspaug.io.outputs`; every check before any work): ``report.md``, ``evaluate.json`` (every AP and difference as
a contrast, the counts, the cache key, what shaped the test set) and ``rejects.csv`` (the files not used, and why).
"""

from __future__ import annotations

from pathlib import Path

from tqdm import tqdm

from graspaug.device import resolve_device
from graspaug.errors import DataError
from graspaug.experiments.evaluate.numbers import test_ap
from graspaug.experiments.evaluate.testset import (
    CARD_KEYS,
    arrange_arms,
    replicate_name,
    shaped_by,
)
from graspaug.experiments.evaluate.words import printed_lines, report_markdown, rules_source
from graspaug.io.checkpoints import read_gqcnn
from graspaug.io.outputs import output_folder
from graspaug.io.sources import folder_sources
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.pipeline.testsets import Params, card_test_set
from graspaug.planning.card import ModelCard
from graspaug.training.gqcnn import predict

ARMS_HINT = "name each arm's replicates (seeds or draws) one after another (at least 2 an arm)"


def run(
    params: Params,
    models: list[Path],
    corpus: Path,
    out: Path,
    cache: Path,
    unit_scale: float,
    limit: int | None,
    n_resamples: int,
    force: bool,
    params_file: Path | None = None,
    seeds: int | None = None,
) -> list[str]:
    """Evaluate ``models`` on the meshes of ``corpus``; the printed lines. ``params_file``: the file ``params`` came
    from (None: the cards' ``test_set_rules``, else the defaults). ``seeds``: arms of that many replicates each."""
    if not corpus.is_dir():
        raise DataError(f"--corpus {corpus}: no such folder")
    if len({str(m) for m in models}) < len(models):
        raise DataError("a model is named twice; name each once")
    if seeds is not None and (seeds < 2 or len(models) % seeds):
        raise DataError(f"--seeds {seeds}: {len(models)} models are not arms of {seeds} replicates each; {ARMS_HINT}")
    homes = [] if params_file is None else [("the project of --params", Path(params_file).absolute().parent)]
    with output_folder(out, "evaluate", [corpus, cache, *models], force, homes) as staging:
        sources = folder_sources(corpus, unit_scale, limit)
        if not sources:
            raise DataError(f"--corpus {corpus}: no mesh files (.obj .stl .ply .off .glb) in it")
        nets, cards, raw = {}, {}, {}
        for path in models:
            nets[str(path)], raw[str(path)] = read_gqcnn(path)
            cards[str(path)] = ModelCard.from_dict(raw[str(path)], nets[str(path)].config.image_input)
        first = next(iter(cards))
        for name, card in cards.items():
            differs = [k for k in CARD_KEYS if getattr(card, k) != getattr(cards[first], k)]
            differs += [] if raw[name].get("test_set_rules") == raw[first].get("test_set_rules") else ["test_set_rules"]
            if differs:
                raise DataError(f"model {name}: its card's {differs[0]} differs from {first}'s; evaluate them apart")
        replicates, arms, pairs = None, None, None
        if seeds is not None:  # replicate k of every arm: the same draw and training seed, whatever the order given
            order, replicates, arms = arrange_arms(raw, seeds)
            nets = {name: nets[name] for name in order}
            pairs = [replicate_name(raw[name]) for name in order[:seeds]]
        test = card_test_set(params, cards[first], raw[first], params_file, sources, cache)
        params, recipe, rules, folder, counts, data, arrays = test
        device = resolve_device(params.device)
        bar = tqdm(nets.items(), desc="evaluate: predict", unit="network", leave=False)
        probabilities = {name: predict(net.to(device), arrays, device) for name, net in bar}
        ids = data.index["shape_id"].to_numpy()
        result = test_ap(arrays.labels, ids, probabilities, n_resamples, params.seed, seeds, replicates, arms, pairs)

        made = shaped_by(recipe, counts, params_file, unit_scale) | {"rules": rules_source(params_file, rules)}
        camera = f"the models' camera ({cards[first].camera_distance[0]:g}-{cards[first].camera_distance[1]:g} m)"
        (staging / "report.md").write_text(report_markdown(result, str(corpus), counts, camera, made))
        summary = {**result, "counts": counts, "corpus": str(corpus), "test_set": folder.name, "shaped_by": made}
        write_json(summary, staging / "evaluate.json")
        write_csv(read_table(folder / "rejects.parquet")[["source", "reason"]], staging / "rejects.csv")
    return printed_lines(result, out / "report.md")
