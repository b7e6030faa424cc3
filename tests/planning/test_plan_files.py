"""`graspaug plan` stays within the hardware and leaves a whole answer or none: no grasp wider than the gripper,
single-channel depth arrays planned, complex ones refused, no grasp.json left by a failure, refusals that name
their culprit."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch
from PIL import Image
from typer.testing import CliRunner

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.io.checkpoints import finish_gqcnn_card, gqcnn_card, save_gqcnn
from graspaug.nets.gqcnn import GQCNN
from graspaug.nets.settings import GQCNNConfig
from graspaug.pipeline.cli import app
from graspaug.planning import PlanningError, load_planner
from graspaug.render.settings import CropGeometry, Intrinsics, ViewpointRanges

K = {"fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5}


@pytest.fixture(scope="module")
def model_path(tmp_path_factory):
    """An untrained GQ-CNN (seeded) with the default model card (the Panda: max width 0.08 m), saved as
    train_gqcnn saves it."""
    torch.manual_seed(0)
    path = tmp_path_factory.mktemp("model") / "model.pt"
    card = gqcnn_card(CropGeometry(), Intrinsics(), ViewpointRanges(), ParallelJawGripper(), 0.002, 0)
    summary = {"pool": "targeted", "base_size": 50, "ratio": 0.0, "seed": 0, "train": {}, "validation": {}, "test": {}}
    save_gqcnn(path, GQCNN(GQCNNConfig(image_input="depth")), summary, finish_gqcnn_card(card, summary))
    return path


@pytest.fixture
def wide_box(box_image):
    """A box 66 px (7.9 cm at its top, 0.62 m away) across, 8 cm tall, on a table 0.70 m away: depth (480, 640) m.
    The sampler bounds a pair's opening at its first jaw's edge depth (the top), so pairs across the box at grasp
    depths below the top open 80-85 mm."""
    return box_image(top=0.62, box=(290, 220, 356, 300), table=0.70)


def _plan(image, model, out, *flags):
    return CliRunner().invoke(app, ["plan", str(image), "--model", str(model), "--fx", "525", *flags, "-o", str(out)])


def test_no_grasp_wider_than_the_gripper_is_returned(wide_box, model_path, tmp_path):
    """Every grasp of --top 10, over three seeds, opens at most the card's max width (before: 80-85 mm)."""
    planner = load_planner(model_path)
    widest = planner.card.gripper["max_width"]
    assert widest == pytest.approx(0.08)
    for seed in range(3):
        grasps = planner.plan(wide_box, K, seed, top=10)
        assert grasps and max(g.width for g in grasps) <= widest + 1e-9, [round(1000 * g.width, 1) for g in grasps]
    np.save(tmp_path / "box.npy", wide_box)
    result = _plan(tmp_path / "box.npy", model_path, tmp_path / "out", "--top", "5", "--min-quality", "0")
    assert result.exit_code == 0, result.output
    planned = json.loads((tmp_path / "out/grasp.json").read_text())
    assert planned["accepted"] is True and planned["model_card"]["gripper"]["max_width"] == pytest.approx(0.08)
    assert planned["grasps"] and all(g["width"] <= 0.08 + 1e-9 for g in planned["grasps"]), planned["grasps"]


def test_a_single_channel_depth_is_planned_and_other_3d_arrays_refused(wide_box, model_path, tmp_path):
    np.save(tmp_path / "channel.npy", wide_box[..., None])  # (480, 640, 1): before, exit 3 and a grasp.json left
    result = _plan(tmp_path / "channel.npy", model_path, tmp_path / "one", "--min-quality", "0")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "one/grasp.png").is_file() and json.loads((tmp_path / "one/grasp.json").read_text())["grasps"]
    np.save(tmp_path / "rgb.npy", np.repeat(wide_box[..., None], 3, axis=2))
    refused = _plan(tmp_path / "rgb.npy", model_path, tmp_path / "three")
    line = refused.output.strip()
    assert refused.exit_code == 2 and "\n" not in line and "rgb.npy" in line and "(480, 640, 3)" in line, line
    assert not (tmp_path / "three").exists()


@pytest.mark.parametrize(("dtype", "text"), [(np.complex128, "complex numbers"), (np.bool_, "real numbers")])
def test_complex_and_bool_depths_are_refused_naming_the_image(wide_box, model_path, tmp_path, dtype, text):
    np.save(tmp_path / "odd.npy", wide_box.astype(dtype))  # complex: before, planned with its imaginary part dropped
    with _no_warning():
        result = _plan(tmp_path / "odd.npy", model_path, tmp_path / "out")
    line = result.output.strip()
    assert result.exit_code == 2 and "\n" not in line and "odd.npy" in line and text in line, line
    assert not (tmp_path / "out").exists()


class _no_warning:
    """A block that fails on any warning (the complex image once raised four ComplexWarnings)."""

    def __enter__(self):
        import warnings

        self._catch = warnings.catch_warnings()
        self._catch.__enter__()
        warnings.simplefilter("error")

    def __exit__(self, *exc):
        return self._catch.__exit__(*exc)


def test_a_failure_while_writing_leaves_the_last_answer_whole(wide_box, model_path, tmp_path, monkeypatch):
    """A crash while drawing grasp.png: exit 3, and the folder keeps the last run's grasp.json and grasp.png
    (before: a new grasp.json saying "accepted": true beside no picture); a new folder is not left behind."""
    np.save(tmp_path / "box.npy", wide_box)
    assert _plan(tmp_path / "box.npy", model_path, tmp_path / "out", "--min-quality", "0").exit_code == 0
    before = {p.name: p.read_bytes() for p in (tmp_path / "out").iterdir()}

    def crash(*args, **kwargs):
        raise RuntimeError("the picture could not be drawn")

    monkeypatch.setattr("graspaug.planning.report.planned_grasps", crash)
    for out in (tmp_path / "out", tmp_path / "new"):
        result = _plan(tmp_path / "box.npy", model_path, out, "--min-quality", "0", "--seed", "3")
        assert result.exit_code == 3 and "the picture could not be drawn" in result.output, result.output
    assert {p.name: p.read_bytes() for p in (tmp_path / "out").iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.npy", "out"]


def test_refusals_of_item_13_name_their_culprit(wide_box, model_path, tmp_path):
    """A .npy given as --model, a folder of several networks, a PNG in centimeters: one short line each."""
    np.save(tmp_path / "box.npy", wide_box)
    for seed in range(4):
        (tmp_path / f"models/s{seed}").mkdir(parents=True)
        (tmp_path / f"models/s{seed}/model.pt").write_bytes(model_path.read_bytes())
    Image.fromarray(np.rint(wide_box * 100).astype(np.uint16)).save(tmp_path / "cm.png")
    cases = [
        (tmp_path / "box.npy", tmp_path / "box.npy", "a NumPy array (.npy), not a trained GQ-CNN"),
        (tmp_path / "box.npy", tmp_path / "models", "4 networks, s0/model.pt, s1/model.pt, s2/model.pt, s3/model.pt"),
        (tmp_path / "cm.png", model_path, "cm.png: its median reading is 70, a table 7 cm from the camera"),
    ]
    for image, model, text in cases:
        result = _plan(image, model, tmp_path / "out")
        line = result.output.strip()
        assert result.exit_code == 2 and "\n" not in line and text in line, line
        assert len(line.replace(str(tmp_path), "")) < 200 and "weights_only" not in line, line
    with pytest.raises(PlanningError, match="looks like centimeters"):
        from graspaug.planning import read_depth_image

        read_depth_image(tmp_path / "cm.png")
