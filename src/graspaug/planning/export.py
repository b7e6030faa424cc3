"""A trained GQ-CNN exported for use without graspaug: TorchScript (and ONNX when installed) with its card."""

from __future__ import annotations

import importlib.util
import json
import os
from pathlib import Path
from typing import Any

import torch

from graspaug.planning.card import ModelCard


class SuccessProbability(torch.nn.Module):
    """P(success) (N,) of a GQ-CNN for crops (N, 1, S, S) m and gripper depths (N,) m (what is exported)."""

    def __init__(self, net) -> None:
        super().__init__()
        self.net = net

    def forward(self, images: torch.Tensor, z: torch.Tensor) -> torch.Tensor:
        return torch.softmax(self.net(images, z), dim=1)[:, 1]


def export_model(path: str | os.PathLike, out: str | os.PathLike) -> dict[str, Any]:
    """Write a GQ-CNN checkpoint as TorchScript for use without graspaug: ``<out>/model.ts``
    (``forward(images (N, 1, S, S) m, z (N,) m) → P(success) (N,)``, CPU, raw depths as in
    :meth:`~graspaug.nets.gqcnn.GQCNN.success_probability`), ``<out>/card.json`` (the model card
    and the input contract) and, when the ``onnx`` package is installed, ``<out>/model.onnx``.
    Returns the card JSON written."""
    from graspaug.io.atomic import atomic_path
    from graspaug.io.checkpoints import read_gqcnn

    net, card = read_gqcnn(path)
    model_card = ModelCard.from_dict(card, net.config.image_input)
    size = net.config.image_size
    example = (torch.full((4, 1, size, size), 0.7), torch.full((4,), 0.68))
    wrapped = SuccessProbability(net).eval()
    with torch.no_grad():
        traced = torch.jit.trace(wrapped, example)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with atomic_path(out / "model.ts") as tmp, open(tmp, "wb") as f:
        torch.jit.save(traced, f)
    files = ["model.ts"]
    if importlib.util.find_spec("onnx") is None:
        onnx_note = "not written: the onnx package is not installed"
    else:  # pragma: no cover - onnx is not a dependency
        axes = {"images": {0: "n"}, "z": {0: "n"}, "p_success": {0: "n"}}
        torch.onnx.export(
            wrapped,
            example,
            str(out / "model.onnx"),
            input_names=["images", "z"],
            output_names=["p_success"],
            dynamic_axes=axes,
        )
        files.append("model.onnx")
        onnx_note = "written"
    images = (
        f"(N, 1, {size}, {size}) float32: grasp-centered depth crops in meters, jaw axis along the rows "
        f"({model_card.crop_size} px of the image averaged down to {model_card.out_size})"
    )
    info = {
        "source": str(path),
        "files": files,
        "onnx": onnx_note,
        "inputs": {"images": images, "z": "(N,) float32: gripper depth in meters (camera frame)"},
        "output": "(N,) float32: predicted P(success)",
        "model_card": model_card.to_dict(),
    }
    with atomic_path(out / "card.json") as tmp:
        tmp.write_text(json.dumps(info, indent=1) + "\n")
    return info
