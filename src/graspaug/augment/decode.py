"""Decode to mesh: the batch runners that turn a pool's candidates into meshes, with the AutoEncoder-Critic
(:func:`mesh_batches`: decode the interpolated latent, then fill, open, marching cubes and smoothing; a decoder of
signed distances: marching cubes at 0 alone) or with no
network (:func:`blend_batches`: the parents' signed distance fields mixed; :func:`warp_batches`: one parent under a
random smooth deformation; :func:`primitive_batches`: random assemblies of primitives, no parent). Each is what
:func:`graspaug.augment.candidates.fill_pool` calls on a batch of candidates."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from graspaug.augment.candidates import Candidate, Decoded
from graspaug.geometry.from_voxels import mesh_decoded
from graspaug.geometry.sdf import mesh_decoded_field
from graspaug.nets.ae_critic import decode

if TYPE_CHECKING:
    from graspaug.augment.pools import BaseSet


def mesh_batches(
    ae, device, base: BaseSet, settings, workers: int, label: str
) -> Callable[[list[Candidate]], list[Decoded]]:
    """A batch runner for :func:`graspaug.augment.candidates.fill_pool`: decodes each candidate's
    ``(1 - α) z_a + α z_b`` with the autoencoder ``ae`` on ``device`` and meshes the grid
    (:func:`graspaug.geometry.from_voxels.mesh_decoded` with ``settings``, or for a decoder of signed distances
    :func:`graspaug.geometry.sdf.mesh_decoded_field`, at the parents' pitches interpolated the same way, m) on
    ``workers`` processes, ``label`` naming the progress."""
    from graspaug.parallel import parallel_map

    z, pitch = base.z, base.pitch
    if ae.cfg.output == "sdf":
        truncation = ae.cfg.truncation
        mesh_grid = lambda job: mesh_decoded_field(job[0], job[1], truncation, settings)  # noqa: E731
    else:
        mesh_grid = lambda job: mesh_decoded(job[0], job[1], settings)  # noqa: E731

    def run_batch(candidates: list[Candidate]) -> list[Decoded]:
        a = np.array([c.a for c in candidates])
        b = np.array([c.b for c in candidates])
        alpha = np.array([c.alpha for c in candidates], dtype=np.float32)[:, None]
        grids = decode(ae, (1 - alpha) * z[a] + alpha * z[b], device)
        child_pitch = (1 - alpha[:, 0]) * pitch[a] + alpha[:, 0] * pitch[b]  # metric size: parents' interpolated
        out = parallel_map(mesh_grid, list(zip(grids, child_pitch)), workers, label)
        return [
            Decoded(c, np.packbits(grid.occupancy), mesh, reason) for c, (grid, mesh, reason) in zip(candidates, out)
        ]

    return run_batch


def blend_batches(
    meshes: Sequence, resolution: int, margin: int, workers: int, label: str
) -> Callable[[list[Candidate]], list[Decoded]]:
    """A batch runner for :func:`graspaug.augment.candidates.fill_pool` that makes each candidate with no
    network: :func:`graspaug.geometry.blend.blend_solids` of its parents among ``meshes`` (the
    base set's meshes, m, in base-set order) at its weight, on ``resolution``-cell grids with
    ``margin`` empty cells, on ``workers`` processes; each parent's distance field is computed once
    per batch. Its grids are not kept (an empty array)."""
    from graspaug.geometry.blend import blend_fields, signed_distance_grid
    from graspaug.parallel import parallel_map

    def run_batch(candidates: list[Candidate]) -> list[Decoded]:
        parents = sorted({i for c in candidates for i in (c.a, c.b)})
        grids = parallel_map(lambda i: signed_distance_grid(meshes[i], resolution, margin), parents, workers, label)
        field = dict(zip(parents, grids))
        jobs = [(field[c.a], field[c.b], c.alpha) for c in candidates]
        out = parallel_map(lambda job: blend_fields(*job), jobs, workers, label)
        return [Decoded(c, np.zeros(0, np.uint8), mesh, reason) for c, (mesh, reason) in zip(candidates, out)]

    return run_batch


def warp_batches(
    meshes: Sequence, settings, surface, key: Sequence[int], workers: int, label: str
) -> Callable[[list[Candidate]], list[Decoded]]:
    """A batch runner that makes each candidate with no network: a random warp
    (:func:`graspaug.geometry.warp.random_warp` within ``settings``, a
    :class:`~graspaug.geometry.settings.WarpSettings`) of its nearer parent ``a`` among ``meshes`` (the base set's
    meshes, m, in base-set order), sized by the ingest rule of ``surface``
    (:class:`~graspaug.geometry.settings.SurfaceSettings`: size rule, size, face budget). Each warp is drawn from its
    own stream ``[*key, a, b, round(1e6 α)]``, so it depends on the candidate alone. The outcome names ``a`` as both
    parents at weight 0 (the shape is ``a``'s alone); on ``workers`` processes."""
    from graspaug.geometry.warp import random_warp, warp_mesh
    from graspaug.parallel import parallel_map

    def one(c: Candidate):
        rng = np.random.default_rng([*key, c.a, c.b, round(1e6 * c.alpha)])
        return warp_mesh(
            meshes[c.a], random_warp(rng, settings), surface.size_rule, surface.size_m, surface.face_budget
        )

    def run_batch(candidates: list[Candidate]) -> list[Decoded]:
        out = parallel_map(one, candidates, workers, label)
        return [
            Decoded(Candidate(c.a, c.a, 0.0, "warp"), np.zeros(0, np.uint8), mesh, reason)
            for c, (mesh, reason) in zip(candidates, out)
        ]

    return run_batch


def primitive_batches(
    settings, surface, key: Sequence[int], workers: int, label: str
) -> Callable[[list[Candidate]], list[Decoded]]:
    """A batch runner for the ``primitives`` pool: candidate k (:class:`~graspaug.augment.candidates.PrimitiveStream`)
    becomes the random assembly of primitives drawn from the stream ``[*key, k]``
    (:func:`graspaug.geometry.primitives.random_assembly` within ``settings``, a
    :class:`~graspaug.geometry.settings.PrimitiveSettings`), sized by ``surface``'s ingest rule; on ``workers``
    processes."""
    from graspaug.geometry.primitives import assembly_mesh, random_assembly
    from graspaug.parallel import parallel_map

    def one(c: Candidate):
        parts = random_assembly(np.random.default_rng([*key, c.a]), settings)
        return assembly_mesh(parts, settings.resolution, surface.size_rule, surface.size_m, surface.face_budget)

    def run_batch(candidates: list[Candidate]) -> list[Decoded]:
        out = parallel_map(one, candidates, workers, label)
        return [Decoded(c, np.zeros(0, np.uint8), mesh, reason) for c, (mesh, reason) in zip(candidates, out)]

    return run_batch


def procedural_batches(
    sources: Sequence, surface, workers: int, label: str
) -> Callable[[list[Candidate]], list[Decoded]]:
    """A batch runner for the ``procedural`` pool: candidate k (:class:`~graspaug.augment.candidates.ProceduralStream`)
    becomes ``sources[k]`` (:class:`graspaug.io.sources.Source`, already shuffled by :func:`procedural_sources`)
    loaded and made one closed solid by ingest's rule (:func:`graspaug.geometry.prepare.prepare_shape` with
    ``surface``, a :class:`~graspaug.geometry.settings.SurfaceSettings`): the object as the default corpus holds it,
    scaled by ``surface``'s size rule even where the corpus keeps real size (size ``real``), as the procedural
    corpus' units are arbitrary; on ``workers`` processes. A file that ingest would reject is rejected with the same
    reason."""
    from graspaug.geometry.loading import MeshRejected, load_shape
    from graspaug.geometry.prepare import prepare_shape
    from graspaug.parallel import parallel_map

    normalized = dataclasses.replace(surface, size="normalize")  # arbitrary units: sized as the default corpus is

    def one(c: Candidate):
        source = sources[c.a]
        try:
            return prepare_shape(load_shape(source.path, source.unit_scale), normalized).mesh, None
        except MeshRejected as exc:
            return None, f"{source.name}: {exc}"

    def run_batch(candidates: list[Candidate]) -> list[Decoded]:
        out = parallel_map(one, candidates, workers, label)
        return [Decoded(c, np.zeros(0, np.uint8), mesh, reason) for c, (mesh, reason) in zip(candidates, out)]

    return run_batch


def procedural_sources(exclude: Sequence[str], key: Sequence[int]) -> list:
    """The ``procedural`` pool's corpus: pybullet's ``random_urdfs`` objects
    (:func:`graspaug.io.sources.pybullet_sources`) whose portable name is not in ``exclude`` (the experiment's own
    sources: a corpus is never its own procedural pool), shuffled by the stream ``key``."""
    from graspaug.io.sources import pybullet_sources

    excluded = set(exclude)
    sources = [s for s in pybullet_sources() if s.name not in excluded]
    return [sources[i] for i in np.random.default_rng(list(key)).permutation(len(sources))]


WARP_SEED, PRIMITIVE_SEED, PROCEDURAL_SEED = 0x3A2B, 0x9817, 0x51D3  # the no-network pools' streams of the data seed


def control_runners(
    pools: Sequence[str],
    meshes: Sequence,
    cfg,
    surface,
    seed: int,
    base_size: int,
    workers: int,
    procedural: Sequence = (),
) -> dict[str, Callable[[list[Candidate]], list[Decoded]]]:
    """The runners of the no-network pools among ``pools`` for base size ``base_size``: ``blend``, ``warp`` (both on
    ``meshes``, the base set's meshes, m), ``primitives`` and ``procedural`` (on ``procedural``, the sources of
    :func:`procedural_sources`), with ``cfg`` (a :class:`~graspaug.augment.settings.GenerateSettings`), ``surface``
    (the ingest sizing rule) and the data ``seed``."""
    runners = {
        "blend": lambda: blend_batches(meshes, cfg.blend.resolution, cfg.blend.margin, workers, f"blend {base_size}"),
        "warp": lambda: warp_batches(
            meshes, cfg.warp, surface, [seed, WARP_SEED, base_size], workers, f"warp {base_size}"
        ),
        "primitives": lambda: primitive_batches(
            cfg.primitives, surface, [seed, PRIMITIVE_SEED, base_size], workers, f"primitives {base_size}"
        ),
        "procedural": lambda: procedural_batches(procedural, surface, workers, f"procedural {base_size}"),
    }
    return {name: make() for name, make in runners.items() if name in pools}


def own_source(ae, train_params: dict, latents, base: BaseSet, k: int, meshes: Callable):
    """The own pool's :class:`graspaug.augment.pools.OwnSource`: ``base`` (its ids, graspness and pitches) with the
    latents of ``latents`` (a table: ``shape_id``, ``z``, the base set encoded by ``ae``) and the rarity among them
    (``k`` neighbours), decoded by ``ae`` through ``meshes`` (:func:`mesh_batches` but its AE, shapes and label: a
    function ``meshes(ae, base=..., label=...)``); a :class:`graspaug.errors.DataError` unless ``ae`` was trained on
    exactly ``base``'s shapes (``train_params["train_ids"]``, as ``train_ae_own`` records them)."""
    from graspaug.augment.pools import BaseSet, OwnSource
    from graspaug.augment.scores import rarity
    from graspaug.errors import DataError

    ids = [str(s) for s in base.ids]
    if list(train_params.get("train_ids", [])) != ids:
        raise DataError(f"the own AE-Critic of base set {len(ids)} was not trained on that base set alone")
    z = np.stack(latents.set_index("shape_id").z.loc[ids].to_numpy()).astype(np.float32)
    shapes = BaseSet(base.ids, z, rarity(z, k), base.graspness, base.pitch)
    return OwnSource(shapes, meshes(ae, base=shapes, label=f"generate {len(ids)} own"))
