"""A folder of meshes → a GQ-CNN test set, made as the pipeline makes its own (:mod:`graspaug.augment.corpus`,
:mod:`graspaug.grasping.labelled`, :mod:`graspaug.render.corpus_dataset`), and the fingerprint it is cached under.

A test set folder holds ``shapes/<shape_id>.ply`` (m, real size, centered), ``shapes.parquet``, ``rejects.parquet``
(``shape_id``, ``source``, ``reason``), ``grasps.parquet`` (the ``grasps`` stage's columns), ``skipped.parquet``
(shapes without datapoints, and why) and ``gqcnn/`` (:mod:`graspaug.io.gqcnn`: depth crops, gripper depths, labels).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.augment.corpus import ingest_source
from graspaug.errors import DataError
from graspaug.geometry.settings import SurfaceSettings
from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.labelled import grasps_of_shapes
from graspaug.grasping.settings import GraspsSettings
from graspaug.io.atomic import atomic_path, exclusive_lock
from graspaug.io.digest import sha256_of
from graspaug.io.gqcnn import write_grasp_images
from graspaug.io.meshes import MESH_SUFFIX
from graspaug.io.sources import Source, tag_cache
from graspaug.io.tables import write_json, write_table
from graspaug.render.corpus_dataset import datapoints_table, render_corpus, with_pool_columns
from graspaug.render.dataset import datapoints_index
from graspaug.render.settings import CropGeometry, Intrinsics, RenderSettings

log = logging.getLogger(__name__)

#: Bump when the layout of a test set folder changes, so older cached sets are not reused (a change to the code that
#: makes one changes its key by itself: :func:`code_fingerprint`).
TESTSET_FORMAT = "graspaug.evaluate-testset/1"

#: The packages and modules whose code makes a test set (:func:`build_test_set`'s import closure, checked by a test):
#: a change to any of their source files gives new cache keys, so a changed sampler, renderer or size rule is never
#: read from an older cached set.
BUILDERS = (
    "graspaug.augment.corpus",
    "graspaug.device",
    "graspaug.errors",
    "graspaug.experiments.evaluate.testset",
    "graspaug.geometry",
    "graspaug.grasping",
    "graspaug.io",
    "graspaug.parallel",
    "graspaug.render",
    "graspaug.rng",
    "graspaug.settings",
)


@dataclasses.dataclass(frozen=True)
class TestSetRecipe:
    """Everything that shapes a test set besides the files: the surface rules (``size: real``), the file limits,
    the grasp sampler and label (the models' gripper and threshold), the render settings (the models' camera) and
    the seed of every random choice."""

    surface: SurfaceSettings
    max_faces: int
    max_file_mb: float
    grasps: GraspsSettings
    render: RenderSettings
    seed: int

    def as_dict(self) -> dict:
        return {"format": TESTSET_FORMAT, **dataclasses.asdict(self)}


#: The model card's keys that shape a test set (:class:`graspaug.planning.card.ModelCard`): models evaluated together
#: must agree on them.
CARD_KEYS = ("intrinsics", "camera_distance", "camera_tilt_deg", "crop_size", "out_size", "gripper", "label_threshold")


def recipe_for(
    surface: SurfaceSettings,
    max_faces: int,
    max_file_mb: float,
    grasps: GraspsSettings,
    render: RenderSettings,
    seed: int,
    card: dict,
) -> TestSetRecipe:
    """The test set a model with ``card`` (:data:`CARD_KEYS` → the card's values) is tested on: the given settings,
    real size (shapes wider than the card's gripper rejected; with ``surface.size`` ``fit``, the real-objects
    profile's, scaled down until they fit, as ingest does), and the card's camera (intrinsics px, distance m, tilt
    deg), crop (px), gripper (m) and label threshold (robust ε; ``grasps.threshold`` where the card has none)."""
    gripper = ParallelJawGripper(**card["gripper"])
    threshold = grasps.threshold if card["label_threshold"] is None else card["label_threshold"]
    view = dataclasses.replace(
        render.viewpoints, distance=tuple(card["camera_distance"]), tilt_deg=tuple(card["camera_tilt_deg"])
    )
    return TestSetRecipe(
        surface=dataclasses.replace(
            surface, size="fit" if surface.size == "fit" else "real", max_width=gripper.max_width
        ),
        max_faces=max_faces,
        max_file_mb=max_file_mb,
        grasps=dataclasses.replace(grasps, gripper=gripper, threshold=threshold),
        render=dataclasses.replace(
            render,
            intrinsics=Intrinsics(**card["intrinsics"]),
            viewpoints=view,
            crop=CropGeometry(crop_size=card["crop_size"], out_size=card["out_size"]),
        ),
        seed=seed,
    )


def code_fingerprint(modules: tuple[str, ...] = BUILDERS) -> str:
    """A 64-hex digest of the package version and of every source file of ``modules`` (a package: each ``.py`` under
    it; their paths relative to the top package and their bytes), found without importing them."""
    from importlib.metadata import version
    from importlib.util import find_spec

    files = set()
    for name in modules:
        spec = find_spec(name)
        if spec is None or spec.origin is None:
            raise ValueError(f"{name}: no such module")
        origin = Path(spec.origin)
        files |= set(origin.parent.rglob("*.py")) if spec.submodule_search_locations else {origin}
    top = Path(find_spec(modules[0].split(".")[0]).origin).parent
    digest = hashlib.sha256(f"graspaug {version('graspaug')}\n".encode())
    for path in sorted(files):
        digest.update(f"{path.relative_to(top).as_posix()}\0{sha256_of(path)}\n".encode())
    return digest.hexdigest()


def recipe_fingerprint(recipe: TestSetRecipe) -> str:
    """A 64-hex digest of the ``recipe`` alone: two runs with equal ones made their test sets the same way."""
    return hashlib.sha256(json.dumps(recipe.as_dict(), sort_keys=True, default=str).encode()).hexdigest()


def fingerprint(sources: list[Source], recipe: TestSetRecipe, code: str) -> str:
    """A 64-hex key of the files' content (sha256 of each, with its id and unit scale), the ``recipe`` and ``code``
    (:func:`code_fingerprint`): equal keys, the same test set. A file that cannot be read hashes as its error, so the
    key still changes when it does."""
    digest = hashlib.sha256(f"{recipe_fingerprint(recipe)}\0{code}\n".encode())
    for source in sources:
        try:
            content = sha256_of(source.path)
        except OSError as exc:
            content = f"unreadable: {exc}"
        digest.update(f"{source.shape_id}\0{source.unit_scale!r}\0{content}\n".encode())
    return digest.hexdigest()


def cached_test_set(sources: list[Source], recipe: TestSetRecipe, cache: Path, workers, shard_rows: int) -> Path:
    """The folder of the test set of ``sources`` made by ``recipe``: ``<cache>/<key>/`` (the first 16 hex of
    :func:`fingerprint`), built there by :func:`build_test_set` (its counts in ``counts.json``) unless it is. One writer
    per key at a time: a second process asking for the same key waits for the first, then reads its set. The cache
    folder is tagged (:func:`~graspaug.io.sources.tag_cache`), so no corpus walk reads its meshes as objects."""
    folder = cache / fingerprint(sources, recipe, code_fingerprint())[:16]
    tag_cache(cache)
    with exclusive_lock(cache / f".{folder.name}.lock"):
        if (folder / "counts.json").is_file():
            log.info("evaluate: the test set is cached in %s", folder)
            return folder
        with atomic_path(folder, directory=True) as tmp:
            write_json(build_test_set(sources, recipe, tmp, workers, shard_rows), tmp / "counts.json")
    return folder


def shaped_by(recipe: TestSetRecipe, counts: dict, params_file: Path | None, unit_scale: float) -> dict:
    """What made a test set, for its report: ``params`` (the file, or "built-in defaults") and its ``params_sha256``,
    the ``recipe`` fingerprint (16 hex), ``label_threshold`` (robust ε), ``size`` rule, ``max_width`` (m),
    ``unit_scale`` (m per file unit), and from ``counts`` the objects ``fitted`` and their ``fit_scale`` range."""
    return {
        "params": "built-in defaults" if params_file is None else str(params_file),
        "params_sha256": None if params_file is None else sha256_of(params_file),
        "recipe": recipe_fingerprint(recipe)[:16],
        "label_threshold": recipe.grasps.threshold,
        "size": recipe.surface.size,
        "max_width": recipe.surface.max_width,
        "unit_scale": unit_scale,
        "fitted": counts.get("fitted", 0),
        "fit_scale": counts.get("fit_scale"),
    }


def build_test_set(sources: list[Source], recipe: TestSetRecipe, folder: Path, workers, shard_rows: int) -> dict:
    """Make the test set of ``sources`` in ``folder`` (an empty folder the caller writes atomically).

    Returns its counts: ``files``, ``shapes`` (ingested), ``rejected``, ``with_datapoints``, ``datapoints``,
    ``positives``, ``size`` (the size rule), ``fitted`` (shapes scaled down to fit the gripper) and ``fit_scale``
    ([smallest, largest] factor they were scaled by; None when none was).
    Raises :class:`DataError` when no file gives a datapoint (with the commonest reasons).
    """
    from graspaug.parallel import parallel_map

    mesh_dir = (folder / "shapes").resolve()  # worker processes may have another working directory
    mesh_dir.mkdir(parents=True)
    rows = parallel_map(
        lambda s: ingest_source(s, recipe.max_faces, recipe.max_file_mb, recipe.surface, mesh_dir),
        sources,
        workers,
        "evaluate: ingest",
    )
    kept = [{k: v for k, v in r.items() if k != "_occupancy"} for r in rows if r.pop("ok")]
    rejects = pd.DataFrame(
        [r for r in rows if "reason" in r], columns=["shape_id", "source", "source_sha256", "reason"]
    )
    write_table(rejects, folder / "rejects.parquet")
    if not kept:
        raise DataError(f"no usable mesh among {len(sources)} files; reasons: {_commonest(rejects['reason'])}")
    shapes = with_pool_columns(pd.DataFrame(kept).assign(origin="original", split="test"))
    unit = {s.shape_id: s.unit_scale for s in sources}
    factor = shapes["scale"].to_numpy(float) / shapes["shape_id"].map(unit).to_numpy(float)  # the size rule's own
    fitted = factor[factor < 1 - 1e-9]
    write_table(shapes, folder / "shapes.parquet")

    ids = list(shapes["shape_id"])
    grasps, _ = grasps_of_shapes(mesh_dir, ids, MESH_SUFFIX, recipe.grasps, recipe.seed, workers, "evaluate: grasps")
    write_table(grasps, folder / "grasps.parquet")
    by_shape, results = render_corpus(
        shapes,
        grasps,
        mesh_dir,
        MESH_SUFFIX,
        recipe.render,
        recipe.grasps.gripper,
        recipe.seed,
        workers,
        "evaluate: render",
    )
    images, parts, skipped, _, _ = datapoints_index(shapes, by_shape, results, recipe.grasps.threshold)
    write_table(pd.DataFrame(skipped, columns=["shape_id", "reason"]), folder / "skipped.parquet")
    if not parts:
        reasons = pd.Series([s["reason"] for s in skipped], dtype=str)
        raise DataError(f"none of the {len(shapes)} usable meshes gave a datapoint; reasons: {_commonest(reasons)}")
    index = datapoints_table(parts)
    (folder / "gqcnn").mkdir()
    write_grasp_images(folder / "gqcnn", np.concatenate(images), index, shard_rows)
    return {
        "files": len(sources),
        "shapes": len(shapes),
        "rejected": len(rejects),
        "with_datapoints": int(index["shape_id"].nunique()),
        "datapoints": len(index),
        "positives": int(index["label"].sum()),
        "size": recipe.surface.size,  # real, or fit: too wide for the gripper scaled down until it fits
        "fitted": len(fitted),
        "fit_scale": [float(fitted.min()), float(fitted.max())] if len(fitted) else None,
    }


def _commonest(reasons: pd.Series, n: int = 3) -> str:
    """The ``n`` commonest reasons with their counts, one line."""
    return "; ".join(f"{count}× {reason}" for reason, count in reasons.value_counts().head(n).items()) or "none given"


#: What must agree between replicates of one arm (``evaluate --seeds``): the card's training set's pool, base size
#: and ratio, its training rule and the rules its data were made by.
ARM_FIELDS = ("pool", "base_size", "ratio", "training_rule", "test_set_rules")


def _arm_field(card: dict, field: str):
    return card.get("training_set", {}).get(field) if field in ("pool", "base_size", "ratio") else card.get(field)


#: What pairs the replicates of two arms (``evaluate --seeds``): the card's draw of the data and training seed.
PAIR_FIELDS = ("data_seed", "seed")


def _pair_key(card: dict) -> tuple:
    return card.get("data_seed"), card.get("training_set", {}).get("seed")


def arm_name(card: dict) -> str:
    """An arm's name from a model card's training set: ``<pool>@<base size>`` (``targeted@50``), ``none@<base size>``
    at ratio 0 (the base set alone, whatever pool the card names), ``<pool>×<ratio>@<base size>`` at another ratio."""
    ts = card.get("training_set", {})
    ratio, base = ts.get("ratio"), ts.get("base_size")
    if ratio is None or base is None:
        return "an arm of unknown training set"
    if float(ratio) == 0:
        return f"none@{base}"
    return f"{ts.get('pool')}@{base}" if float(ratio) == 1 else f"{ts.get('pool')}×{float(ratio):g}@{base}"


def replicate_name(card: dict) -> str:
    """A replicate's name from its card: ``d<draw> s<training seed>`` (``d10 s0``)."""
    draw, seed = _pair_key(card)
    return f"d{draw} s{seed}"


def arrange_arms(cards: dict[str, dict], k: int) -> tuple[list[str], str, list[str]]:
    """The models of ``evaluate --seeds k`` as arms of ``k`` replicates, paired by their cards.

    ``cards``: model name → card, in the order given; each ``k`` consecutive models are one arm. Within an arm the
    pool, base size, ratio, training rule and test-set rules (:data:`ARM_FIELDS`) must agree, and no two models may
    be the same replicate; every arm must hold the same replicates (draw ``data_seed`` and training seed, the
    :data:`PAIR_FIELDS`) as the first, in any order (cards that record no draw, all of them, are paired by training
    seed). Anything else is a :class:`DataError` naming the field and the
    files.

    Returns
    -------
    names : the models, arm by arm, each arm's replicates in the order (draw, seed): replicate k of every arm is the
        same draw and training seed, whatever order they were given in
    kind : ``seeds`` (training seeds of one draw of the data) or ``draws`` (networks of distinct draws)
    arms : each arm's name (:func:`arm_name`; the first model's name added where two arms would share one)
    """
    given = list(cards)
    for name in given:
        if _pair_key(cards[name])[1] is None:
            raise DataError(f"--seeds {k}: model {name}'s card has no training_set.seed, so it cannot be paired")
    undrawn = [name for name in given if _pair_key(cards[name])[0] is None]  # older cards: one draw, not recorded
    if undrawn and len(undrawn) < len(given):
        drawn = next(name for name in given if name not in undrawn)
        raise DataError(
            f"--seeds {k}: model {undrawn[0]}'s card has no data_seed (its draw) but {drawn}'s has one, so they cannot "
            "be paired"
        )
    groups = [given[start : start + k] for start in range(0, len(given), k)]
    kinds = set()
    for arm in groups:
        head = cards[arm[0]]
        for name in arm[1:]:
            for field in ARM_FIELDS:
                if _arm_field(cards[name], field) != _arm_field(head, field):
                    raise DataError(
                        f"--seeds {k}: model {name} is not a replicate of {arm[0]}: its card's {field} is "
                        f"{_arm_field(cards[name], field)!r}, not {_arm_field(head, field)!r}"
                    )
        keys = [_pair_key(cards[n]) for n in arm]
        if len(set(keys)) < len(keys):
            twins = [n for n in arm if keys.count(_pair_key(cards[n])) > 1]
            raise DataError(
                f"--seeds {k}: models {twins[0]} and {twins[1]} share a draw (data_seed) and training seed: the same "
                "replicate twice"
            )
        kinds.add("draws" if None not in keys[0] and len({d for d, _ in keys}) == len(keys) else "seeds")
    if len(kinds) > 1:
        raise DataError(f"--seeds {k}: some arms are replicates over seeds, others over draws; evaluate them apart")
    first = {_pair_key(cards[n]): n for n in groups[0]}
    for arm in groups[1:]:
        for name in arm:
            if _pair_key(cards[name]) not in first:
                draw, seed = _pair_key(cards[name])
                raise DataError(
                    f"--seeds {k}: model {name} (data_seed {draw}, training seed {seed}) has no partner of that draw "
                    f"and seed in the first arm ({', '.join(groups[0])}); give every arm the same replicates"
                )
    names = [n for arm in groups for n in sorted(arm, key=lambda n: _pair_key(cards[n]))]
    arms = [arm_name(cards[arm[0]]) for arm in groups]
    arms = [a if arms.count(a) == 1 else f"{a} ({arm[0]})" for a, arm in zip(arms, groups, strict=True)]
    return names, kinds.pop(), arms
