"""The networks a study keeps in ``results/`` for its users: each network's weights and its model card as text."""

from __future__ import annotations

import json
from pathlib import Path


def keep_networks(seed_dir: Path, out: Path, keys) -> list[Path]:
    """Copy the networks ``keys`` ((pool, B, R) each) of one draw's training seed (its folder ``seed_dir``) into
    ``out``/<pool>-<B>-<R>/: ``model.pt`` (weights, training summary and model card) and ``card.json`` (the card as
    text: the camera, crop, gripper, label threshold and training set a user checks before ``graspaug evaluate``).
    Returns the model files written."""
    import shutil

    from graspaug.experiments.ap.numbers import network_folder
    from graspaug.io.atomic import atomic_path
    from graspaug.io.checkpoints import read_gqcnn

    written = []
    for pool, b, r in keys:
        model = network_folder(seed_dir, (pool, b, float(r))) / "model.pt"
        folder = Path(out) / f"{pool}-{b}-{float(r):g}"
        folder.mkdir(parents=True, exist_ok=True)
        with atomic_path(folder / "model.pt") as tmp:
            shutil.copyfile(model, tmp)
        card = read_gqcnn(model)[1]
        with atomic_path(folder / "card.json") as tmp:
            tmp.write_text(json.dumps(card, indent=1, default=str) + "\n")
        written.append(folder / "model.pt")
    return written
