"""The quality floor and the out-of-range warnings: the operating point is the max-F1 threshold of the
validation predictions (checked against a slow reference, and end to end through ``train_network``), the
floor's source is named, object heights are measured above a fitted (tilted) table."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import trimesh

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.io.checkpoints import (
    GQCNN_CARD_FORMAT,
    finish_gqcnn_card,
    gqcnn_card,
    operating_point,
    read_gqcnn,
    training_range,
)
from graspaug.planning import ModelCard
from graspaug.planning.limits import DEFAULT_MIN_QUALITY, object_height, quality_floor, range_warnings
from graspaug.render.camera import look_at
from graspaug.render.depth import render_depth
from graspaug.render.settings import CropGeometry, Intrinsics, ViewpointRanges

K = {"fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5}


def _max_f1_reference(labels: np.ndarray, probability: np.ndarray) -> tuple[float, float]:
    """(threshold, F1) by trying every distinct probability as the threshold (P >= t: success), one at a
    time; among equal F1 the lowest threshold."""
    best = (math.inf, -1.0)
    for t in sorted(set(probability.tolist()), reverse=True):
        predicted = probability >= t
        hits = int((predicted & (labels == 1)).sum())
        precision = hits / predicted.sum()
        recall = hits / (labels == 1).sum()
        f1 = 0.0 if hits == 0 else 2 * precision * recall / (precision + recall)
        if f1 >= best[1] - 1e-12:
            best = (t, f1)
    return best


def test_the_operating_point_maximises_f1_on_the_predictions_it_is_given():
    rng = np.random.default_rng(0)
    for trial in range(30):
        n = int(rng.integers(2, 400))
        labels = (rng.random(n) < rng.uniform(0.05, 0.5)).astype(np.uint8)
        if labels.sum() in (0, n):
            labels[: 1 + trial % 2] = 1 - labels[: 1 + trial % 2]
        probability = np.clip(0.3 * labels + rng.normal(0.3, 0.2, n), 0, 1).astype(np.float32)
        if trial % 3 == 0:
            probability = np.round(probability, 1)  # ties between datapoints
        point = operating_point(labels, probability)
        threshold, f1 = _max_f1_reference(labels, probability.astype(np.float64))
        assert point["rule"] == "max_f1" and point["threshold"] == pytest.approx(threshold, abs=0), trial
        assert point["f1"] == pytest.approx(f1, rel=1e-9) and point["datapoints"] == n
        predicted = probability >= point["threshold"]
        assert point["precision"] == pytest.approx(labels[predicted].mean())
        assert point["recall"] == pytest.approx(predicted[labels == 1].mean())
    # a perfectly separated set: the floor sits at the lowest success
    assert operating_point([0, 0, 1, 1], [0.1, 0.2, 0.9, 0.95])["threshold"] == pytest.approx(0.9)
    assert operating_point([1, 1, 1], [0.2, 0.5, 0.9]) is None and operating_point([0, 0], [0.2, 0.5]) is None
    with pytest.raises(ValueError, match="3 labels but 2 probabilities"):
        operating_point([0, 1, 1], [0.2, 0.5])


def _dataset(folder, rng, shapes: dict[str, str], per_shape: int = 24) -> None:
    """A GQ-CNN dataset folder of synthetic crops (a table with a box of random height) for ``shapes``
    (shape id → split); success is likelier on lower boxes."""
    from graspaug.io.gqcnn import write_grasp_images

    rows, images = [], []
    for shape_id, split in shapes.items():
        for _ in range(per_shape):
            table, top = rng.uniform(0.65, 0.75), rng.uniform(0.005, 0.06)
            crop = np.full((32, 32), table, np.float32)
            crop[10:22, 8:24] = table - top
            images.append(crop)
            label = int(rng.random() < (0.7 if top < 0.03 else 0.15))
            rows.append({"shape_id": shape_id, "split": split, "z": table - top / 2, "label": label, "eps": 0.0})
    folder.mkdir()
    write_grasp_images(folder, np.stack(images), pd.DataFrame(rows), shard_rows=50)


def test_train_network_writes_the_operating_point_of_its_validation_predictions(tmp_path):
    """The card's operating point is the max-F1 threshold of the network's validation predictions (and
    not of its test predictions); its training range that of the crops it trained on."""
    from graspaug.nets.settings import GQCNNConfig
    from graspaug.training.gqcnn_data import Corpora, ExperimentSplit, shapes_datapoints, test_set
    from graspaug.training.networks import NetworkJob, seed_members, train_network
    from graspaug.training.settings import TrainSettings
    from graspaug.training.variants import Variant

    corpora = Corpora(tmp_path / "original")
    _dataset(
        corpora.original, np.random.default_rng(1), {"a": "train", "b": "train", "c": "train", "t": "test", "u": "test"}
    )
    split = ExperimentSplit(base={2: ("a", "b")}, validation=("c",), real_pool=(), ceiling=("a", "b"))
    config = GQCNNConfig(filters=4, fc=8, pose_fc=4)
    inits, noise_seeds = seed_members(config, 0, 0, 1)
    settings = TrainSettings(min_steps=4, max_steps=4, batch_size=16, evals=1)
    card = gqcnn_card(CropGeometry(), Intrinsics(), ViewpointRanges(), ParallelJawGripper(), 0.002, 0)
    job = NetworkJob(
        Variant("targeted", 2, 0.0), split, config, settings, inits, noise_seeds, 0, "cpu", tmp_path, corpora, card
    )
    train_network(job)
    folder = tmp_path / "targeted" / "2-0"
    _, saved = read_gqcnn(folder / "model.pt")
    val, test = shapes_datapoints(corpora.original, ("c",))[0], test_set(corpora.original)[0]
    val_p, test_p = np.load(folder / "val_predictions.npy"), np.load(folder / "test_predictions.npy")
    assert saved["format"] == GQCNN_CARD_FORMAT == "graspaug.gqcnn-card/2"
    assert saved["operating_point"] == operating_point(val.labels, val_p)
    assert saved["operating_point"]["datapoints"] == len(val) != len(test)
    assert saved["operating_point"] != operating_point(test.labels, test_p)
    train = shapes_datapoints(corpora.original, ("a", "b"))[0]
    assert saved["training_range"] == training_range(train.images, train.z)
    heights = saved["training_range"]["object_height"]
    assert 0.005 <= heights[0] < heights[1] <= 0.06
    floor = quality_floor(ModelCard.from_dict(saved))
    assert floor.value == saved["operating_point"]["threshold"] and "validation operating point" in floor.source


def test_the_floor_comes_from_the_flag_the_card_or_a_default():
    card = gqcnn_card(CropGeometry(), Intrinsics(), ViewpointRanges(), ParallelJawGripper(), 0.002, 0)
    summary = {"pool": "targeted", "base_size": 50, "ratio": 0.0, "seed": 0, "train": {}, "validation": {}, "test": {}}
    point = operating_point([0, 0, 1, 1], [0.1, 0.2, 0.42, 0.95])
    new = ModelCard.from_dict(finish_gqcnn_card(card, summary, point, None))
    floor = quality_floor(new)
    assert floor.value == pytest.approx(0.42) and "validation operating point, max F1 1.00 on 4" in floor.source
    assert floor.accepts(0.42) and not floor.accepts(0.419) and not floor.accepts(float("nan"))
    assert quality_floor(new, 0.7).value == 0.7 and quality_floor(new, 0.7).source == "--min-quality"
    off = quality_floor(new, 0)
    assert off.accepts(0.0) and off.accepts(float("nan"))  # 0 disables the floor
    # a card of format /1 (no operating point, no training range) and a checkpoint without a card
    old = {k: v for k, v in finish_gqcnn_card(card, summary).items() if k not in ("operating_point", "training_range")}
    for older in (ModelCard.from_dict({**old, "format": "graspaug.gqcnn-card/1"}), ModelCard.from_dict(None)):
        assert older.operating_point is None and older.training_range is None
        fallback = quality_floor(older)
        assert fallback.value == DEFAULT_MIN_QUALITY == 0.1 and "no validation operating point" in fallback.source
        assert range_warnings(older, np.full((480, 640), 0.7), K, []) == []
    with pytest.raises(ValueError, match=r"min_quality must lie in \[0, 1\]"):
        quality_floor(new, 1.5)


def test_object_height_is_measured_above_a_tilted_table():
    """A 12 cm box seen by a camera tilted 5° at 0.7 m: its height above the fitted table plane; an
    empty table: none."""
    box = trimesh.creation.box((0.05, 0.06, 0.12))
    box.apply_translation([0.0, 0.0, 0.06])
    tilt = math.radians(5)
    camera = look_at(0.7 * np.array([math.sin(tilt), 0.0, math.cos(tilt)]), np.zeros(3))
    depth = render_depth(box, camera, Intrinsics())
    assert object_height(depth, Intrinsics()) == pytest.approx(0.12, abs=0.002)
    empty = render_depth(trimesh.creation.box((0.01, 0.01, 0.0005)), camera, Intrinsics())  # a 0.5 mm sheet
    assert object_height(empty, Intrinsics()) < 0.003


def test_a_camera_outside_the_training_distances_is_warned_of():
    card = ModelCard(training_range={"gripper_depth": [0.6, 0.75], "object_height": [0.0, 0.08], "datapoints": 9})
    assert range_warnings(card, np.full((480, 640), 0.70), K, []) == []
    far = range_warnings(card, np.full((480, 640), 0.90), K, [])
    assert len(far) == 1 and "0.900 m from the table" in far[0] and "0.65-0.75 m" in far[0]
    given = range_warnings(card, np.full((480, 640), 0.70), K, [], camera_distance=0.6)
    assert len(given) == 1 and "0.600 m" in given[0] and "--camera-distance" in given[0]
