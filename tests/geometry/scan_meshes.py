"""Meshes shaped like a lab's own scans, built here so that tests can measure what ingest makes of them.

Each builder returns ``(text or mesh, true_volume)``: the volume, in m³, of the solid the
file is meant to describe. OBJ text gets a distinct texture coordinate at every face
corner, as textured exports have at UV seams, so a loader that keeps texture coordinates
splits every vertex (the file's faces do not share a single vertex).
"""

from __future__ import annotations

import numpy as np
import trimesh


def obj_with_face_uvs(mesh: trimesh.Trimesh, groups: np.ndarray | None = None) -> str:
    """OBJ text of ``mesh`` with one ``vt`` per face corner (a seam along every edge).

    ``groups`` (one int per face) writes faces under ``o part_<g>`` headers, as scanners
    and exporters split one object into pieces.
    """
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in mesh.vertices]
    n = 3 * len(mesh.faces)
    lines += [f"vt {(i % 1000) / 1000:.4f} {(i // 1000) / 1000:.4f}" for i in range(n)]
    order = np.arange(len(mesh.faces)) if groups is None else np.argsort(groups, kind="stable")
    current = None
    for fi in order:
        if groups is not None and groups[fi] != current:
            current = groups[fi]
            lines.append(f"o part_{current}")
        a, b, c = mesh.faces[fi] + 1
        t = 3 * fi + 1
        lines.append(f"f {a}/{t} {b}/{t + 1} {c}/{t + 2}")
    return "\n".join(lines) + "\n"


def seamed_cylinder() -> tuple[str, float]:
    """A food can (r 3 cm, h 10 cm) as a textured OBJ: closed only when vertices merge by position."""
    can = trimesh.creation.cylinder(radius=0.03, height=0.1, sections=48)
    return obj_with_face_uvs(can), float(can.volume)


def seamed_box() -> tuple[str, float]:
    """A foam brick (8 x 5 x 3 cm) as a textured OBJ, one ``o`` group per side."""
    box = trimesh.creation.box(extents=(0.08, 0.05, 0.03))
    sides = np.unique(np.round(box.face_normals, 6), axis=0, return_inverse=True)[1].ravel()
    return obj_with_face_uvs(box, sides), float(box.volume)


def _without_faces_near(
    mesh: trimesh.Trimesh, centers: np.ndarray, radius: float = 0.0, count: int = 0
) -> trimesh.Trimesh:
    """``mesh`` less the faces whose centers lie within ``radius`` of ``centers``, or the ``count`` nearest ones."""
    keep = np.ones(len(mesh.faces), bool)
    for c in centers:
        dist = np.linalg.norm(mesh.triangles_center - c, axis=1)
        keep &= dist > radius
        keep[np.argsort(dist)[:count]] = False
    out = mesh.copy()
    out.update_faces(keep)
    out.remove_unreferenced_vertices()
    return out


def holed_sphere(hole: float = 0.0025) -> tuple[trimesh.Trimesh, float]:
    """A ball (r 4 cm, 1.5 mm triangles) with three holes: the faces whose centers lie within
    ``hole / 2`` of three vertices removed (the default removes their rings of six: holes of
    about 3 mm that trimesh's hole filling leaves open)."""
    ball = trimesh.creation.icosphere(subdivisions=5, radius=0.04)
    centers = ball.vertices[[0, 100, 1000]]
    return _without_faces_near(ball, centers, hole / 2), float(ball.volume)


def _lathe(profile: list[tuple[float, float]], step: float, sections: int) -> trimesh.Trimesh:
    """A closed solid of revolution about z: the (radius, height) polyline resampled every
    ``step`` meters or less, so that its triangles are small and even, as a scan's are."""
    points = [np.asarray(profile[0], float)]
    for a, b in zip(profile[:-1], profile[1:]):
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = max(int(np.ceil(np.linalg.norm(b - a) / step)), 1)
        points += [a + (b - a) * k / n for k in range(1, n + 1)]
    return trimesh.creation.revolve(np.array(points), sections=sections)


