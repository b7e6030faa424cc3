"""``graspaug study precision``: does bfloat16 training keep what float32 training gives? Two finished runs of one
project (``dvc repro`` in two clones) that differ only in ``gqcnn.train.precision`` and ``ae.train.precision``
(and, if you like, ``gqcnn.members``: member 0 is compared), read and compared on validation
(:mod:`graspaug.experiments.precision` has the rules).

It reads, from each project: every GQ-CNN's ``summary.json`` and validation predictions (``models/gqcnn/s<k>/``),
the validation labels (``data/gqcnn/original``), the AutoEncoders (``models/ae.pt``, ``models/ae_critic.pt``) and
the test split's grids (``data/voxels.npz``, which must be the same file in both), and the recon pool's row of
``reports/fidelity/<B>/fidelity.csv``. It writes ``networks.csv``, ``ae_iou.csv``, ``recon.csv``, ``summary.json``
and ``precision.md`` to its output folder and returns the markdown.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.errors import DataError
from graspaug.experiments.precision import markdown, summarize
from graspaug.io.tables import read_table, write_csv, write_json
from graspaug.pipeline.params.model import load_params
from graspaug.pipeline.paths import AE_CRITIC_MODEL, AE_MODEL, SHAPES_TABLE, VOXELS, fidelity_reports, gqcnn_dir

AES = {"ae": AE_MODEL, "ae_critic": AE_CRITIC_MODEL}


def validation_aps(project: Path, precision: str) -> pd.DataFrame:
    """One row per training seed and network of ``project``: ``precision`` (the run's label), ``trained_as`` (its
    card's), ``seed``, ``network``, ``members``, ``val_ap`` (member 0's validation AP) and ``val_ap_network`` (the
    network's, its members averaged)."""
    from sklearn.metrics import average_precision_score

    labels = read_table(project / gqcnn_dir("original") / "index.parquet").label.to_numpy()
    rows = []
    for seed_dir in sorted((project / "models/gqcnn").glob("s[0-9]*")):
        y = labels[np.load(seed_dir / "val_rows.npy")]
        for summary_file in sorted(seed_dir.rglob("summary.json")):
            s, folder = json.loads(summary_file.read_text()), summary_file.parent
            members = folder / "val_predictions_members.npy"
            p0 = np.load(members)[0] if members.is_file() else np.load(folder / "val_predictions.npy")
            rows.append(
                {
                    "precision": precision,
                    "trained_as": s["train"]["precision"],
                    "seed": s["seed"],
                    "network": folder.relative_to(seed_dir).as_posix(),
                    "members": s["train"].get("members", 1),
                    "val_ap": round(float(average_precision_score(y, p0)), 6),
                    "val_ap_network": s["validation"]["ap"],
                }
            )
    if not rows:
        raise DataError(f"{project}: no trained GQ-CNN under models/gqcnn (run `dvc repro` there first)")
    return pd.DataFrame(rows)


def heldout_ious(projects: dict[str, Path]) -> pd.DataFrame:
    """One row per AutoEncoder (:data:`AES`) and test shape: ``ae``, ``shape_id`` and each precision's IoU."""
    import torch

    from graspaug.io.checkpoints import load_autoencoder
    from graspaug.training.autoencoder import reconstruction_ious, voxel_grids

    digests = {p: hashlib.sha256((project / VOXELS).read_bytes()).hexdigest() for p, project in projects.items()}
    if len(set(digests.values())) != 1:
        raise DataError(f"the two projects voxelized other shapes ({VOXELS} differs): not one project's two runs")
    project = projects["bfloat16"]
    params = load_params(project / "params.yaml")
    ids, split, grids = voxel_grids(project / VOXELS, project / SHAPES_TABLE, params.ae.net.output)
    test = split == "test"
    table = []
    for ae in AES:
        row = {"ae": ae, "shape_id": ids[test]}
        for precision, where in projects.items():
            net, _, _ = load_autoencoder(where / AES[ae], params.ae.net)
            row[precision] = reconstruction_ious(net, grids[torch.from_numpy(test)], torch.device("cpu"))
        table.append(pd.DataFrame(row))
    return pd.concat(table, ignore_index=True)


def recon_rows(projects: dict[str, Path]) -> pd.DataFrame:
    """The recon pool's row of each project's fidelity table (the smallest augmented base size), ``precision``
    added."""
    rows = []
    for precision, project in projects.items():
        params = load_params(project / "params.yaml")
        table = pd.read_csv(project / fidelity_reports(min(params.gqcnn.augment_base_sizes)) / "fidelity.csv")
        if "recon" not in set(table.pool):
            raise DataError(f"{project}: the fidelity table has no recon pool (gqcnn.pools lacks recon)")
        rows.append(table[table.pool == "recon"].assign(precision=precision))
    return pd.concat(rows, ignore_index=True)


def run(float32: Path, bfloat16: Path, out: Path) -> tuple[str, dict[str, pd.DataFrame]]:
    """Compare the two projects, write the tables and the summary to ``out``; the markdown and the tables
    (``networks``, ``ae_iou``, ``recon``: what ``results/precision-<label>/`` keeps)."""
    projects = {"float32": Path(float32), "bfloat16": Path(bfloat16)}
    networks = pd.concat([validation_aps(p, precision) for precision, p in projects.items()], ignore_index=True)
    tables = {"networks": networks, "ae_iou": heldout_ious(projects), "recon": recon_rows(projects)}
    summary = summarize(*tables.values())
    for name, table in tables.items():
        write_csv(table, out / f"{name}.csv")
    write_json(summary, out / "summary.json")
    text = markdown(summary)
    (out / "precision.md").write_text(text)
    return text, tables
