"""Objects for the simulated trials: the everyday objects of ``pybullet_data`` and held-out test
shapes, as meshes in meters with a cached convex decomposition for collisions.

Every object is a visual mesh (what the camera sees) plus its convex decomposition by pybullet's
V-HACD (what collides); the decomposition is cached per mesh under the cache folder, keyed by the
SHA-256 of the mesh file and the V-HACD resolution, so it runs once per machine.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import pybullet
import pybullet_data
import trimesh

from graspaug.sim.catalog import EVERYDAY_OBJECTS


@dataclass(frozen=True)
class SimObject:
    """One graspable object: ``visual`` and ``collision`` are .obj files in meters (the collision
    file holds one ``o`` group per convex hull); ``mass`` kg; frictions dimensionless."""

    name: str
    visual: Path
    collision: Path
    mass: float
    lateral_friction: float
    spinning_friction: float = 0.001
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


def convex_decomposition(mesh_file: Path, cache_dir: Path, resolution: int = 100_000) -> Path:
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
    root = os.environ.get("GRASPAUG_CACHE") or Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "graspaug"
    return Path(root) / "sim"


def prepare_object(name: str, mesh: trimesh.Trimesh, cache_dir: Path, mass: float, lateral_friction: float,
                   resolution: int = 100_000) -> SimObject:
    """Write ``mesh`` (m) to the cache as ``<name>-<sha256>.obj``, decompose it, and return the
    :class:`SimObject` for the trials. The mesh is centered on its center of mass when it is a
    closed volume, else on its bounding-box center (several pybullet_data meshes are open); the
    body's center of mass is that origin."""
    mesh = mesh.copy()
    mesh.apply_translation(-mesh.center_mass if mesh.is_volume else -mesh.bounds.mean(axis=0))
    cache_dir = Path(cache_dir)
    cache_dir.mkdir(parents=True, exist_ok=True)
    data = trimesh.exchange.obj.export_obj(mesh, include_normals=False, include_texture=False)
    visual = cache_dir / f"{name}-{hashlib.sha256(data.encode()).hexdigest()[:16]}.obj"
    if not visual.exists():
        fd, tmp = tempfile.mkstemp(suffix=".obj", dir=cache_dir)
        with os.fdopen(fd, "w") as f:
            f.write(data)
        os.replace(tmp, visual)
    return SimObject(name=name, visual=visual, collision=convex_decomposition(visual, cache_dir, resolution),
                     mass=mass, lateral_friction=lateral_friction)
