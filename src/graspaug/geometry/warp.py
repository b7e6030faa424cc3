"""New shapes from one real shape with no network: a random smooth deformation of its surface.

The ``warp`` pool's augmentation, the handcrafted kind a researcher tries before training a generator
("shifting, scaling and rotating", and a little more). In a randomly rotated frame of the shape
(centre of mass at the origin, m) a point ``p = (x, y, z)`` goes through, in order:

1. an anisotropic scale ``diag(s)``, each ``s_i`` log-uniform in ``[1 / scale, scale]``;
2. a shear ``x += k_x z``, ``y += k_y z``, each ``k`` uniform in ``[-shear, shear]``;
3. a taper along z: ``x, y *= 1 + t z' / h`` with ``z'`` measured from the middle of the z range and ``h`` half
   that range, ``t`` uniform in ``[-taper, taper]``;
4. a bend of the z axis in the xz plane through ``φ`` uniform in ``[-bend, bend]`` degrees over the shape's
   largest extent ``L`` (curvature ``κ = φ / L``; with φ ≤ 45° the bending radius stays above ``L``, so no fold).

Every step is a smooth one-to-one map, so a closed surface stays closed and its flat faces stay flat
under steps 1–2 (the steps a grasp is most sensitive to keep). Steps 3–4 bend faces; the surface is
subdivided first so a face bends with its vertices, then decimated back to its face budget. The result
is sized by the ingest rule (one extent set to a length) and centred on its centre of mass.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from graspaug.geometry.fields import decimate
from graspaug.geometry.normalize import normalization
from graspaug.geometry.settings import WarpSettings

SUBDIVISIONS_PER_EXTENT = 16  # a bent or tapered surface is subdivided to edges ≤ its largest extent / this


@dataclass(frozen=True)
class Warp:
    """One deformation (module docstring), in the frame ``rotation`` (3, 3) maps the shape into.

    scale : (3,) — factors along the frame's axes
    shear : (2,) — ``k_x``, ``k_y``: x and y move by ``k z``
    taper : float — ``t``: x and y scale by ``1 + t z' / h`` (z' from the middle of the z range, h half of it)
    bend_deg : float — ``φ``: the z axis bends through this angle over the largest extent, degrees
    """

    rotation: np.ndarray
    scale: np.ndarray
    shear: np.ndarray
    taper: float
    bend_deg: float

    @staticmethod
    def identity() -> Warp:
        return Warp(np.eye(3), np.ones(3), np.zeros(2), 0.0, 0.0)

    @property
    def smooth(self) -> bool:
        """Whether the warp bends faces (taper or bend), so the surface must be subdivided first."""
        return self.taper != 0.0 or self.bend_deg != 0.0


def random_warp(rng: np.random.Generator, settings: WarpSettings) -> Warp:
    """A :class:`Warp` drawn from ``rng`` within ``settings``' ranges (a random rotation of the frame)."""
    rotation = Rotation.random(random_state=rng).as_matrix()
    log_scale = np.log(settings.scale)
    return Warp(
        rotation,
        np.exp(rng.uniform(-log_scale, log_scale, 3)),
        rng.uniform(-settings.shear, settings.shear, 2),
        float(rng.uniform(-settings.taper, settings.taper)),
        float(rng.uniform(-settings.bend_deg, settings.bend_deg)),
    )


def warp_points(points: np.ndarray, warp: Warp) -> np.ndarray:
    """``points`` (n, 3) m, centred on the shape's centre of mass, warped (n, 3) m (module docstring)."""
    p = points @ warp.rotation.T * warp.scale
    x, y, z = p[:, 0] + warp.shear[0] * p[:, 2], p[:, 1] + warp.shear[1] * p[:, 2], p[:, 2]
    if warp.taper:
        half = max(0.5 * float(np.ptp(z)), 1e-12)
        factor = 1.0 + warp.taper * (z - 0.5 * (z.max() + z.min())) / half
        x, y = x * factor, y * factor
    if warp.bend_deg:
        length = float(np.ptp(np.stack([x, y, z]), axis=1).max())
        radius = length / np.radians(warp.bend_deg)  # signed: the side the axis bends to
        theta = z / radius
        x, z = radius - (radius - x) * np.cos(theta), (radius - x) * np.sin(theta)
    return np.stack([x, y, z], axis=1) @ warp.rotation


def warp_mesh(
    mesh: trimesh.Trimesh, warp: Warp, size_rule: str, size_m: float, face_budget: int
) -> tuple[trimesh.Trimesh | None, str | None]:
    """``mesh`` (closed, m) under ``warp``, sized so its ``size_rule`` extent is ``size_m`` m and centred on its
    centre of mass; after a smooth warp's subdivision, decimated towards ``face_budget`` faces (:func:`decimate`
    keeps the finer mesh when no decimation stays closed).

    Returns (mesh, None), or (None, reason) when the result is not a closed solid in one piece.
    """
    out = mesh.copy()
    center = out.center_mass
    if warp.smooth:
        edge = float(out.extents.max()) / SUBDIVISIONS_PER_EXTENT
        vertices, faces = trimesh.remesh.subdivide_to_size(out.vertices, out.faces, max_edge=edge)
        out = trimesh.Trimesh(vertices, faces, process=True)
    out = trimesh.Trimesh(warp_points(out.vertices - center, warp), out.faces, process=False)
    if warp.smooth:
        out = decimate(out, face_budget)
    if not out.is_watertight or out.volume <= 0:
        return None, "not a closed solid after warping"
    if out.body_count != 1:
        return None, f"in pieces after warping ({out.body_count})"
    return normalization(out, size_rule, size_m).apply(out), None
