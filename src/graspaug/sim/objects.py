"""Objects for the simulated trials: the everyday objects of ``pybullet_data``, held-out test
shapes and the meshes of a user's folder, as meshes in meters with a cached convex
decomposition for collisions, and each object's mass and friction drawn from a seed
(:func:`prepare_objects`: the same body for a name and seed in every stage that picks it).

Every object is a visual mesh (what the camera sees) plus its convex decomposition by pybullet's
V-HACD (what collides); the decomposition is cached per mesh under the cache folder, keyed by the
SHA-256 of the mesh file and the V-HACD resolution, so it runs once per machine.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import logging
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pybullet
import pybullet_data
import trimesh

from graspaug.errors import DataError
from graspaug.rng import shape_rng
from graspaug.sim.catalog import EVERYDAY_OBJECTS
from graspaug.sim.settings import ObjectPhysics

log = logging.getLogger(__name__)

MESH_SUFFIXES = (".obj", ".stl", ".ply")  # what a user's object folder may hold


@dataclass(frozen=True)
class SimObject:
    """One graspable object: ``visual`` and ``collision`` are .obj files in meters (the collision
    file holds one ``o`` group per convex hull); ``mass`` kg; frictions dimensionless."""

    name: str
    visual: Path
    collision: Path
    mass: float
    lateral_friction: float
    spinning_friction: float = 0.0
    rolling_friction: float = 0.0


def everyday_mesh(name: str) -> trimesh.Trimesh:
    """The catalog object ``name`` as a mesh in meters (its own frame, scaled)."""
    try:
        entry = EVERYDAY_OBJECTS[name]
    except KeyError:
        raise ValueError(f"unknown everyday object {name!r}; choose from {sorted(EVERYDAY_OBJECTS)}") from None
    mesh = trimesh.load(Path(pybullet_data.getDataPath()) / entry.mesh, force="mesh", process=True)
    mesh.apply_scale(entry.scale)
    return mesh


@contextlib.contextmanager
def _quiet_stdout():
    """Silence the C library's prints on file descriptor 1 (V-HACD reports every step)."""
    saved = os.dup(1)
    with open(os.devnull, "wb") as null:
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            os.dup2(saved, 1)
            os.close(saved)


def convex_decomposition(mesh_file: Path, cache_dir: Path, resolution: int = 4_000_000) -> Path:
    """The V-HACD decomposition of ``mesh_file`` (.obj, m), computed once and cached in
    ``cache_dir`` as ``<sha256>-<resolution>.obj`` (written atomically)."""
    digest = hashlib.sha256(Path(mesh_file).read_bytes()).hexdigest()[:20]
    out = Path(cache_dir) / f"{digest}-{resolution}.obj"
    if out.exists():
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    client = pybullet.connect(pybullet.DIRECT)
    fd, tmp = tempfile.mkstemp(suffix=".obj", dir=out.parent)
    os.close(fd)
    try:
        with _quiet_stdout():
            pybullet.vhacd(str(mesh_file), tmp, os.devnull, resolution=resolution, physicsClientId=client)
        if "\no " not in "\n" + Path(tmp).read_text():
            raise RuntimeError(f"V-HACD produced no convex hull for {mesh_file}")
        os.replace(tmp, out)
    finally:
        pybullet.disconnect(client)
        if os.path.exists(tmp):
            os.unlink(tmp)
    return out


def default_cache_dir() -> Path:
    """Where decompositions are cached: ``$GRASPAUG_CACHE`` or ``$XDG_CACHE_HOME/graspaug``
    (``~/.cache/graspaug``), subfolder ``sim``."""
    root = (
        os.environ.get("GRASPAUG_CACHE") or Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "graspaug"
    )
    return Path(root) / "sim"


def mesh_volume(mesh: trimesh.Trimesh) -> float:
    """Volume (m³) of a closed mesh, or of its convex hull when it is open."""
    return float(mesh.volume) if mesh.is_volume else float(mesh.convex_hull.volume)


def draw_physics(volume: float, settings: ObjectPhysics, rng: np.random.Generator) -> dict[str, float]:
    """One object's ``density`` (kg/m³, uniform in the range), ``mass`` (kg: density × ``volume``
    m³, clipped), ``lateral_friction`` (uniform in the range), ``spinning_friction`` and
    ``rolling_friction`` (m)."""
    density = float(rng.uniform(*settings.density_range))
    friction = float(rng.uniform(*settings.friction_range))
    mass = float(np.clip(density * volume, *settings.mass_range))
    return {
        "density": density,
        "mass": mass,
        "lateral_friction": friction,
        "spinning_friction": settings.spinning_friction,
        "rolling_friction": settings.rolling_friction,
    }


