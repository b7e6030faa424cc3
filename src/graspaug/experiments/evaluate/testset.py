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
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.augment.corpus import ingest_source
from graspaug.errors import DataError
from graspaug.geometry.settings import SurfaceSettings
from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.labelled import grasps_of_shapes
from graspaug.grasping.settings import GraspsSettings
from graspaug.io.digest import sha256_of
from graspaug.io.gqcnn import write_grasp_images
from graspaug.io.meshes import MESH_SUFFIX
from graspaug.io.sources import Source
from graspaug.io.tables import write_table
from graspaug.render.corpus_dataset import datapoints_table, render_corpus, with_pool_columns
from graspaug.render.dataset import datapoints_index
from graspaug.render.settings import CropGeometry, Intrinsics, RenderSettings

#: Bump when the way a test set is made changes, so older cached sets are not reused.
TESTSET_FORMAT = "graspaug.evaluate-testset/1"


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


def fingerprint(sources: list[Source], recipe: TestSetRecipe) -> str:
    """A 64-hex key of the files' content (sha256 of each, with its id and unit scale) and the ``recipe``: equal keys,
    the same test set. A file that cannot be read hashes as its error, so the key still changes when it does."""
    digest = hashlib.sha256(json.dumps(recipe.as_dict(), sort_keys=True, default=str).encode())
    for source in sources:
        try:
            content = sha256_of(source.path)
        except OSError as exc:
            content = f"unreadable: {exc}"
        digest.update(f"{source.shape_id}\0{source.unit_scale!r}\0{content}\n".encode())
    return digest.hexdigest()


def build_test_set(sources: list[Source], recipe: TestSetRecipe, folder: Path, workers, shard_rows: int) -> dict:
    """Make the test set of ``sources`` in ``folder`` (an empty folder the caller writes atomically).

    Returns its counts: ``files``, ``shapes`` (ingested), ``rejected``, ``with_datapoints``, ``datapoints``, ``size``,
    ``positives``. Raises :class:`DataError` when no file gives a datapoint (with the commonest reasons).
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
    }


def _commonest(reasons: pd.Series, n: int = 3) -> str:
    """The ``n`` commonest reasons with their counts, one line."""
    return "; ".join(f"{count}× {reason}" for reason, count in reasons.value_counts().head(n).items()) or "none given"
