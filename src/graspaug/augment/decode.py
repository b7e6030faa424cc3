"""Decode to mesh: the batch runners that turn a pool's candidates into meshes, with the AutoEncoder-Critic
(:func:`mesh_batches`: decode the interpolated latent, then fill, open, marching cubes and smoothing; a decoder of
signed distances: marching cubes at 0 alone) or with no
network (:func:`blend_batches`: the parents' signed distance fields mixed). Each is what
:func:`graspaug.augment.candidates.fill_pool` calls on a batch of candidates."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from graspaug.augment.candidates import Candidate, Decoded
from graspaug.geometry.from_voxels import mesh_decoded
from graspaug.geometry.sdf import mesh_decoded_field
from graspaug.training.autoencoder import decode

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
