"""Quasi-static stable resting poses of a rigid object on a table (Goldberg et al. 1999).

The same computation as ``trimesh.poses.compute_stable_poses`` with ``sigma = 0`` (Dex-Net's
stable poses), vectorized over the convex hull's triangles: each hull triangle's prior is the
solid angle it covers seen from the center of mass over 4π; a triangle whose plane does not
hold the projected center of mass inside it topples across the edge that the projected center
lies beyond; probability flows along topples to resting triangles; coplanar resting triangles
(normals equal to 3 decimals) are one pose. Trimesh walks a networkx graph one triangle at a
time (~0.15 s for a 900-triangle hull); this takes a few milliseconds and gives the same poses
(tests/render/test_stable_poses.py).

A round object (a ball, a marble) rests in any orientation: its hull's many facets each hold a sliver of the
probability, none reaching the :data:`ROUND_PROBABILITY` that Dex-Net prunes below, so it would get no pose at all.
Such an object gets :data:`N_ROUND` orientations drawn uniformly over all rotations instead, each as likely
(``1 / N_ROUND``), drawn by a fixed seed (``seed``) so that every stage recomputing them gets the same.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

#: An object whose likeliest stable pose is less likely than this is round: it rests in any orientation.
ROUND_PROBABILITY = 0.01
#: Orientations a round object is given, each with probability 1 / N_ROUND.
N_ROUND = 10


@dataclass(frozen=True)
class StablePoses:
    """``transforms`` (P, 4, 4): each moves the object (in its own frame) to rest on the table
    plane z = 0 with z up; ``probabilities`` (P,): chance of landing in that pose when dropped
    in a uniformly random orientation. Most probable first. ``round``: the object rests in any orientation
    and these are uniformly drawn ones (:data:`N_ROUND`, equally likely)."""

    transforms: np.ndarray
    probabilities: np.ndarray
    round: bool = False  # uniformly drawn orientations of a round object, not the solver's poses

    def __len__(self) -> int:
        return len(self.probabilities)


def _orient(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Sign of d relative to the plane through a, b, c (rows), as trimesh's ``_orient3dfast``."""
    return np.einsum("ij,ij->i", a - d, np.cross(b - d, c - d))


def _landing_probabilities(triangles: np.ndarray, center: np.ndarray) -> np.ndarray:
    """Solid angle of each triangle (F, 3, 3) seen from ``center`` over 4π (L'Huilier's formula)."""
    unit = triangles - center
    unit /= np.linalg.norm(unit, axis=2, keepdims=True)
    cos = np.stack([np.einsum("ij,ij->i", unit[:, i], unit[:, (i + 1) % 3]) for i in range(3)], axis=1)
    a, b, c = np.arccos(np.clip(cos, -1.0, 1.0)).T
    s = (a + b + c) / 2
    product = np.tan(s / 2) * np.tan((s - a) / 2) * np.tan((s - b) / 2) * np.tan((s - c) / 2)
    return np.arctan(np.sqrt(np.clip(product, 0.0, None))) / np.pi


