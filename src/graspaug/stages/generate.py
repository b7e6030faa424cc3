"""Stage ``generate``: for one base set of B train shapes, a targeted and a random pool of new shapes.

``dvc.yaml`` runs it once per base size (``generate@50`` …). The targeted pool pairs the base
set's rare shapes, and separately its graspable ones, with their N-th … (N+K)-th nearest
neighbours in latent space, decodes ``(1 - α) z_a + α z_b`` with the AE-Critic and meshes it
(paper Section III-C); the random pool does the same for random pairs (the baseline the paper
argues against). Each pool holds ``ceil(max ratio × B)`` kept shapes in order: the first
``round(R × B)`` are the augmentation set of ratio R. A degenerate decode is rejected with its
reason and replaced by the next candidate.

Outputs, in ``data/generated/<B>/``: ``meshes/<shape_id>.obj``, ``index.parquet`` (one row
per kept shape), ``rejects.parquet``, ``base.parquet`` (the base set with its scores); plus
``metrics/generate/<B>.json`` and ``reports/generate/<B>/{pairs,tsne}.png``.
"""

from __future__ import annotations

import logging
import time

import numpy as np
import pandas as pd

from graspaug.device import resolve_device
from graspaug.embedding import tsne_2d
from graspaug.generation import (
    BASE_SEED,
    Candidate,
    Decoded,
    PoolExhausted,
    RandomStream,
    TargetedStream,
    base_scores_table,
    draw_base_sets,
    fill_pool,
    pool_size,
    pool_summary,
    pool_tables,
)
from graspaug.geometry.from_voxels import mesh_decoded
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
    generated_dir,
    timing_file,
)
from graspaug.plots import generated_pairs, scatter_2d
from graspaug.scores import rarity
from graspaug.stages import StageError
from graspaug.training.autoencoder import decode

log = logging.getLogger(__name__)

Params = params_model(
    "The params the `generate` stage reads.", ae=AEParams, embed=EmbedParams, score=ScoreParams, generate=GenerateParams
)


def run(params: Params, base_size: int) -> None:
    from graspaug.parallel import parallel_map

    start = time.perf_counter()
    cfg = params.generate
    if base_size not in cfg.base_sizes:
        raise StageError(f"base size {base_size} is not in generate.base_sizes {list(cfg.base_sizes)}")
    shapes = read_table(SHAPES_TABLE)
    n_train = int((shapes.split == "train").sum())
    if n_train < max(cfg.base_sizes):
        raise StageError(f"generate.base_sizes: {max(cfg.base_sizes)} is larger than the {n_train} train shapes")
    base = draw_base_sets(shapes, cfg.base_sizes, params.seed)[base_size]
    latents = read_table(LATENTS).set_index("shape_id").z
    scores = read_table(SCORES).set_index("shape_id")
    voxels = read_voxels(VOXELS)
    pitch_of = dict(zip(voxels.shape_id, voxels.pitch))
    z = np.stack(latents.loc[base].to_numpy()).astype(np.float32)
    base_rarity = rarity(z, params.score.k)  # relative to this base set
    graspness = scores.graspness.loc[base].to_numpy()
    pitch = np.array([pitch_of[s] for s in base])

    device = resolve_device(params.device)
    ae, _, _ = load_autoencoder(AE_CRITIC_MODEL, params.ae.net)

    def run_batch(candidates: list[Candidate]) -> list[Decoded]:
        a = np.array([c.a for c in candidates])
        b = np.array([c.b for c in candidates])
        alpha = np.array([c.alpha for c in candidates], dtype=np.float32)[:, None]
        probability = decode(ae, (1 - alpha) * z[a] + alpha * z[b], device)
        child_pitch = (1 - alpha[:, 0]) * pitch[a] + alpha[:, 0] * pitch[
            b
        ]  # metric size: the parents' scales interpolated
        out = parallel_map(
            lambda job: mesh_decoded(job[0], job[1], cfg.decode),
            list(zip(probability, child_pitch)),
            params.workers,
            f"generate {base_size}",
        )
        return [
            Decoded(c, np.packbits(grid.occupancy), mesh, reason) for c, (grid, mesh, reason) in zip(candidates, out)
        ]

    needed = pool_size(cfg.ratios, base_size)
    targeted_stream = TargetedStream(
        z, base_rarity, graspness, cfg.percentile, cfg.first_neighbour, cfg.extra_neighbours, cfg.alphas
    )
    random_stream = RandomStream(base_size, cfg.alphas, np.random.default_rng([params.seed, BASE_SEED, base_size]))
    pools = {}
    for name, stream in (("targeted", targeted_stream), ("random", random_stream)):
        try:
            pools[name] = fill_pool(stream, needed, run_batch)
        except PoolExhausted as exc:
            raise StageError(f"generate {base_size}, {name} pool: {exc}") from None
    for note in targeted_stream.notes:
        log.info("generate %d: %s", base_size, note)
    (targeted, _), (randoms, _) = pools["targeted"], pools["random"]

    rows, reject_rows = pool_tables(base, z, pools, base_size)
    index = pd.DataFrame(rows)
    index["rarity_vs_base"] = rarity(z, params.score.k, query=np.stack(index.z.to_numpy()))
    base_table = base_scores_table(base, base_rarity, graspness, targeted_stream.percentile)
    with atomic_path(generated_dir(base_size), directory=True) as folder:
        (folder / "meshes").mkdir()
        for row, d in zip(rows, targeted + randoms):
            write_obj(d.mesh, mesh_path(folder / "meshes", row["shape_id"], GENERATED_SUFFIX))
        write_table(index, folder / "index.parquet")
        write_table(
            pd.DataFrame(reject_rows, columns=["pool", "parent_a", "parent_b", "alpha", "selected_by", "reason"]),
            folder / "rejects.parquet",
        )
        write_table(base_table, folder / "base.parquet")

    generated_pairs(
        base,
        voxels,
        targeted[: cfg.n_examples] + randoms[:2],
        generate_reports(base_size) / "pairs.png",
        f"Generated shapes of base set {base_size}",
    )
    xy = tsne_2d(np.concatenate([z, np.stack(index.z.to_numpy())]), params.embed.perplexity, params.seed)
    groups = ["base"] * base_size + [f"generated ({s})" for s in index.selected_by]
    scatter_2d(
        xy, groups, generate_reports(base_size) / "tsne.png", f"t-SNE of base set {base_size} and its generated shapes"
    )

    summary, kept_share = pool_summary(base_size, needed, pools, targeted_stream, index, reject_rows)
    for name, share in kept_share.items():
        if share < 0.95:
            log.warning(
                "generate %d: only %.1f%% of the %s pool's decodes were usable meshes", base_size, 100 * share, name
            )
    write_json(summary, generate_metrics(base_size))
    seconds = round(time.perf_counter() - start, 1)
    write_json({"seconds": seconds}, timing_file("generate", str(base_size)))
    log.info(
        "generate %d: %d targeted (%d tried) + %d random (%d tried) shapes, %d rejected, in %.1f s",
        base_size,
        len(targeted),
        summary["targeted"]["tried"],
        len(randoms),
        summary["random"]["tried"],
        len(reject_rows),
        seconds,
    )
