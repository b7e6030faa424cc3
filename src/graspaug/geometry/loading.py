"""Loading mesh files into checked triangle meshes, with a reason when they are unusable.

A file becomes either a :class:`LoadedShape` (its triangles, and its convex parts
when it is an assembly of closed convex pieces like pybullet's ``random_urdfs``)
or a :class:`MeshRejected` exception whose message is the one-line reason that
the ingest stage records.

Meshes are loaded by geometry: when the file's pieces are not closed as they are
(textured exports split vertices at UV seams, so one object loads as many open
pieces), vertices are merged by position alone (UVs and normals ignored), degenerate
and duplicate faces dropped and holes of three or four edges filled; ``closed_by``
says which of these closed it (see :class:`LoadedShape`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from graspaug.geometry.solid import ConvexPart, convex_part

MESH_SUFFIXES = (".obj", ".stl", ".ply", ".off", ".glb")

# extents below this share of the largest one make a shape flat (no volume)
_FLAT_RATIO = 1e-4
#: Vertex coordinates are read to this many decimals of a metre (1 µm, far below any scan's accuracy): the digits
#: beyond are float noise of the file's unit (a float32 file in mm and one in m of one object differ by 1e-9 m), and
#: the decimator, whose collapses tie on flat faces, would turn that noise into another triangulation, other
#: sampled grasps and another test set.
VERTEX_DIGITS = 6


class MeshRejected(Exception):
    """A mesh file that cannot become a shape; ``str(exc)`` is the one-line reason."""


@dataclass
class LoadedShape:
    """Triangles of one source file in meters, and its convex parts when it is made of them.

    Attributes
    ----------
    mesh : all triangles (parts concatenated), meters
    parts : convex parts as half-spaces, meters; empty unless every piece is a closed convex body
    closed_by : ``as_is`` when every piece is closed as loaded, ``merged`` when closed after
        merging vertices by position (and filling holes of three or four edges), ``open``
        when still open (:func:`graspaug.geometry.closing.fill_open_mesh` fills it)
    """

    mesh: trimesh.Trimesh
    parts: list[ConvexPart]
    closed_by: str = "as_is"


def by_geometry(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """The triangles alone: vertices merged by position (UVs, normals and colors dropped),
    degenerate and duplicate faces removed."""
    out = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    out.merge_vertices(merge_tex=True, merge_norm=True)
    out.update_faces(out.nondegenerate_faces() & out.unique_faces())
    out.remove_unreferenced_vertices()
    return out


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0][:120]}" if text else type(exc).__name__


def load_shape(
    path: str | os.PathLike, unit_scale: float = 1.0, max_faces: int = 1_000_000, max_file_mb: float = 100.0
) -> LoadedShape:
    """Load and check one mesh file.

    Parameters
    ----------
    path : a .obj/.stl/.ply/.off/.glb file
    unit_scale : float — meters per file unit (a URDF's mesh scale)
    max_faces : int — more triangles than this is rejected
    max_file_mb : float — a larger file is rejected before it is read

    Raises
    ------
    MeshRejected
        with the reason: file too large, empty file, unreadable, not a mesh, no
        triangles, too many faces, non-finite vertex coordinates, or degenerate.
    """
    path = Path(path)
    size_mb = path.stat().st_size / 2**20
    if size_mb > max_file_mb:
        raise MeshRejected(f"file too large: {size_mb:.1f} MB > max_file_mb={max_file_mb:g}")
    if size_mb == 0:
        raise MeshRejected("empty file")
    try:
        loaded = trimesh.load(path, split_objects=True, group_material=False, process=False)
    except Exception as exc:  # noqa: BLE001 — any parser failure is a reason, not a crash
        raise MeshRejected(f"unreadable: {_first_line(exc)}") from None

    if isinstance(loaded, trimesh.Scene):
        pieces = list(loaded.dump()) if loaded.geometry else []
    else:
        pieces = [loaded]
    if not pieces:
        raise MeshRejected("no triangles: the file holds no geometry")
    not_mesh = [type(p).__name__ for p in pieces if not isinstance(p, trimesh.Trimesh)]
    if not_mesh:
        raise MeshRejected(f"not a mesh: holds {not_mesh[0]}")
    pieces = [p for p in pieces if len(p.faces)]
    n_faces = sum(len(p.faces) for p in pieces)
    if n_faces == 0:
        raise MeshRejected("no triangles: the file holds no faces")
    if n_faces > max_faces:
        raise MeshRejected(f"too many faces: {n_faces} > max_faces={max_faces}")
    for p in pieces:
        if not np.isfinite(p.vertices).all():
            raise MeshRejected("non-finite vertex coordinates (NaN or inf)")
        p.apply_scale(unit_scale)
        p.vertices = np.round(p.vertices, VERTEX_DIGITS)  # to 1 µm: the same file in mm or m gives the same metres
        p.merge_vertices()  # STL and some PLY store each triangle's corners separately

    mesh = trimesh.util.concatenate(pieces) if len(pieces) > 1 else pieces[0].copy()
    mesh.merge_vertices()
    mesh.update_faces(mesh.nondegenerate_faces())
    mesh.remove_unreferenced_vertices()
    if len(mesh.faces) == 0 or not mesh.area > 0:
        raise MeshRejected("degenerate: zero surface area")
    # flat along the mesh's own principal directions (a tilted sheet too), not just x, y, z
    spread = np.linalg.svd(mesh.vertices - mesh.vertices.mean(axis=0), compute_uv=False)
    if len(spread) < 3 or spread[2] <= _FLAT_RATIO * spread[0]:
        raise MeshRejected(f"degenerate: flat, extents {np.array2string(mesh.extents, precision=4)} m")

    closed_by = "as_is"
    if not all(p.is_watertight for p in pieces):
        pieces = [by_geometry(p) for p in pieces]
        mesh = by_geometry(mesh)
        if not all(p.is_watertight for p in pieces):
            trimesh.repair.fill_holes(mesh)  # a missing triangle or quad
        closed_by = "merged" if all(p.is_watertight for p in pieces) or mesh.is_watertight else "open"

    parts: list[ConvexPart] = []
    if all(p.is_watertight and p.is_convex for p in pieces):
        parts = [part for part in map(convex_part, (p.vertices for p in pieces)) if part is not None]
    return LoadedShape(mesh=mesh, parts=parts, closed_by=closed_by)
