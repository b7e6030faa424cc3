"""Stage ``generate``: for one base set of B train shapes (``generate@50`` …), pools of new shapes.

Targeted: the base set's rare, and separately graspable, shapes with their N-th … (N+K)-th latent neighbours,
``(1 - α) z_a + α z_b`` decoded by the AE-Critic and meshed (paper Section III-C); own: the same with the AE-Critic of
``train_ae_own@B`` (the base set alone); random: random pairs; recon: the real pool's shapes from their own latents;
blend: the targeted pairs with no network; warp: each pair's nearer parent randomly deformed; primitives: random
assemblies of primitives; procedural: pybullet's random_urdfs objects. ``gqcnn.pools`` says which (``gqcnn.networks``,
where set: those its networks train on); each holds ``ceil(max ratio × B)`` kept shapes, the first ``round(R × B)``
ratio R's set; a failed shape is replaced by the next candidate, except in recon (dropped, and said). Writes
``data/generated/<B>/`` (meshes, index, rejects, base), ``metrics/generate/<B>.json``, ``reports/generate/<B>/``."""

from __future__ import annotations

import logging
import time
from functools import partial

from graspaug.augment.decode import PROCEDURAL_SEED, control_runners, mesh_batches, own_source, procedural_sources
from graspaug.augment.pool_tables import generate_headline
from graspaug.augment.pools import GENERATED_POOLS, ReconSource, base_ids, base_set, generate_pools, tsne_groups
from graspaug.device import resolve_device
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.meshes import mesh_path, read_mesh, write_obj
from graspaug.io.tables import read_table, write_json, write_table
from graspaug.io.voxels import read_voxels
from graspaug.pipeline import paths, shape_needs
from graspaug.pipeline.params.ae import AEParams
from graspaug.pipeline.params.base import params_model
from graspaug.pipeline.params.embed import EmbedParams
from graspaug.pipeline.params.generate import GenerateParams
from graspaug.pipeline.params.gqcnn import GQCNNParams
from graspaug.pipeline.params.ingest import IngestParams
from graspaug.pipeline.params.score import ScoreParams
from graspaug.plots import generated_pairs, scatter_2d
from graspaug.training.gqcnn_data import load_split
from graspaug.training.settings import listed_pools

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `generate` stage reads.",
    ingest=IngestParams,
    ae=AEParams,
    embed=EmbedParams,
    score=ScoreParams,
    generate=GenerateParams,
    gqcnn=GQCNNParams,
)


def run(params: Params, base_size: int) -> None:
    start, cfg, gq = time.perf_counter(), params.generate, params.gqcnn
    shapes, latents, scores = (read_table(path) for path in (paths.SHAPES_TABLE, paths.LATENTS, paths.SCORES))
    voxels = read_voxels(paths.VOXELS)
    ids = base_ids(shapes, cfg.base_sizes, base_size, params.data_seed)
    base = base_set(ids, latents, scores, voxels, params.score.k)

    ae, _, _ = load_autoencoder(paths.AE_CRITIC_MODEL, params.ae.net)
    meshes = partial(mesh_batches, device=resolve_device(params.device), settings=cfg.decode, workers=params.workers)
    cfg, pools = listed_pools(cfg, [p for p in GENERATED_POOLS if p in gq.pools], gq.networks, base_size)
    recon, own = None, None
    if "recon" in pools:  # the real pool as the GQ-CNN experiment draws it
        split = load_split(paths.gqcnn_dir("original"), shapes, list(cfg.base_sizes), gq.val_shapes, params.data_seed)
        real_ids = shape_needs.real_pool_ids(split, params.ingest, params.generate, gq)  # too few: exit 2, one line
        real = base_set(real_ids, latents, scores, voxels, params.score.k)
        recon = ReconSource(real, meshes(ae, base=real, label=f"generate {base_size} recon"))
    if "own" in pools:  # the base set under the AE-Critic that train_ae_own@B trained on it alone
        own_ae, _, trained = load_autoencoder(paths.ae_own_model(base_size), params.ae.net)
        own = own_source(own_ae, trained, read_table(paths.ae_own_latents(base_size)), base, params.score.k, meshes)
    solids = [read_mesh(mesh_path(paths.SHAPES_DIR, s)) for s in ids] if {"blend", "warp"} & set(pools) else []
    surface = params.ingest.surface  # the warp and primitives pools' shapes are sized as ingest sizes a shape
    key = [params.data_seed, PROCEDURAL_SEED, base_size]  # the procedural corpus less this one's sources, shuffled
    procedural = procedural_sources(list(shapes.source), key) if "procedural" in pools else []
    controls = control_runners(pools, solids, cfg, surface, params.data_seed, base_size, params.workers, procedural)
    run_batch, procedural_ids = meshes(ae, base=base, label=f"generate {base_size}"), [s.shape_id for s in procedural]
    inputs = (base, cfg, params.data_seed, run_batch, params.score.k, pools, recon, controls, procedural_ids)
    out = generate_pools(*inputs, control_ratios=gq.control_ratios, own=own)  # all but targeted at their own ratios
    for level, message in [(logging.INFO, n) for n in out.notes] + [(logging.WARNING, w) for w in out.warnings]:
        log.log(level, "generate %d: %s", base_size, message)

    with atomic_path(paths.generated_dir(base_size), directory=True) as folder:
        (folder / "meshes").mkdir()
        for shape_id, d in zip(out.index.shape_id, out.kept):
            write_obj(d.mesh, mesh_path(folder / "meshes", shape_id, paths.GENERATED_SUFFIX))
        for name, table in (("index", out.index), ("rejects", out.rejects), ("base", out.base_table)):
            write_table(table, folder / f"{name}.parquet")

    reports = paths.generate_reports(base_size)
    generated_pairs(ids, voxels, out.examples, reports / "pairs.png", f"Generated shapes of base set {base_size}")
    xy, groups = tsne_groups(base, out.index, params.embed.perplexity, params.seed)
    scatter_2d(xy, groups, reports / "tsne.png", f"t-SNE of base set {base_size} and its generated shapes")

    write_json(out.summary, paths.generate_summary(base_size))
    write_json(generate_headline(out.summary), paths.generate_metrics(base_size))
    seconds = round(time.perf_counter() - start, 1)
    write_json({"seconds": seconds}, paths.timing_file("generate", str(base_size)))
    counts = " + ".join(f"{out.summary[p]['kept']} {p} ({out.summary[p]['tried']} tried)" for p in pools)
    log.info("generate %d: %s shapes, %d rejected, in %.1f s", base_size, counts, len(out.rejects), seconds)


if __name__ == "__main__":
    import typer

    from graspaug.pipeline.entry import stage_main

    stage_main(__spec__.name, base_size=(int, typer.Option(..., "--base-size", "-b", help="The base set size B.")))
