"""Meshes on disk, one file per shape, openable in MeshLab, Blender, trimesh: binary PLY for
ingested shapes, Wavefront OBJ for generated ones."""

from __future__ import annotations

import os
from pathlib import Path

import trimesh

MESH_SUFFIX = ".ply"


def mesh_path(folder: str | os.PathLike, shape_id: str, suffix: str = MESH_SUFFIX) -> Path:
    """Where the mesh of ``shape_id`` lives in ``folder``."""
    return Path(folder) / f"{shape_id}{suffix}"


def write_mesh(mesh: trimesh.Trimesh, path: str | os.PathLike) -> None:
    """Write ``mesh`` as binary PLY (caller makes the folder write atomic)."""
    Path(path).write_bytes(trimesh.exchange.ply.export_ply(mesh, encoding="binary", include_attributes=False))


def write_obj(mesh: trimesh.Trimesh, path: str | os.PathLike) -> None:
    """Write ``mesh`` as a Wavefront OBJ with vertices and faces only (caller makes the folder write atomic)."""
    Path(path).write_text(
        trimesh.exchange.obj.export_obj(
            mesh, include_normals=False, include_color=False, include_texture=False, digits=10, header=None
        )
    )


def read_mesh(path: str | os.PathLike) -> trimesh.Trimesh:
    """Read a mesh written by :func:`write_mesh` or :func:`write_obj`, vertices and faces as stored."""
    return trimesh.load(path, force="mesh", process=False)
