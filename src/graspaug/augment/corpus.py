"""One source file → one row of the shape table (its mesh written), duplicates, and the train/test split."""

from __future__ import annotations

import os
import stat
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from graspaug.geometry.loading import MeshRejected, load_shape
from graspaug.geometry.prepare import SurfaceSettings, prepare_shape
from graspaug.geometry.voxelize import fit_grid, pack_bits, voxelize_solid
from graspaug.io.digest import sha256_of
from graspaug.io.meshes import mesh_path, write_mesh
from graspaug.io.sources import Source

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)


def file_problem(path: Path) -> str | None:
    """Why ``path`` cannot be read as a mesh file without opening it (None: a regular file,
    or a symlink to one): a broken or looping symlink, or a special file (FIFO, device, socket,
    directory), which could block or never end when read."""
    try:
        link = stat.S_ISLNK(os.lstat(path).st_mode)
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return (
            f"broken symlink: its target {os.readlink(path)} does not exist"
            if os.path.islink(path)
            else "file vanished"
        )
    except OSError as exc:
        return f"unreadable: {'symlink loop' if exc.errno == 40 else exc.strerror or exc}"
    if stat.S_ISREG(mode):
        return None
    kind = next((name for test, name in _KINDS if test(mode)), "not a regular file")
    return f"not a regular file: {'symlink to ' + kind + ' ' + os.path.realpath(path) if link else kind}"


#: Voxel IoU (32³) from which two shapes of equal extents are the same geometry (0.95 would pair distinct random_urdfs
#: plates).
NEAR_DUPLICATE_IOU = 0.99
NEAR_DUPLICATE_EXTENT = 0.001  # m: ... and their normalized extents differ by at most this


def occupancy_bits(mesh, resolution: int = 32) -> bytes:
    """The packed solid voxel grid (R³, fit to the bounds) of a normalized mesh."""
    grid = fit_grid(mesh.bounds, resolution)
    return pack_bits(voxelize_solid(np.asarray(mesh.vertices), np.asarray(mesh.faces), grid)).tobytes()


def _with_warnings(reason: str, caught: list) -> str:
    """The reason plus the distinct warnings raised while reading the file (at most two)."""
    messages = list(dict.fromkeys(f"{w.category.__name__}: {str(w.message).splitlines()[0][:80]}" for w in caught))
    return f"{reason} (warnings: {'; '.join(messages[:2])}{'; …' if len(messages) > 2 else ''})" if messages else reason


def occupied_voxels(mesh, resolution: int, margin: int) -> int:
    """Occupied voxels of ``mesh``'s solid grid as the ``voxelize`` stage builds it (R³ fit to the bounds with
    ``margin`` empty voxels): a thin shape (a fork's tines) can fill none at a coarse R."""
    grid = fit_grid(mesh.bounds, resolution, margin)
    return int(np.count_nonzero(voxelize_solid(np.asarray(mesh.vertices), np.asarray(mesh.faces), grid)))


def ingest_source(
    source: Source,
    max_faces: int,
    max_file_mb: float,
    settings: SurfaceSettings,
    out_dir: Path,
    voxel_grid: tuple[int, int] | None = None,
    min_voxels: int = 1,
) -> dict:
    """Process one source: a shapes row (``ok``) or a rejects row (``reason``). Symlinks to
    regular files are read; special files and broken links are rejected before opening.
    Warnings while reading go into the reason of a rejected file, never to the console.
    With ``voxel_grid`` (resolution R, margin in voxels of the voxelize stage), a shape whose solid grid
    holds fewer than ``min_voxels`` occupied voxels is rejected: the AutoEncoder would see it empty."""
    row: dict = {"shape_id": source.shape_id, "source": source.name}
    problem = file_problem(Path(source.path))
    if problem is not None:
        return {**row, "ok": False, "reason": problem}
    with warnings.catch_warnings(record=True) as caught, np.errstate(all="warn"):
        warnings.simplefilter("always")
        try:
            row["source_sha256"] = sha256_of(source.path)
            loaded = load_shape(source.path, source.unit_scale, max_faces, max_file_mb)
            prepared = prepare_shape(loaded, settings)
            row["_occupancy"] = occupancy_bits(prepared.mesh)
            if voxel_grid is not None:
                filled = occupied_voxels(prepared.mesh, *voxel_grid)
                if filled < min_voxels:
                    raise MeshRejected(
                        f"{'empty' if filled == 0 else 'nearly empty'} voxel grid: {filled} occupied voxels at "
                        f"{voxel_grid[0]}³ < min_voxels={min_voxels}"
                    )
        except MeshRejected as exc:
            return {**row, "ok": False, "reason": _with_warnings(str(exc), caught)}
        except OSError as exc:
            return {
                **row,
                "ok": False,
                "reason": _with_warnings(f"unreadable: {type(exc).__name__}: {exc.strerror or exc}", caught),
            }
    mesh, norm = prepared.mesh, prepared.normalization
    write_mesh(mesh, mesh_path(out_dir, source.shape_id))
    extents = mesh.extents
    return {
        **row,
        "ok": True,
        "faces": len(mesh.faces),
        "vertices": len(mesh.vertices),
        "watertight": bool(mesh.is_watertight),
        "volume": float(mesh.volume),
        "extent_x": float(extents[0]),
        "extent_y": float(extents[1]),
        "extent_z": float(extents[2]),
        # normalized = scale * (source file coordinates) + offset, meters
        "scale": source.unit_scale * norm.scale,
        "offset_x": float(norm.offset[0]),
        "offset_y": float(norm.offset[1]),
        "offset_z": float(norm.offset[2]),
        "n_parts": prepared.n_parts,
        "surface_resolution": prepared.resolution,
        "dropped_volume": prepared.dropped_volume,
        "closed_by": prepared.closed_by,  # as_is, merged (vertices merged by position) or filled (open mesh filled)
        "hull_fill": prepared.hull_fill,  # volume / convex-hull volume (a hollow shell shows as a small value)
    }


