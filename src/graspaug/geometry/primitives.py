"""Procedural objects: random assemblies of a few primitives (box, cylinder, sphere, capsule, ring), one solid.

The ``primitives`` pool's shapes, independent of any real shape: the kind of training object procedural
grasping datasets use. An assembly is 1 … ``max_parts`` primitives, each at a random orientation, the first at
the origin and each next one centred within 0.6 of the bounding radius of an earlier one (usually touching it;
a ring's hole or a thin part can leave it detached). Its solid is the union of the parts, ``min`` of their exact
signed distances sampled on a grid of ``resolution`` cells along the largest side of the box around the parts'
bounding spheres, meshed by marching cubes at 0 (faces at sub-cell positions, so a box's faces stay flat), cut to
its largest piece (a detached part holding under 10% of the volume is dropped, more rejects the assembly),
decimated towards a face budget and sized by the ingest rule.

Each part's size is drawn in units of the assembly (the sizing fixes metres afterwards):

=========  ==============================================  ==========================
kind       size (3,)                                       local frame
=========  ==============================================  ==========================
box        half extents, each U(0.1, 0.5)                  centred
cylinder   radius U(0.1, 0.4), half height U(0.1, 0.5), 0  axis z
sphere     radius U(0.15, 0.4), 0, 0                       centred
capsule    radius U(0.08, 0.3), half length U(0.1, 0.4), 0 axis z, hemispherical ends
ring       major radius U(0.2, 0.4), minor 0.2–0.45 × it   a torus around z
=========  ==============================================  ==========================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh
from scipy.spatial.transform import Rotation

from graspaug.geometry.fields import decimate, largest_piece, surface_from_field
from graspaug.geometry.normalize import normalization
from graspaug.geometry.settings import PrimitiveSettings

KINDS = ("box", "cylinder", "sphere", "capsule", "ring")
PAD_CELLS = 2  # samples beyond the assembly's bounds on every side: the field is positive on the border
MAX_DROPPED = 0.1  # an assembly whose largest piece misses more than this share of its volume is rejected


@dataclass(frozen=True)
class Primitive:
    """One part: ``kind`` (of :data:`KINDS`), ``size`` (3,) (module docstring), ``rotation`` (3, 3) from its local
    frame to the assembly's, ``center`` (3,) in the assembly's frame (assembly units)."""

    kind: str
    size: np.ndarray
    rotation: np.ndarray
    center: np.ndarray

    @property
    def radius(self) -> float:
        """Radius of a sphere around the centre that holds the part."""
        a, b, _ = self.size
        return {
            "box": float(np.linalg.norm(self.size)),
            "cylinder": float(np.hypot(a, b)),
            "sphere": float(a),
            "capsule": float(a + b),
            "ring": float(a + b),
        }[self.kind]


def primitive_distance(points: np.ndarray, part: Primitive) -> np.ndarray:
    """Signed distance (n,) from ``points`` (n, 3) to ``part``'s surface, negative inside (assembly units)."""
    q = (points - part.center) @ part.rotation  # into the part's frame
    a, b, c = part.size
    if part.kind == "box":
        d = np.abs(q) - part.size
        return np.linalg.norm(np.maximum(d, 0), axis=1) + np.minimum(d.max(axis=1), 0)
    if part.kind == "sphere":
        return np.linalg.norm(q, axis=1) - a
    radial = np.hypot(q[:, 0], q[:, 1])
    if part.kind == "cylinder":
        d = np.stack([radial - a, np.abs(q[:, 2]) - b], axis=1)
        return np.linalg.norm(np.maximum(d, 0), axis=1) + np.minimum(d.max(axis=1), 0)
    if part.kind == "capsule":
        return np.hypot(radial, q[:, 2] - np.clip(q[:, 2], -b, b)) - a
    if part.kind == "ring":
        return np.hypot(radial - a, q[:, 2]) - b
    raise ValueError(f"unknown primitive kind {part.kind!r}; expected one of {KINDS}")


def random_part(rng: np.random.Generator, kind: str, center: np.ndarray) -> Primitive:
    """A part of ``kind`` with a random size (module docstring table) and orientation, centred at ``center``."""
    u = rng.uniform
    size = {
        "box": lambda: u(0.1, 0.5, 3),
        "cylinder": lambda: np.array([u(0.1, 0.4), u(0.1, 0.5), 0.0]),
        "sphere": lambda: np.array([u(0.15, 0.4), 0.0, 0.0]),
        "capsule": lambda: np.array([u(0.08, 0.3), u(0.1, 0.4), 0.0]),
        "ring": lambda: (lambda major: np.array([major, major * u(0.2, 0.45), 0.0]))(u(0.2, 0.4)),
    }[kind]()
    return Primitive(kind, size, Rotation.random(random_state=rng).as_matrix(), np.asarray(center, float))


def random_assembly(rng: np.random.Generator, settings: PrimitiveSettings) -> list[Primitive]:
    """1 … ``settings.max_parts`` parts of ``settings.kinds`` drawn from ``rng`` (module docstring)."""
    parts: list[Primitive] = []
    for _ in range(int(rng.integers(1, settings.max_parts + 1))):
        center = np.zeros(3)
        if parts:
            anchor = parts[int(rng.integers(len(parts)))]
            direction = rng.normal(size=3)
            center = anchor.center + direction / np.linalg.norm(direction) * anchor.radius * rng.uniform(0.0, 0.6)
        parts.append(random_part(rng, settings.kinds[int(rng.integers(len(settings.kinds)))], center))
    return parts


def assembly_field(parts: list[Primitive], resolution: int) -> tuple[np.ndarray, np.ndarray, float]:
    """The union's signed distance sampled on a grid around the parts' bounding spheres.

    Returns (field (a, b, c) float32, assembly units, negative inside; origin (3,) of sample (0, 0, 0); pitch)."""
    from graspaug.geometry.fields import grid_around

    low = np.min([p.center - p.radius for p in parts], axis=0)
    high = np.max([p.center + p.radius for p in parts], axis=0)
    origin, pitch, shape = grid_around(np.stack([low, high]), resolution, PAD_CELLS)
    axes = [origin[i] + pitch * np.arange(shape[i]) for i in range(3)]
    points = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    field = np.min([primitive_distance(points, p) for p in parts], axis=0)
    return field.reshape(shape).astype(np.float32), origin, pitch


def assembly_mesh(
    parts: list[Primitive], resolution: int, size_rule: str, size_m: float, face_budget: int
) -> tuple[trimesh.Trimesh | None, str | None]:
    """The closed surface of ``parts``' union (``resolution`` cells along the largest side of the box around the
    parts' bounding spheres), decimated towards ``face_budget`` faces, sized so its ``size_rule`` extent is
    ``size_m`` m, centred on its centre of mass.

    Returns (mesh, None), or (None, reason) when the union is not one closed solid."""
    field, origin, pitch = assembly_field(parts, resolution)
    mesh, dropped = largest_piece(surface_from_field(field, origin, pitch))
    if dropped > MAX_DROPPED:
        return None, f"in pieces: {dropped:.0%} of the volume outside the largest piece"
    mesh = decimate(decimate(mesh, face_budget), face_budget)  # a second pass reaches the budget more often
    if not mesh.is_watertight or mesh.volume <= 0:
        return None, "not a closed solid"
    return normalization(mesh, size_rule, size_m).apply(mesh), None
