"""Depth by ray casting: an object mesh (embree through trimesh) above an analytic table plane."""

from __future__ import annotations

import numpy as np
import trimesh

from graspaug.render.camera import CameraPose
from graspaug.render.settings import Intrinsics


def table_depth(
    camera: CameraPose, intrinsics: Intrinsics, u: np.ndarray, v: np.ndarray, table_height: float = 0.0
) -> np.ndarray:
    """Depth (N,) of the table plane z = ``table_height`` seen through pixels (u, v); inf where
    the ray does not go down to it."""
    directions = intrinsics.rays(u, v) @ camera.rotation.T  # table frame, unit camera-z
    down = directions[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        depth = (table_height - camera.position[2]) / down
    return np.where(down < 0, depth, np.inf)


def object_depth(
    mesh: trimesh.Trimesh, camera: CameraPose, intrinsics: Intrinsics, u: np.ndarray, v: np.ndarray
) -> np.ndarray:
    """Depth (N,) of ``mesh`` (table frame, m) through pixels (u, v); inf where a ray misses.

    Embree finds the first triangle each ray hits (in float32); the depth is then recomputed in
    float64 from that triangle's plane, so it is exact up to the choice of triangle at edges."""
    directions = intrinsics.rays(u, v) @ camera.rotation.T
    depth = np.full(len(directions), np.inf)
    if len(directions) == 0:
        return depth
    origins = np.broadcast_to(camera.position, directions.shape)
    hit = mesh.ray.intersects_first(ray_origins=origins, ray_directions=directions)
    rays = np.flatnonzero(hit >= 0)
    faces = hit[rays]
    normals = mesh.face_normals[faces]
    corner = mesh.triangles[faces, 0]
    depth[rays] = np.einsum("ij,ij->i", normals, corner - camera.position) / np.einsum(
        "ij,ij->i", normals, directions[rays]
    )
    return depth


def scene_depth(
    mesh: trimesh.Trimesh | None, camera: CameraPose, intrinsics: Intrinsics, u: np.ndarray, v: np.ndarray
) -> np.ndarray:
    """Depth (N,) of the object on the table (the nearer of the two) through pixels (u, v)."""
    depth = table_depth(camera, intrinsics, u, v)
    if mesh is not None:
        depth = np.minimum(depth, object_depth(mesh, camera, intrinsics, u, v))
    return depth


def render_depth(mesh: trimesh.Trimesh | None, camera: CameraPose, intrinsics: Intrinsics) -> np.ndarray:
    """The full depth image (height, width) float64 (m) by one ray per pixel center."""
    v, u = np.mgrid[0 : intrinsics.height, 0 : intrinsics.width]
    return scene_depth(mesh, camera, intrinsics, u.ravel(), v.ravel()).reshape(intrinsics.height, intrinsics.width)
