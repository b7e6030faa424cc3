"""Stage ``generate``: for one base set of B train shapes, a targeted and a random pool of new shapes.

``dvc.yaml`` runs it once per base size (``generate@50`` …). The targeted pool pairs the base
set's rare shapes, and separately its graspable ones, with their N-th … (N+K)-th nearest
neighbours in latent space, decodes ``(1 - α) z_a + α z_b`` with the AE-Critic and meshes it
(paper Section III-C); the random pool does the same for random pairs (the baseline the paper
argues against). Each pool holds ``ceil(max ratio × B)`` kept shapes in order: the first
``round(R × B)`` are the augmentation set of ratio R. A degenerate decode is rejected with its
reason and replaced by the next candidate.

Outputs, in ``data/generated/<B>/``: ``meshes/<shape_id>.obj``, ``index.parquet`` (one row per kept shape),
``rejects.parquet``, ``base.parquet`` (the base set with its scores); ``metrics/generate/<B>.json`` (shapes
kept, kept share); ``reports/generate/<B>/{summary.json,pairs.png,tsne.png}`` (summary: every pool count).
"""

from __future__ import annotations

import logging
import time

from graspaug.device import resolve_device
from graspaug.generation import generate_headline
from graspaug.generation_meshes import base_ids, base_set, generate_pools, mesh_batches, tsne_groups
from graspaug.io.atomic import atomic_path
from graspaug.io.checkpoints import load_autoencoder
from graspaug.io.meshes import mesh_path, write_obj
from graspaug.io.tables import read_table, write_json, write_table
from graspaug.io.voxels import read_voxels
from graspaug.params.ae import AEParams
from graspaug.params.base import params_model
from graspaug.params.embed import EmbedParams
from graspaug.params.generate import GenerateParams
from graspaug.params.score import ScoreParams
from graspaug.paths import (
    AE_CRITIC_MODEL,
    GENERATED_SUFFIX,
    LATENTS,
    SCORES,
    SHAPES_TABLE,
    VOXELS,
    generate_metrics,
    generate_reports,
    generate_summary,
    generated_dir,
    timing_file,
)
from graspaug.plots import generated_pairs, scatter_2d

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `generate` stage reads.", ae=AEParams, embed=EmbedParams, score=ScoreParams, generate=GenerateParams
)


def run(params: Params, base_size: int) -> None:
    start = time.perf_counter()
    cfg = params.generate
    ids = base_ids(read_table(SHAPES_TABLE), cfg.base_sizes, base_size, params.seed)
    voxels = read_voxels(VOXELS)
    base = base_set(ids, read_table(LATENTS), read_table(SCORES), voxels, params.score.k)

    device = resolve_device(params.device)
    ae, _, _ = load_autoencoder(AE_CRITIC_MODEL, params.ae.net)
    run_batch = mesh_batches(ae, device, base, cfg.decode, params.workers, f"generate {base_size}")
    out = generate_pools(base, cfg, params.seed, run_batch, params.score.k)
    for note in out.notes:
        log.info("generate %d: %s", base_size, note)

    with atomic_path(generated_dir(base_size), directory=True) as folder:
        (folder / "meshes").mkdir()
        for shape_id, d in zip(out.index.shape_id, out.kept):
            write_obj(d.mesh, mesh_path(folder / "meshes", shape_id, GENERATED_SUFFIX))
        write_table(out.index, folder / "index.parquet")
        write_table(out.rejects, folder / "rejects.parquet")
        write_table(out.base_table, folder / "base.parquet")

    reports = generate_reports(base_size)
    title = f"Generated shapes of base set {base_size}"
    generated_pairs(ids, voxels, out.examples, reports / "pairs.png", title)
    xy, groups = tsne_groups(base, out.index, params.embed.perplexity, params.seed)
    scatter_2d(xy, groups, reports / "tsne.png", f"t-SNE of base set {base_size} and its generated shapes")

    for message in out.warnings:
        log.warning("generate %d: %s", base_size, message)
    write_json(out.summary, generate_summary(base_size))
    write_json(generate_headline(out.summary), generate_metrics(base_size))
    seconds = round(time.perf_counter() - start, 1)
    write_json({"seconds": seconds}, timing_file("generate", str(base_size)))
    targeted, randoms = out.summary["targeted"], out.summary["random"]
    log.info(
        "generate %d: %d targeted (%d tried) + %d random (%d tried) shapes, %d rejected, in %.1f s",
        base_size,
        targeted["kept"],
        targeted["tried"],
        randoms["kept"],
        randoms["tried"],
        len(out.rejects),
        seconds,
    )
