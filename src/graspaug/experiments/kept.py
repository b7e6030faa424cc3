"""What a study keeps in ``results/``: networks for its users (weights and model card as text) and every network's
predictions on its test datapoints."""

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


def write_predictions(columns: dict, path: Path) -> None:
    """One float32 column per network (name → (N,) P(success)) to the parquet file ``path``, atomically: float32 bytes
    split by position and zstd, 40% smaller than the default, so a study's predictions fit in git."""
    import pandas as pd

    from graspaug.io.atomic import atomic_path

    with atomic_path(path) as tmp:
        pd.DataFrame(columns).to_parquet(
            tmp, index=False, compression="zstd", compression_level=19, use_byte_stream_split=True, use_dictionary=False
        )
