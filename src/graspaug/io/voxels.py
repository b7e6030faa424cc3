"""``voxels.npz``: all occupancy grids of a corpus in one bit-packed file (and their signed distances).

Keys
----
shape_id : (N,) str
occupancy : (N, R³/8) uint8 — ``numpy.packbits`` of the C-ordered (R, R, R) grids
resolution : () int — R
pitch : (N,) float — voxel edge, meters
origin : (N, 3) float — grid corner in the shape's normalized frame, meters;
    voxel (i, j, k) has its center at ``origin + pitch * (ijk + 0.5)``
sdf : (N, R, R, R) int8, only with signed distances — the truncated signed distance at each voxel center
    divided by ``truncation``, times 127 and rounded (a step of truncation / 127 voxels)
truncation : () float, only with signed distances — voxels
"""

from __future__ import annotations

import os
import zipfile
from dataclasses import dataclass

import numpy as np

from graspaug.geometry.voxelize import VoxelGrid, pack_bits, unpack_bits
from graspaug.io.atomic import atomic_path


@dataclass
class VoxelSet:
    """Occupancy grids with their shape ids and metric placement."""

    shape_id: np.ndarray  # (N,) str
    occupancy: np.ndarray  # (N, R, R, R) bool
    pitch: np.ndarray  # (N,) meters
    origin: np.ndarray  # (N, 3) meters
    sdf: np.ndarray | None = None  # (N, R, R, R) float32 signed distance / truncation in [-1, 1], negative inside
    truncation: float | None = None  # voxels

    @property
    def resolution(self) -> int:
        return int(self.occupancy.shape[1])

    def grid(self, i: int) -> VoxelGrid:
        """Placement of grid ``i`` in its shape's normalized frame."""
        return VoxelGrid(self.resolution, float(self.pitch[i]), self.origin[i])


def write_npz(arrays: dict[str, np.ndarray], path: str | os.PathLike) -> None:
    """A compressed ``.npz`` whose bytes depend only on ``arrays`` (atomic).

    ``numpy.savez_compressed`` stamps every member with the current time, so the
    same arrays would hash differently on every run and DVC would see a change.
    """
    with atomic_path(path) as tmp, zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for key, value in arrays.items():
            info = zipfile.ZipInfo(f"{key}.npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            with zf.open(info, "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.asanyarray(value), allow_pickle=False)


def write_voxels(voxels: VoxelSet, path: str | os.PathLike) -> None:
    """Write a :class:`VoxelSet` to a compressed, byte-reproducible npz (atomic); without signed distances the
    file holds the occupancy keys alone."""
    arrays = {
        "shape_id": np.asarray(voxels.shape_id, dtype=str),
        "occupancy": pack_bits(voxels.occupancy),
        "resolution": np.int64(voxels.resolution),
        "pitch": np.asarray(voxels.pitch, dtype=np.float64),
        "origin": np.asarray(voxels.origin, dtype=np.float64),
    }
    if voxels.sdf is not None:
        steps = np.round(np.clip(voxels.sdf, -1.0, 1.0) * 127).astype(np.int8)
        arrays["sdf"] = np.where((steps == 0) & (voxels.sdf < 0), np.int8(-1), steps)  # inside stays inside
        arrays["truncation"] = np.float64(voxels.truncation)
    write_npz(arrays, path)


def read_voxels(path: str | os.PathLike) -> VoxelSet:
    """Read a file written by :func:`write_voxels`."""
    with np.load(path, allow_pickle=False) as z:
        r = int(z["resolution"])
        sdf = z["sdf"].astype(np.float32) / 127 if "sdf" in z.files else None
        truncation = float(z["truncation"]) if "truncation" in z.files else None
        return VoxelSet(
            shape_id=z["shape_id"],
            occupancy=unpack_bits(z["occupancy"], r),
            pitch=z["pitch"],
            origin=z["origin"],
            sdf=sdf,
            truncation=truncation,
        )