def flag_duplicates(shapes: pd.DataFrame, occupancy: list[bytes]) -> pd.DataFrame:
    """``shapes`` with ``duplicate_of`` (the shape_id, first in id order, of a shape with the
    same file bytes or the same normalized geometry; "" for none) and ``duplicate_kind``
    (``exact``: same ``source_sha256``; ``geometry``: normalized extents within 1 mm and
    solid voxel grids (32³, packed in ``occupancy``, one per row) with IoU >= 0.99)."""
    out = shapes.reset_index(drop=True).copy()
    if out.empty:
        return out.assign(duplicate_of=pd.Series(dtype=str), duplicate_kind=pd.Series(dtype=str))
    order = np.argsort(out["shape_id"].to_numpy(), kind="stable")
    extents = np.sort(out[["extent_x", "extent_y", "extent_z"]].to_numpy(float), axis=1)
    grids = np.stack([np.unpackbits(np.frombuffer(b, dtype=np.uint8)) for b in occupancy]).astype(bool)
    duplicate_of, kind = [""] * len(out), [""] * len(out)
    originals: list[int] = []  # rows that are nobody's duplicate, in id order
    first_by_hash: dict[str, int] = {}
    for row in order:
        original = first_by_hash.get(out.at[row, "source_sha256"])
        if original is not None:
            duplicate_of[row], kind[row] = out.at[original, "shape_id"], "exact"
            continue
        near = [o for o in originals if np.abs(extents[o] - extents[row]).max() <= NEAR_DUPLICATE_EXTENT]
        for o in near:
            union = np.count_nonzero(grids[o] | grids[row])
            if union and np.count_nonzero(grids[o] & grids[row]) / union >= NEAR_DUPLICATE_IOU:
                duplicate_of[row], kind[row] = out.at[o, "shape_id"], "geometry"
                break
        if not duplicate_of[row]:
            originals.append(row)
        first_by_hash.setdefault(
            out.at[row, "source_sha256"],
            row if not duplicate_of[row] else int(np.flatnonzero(out["shape_id"] == duplicate_of[row])[0]),
        )
    out["duplicate_of"], out["duplicate_kind"] = duplicate_of, kind
    return out


def split_seed(seed: int, data_seed: int, independent_draws: bool) -> int | list[int]:
    """The seed of the train/test split: ``seed``, or with ``independent_draws`` the pair (``seed``, ``data_seed``)
    (a NumPy seed sequence), a split of its own for every draw of the data."""
    return [seed, data_seed] if independent_draws else seed


def assign_split(
    shape_ids: list[str], test_fraction: float, seed: int | list[int], duplicate_of: dict[str, str] | None = None
) -> dict[str, str]:
    """Seeded shuffle of the sorted ids; the first ``round(test_fraction * n)`` are ``test``.
    A shape in ``duplicate_of`` (id → the id it duplicates) takes its original's split, so a
    duplicate never sits on the other side of the split (n counts originals only)."""
    duplicate_of = {k: v for k, v in (duplicate_of or {}).items() if v}
    ids = sorted(i for i in shape_ids if i not in duplicate_of)
    order = np.random.default_rng(seed).permutation(len(ids))
    n_test = int(round(test_fraction * len(ids)))
    split = {ids[i]: ("test" if rank < n_test else "train") for rank, i in enumerate(order)}
    return {i: split[duplicate_of.get(i, i)] for i in shape_ids}


def split_objects(objects: pd.DataFrame, test_fraction: float, seed: int | list[int]) -> pd.DataFrame:
    """The objects table (``shape_id``, ``duplicate_of``) with each object's ``split`` (:func:`assign_split` seeded
    by ``seed``, a :func:`split_seed`): the shape table the ``split`` stage writes."""
    duplicates = dict(zip(objects.shape_id, objects.duplicate_of))
    return objects.assign(
        split=objects.shape_id.map(assign_split(list(objects.shape_id), test_fraction, seed, duplicates))
    )


def closing_summary(shapes: pd.DataFrame) -> str:
    """One line on how the corpus was closed: counts of ``closed_by`` and the ``hull_fill`` spread."""
    closed = shapes["closed_by"].value_counts()
    lowest = shapes.loc[shapes["hull_fill"].idxmin()]
    return (
        f"closed_by as_is {closed.get('as_is', 0)}, merged {closed.get('merged', 0)}, filled "
        f"{closed.get('filled', 0)}; "
        f"hull_fill median {shapes['hull_fill'].median():.2f}, lowest {lowest['hull_fill']:.2f} ({lowest['shape_id']})"
    )


def reject_lines(rejects: pd.DataFrame, table: str | Path, limit: int = 10) -> list[str]:
    """Log lines naming each rejected file (``rejects``: the reject table, ``source`` and ``reason`` columns) with
    its reason, the first ``limit`` of them; then how many more and where every one is listed
    (``table``)."""
    lines = [f"rejected {row.source}: {row.reason}" for row in rejects.head(limit).itertuples()]
    if len(rejects) > limit:
        lines.append(f"... and {len(rejects) - limit} more, see {table}")
    return lines
