"""Grasp-centered depth crops: translate, rotate (jaw axis horizontal), crop, downsample.

A crop of ``crop_size`` pixels (Dex-Net: 96) around a grasp center, turned so the jaw axis runs
along the crop's rows, is sampled from the depth image by bilinear interpolation, then reduced
to ``out_size`` (Dex-Net: 32) by averaging ``crop_size / out_size`` square blocks. Crop pixel
(row r, column c) reads the image at

    (u, v) = center + R(angle) · (c − (S − 1)/2, r − (S − 1)/2),   S = crop_size,

so the grasp center sits at the crop's center and image direction ``angle`` (radians, from the
image's u axis toward its v axis) points along the crop's columns.

Two ways to get the same crops: :func:`crops_from_depth_image` from any full depth image (the
reference, and what a robot's camera gives), and :func:`crops_by_ray_casting`, which casts rays
only for the image pixels the crops read and only where the object can be (the table is
analytic), then runs the same bilinear + block-average sampling in compiled code.
"""

from __future__ import annotations

import numba
import numpy as np
import trimesh
from scipy import ndimage

from graspaug.render.camera import CameraPose
from graspaug.render.depth import object_depth, table_depth
from graspaug.render.settings import CropGeometry, Intrinsics


def crop_sample_points(
    centers: np.ndarray, angles: np.ndarray, geometry: CropGeometry
) -> tuple[np.ndarray, np.ndarray]:
    """Image coordinates u, v (G, S, S) read by the crops of grasps at ``centers`` (G, 2) as
    (u, v) with jaw directions ``angles`` (G,) (radians)."""
    offsets = np.arange(geometry.crop_size) - (geometry.crop_size - 1) / 2
    dy, dx = np.meshgrid(offsets, offsets, indexing="ij")
    cos, sin = np.cos(angles)[:, None, None], np.sin(angles)[:, None, None]
    u = centers[:, 0, None, None] + cos * dx - sin * dy
    v = centers[:, 1, None, None] + sin * dx + cos * dy
    return u, v


def block_mean(crops: np.ndarray, geometry: CropGeometry) -> np.ndarray:
    """(G, S, S) → (G, S/f, S/f): the mean of each f×f block."""
    g, f, n = len(crops), geometry.factor, geometry.out_size
    return crops.reshape(g, n, f, n, f).mean(axis=(2, 4))


def crops_from_depth_image(
    image: np.ndarray, centers: np.ndarray, angles: np.ndarray, geometry: CropGeometry = CropGeometry()
) -> np.ndarray:
    """Crops (G, out, out) float32 of a depth image (H, W) (m) for grasps at ``centers`` (G, 2)
    as (u, v) pixels with jaw directions ``angles`` (G,) (radians). Pixels outside the image
    repeat its border."""
    centers = np.asarray(centers, dtype=float).reshape(-1, 2)
    u, v = crop_sample_points(centers, np.asarray(angles, dtype=float).ravel(), geometry)
    sampled = ndimage.map_coordinates(np.asarray(image, dtype=float), [v.ravel(), u.ravel()], order=1, mode="nearest")
    return block_mean(sampled.reshape(u.shape), geometry).astype(np.float32)