def folder_meshes(
    folder: Path, surface, max_faces: int = 1_000_000, max_file_mb: float = 100.0, label: str = "sim"
) -> tuple[list[tuple[str, trimesh.Trimesh]], dict[str, str]]:
    """The meshes (.obj, .stl, .ply) of ``folder``, named by file stem, each loaded, closed and
    scaled as the corpus's shapes are (:func:`graspaug.geometry.prepare.prepare_shape` with
    ``surface``, the ``ingest.surface`` settings), and {file name: reason} for those skipped.
    Raises ValueError (one line) when the folder is missing or holds no mesh file, or when no
    mesh survives. ``label`` starts each skipped file's warning (the command that reads the folder)."""
    from graspaug.geometry.loading import MeshRejected, load_shape
    from graspaug.geometry.prepare import prepare_shape

    folder = Path(folder)
    if not folder.is_dir():
        raise ValueError(f"sim.objects_path: {folder} is not a folder")
    files = sorted(p for p in folder.iterdir() if p.is_file() and p.suffix.lower() in MESH_SUFFIXES)
    if not files:
        raise ValueError(f"sim.objects_path: {folder} holds no mesh file ({', '.join(MESH_SUFFIXES)})")
    meshes, skipped = [], {}
    for path in files:
        try:
            meshes.append((path.stem, prepare_shape(load_shape(path, 1.0, max_faces, max_file_mb), surface).mesh))
        except (MeshRejected, OSError, ValueError) as exc:
            skipped[path.name] = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            log.warning("%s: skipping %s: %s", label, path, skipped[path.name])
    if not meshes:
        raise ValueError(
            f"sim.objects_path: no usable mesh in {folder} ({len(skipped)} skipped: "
            f"{'; '.join(f'{k}: {v}' for k, v in skipped.items())})"
        )
    return meshes, skipped


def body_origin(mesh: trimesh.Trimesh) -> np.ndarray:
    """Where a simulated object's body frame sits in its mesh's frame (3,) m: the center of mass of a
    closed volume, else the bounding-box center (several pybullet_data meshes are open)."""
    return np.asarray(mesh.center_mass if mesh.is_volume else mesh.bounds.mean(axis=0), dtype=float)


def prepare_object(
    name: str,
    mesh: trimesh.Trimesh,
    cache_dir: Path,
    mass: float,
    lateral_friction: float,
    resolution: int = 4_000_000,
    spinning_friction: float = 0.0,
    rolling_friction: float = 0.0,
) -> SimObject:
    """Write ``mesh`` (m) to the cache as ``<name>-<sha256>.obj``, decompose it, and return the
    :class:`SimObject` for the trials. The mesh is moved so that :func:`body_origin` is its
    origin; the body's center of mass is that origin."""
    mesh = mesh.copy()
    mesh.apply_translation(-body_origin(mesh))
    cache_dir = Path(cache_dir)
    cache_dir.mkdir(parents=True, exist_ok=True)
    data = trimesh.exchange.obj.export_obj(mesh, include_normals=False, include_texture=False)
    visual = cache_dir / f"{name}-{hashlib.sha256(data.encode()).hexdigest()[:16]}.obj"
    if not visual.exists():
        fd, tmp = tempfile.mkstemp(suffix=".obj", dir=cache_dir)
        with os.fdopen(fd, "w") as f:
            f.write(data)
        os.replace(tmp, visual)
    return SimObject(
        name=name,
        visual=visual,
        collision=convex_decomposition(visual, cache_dir, resolution),
        mass=mass,
        lateral_friction=lateral_friction,
        spinning_friction=spinning_friction,
        rolling_friction=rolling_friction,
    )


@dataclass(frozen=True)
class PreparedObject:
    """An object of the trials: its name, kind, physics body, extents (3,) m and drawn density (kg/m³)."""

    name: str
    kind: str
    body: SimObject
    extents: tuple[float, float, float]
    density: float