def _topple_targets(hull: trimesh.Trimesh, center: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each hull triangle, the triangle it topples to (itself when it is a resting one),
    and which triangles rest (hold the projected center of mass)."""
    triangles, normals = hull.triangles, hull.face_normals
    n_faces = len(triangles)
    projected = center - np.einsum("ij,ij->i", normals, center - triangles[:, 0])[:, None] * normals
    with np.errstate(divide="ignore", invalid="ignore"):  # sliver hull triangles give NaN: not toppling, as in trimesh
        barycentric = trimesh.triangles.points_to_barycentric(triangles, projected)
    target = np.arange(n_faces)
    unstable = np.any(barycentric < 0, axis=1)

    # every (face, neighbour, shared edge) once per side, in face order
    pairs, edges = hull.face_adjacency, hull.face_adjacency_edges
    face = np.concatenate([pairs[:, 0], pairs[:, 1]])
    neighbour = np.concatenate([pairs[:, 1], pairs[:, 0]])
    edge = np.concatenate([edges, edges])
    keep = unstable[face]
    face, neighbour, edge = face[keep], neighbour[keep], edge[keep]
    centroid, normal, point = hull.triangles_center[face], normals[face], projected[face]
    v1, v2 = hull.vertices[edge[:, 0]], hull.vertices[edge[:, 1]]
    flip = np.einsum("ij,ij->i", np.cross(v1 - centroid, v2 - centroid), normal) < 0
    v1[flip], v2[flip] = v2[flip], v1[flip].copy()
    beyond = (_orient(centroid, v1, v1 + normal, point) >= 0) & (_orient(centroid, v2 + normal, v2, point) >= 0)
    order = np.lexsort((~beyond, face))  # per face, the first edge the projected center lies beyond
    face, neighbour = face[order], neighbour[order]
    if len(face) == 0:
        return target, ~unstable
    first = np.r_[True, face[1:] != face[:-1]]
    target[face[first]] = neighbour[first]
    return target, ~unstable


def round_poses(hull: trimesh.Trimesh, n: int = N_ROUND, seed: int = 0) -> StablePoses:
    """``n`` orientations of a round object drawn uniformly over all rotations (``seed``), each resting on the
    table (its lowest ``hull`` vertex at z = 0, the origin above the table's origin), each with probability 1/n."""
    transforms = np.tile(np.eye(4), (n, 1, 1))
    transforms[:, :3, :3] = Rotation.random(n, random_state=np.random.default_rng(seed)).as_matrix()
    transforms[:, 2, 3] = -np.min(np.einsum("pj,vj->pv", transforms[:, 2, :3], hull.vertices), axis=1)
    return StablePoses(transforms=transforms, probabilities=np.full(n, 1.0 / n), round=True)


def stable_poses(mesh: trimesh.Trimesh, center_of_mass: np.ndarray | None = None, seed: int = 0) -> StablePoses:
    """All resting poses of ``mesh`` (meters) with their probabilities (those sum to 1 up to
    triangles whose topple chain loops, which are dropped); for a round object, whose likeliest pose is below
    :data:`ROUND_PROBABILITY` (or that has none), :func:`round_poses` drawn by ``seed``."""
    hull = mesh.convex_hull
    center = np.asarray(mesh.center_mass if center_of_mass is None else center_of_mass, dtype=float)
    prior = _landing_probabilities(hull.triangles, center)
    target, rests = _topple_targets(hull, center)
    for _ in range(len(target)):  # follow topples (pointer doubling) until each chain ends
        nxt = target[target]
        if np.array_equal(nxt, target):
            break
        target = nxt
    lands = rests[target]  # chains that end on a resting face; a loop of toppling faces does not
    mass = np.bincount(target[lands], weights=prior[lands], minlength=len(target))

    faces = np.flatnonzero(mass > 0)
    keys = np.round(hull.face_normals[faces], 3)
    _, first, group = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    probabilities = np.bincount(group.ravel(), weights=mass[faces])
    normals = hull.face_normals[faces[first]]

    transforms = np.tile(np.eye(4), (len(normals), 1, 1))
    for pose, normal in zip(transforms, normals):
        z = -normal
        x = np.array([-z[1], z[0], 0.0])
        x = np.array([1.0, 0.0, 0.0]) if np.linalg.norm(x) == 0 else x / np.linalg.norm(x)
        y = np.cross(z, x)
        pose[:3, :3] = np.stack([x, y / np.linalg.norm(y), z])
        pose[2, 3] = -np.min(hull.vertices @ pose[2, :3])
    if not len(probabilities) or probabilities.max() < ROUND_PROBABILITY:
        return round_poses(hull, N_ROUND, seed)
    order = np.argsort(-probabilities, kind="stable")
    return StablePoses(transforms=transforms[order], probabilities=probabilities[order])