@numba.njit(cache=True)
def _sample_crops(patch, u0, v0, table, centers, angles, crop_size, out_size, out):  # pragma: no cover - compiled
    """Bilinear samples of the scene's depth at every crop pixel, averaged per output block,
    into ``out`` (G, out_size, out_size). Image pixel (u, v) has depth ``patch[v - v0, u - u0]``
    inside ``patch`` (the window around the object), else the table's
    ``table[3] / (table[0] u + table[1] v + table[2])``."""
    factor = crop_size // out_size
    half = (crop_size - 1) / 2.0
    scale = 1.0 / (factor * factor)
    margin = (factor - 1) / np.sqrt(2.0) + 1.0
    rows, cols = patch.shape
    for g in range(centers.shape[0]):
        cos = np.cos(angles[g])
        sin = np.sin(angles[g])
        for i in range(out_size):
            for j in range(out_size):
                # block center; its samples and their bilinear taps lie within `margin` pixels
                bu = (
                    centers[g, 0]
                    + cos * (j * factor + (factor - 1) / 2.0 - half)
                    - sin * (i * factor + (factor - 1) / 2.0 - half)
                )
                bv = (
                    centers[g, 1]
                    + sin * (j * factor + (factor - 1) / 2.0 - half)
                    + cos * (i * factor + (factor - 1) / 2.0 - half)
                )
                if bv + margin < v0 or bv - margin > v0 + rows - 1 or bu + margin < u0 or bu - margin > u0 + cols - 1:
                    # only table under the block: the mean of the smooth table depth over the
                    # block equals its value at the block center to < 1e-8 m
                    out[g, i, j] = table[3] / (table[0] * bu + table[1] * bv + table[2])
                    continue
                total = 0.0
                for a in range(factor):
                    dy = i * factor + a - half
                    for b in range(factor):
                        dx = j * factor + b - half
                        u = centers[g, 0] + cos * dx - sin * dy
                        v = centers[g, 1] + sin * dx + cos * dy
                        iu = int(np.floor(u))
                        iv = int(np.floor(v))
                        r = iv - v0
                        c = iu - u0
                        if r < -1 or r >= rows or c < -1 or c >= cols:
                            # no object pixel among the four: the table, whose depth is smooth
                            # enough that bilinear interpolation equals its value to < 1e-8 m
                            total += table[3] / (table[0] * u + table[1] * v + table[2])
                            continue
                        fu = u - iu
                        fv = v - iv
                        value = 0.0
                        for dv in range(2):
                            for du in range(2):
                                if 0 <= r + dv < rows and 0 <= c + du < cols:
                                    depth = patch[r + dv, c + du]
                                else:
                                    depth = table[3] / (table[0] * (iu + du) + table[1] * (iv + dv) + table[2])
                                value += (fu if du else 1.0 - fu) * (fv if dv else 1.0 - fv) * depth
                        total += value
                out[g, i, j] = total * scale


def crops_by_ray_casting(
    mesh: trimesh.Trimesh,
    camera: CameraPose,
    intrinsics: Intrinsics,
    centers: np.ndarray,
    angles: np.ndarray,
    geometry: CropGeometry = CropGeometry(),
    pose: np.ndarray | None = None,
) -> tuple[np.ndarray, int]:
    """The crops (G, out, out) float32 that :func:`crops_from_depth_image` would cut from the
    full ray-cast depth image of ``mesh`` (m) on the table, and the number of rays cast.

    ``pose`` (4, 4) places the mesh in the table frame (default: the mesh is given in it); the
    mesh itself is not moved, so its ray-casting structure is built once for all its poses.
    Rays go only through pixels that some crop reads and that lie inside the bounding box of
    the object's projected vertices; every other pixel is the analytic table."""
    centers = np.asarray(centers, dtype=float).reshape(-1, 2)
    angles = np.asarray(angles, dtype=float).ravel()
    out = np.empty((len(centers), geometry.out_size, geometry.out_size))
    if len(centers) == 0:
        return out.astype(np.float32), 0
    if camera.position[2] <= 0:
        raise ValueError(f"the camera must be above the table, got height {camera.position[2]}")
    reach = (
        (geometry.crop_size - 1) / 2 * (np.abs(np.cos(angles)) + np.abs(np.sin(angles)))
    )  # half-size of each crop's bounding box
    u0, v0 = np.floor(np.min(centers - reach[:, None], axis=0)).astype(int)
    u1, v1 = np.floor(np.max(centers + reach[:, None], axis=0)).astype(int) + 1
    object_camera = camera if pose is None else camera.in_frame(pose)
    footprint = intrinsics.project(object_camera.to_camera(mesh.vertices))
    fu0, fv0 = np.maximum(np.floor(footprint.min(axis=0)).astype(int), (u0, v0))
    fu1, fv1 = np.minimum(np.ceil(footprint.max(axis=0)).astype(int), (u1, v1))
    if fu0 <= fu1 and fv0 <= fv1:
        vv, uu = np.mgrid[fv0 : fv1 + 1, fu0 : fu1 + 1]
        patch = np.minimum(
            object_depth(mesh, object_camera, intrinsics, uu.ravel(), vv.ravel()),
            table_depth(camera, intrinsics, uu.ravel(), vv.ravel()),
        ).reshape(uu.shape)
    else:
        fu0, fv0, patch = 0, 0, np.full((0, 0), np.inf)
    # table depth at pixel (u, v) = -height / (ray_z(u, v)), ray_z linear in u and v
    down = camera.rotation[2]
    a, b = down[0] / intrinsics.fx, down[1] / intrinsics.fy
    table = np.array([a, b, down[2] - a * intrinsics.cx - b * intrinsics.cy, -camera.position[2]])
    _sample_crops(patch, fu0, fv0, table, centers, angles, geometry.crop_size, geometry.out_size, out)
    return out.astype(np.float32), patch.size