def _prepare_one(item: tuple, physics, seed: int, vhacd_resolution: int, cache: Path) -> PreparedObject:
    name, kind, mesh = item
    drawn = draw_physics(mesh_volume(mesh), physics, shape_rng(seed, name, "sim-physics"))
    body = prepare_object(
        name,
        mesh,
        cache,
        drawn["mass"],
        drawn["lateral_friction"],
        vhacd_resolution,
        drawn["spinning_friction"],
        drawn["rolling_friction"],
    )
    return PreparedObject(name, kind, body, tuple(float(x) for x in mesh.extents), drawn["density"])


def prepare_objects(
    everyday: Sequence[str],
    test_shapes: Sequence[str],
    shapes_dir: Path,
    physics,
    seed: int,
    vhacd_resolution: int,
    user_meshes: Sequence[tuple[str, object]] = (),
    cache_dir: Path | None = None,
    workers=1,
) -> list[PreparedObject]:
    """Every object of the trials (everyday, test shapes read from the mesh folder ``shapes_dir``,
    the user's meshes), decompositions cached (computed on ``workers``, a process count or
    :class:`graspaug.parallel.Workers`), with mass and friction drawn per object from ``physics``
    (``sim.physics``) and the global ``seed`` (the same for every arm)."""
    from graspaug.io.meshes import mesh_path, read_mesh
    from graspaug.parallel import parallel_map

    cache = default_cache_dir() if cache_dir is None else Path(cache_dir)
    meshes = [(name, "everyday", everyday_mesh(name)) for name in everyday]
    meshes += [(shape_id, "test_shape", read_mesh(mesh_path(shapes_dir, shape_id))) for shape_id in test_shapes]
    meshes += [(name, "user", mesh) for name, mesh in user_meshes]
    names = [name for name, _, _ in meshes]
    if len(set(names)) != len(names):
        raise DataError(
            f"sim: two objects share a name: {sorted({n for n in names if names.count(n) > 1})} "
            "(rename the user's mesh files)"
        )
    work = functools.partial(_prepare_one, physics=physics, seed=seed, vhacd_resolution=vhacd_resolution, cache=cache)
    return parallel_map(work, meshes, workers, "sim objects")


def collision_hulls(path: Path) -> list[trimesh.Trimesh]:
    """The convex hulls of a decomposition file (.obj, one ``o`` group per hull, vertices numbered across the
    file), each as a closed convex mesh (m)."""
    vertices, groups = [], []
    for line in Path(path).read_text().splitlines():
        if line.startswith("v "):
            vertices.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("o ") or (line.startswith("f ") and not groups):
            groups.append([])
        if line.startswith("f "):
            groups[-1].extend(int(tok.split("/")[0]) - 1 for tok in line.split()[1:])
    points = np.asarray(vertices, dtype=float)
    return [trimesh.convex.convex_hull(points[sorted(set(g))]) for g in groups if len(set(g)) >= 4]


def hull_offset(mesh: trimesh.Trimesh, hulls: Sequence[trimesh.Trimesh], n: int = 20_000, seed: int = 0) -> dict:
    """How far a collision shape (the union of ``hulls``) lies outside the visual ``mesh`` (both m, one frame):
    points sampled on the hulls' surfaces by area, those inside another hull dropped (they are not on the union's
    surface), each one's distance outside the mesh (0 inside); ``median`` and ``p90`` of those distances, and
    ``box``: the largest growth of the axis-aligned bounding box on any side (what a jaw closing across feels)."""
    rng = np.random.default_rng(seed)
    areas = np.array([h.area for h in hulls])
    counts = rng.multinomial(n, areas / areas.sum())
    seeds = rng.integers(2**31, size=len(hulls))
    points = np.concatenate(
        [trimesh.sample.sample_surface(h, k, seed=int(s))[0] for h, k, s in zip(hulls, counts, seeds)]
    )
    owner = np.repeat(np.arange(len(hulls)), counts)
    outer = np.ones(len(points), dtype=bool)
    for i, h in enumerate(hulls):
        inside = h.contains(points) if len(hulls) > 1 else np.zeros(len(points), dtype=bool)
        outer &= ~(inside & (owner != i))
    points = points[outer]
    outside = np.clip(-trimesh.proximity.signed_distance(mesh, points), 0.0, None)
    low = np.min([h.bounds[0] for h in hulls], axis=0)
    high = np.max([h.bounds[1] for h in hulls], axis=0)
    growth = np.concatenate([mesh.bounds[0] - low, high - mesh.bounds[1]])
    return {
        "median": float(np.median(outside)),
        "p90": float(np.percentile(outside, 90)),
        "box": float(growth.max()),
        "hulls": len(hulls),
    }
