"""Stage ``lifelong@r<k>``: round k ≥ 1 of the lifelong loop, from round k − 1's outputs (and the corpus, the AE and
the round-0 networks). Arms ``failure`` (parents near the last round's worst validation objects), ``random`` and
``real`` each add ``lifelong.shapes_per_round`` shapes and train, paired per seed, on the base set plus every round's
shapes. Writes ``lifelong/r<k>/`` in ``data/``, ``models/``, ``metrics/`` and ``reports/``.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from graspaug.augment.decode import mesh_batches
from graspaug.augment.failures import loop_shapes
from graspaug.augment.pools import base_set
from graspaug.device import resolve_device
from graspaug.experiments.ap.numbers import test_labels
from graspaug.experiments.lifelong.numbers import ARMS, arm_variant, disjoint, failure_anchors, round_networks
from graspaug.experiments.lifelong.round import render_round, score_round, write_round
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.tables import read_table, write_table
from graspaug.io.voxels import read_voxels
from graspaug.pipeline import paths
from graspaug.pipeline.params import ae, generate, gqcnn, grasps, lifelong, render, score
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.provenance import report_header
from graspaug.pipeline.stages import StageError
from graspaug.training.gqcnn_data import Corpora, load_split, training_shapes
from graspaug.training.networks import network_seed, network_workers, seed_card, train_paired

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `lifelong` stage reads.",
    ae=ae.AEParams,
    score=score.ScoreParams,
    generate=generate.GenerateParams,
    grasps=grasps.GraspsParams,
    render=render.RenderParams,
    gqcnn=gqcnn.GQCNNParams,
    lifelong=lifelong.LifelongParams,
)


def run(params: Params, round_: int) -> None:
    cfg, gq, b, draws_apart = params.lifelong, params.gqcnn, params.lifelong.base_size, params.independent_draws
    if round_ not in cfg.round_numbers():
        raise StageError(f"round {round_} is not in lifelong.rounds {sorted(cfg.rounds)}")
    before, label = paths.lifelong_data(round_ - 1), f"lifelong r{round_}"
    shapes, latents, voxels = read_table(paths.SHAPES_TABLE), read_table(paths.LATENTS), read_voxels(paths.VOXELS)
    original, device = paths.gqcnn_dir("original"), resolve_device(params.device)
    split = load_split(original, shapes, list(params.generate.base_sizes), gq.val_shapes, params.data_seed)
    base = base_set(np.array(split.base[b]), latents, read_table(paths.SCORES), voxels, params.score.k)
    failures = pd.read_csv(before / "failures.csv", index_col="object")
    chosen = list(failures.index[failures.chosen])
    made = read_table(before / "shapes.parquet") if round_ > 1 else None
    anchors, served = failure_anchors(base.z, np.stack(latents.set_index("shape_id").z.loc[chosen]), cfg.per_failure)
    ae_critic, _, _ = load_autoencoder(paths.AE_CRITIC_MODEL, params.ae.net)
    run_batch = mesh_batches(ae_critic, device, base, params.generate.decode, params.workers, label)
    rng, failed = np.random.default_rng([params.data_seed, 0x11FE, round_]), [chosen[f] for f in served]
    index, rejects, kept, notes = loop_shapes(
        base, anchors, failed, made, cfg.shapes_per_round, params.generate, run_batch, rng, round_
    )
    for note in notes:
        log.info("%s: %s", label, note)
    variants = [arm_variant(arm, b, round_ * cfg.shapes_per_round) for arm in ARMS]
    held_out = [*split.validation, *shapes.shape_id[shapes.split == "test"]]
    for v in variants:  # parents and trained-on shapes are train shapes outside validation
        disjoint(training_shapes(v, split)[0] + [*index.parent_a, *index.parent_b], held_out)
    data, models = paths.lifelong_data(round_), paths.lifelong_models(round_)
    with atomic_path(data, directory=True) as folder, atomic_path(models, directory=True) as nets:
        (folder / "meshes").mkdir()
        (folder / "dataset").mkdir()
        previous, settings = (before / "dataset" if round_ > 1 else None), (params.grasps, params.render)
        total, skipped = render_round(
            folder / "meshes", folder / "dataset", previous, index, kept, *settings, params.seed, params.workers, label
        )
        write_table(index if made is None else pd.concat([made, index], ignore_index=True), folder / "shapes.parquet")
        rejects.to_csv(folder / "rejects.csv", index=False)
        pd.DataFrame(skipped, columns=["shape_id", "reason"]).to_csv(folder / "skipped.csv", index=False)
        real = training_shapes(variants[ARMS.index("real")], split)[0][b:]
        pd.DataFrame({"shape_id": real}).to_csv(folder / "real.csv", index=False)
        corpora, card = Corpora(original, {b: folder / "dataset"}), seed_card(params.render, params.grasps, params.seed)
        workers, seeds = network_workers(params.workers), network_seed(params.seed, params.data_seed, draws_apart)
        train_paired(variants, split, gq, seeds, device, nets, corpora, card, label, workers)
        seed_dirs, corpus = {s: nets / f"s{s}" for s in gq.seeds}, read_table(original / "index.parquet")
        history, curve = pd.read_csv(before / "history.csv"), pd.read_csv(before / "curve.csv")
        errors, history, followed = score_round(seed_dirs, variants, ARMS, corpus, failures, history, round_, cfg.worst)
        errors.to_csv(folder / "failures.csv")
        history.to_csv(folder / "history.csv", index=False)
        labels, objects = test_labels(corpus, seed_dirs[gq.seeds[0]])
        start = {s: paths.gqcnn_seed_dir(s) / arm_variant("none", b, 0).name for s in gq.seeds}
        networks = {params.data_seed: round_networks(start, seed_dirs, variants)}
        reports = paths.lifelong_metrics(round_), paths.lifelong_reports(round_), followed
        header = report_header(params.file_text, shapes)  # the profile and corpus
        curve = write_round(round_, networks, labels, objects, curve, history, params, voxels, *reports, header)
        curve.to_csv(folder / "curve.csv", index=False)
    log.info("%s: %d new shapes per arm, %d generated datapoints in all", label, len(index) // 2, total)


if __name__ == "__main__":
    import typer

    from graspaug.pipeline.entry import round_number, stage_main

    round_ = typer.Option(..., "--round", "-r", parser=round_number, help="The round r<k>, one of lifelong.rounds.")
    stage_main(__spec__.name, round_=(int, round_))