def scan_like_can(seed: int = 0) -> tuple[str, float]:
    """A soup can (r 3.3 cm, h 10 cm) as a scanner exports it.

    Small triangles (about 3 mm) in 10 pieces whose vertices are perturbed independently
    (0.15 mm noise: the pieces no longer meet, hair cracks along every piece border),
    two small holes (about 4 mm) where faces are missing, a textured OBJ (UV seams), a
    stray closed blob and an open flap inside the can.
    """
    rng = np.random.default_rng(seed)
    r, h = 0.033, 0.1
    fine = _lathe([(0, 0), (r, 0), (r, h), (0, h)], step=0.003, sections=72)
    true_volume = float(fine.volume)
    centers = fine.triangles_center
    # pieces: 8 sectors of the side, the two lids
    sector = np.floor((np.arctan2(centers[:, 1], centers[:, 0]) + np.pi) / (2 * np.pi) * 8).astype(int) % 8
    piece = np.where(np.abs(fine.face_normals[:, 2]) > 0.9, 8 + (centers[:, 2] > h / 2), sector)
    holes = np.array([[r, 0.0, 0.03], [0.0, 0.01, h]])
    keep = np.ones(len(fine.faces), bool)
    for c in holes:
        keep &= np.linalg.norm(centers - c, axis=1) > 0.002
    assert (~keep).sum() >= 4
    # every piece gets its own vertices, each perturbed on its own
    verts, faces, groups = [], [], []
    offset = 0
    for p in range(10):
        sel = np.flatnonzero((piece == p) & keep)
        used, inverse = np.unique(fine.faces[sel], return_inverse=True)
        verts.append(fine.vertices[used] + rng.normal(0, 0.00015, (len(used), 3)))
        faces.append(inverse.reshape(-1, 3) + offset)
        groups.append(np.full(len(sel), p))
        offset += len(used)
    blob = trimesh.creation.icosphere(subdivisions=1, radius=0.008)
    flap = trimesh.creation.box(extents=(0.02, 0.02, 0.0)).subdivide()  # an open sheet
    flap = trimesh.Trimesh(flap.vertices, flap.faces[: len(flap.faces) // 2])
    for extra, gid, shift in ((blob, 10, (0.01, 0, 0.07)), (flap, 11, (-0.01, 0.005, 0.03))):
        verts.append(extra.vertices + shift)
        faces.append(extra.faces + offset)
        groups.append(np.full(len(extra.faces), gid))
        offset += len(extra.vertices)
    mesh = trimesh.Trimesh(np.vstack(verts), np.vstack(faces), process=False)
    return obj_with_face_uvs(mesh, np.concatenate(groups)), true_volume


def mug(wall: float = 0.005, holes: bool = True) -> tuple[str, float]:
    """An open-top mug: r 4 cm, h 10 cm, ``wall`` thick sides, 8 mm base; a textured OBJ.

    With ``holes``, the three faces nearest to two points of the outer wall are missing
    (holes about 4 mm wide with five edges, which trimesh's hole filling leaves open), so
    the mesh stays open after merging. The true volume is its walls plus base.
    """
    r, h, base = 0.04, 0.1, 0.008
    body = _lathe([(0, 0), (r, 0), (r, h), (r - wall, h), (r - wall, base), (0, base)], step=0.004, sections=64)
    true_volume = float(body.volume)
    if holes:
        body = _without_faces_near(body, np.array([[r, 0, 0.03], [0, -r, 0.07]]), count=3)
    return obj_with_face_uvs(body), true_volume


def far_apart_bodies() -> tuple[str, float]:
    """Two closed boxes (4 cm) 10 cm apart, textured OBJ: two objects, not one."""
    a = trimesh.creation.box(extents=(0.04, 0.04, 0.04))
    b = trimesh.creation.box(extents=(0.04, 0.04, 0.04)).apply_translation((0.14, 0, 0))
    both = trimesh.util.concatenate([a, b])
    return obj_with_face_uvs(both), float(both.volume)
