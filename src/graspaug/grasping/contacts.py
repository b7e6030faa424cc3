"""Where a closing parallel-jaw gripper touches a closed mesh: one ray per jaw (embree via trimesh)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh


@dataclass(frozen=True)
class Contacts:
    """Jaw contacts of N grasps: points ``p1, p2`` (N, 3) m and unit outward surface normals
    ``n1, n2`` (N, 3) there; ``found`` (N,) is False where a jaw misses the object or starts
    inside it (those rows hold NaN)."""

    p1: np.ndarray
    n1: np.ndarray
    p2: np.ndarray
    n2: np.ndarray
    found: np.ndarray


def first_entries(
    mesh: trimesh.Trimesh, origins: np.ndarray, directions: np.ndarray, max_distance: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First surface crossing of each ray (N, 3) origins / unit directions, if it enters the solid.

    Returns hit points (N, 3), outward face normals (N, 3) and ``ok`` (N,): False where the ray
    misses within ``max_distance`` m or its first crossing leaves the solid (origin inside).
    The hit is recomputed in float64 on the hit triangle's plane (embree works in float32).
    """
    n = len(origins)
    points = np.full((n, 3), np.nan)
    normals = np.full((n, 3), np.nan)
    ok = np.zeros(n, dtype=bool)
    if n == 0:
        return points, normals, ok
    _, rays, tris = mesh.ray.intersects_location(origins, directions, multiple_hits=False)
    if len(rays):
        face_normals = mesh.face_normals[tris]
        d = directions[rays]
        o = origins[rays]
        denom = np.einsum("ij,ij->i", face_normals, d)
        vertex = mesh.vertices[mesh.faces[tris, 0]]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.einsum("ij,ij->i", face_normals, vertex - o) / denom
        good = (denom < 0) & (t >= 0) & (t <= max_distance)
        rays, t, d, o, face_normals = rays[good], t[good], d[good], o[good], face_normals[good]
        points[rays] = o + t[:, None] * d
        normals[rays] = face_normals
        ok[rays] = True
    return points, normals, ok


def close_fingers(mesh: trimesh.Trimesh, centers: np.ndarray, axes: np.ndarray, max_width: float) -> Contacts:
    """Contacts of jaws opened to ``max_width`` m around ``centers`` (N, 3) and closed along
    unit ``axes`` (N, 3): jaw 1 starts at ``center - max_width/2 · axis`` and moves along
    ``+axis``, jaw 2 starts at ``center + max_width/2 · axis`` and moves along ``-axis``; each
    stops at the first surface it meets (Dex-Net's ``close_fingers``)."""
    centers = np.asarray(centers, dtype=float)
    axes = np.asarray(axes, dtype=float)
    half = 0.5 * max_width * axes
    origins = np.concatenate([centers - half, centers + half])
    directions = np.concatenate([axes, -axes])
    points, normals, ok = first_entries(mesh, origins, directions, max_width)
    n = len(centers)
    p1, p2 = points[:n], points[n:]
    found = ok[:n] & ok[n:]
    found &= np.einsum("ij,ij->i", np.nan_to_num(p2 - p1), axes) > 0  # the jaws have not crossed
    return Contacts(p1=p1, n1=normals[:n], p2=p2, n2=normals[n:], found=found)
