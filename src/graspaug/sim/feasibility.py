"""Which objects a parallel jaw can hold, from geometry alone (never from a pick outcome).

An object is dropped onto the table and rests in one of its stable poses (:func:`graspaug.render.stable_poses`,
each with its landing probability). In a pose a top-down parallel jaw can take it where some horizontal width of
it fits the jaw's opening with a margin on each side (the least caliper width of its outline seen from above) and
it stands tall enough that the fingertips, reaching past a grasp center at half its height, stay off the table.
The object's feasibility is the share of its landing probability in such poses; it is ``feasible`` where that
share is at least one half. A round object whose stable poses hold little probability (a ball rolls: its hull has
no face it stays on) is judged over seeded uniformly random orientations instead, as it lands.
"""

from __future__ import annotations

import numpy as np
import trimesh
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from graspaug.render.stable_poses import stable_poses

#: Random orientations a round object is judged over (seeded: the same every run).
ROUND_ORIENTATIONS = 64


def least_width(points: np.ndarray) -> float:
    """The least caliper width (m) of 2-D ``points`` (N, 2): the narrowest a parallel jaw closes across them."""
    hull = points[ConvexHull(points).vertices]
    edges = np.roll(hull, -1, axis=0) - hull
    normals = np.stack([-edges[:, 1], edges[:, 0]], axis=1) / np.linalg.norm(edges, axis=1, keepdims=True)
    spans = hull @ normals.T
    return float(np.min(spans.max(axis=0) - spans.min(axis=0)))


def pose_fits(vertices: np.ndarray, rotation: np.ndarray, opening: float, min_height: float) -> tuple[bool, float]:
    """Whether the hull ``vertices`` (N, 3) m, turned by ``rotation`` (3, 3) onto the table, fit a jaw of
    ``opening`` m (some horizontal width at most that) and stand at least ``min_height`` m tall; and the width."""
    turned = vertices @ rotation.T
    width = least_width(turned[:, :2])
    height = float(np.ptp(turned[:, 2]))
    return bool(width <= opening and height >= min_height), width


def feasibility(mesh: trimesh.Trimesh, max_width: float, margin: float = 0.005, min_height: float = 0.015) -> dict:
    """How well a parallel jaw of opening ``max_width`` m can hold ``mesh`` (m) as it lands on a table:
    ``share`` of its landing probability in poses where a horizontal width fits ``max_width`` − 2 ``margin`` and it
    stands ``min_height`` tall (the fingertips past a grasp center at half height stay off the table),
    ``feasible`` (share ≥ 0.5), ``poses`` (how many poses were judged) and ``round`` (judged over random
    orientations: its stable poses hold under half its landing probability)."""
    vertices = np.asarray(mesh.convex_hull.vertices, dtype=float)
    opening = max_width - 2 * margin
    poses = stable_poses(mesh)
    if len(poses) and poses.probabilities.sum() >= 0.5:
        fits = [pose_fits(vertices, t[:3, :3], opening, min_height)[0] for t in poses.transforms]
        share = float(np.sum(poses.probabilities[fits]) / np.sum(poses.probabilities))
        judged, round_ = len(poses), False
    else:
        rotations = Rotation.random(ROUND_ORIENTATIONS, random_state=0).as_matrix()
        share = float(np.mean([pose_fits(vertices, r, opening, min_height)[0] for r in rotations]))
        judged, round_ = ROUND_ORIENTATIONS, True
    return {"share": share, "feasible": share >= 0.5, "poses": judged, "round": round_}
