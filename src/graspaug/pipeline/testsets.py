"""The test set a network's card makes of a folder of meshes, for ``graspaug evaluate`` and ``graspaug study external``:
the card's ``test_set_rules`` (or the params of ``--params``) over the params ``evaluate`` reads, its camera, crop and
gripper, cached by its recipe (:func:`~graspaug.experiments.evaluate.testset.cached_test_set`)."""

from __future__ import annotations

import json
from pathlib import Path

from graspaug.experiments.evaluate.testset import CARD_KEYS, cached_test_set, recipe_for
from graspaug.io.gqcnn import GraspImages
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.grasps import GraspsParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.profiles import with_sections
from graspaug.pipeline.params.render import RenderParams
from graspaug.planning.card import ModelCard
from graspaug.training.gqcnn import GraspArrays

Params = params_model(
    "The params `graspaug evaluate` reads.", ingest=IngestParams, grasps=GraspsParams, render=RenderParams
)


def card_test_set(params: Params, card: ModelCard, raw: dict, params_file: Path | None, sources: list, cache: Path):
    """The test set of ``sources`` made by a network's card (its ``test_set_rules``, unless ``params_file`` gave the
    params; its camera, crop and gripper), from or into ``cache``: (the params used, the recipe, the rules, the cached
    folder, its counts, its :class:`GraspImages`, its :class:`GraspArrays`)."""
    rules = None if params_file is not None else raw.get("test_set_rules")  # --params overrides the card
    params = with_sections(params, rules) if rules else params
    i, keys = params.ingest, {k: getattr(card, k) for k in CARD_KEYS}
    recipe = recipe_for(i.surface, i.max_faces, i.max_file_mb, params.grasps, params.render, params.seed, keys)
    folder = cached_test_set(sources, recipe, cache, params.workers, params.render.shard_rows)
    counts = json.loads((folder / "counts.json").read_text())
    data = GraspImages.open(folder / "gqcnn")
    arrays = GraspArrays(data.images(), data.read("z"), data.read("labels"))
    return params, recipe, rules, folder, counts, data, arrays
