"""Dex-Net's antipodal grasp sampler on a closed mesh (lengths in meters).

Per round: sample up to ``max_surface_points`` surface points (area-weighted), draw
``tries_per_point`` grasp axes inside each point's friction cone, find the opposite contact
with the jaw that closes from ``max_width`` away, re-find both contacts as the closing jaws
meet the surface, keep grasps whose contacts are far enough apart and in force closure, drop
grasps whose centers are closer than ``coverage_dist`` to a kept one; oversample
×``oversample`` and double that every round until ``n_grasps`` are kept or ``max_rounds``
have run, then shuffle and truncate.

Unlike Dex-Net, surface points come from the exact mesh surface rather than SDF grid cells
(so no point jitter is needed), contact normals are the hit triangles' normals rather than
SDF gradients, and axes are not flipped at random: Dex-Net flips because SDF gradients can
point the wrong way, while the normals of our closed, outward-oriented meshes cannot.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from graspaug.grasping.contacts import close_fingers, first_entries
from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.grasping.quality import contact_frames
from graspaug.grasping.settings import AntipodalSettings


@dataclass(frozen=True)
class Grasps:
    """N parallel-jaw grasps: ``center`` (N, 3) m, unit ``axis`` (N, 3) from jaw 1 to jaw 2,
    contacts ``p1, p2`` (N, 3) m with outward normals ``n1, n2`` (N, 3), and ``width`` (N,) m,
    the distance between the contacts."""

    center: np.ndarray
    axis: np.ndarray
    p1: np.ndarray
    n1: np.ndarray
    p2: np.ndarray
    n2: np.ndarray
    width: np.ndarray

    def __len__(self) -> int:
        return len(self.center)

    def take(self, index: np.ndarray) -> Grasps:
        return Grasps(*(getattr(self, f)[index] for f in self.__dataclass_fields__))

    @staticmethod
    def concatenate(parts: list[Grasps]) -> Grasps:
        return Grasps(*(np.concatenate([getattr(p, f) for p in parts]) for f in Grasps.__dataclass_fields__))

    @staticmethod
    def empty() -> Grasps:
        return Grasps(*(np.zeros((0, 3)) for _ in range(6)), np.zeros(0))


def force_closure(p1: np.ndarray, n1: np.ndarray, p2: np.ndarray, n2: np.ndarray, friction_coef: float) -> np.ndarray:
    """Dex-Net's two-contact force-closure test (N,) bool: the line between the contacts lies
    within ``arctan(μ)`` of both inward normals (``n1, n2`` are outward unit normals)."""
    line = p2 - p1
    length = np.linalg.norm(line, axis=1)
    ok = length > 0
    limit = np.arctan(friction_coef)
    for normal in (n1, n2):
        cos = np.abs(np.einsum("ij,ij->i", -normal, line)) / np.where(ok, length, 1.0)
        ok &= np.arccos(np.clip(cos, -1.0, 1.0)) <= limit
    return ok


def _candidates(
    mesh: trimesh.Trimesh,
    gripper: ParallelJawGripper,
    settings: AntipodalSettings,
    n_points: int,
    rng: np.random.Generator,
) -> Grasps:
    """One sampling round: up to ``n_points · tries_per_point`` grasps that pass every test."""
    points, faces = trimesh.sample.sample_surface(mesh, n_points, seed=rng)
    points = np.repeat(points, settings.tries_per_point, axis=0)
    normals = np.repeat(mesh.face_normals[faces], settings.tries_per_point, axis=0)
    t1, t2 = contact_frames(-normals)
    # Axis in the friction cone: r = μ U(0,1), θ = U(0, 2π), axis = -(n + r cosθ t1 + r sinθ t2).
    r = settings.friction_coef * rng.random(len(points))
    theta = 2 * np.pi * rng.random(len(points))
    axis = -(normals + (r * np.cos(theta))[:, None] * t1 + (r * np.sin(theta))[:, None] * t2)
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    # The opposite jaw closes from max_width away along -axis and stops at the first surface.
    far, _, hit = first_entries(mesh, points + gripper.max_width * axis, -axis, gripper.max_width)
    keep = hit & (np.einsum("ij,ij->i", np.nan_to_num(far - points), axis) >= settings.min_contact_dist)
    center = 0.5 * (points[keep] + far[keep])
    axis = axis[keep]
    contacts = close_fingers(mesh, center, axis, gripper.max_width)
    width = np.linalg.norm(contacts.p2 - contacts.p1, axis=1)
    ok = contacts.found & (width >= max(settings.min_contact_dist, gripper.min_width))
    ok[ok] = force_closure(contacts.p1[ok], contacts.n1[ok], contacts.p2[ok], contacts.n2[ok], settings.friction_coef)
    return Grasps(center[ok], axis[ok], contacts.p1[ok], contacts.n1[ok], contacts.p2[ok], contacts.n2[ok], width[ok])


def _spread(grasps: Grasps, kept_centers: np.ndarray, min_dist: float) -> np.ndarray:
    """Indices of ``grasps`` kept greedily so that no two centers (nor one and a
    ``kept_centers`` row) are closer than ``min_dist`` m."""
    if min_dist <= 0:
        return np.arange(len(grasps))
    chosen: list[int] = []
    taken = list(kept_centers)
    for i, c in enumerate(grasps.center):
        if not taken or np.min(np.linalg.norm(np.asarray(taken) - c, axis=1)) >= min_dist:
            chosen.append(i)
            taken.append(c)
    return np.array(chosen, dtype=np.int64)


def sample_antipodal_grasps(
    mesh: trimesh.Trimesh, gripper: ParallelJawGripper, settings: AntipodalSettings, rng: np.random.Generator
) -> Grasps:
    """Up to ``settings.n_grasps`` antipodal grasps on the closed ``mesh`` (fewer, maybe none,
    if the rounds run out: e.g. an object wider than the gripper everywhere)."""
    kept: list[Grasps] = []
    n_kept = 0
    multiplier = settings.oversample
    for _ in range(settings.max_rounds):
        remaining = settings.n_grasps - n_kept
        if remaining <= 0:
            break
        n_points = min(settings.max_surface_points, int(np.ceil(multiplier * remaining / settings.tries_per_point)))
        new = _candidates(mesh, gripper, settings, n_points, rng)
        kept_centers = np.concatenate([g.center for g in kept]) if kept else np.zeros((0, 3))
        new = new.take(_spread(new, kept_centers, settings.coverage_dist))
        kept.append(new)
        n_kept += len(new)
        multiplier *= 2
    grasps = Grasps.concatenate(kept) if kept else Grasps.empty()
    order = rng.permutation(len(grasps))[: settings.n_grasps]
    return grasps.take(order)
