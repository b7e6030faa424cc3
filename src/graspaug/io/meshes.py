"""Meshes on disk: binary PLY, one file per shape, openable in MeshLab, Blender, trimesh."""
from __future__ import annotations

import os
from pathlib import Path

import trimesh

MESH_SUFFIX = ".ply"


def mesh_path(folder: str | os.PathLike, shape_id: str) -> Path:
    """Where the mesh of ``shape_id`` lives in ``folder``."""
    return Path(folder) / f"{shape_id}{MESH_SUFFIX}"


def write_mesh(mesh: trimesh.Trimesh, path: str | os.PathLike) -> None:
    """Write ``mesh`` as binary PLY (caller makes the folder write atomic)."""
    Path(path).write_bytes(trimesh.exchange.ply.export_ply(mesh, encoding="binary", include_attributes=False))


def read_mesh(path: str | os.PathLike) -> trimesh.Trimesh:
    """Read a mesh written by :func:`write_mesh`, vertices and faces exactly as stored."""
    return trimesh.load(path, force="mesh", process=False)
