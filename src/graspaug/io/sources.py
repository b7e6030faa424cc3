"""Finding the source mesh files of a corpus.

A source is named portably: ``pybullet_data:random_urdfs/000/000.obj`` for files
that ship in pybullet's data package, ``folder:<path relative to the folder>``
for a user's mesh folder, so tables do not depend on where a venv lives.
"""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from graspaug.geometry.loading import MESH_SUFFIXES


@dataclass(frozen=True)
class Source:
    """One source file of the corpus.

    Attributes
    ----------
    shape_id : stable id, e.g. ``rnd_000``
    name : portable name of the file (see module doc)
    path : where the file is on this machine
    unit_scale : meters per file unit
    """

    shape_id: str
    name: str
    path: Path
    unit_scale: float


def pybullet_data_root() -> Path:
    """The folder of the ``pybullet_data`` package."""
    import pybullet_data

    return Path(pybullet_data.getDataPath())


def urdf_mesh(urdf: Path) -> tuple[Path, float]:
    """The collision mesh file of a one-link URDF and its (uniform) mesh scale."""
    root = ET.parse(urdf).getroot()
    mesh = root.find(".//collision/geometry/mesh")
    if mesh is None:
        mesh = root.find(".//geometry/mesh")
    if mesh is None:
        raise ValueError(f"{urdf}: no mesh geometry")
    scale = [float(s) for s in mesh.get("scale", "1 1 1").split()]
    if len(set(scale)) != 1:
        raise ValueError(f"{urdf}: non-uniform mesh scale {scale}")
    return urdf.parent / mesh.get("filename"), scale[0]


def pybullet_sources(limit: int | None = None) -> list[Source]:
    """The ``random_urdfs`` objects of pybullet_data, in numeric order, ids ``rnd_NNN``."""
    root = pybullet_data_root()
    out = []
    for urdf in sorted((root / "random_urdfs").glob("*/*.urdf")):
        path, scale = urdf_mesh(urdf)
        out.append(Source(f"rnd_{urdf.stem}", f"pybullet_data:{path.relative_to(root).as_posix()}", path, scale))
        if limit is not None and len(out) >= limit:
            break
    return out


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_").lower() or "shape"


#: The file that marks a cache folder (the Cache Directory Tagging convention, which backup tools honour too): a mesh
#: folder walk never enters a folder holding it, so a tool's cache inside a corpus (``graspaug evaluate``'s test sets,
#: meshes included) is never read as objects.
CACHE_TAG = "CACHEDIR.TAG"
CACHE_TAG_TEXT = "Signature: 8a477f597d28d172789f06886806bc55\n# graspaug's cache: its meshes are no corpus' objects\n"


def tag_cache(folder: str | Path) -> None:
    """Make ``folder`` (and its parents) and mark it a cache (:data:`CACHE_TAG`), so no corpus walk enters it."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if not (folder / CACHE_TAG).is_file():
        (folder / CACHE_TAG).write_text(CACHE_TAG_TEXT)


def portable_name(relative: str) -> str:
    """A file's path relative to its folder as text that any table can hold: bytes that are not UTF-8 (a name
    os.walk decoded with surrogate escapes) shown as ``\\xNN``."""
    return os.fsencode(relative).decode("utf-8", "backslashreplace")


def folder_sources(folder: str | Path, unit_scale: float = 1.0, limit: int | None = None) -> list[Source]:
    """Every mesh file under ``folder`` (recursively, any file name, folders tagged as caches skipped), sorted; ids
    from the relative path."""
    folder = Path(folder).resolve()
    if not folder.is_dir():
        raise FileNotFoundError(f"mesh folder not found: {folder}")
    # every entry with a mesh suffix, links and special files too (ingest reads or rejects each
    # with a reason); linked folders are not entered, nor caches
    files = []
    for root, dirs, names in os.walk(folder):
        dirs[:] = [d for d in dirs if not os.path.isfile(os.path.join(root, d, CACHE_TAG))]
        files += [
            Path(root, name)
            for name in [*names, *dirs]
            if Path(name).suffix.lower() in MESH_SUFFIXES
            and (name in names or os.path.islink(os.path.join(root, name)))
        ]
    files.sort()
    out, seen = [], set()
    for path in files:
        rel = portable_name(path.relative_to(folder).as_posix())
        shape_id = base = f"f_{_slug(rel.rsplit('.', 1)[0])}"
        n = 1
        while shape_id in seen:
            n += 1
            shape_id = f"{base}_{n}"
        seen.add(shape_id)
        out.append(Source(shape_id, f"folder:{rel}", path, unit_scale))
        if limit is not None and len(out) >= limit:
            break
    return out
