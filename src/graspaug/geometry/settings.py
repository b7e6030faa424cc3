"""Settings of the geometry library: rebuilding surfaces at ingest, meshing decoded grids."""

from __future__ import annotations

from typing import Literal

from graspaug.settings import Field, settings


@settings
class SurfaceSettings:
    """How the outer surface is rebuilt and sized (params section ``ingest.surface``)."""

    resolution: int = Field(
        96,
        ge=16,
        le=512,
        description=(
            "Marching-cubes samples along a shape's largest extent when its closed outer surface is rebuilt (cell = "
            "extent / resolution)."
        ),
    )
    finest_resolution: int = Field(
        160,
        ge=16,
        le=512,
        description=(
            "Upper limit of that resolution for shapes made of thin convex parts (lattices), which get a finer grid."
        ),
    )
    cells_per_thickness: float = Field(
        6.0,
        ge=0,
        description=(
            "Field cells across a typical (median) convex part; sets the finer grid for thin-part shapes (0: always "
            "resolution)."
        ),
    )
    face_budget: int = Field(5000, ge=100, description="Triangles per outer surface after quadric decimation.")
    size: Literal["normalize", "real", "fit"] = Field(
        "normalize",
        description=(
            "`normalize`: every shape is scaled so the size rule's extent is size_m (the default corpus' units are "
            "arbitrary); `real`: each shape keeps its size in the file (times data.unit_scale), and shapes the "
            "gripper cannot take (min_extent, max_width) are rejected; `fit`: as `real`, but a shape too wide for the "
            "gripper is scaled down (its shape kept, its scale in the shape table) until its narrowest side is 0.9 "
            "max_width; one it would scale by less than fit_min_scale is rejected (a unit mistake, or another "
            "object)."
        ),
    )
    fit_min_scale: float = Field(
        0.5,
        gt=0,
        le=1,
        description=(
            "With size `fit`: a shape it would scale by less than this is rejected, naming the likely unit mistake "
            "(millimetres read as metres shrink by 0.001); a corpus of large real objects meant to be shrunk (the "
            "real_objects profile) lowers it."
        ),
    )
    min_extent: float = Field(
        0.01,
        gt=0,
        description="With size `real` or `fit`: a shape whose largest extent is below this (m) is rejected as too "
        "small.",
    )
    max_width: float = Field(
        0.08,
        gt=0,
        description=(
            "With size `real`: a shape whose oriented bounding box's smallest side exceeds this (m) is rejected "
            "(`fit`: scaled down), as no parallel-jaw grasp fits across it (the Franka Panda's opening, "
            "grasps.gripper.max_width)."
        ),
    )
    size_rule: Literal["min", "mid", "max"] = Field(
        "mid",
        description="With size `normalize`: which extent the size rule fixes: `min`, `mid` (the middle one) or `max`.",
    )
    size_m: float = Field(
        0.06,
        gt=0,
        description=(
            "With size `normalize`: that extent after scaling, meters. Default: middle extent 0.06 m, so a Franka "
            "Panda (0.08 m opening) closes across the two smaller extents of most objects."
        ),
    )
    max_dropped: float = Field(
        0.1,
        ge=0,
        le=1,
        description="Reject a shape whose largest connected piece misses more than this share of its volume.",
    )
    max_gap: float = Field(
        0.05,
        ge=0,
        le=0.5,
        description=(
            "Widest hole or crack bridged when an open mesh (a scan, a file split at UV seams) is rebuilt as a solid, "
            "as a share of the shape's largest extent (0.05: 5 mm on a 10 cm object); a mesh that needs a wider one "
            "bridged is rejected. Openings wider than this (a mug's top) stay open."
        ),
    )


@settings
class DecodeSettings:
    """Decoded occupancy probabilities → a cleaned solid and its mesh (params section ``generate.decode``)."""

    threshold: float = Field(0.5, gt=0, le=1, description="Occupancy threshold of decoded grids.")
    opening: int = Field(
        1, ge=0, le=3, description="Binary opening iterations on the decoded solid (removes one-voxel spurs)."
    )
    min_voxels: int = Field(
        100, ge=1, description="A decode with a largest piece smaller than this is rejected (tiny)."
    )
    min_main_share: float = Field(
        0.9,
        gt=0,
        le=1,
        description="A decode whose largest piece holds less than this share of its voxels is rejected (in pieces).",
    )
    smoothing_iterations: int = Field(10, ge=0, description="Humphrey smoothing iterations on the marching-cubes mesh.")


@settings
class BlendSettings:
    """Two parents' signed distance fields → their weighted blend (params section ``generate.blend``)."""

    resolution: int = Field(
        96, ge=16, le=256, description="Cells per side of each parent's grid (the default ingest surface resolution)."
    )
    margin: int = Field(
        3,
        ge=1,
        description="Empty cells around each parent along its largest extent (one voxel of a 32³ grid at 96 cells).",
    )


@settings
class WarpSettings:
    """Ranges of the random smooth deformation that makes a ``warp`` shape from a real one (params section
    ``generate.warp``; :mod:`graspaug.geometry.warp`)."""

    scale: float = Field(
        1.5,
        ge=1,
        le=4,
        description="Anisotropic scale: each axis of a random frame scaled by a factor log-uniform in [1/scale, "
        "scale] (1: none), before the shape is sized by the ingest rule.",
    )
    shear: float = Field(0.3, ge=0, le=1, description="Shear: x and y move by k z, k uniform in [-shear, shear].")
    taper: float = Field(
        0.3,
        ge=0,
        lt=1,
        description="Taper: x and y scale by 1 + t z / h (z from the middle of the z range, h: half that range), t in "
        "[-taper, taper].",
    )
    bend_deg: float = Field(
        30.0,
        ge=0,
        le=45,
        description="Bend: the z axis bends through an angle uniform in [-bend_deg, bend_deg] degrees over the "
        "shape's largest extent (≤ 45: the bending radius stays above that extent, so no fold).",
    )


@settings
class PrimitiveSettings:
    """Random assemblies of primitives, the ``primitives`` pool's shapes (params section ``generate.primitives``;
    :mod:`graspaug.geometry.primitives`)."""

    max_parts: int = Field(5, ge=1, le=10, description="Parts per assembly: uniform in 1 … max_parts.")
    kinds: tuple[Literal["box", "cylinder", "sphere", "capsule", "ring"], ...] = Field(
        ("box", "cylinder", "sphere", "capsule", "ring"),
        min_length=1,
        description="The kinds a part is drawn from, uniformly.",
    )
    resolution: int = Field(
        64,
        ge=16,
        le=256,
        description="Field samples along the largest side of the box around the parts' bounding spheres before "
        "marching cubes (exact distances: faces land between samples, so 64 keeps a box's faces flat).",
    )
