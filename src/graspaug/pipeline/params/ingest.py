"""The ``ingest`` section: checking, rebuilding, sizing and splitting the shapes."""

from __future__ import annotations

from graspaug.geometry.settings import SurfaceSettings
from graspaug.settings import Field, settings


@settings
class IngestParams:
    """Checking, rebuilding, sizing and splitting the shapes."""

    max_faces: int = Field(1_000_000, ge=1, description="A file with more triangles is rejected.")
    max_file_mb: float = Field(100.0, gt=0, description="A larger file is rejected before it is read, MB.")
    min_shapes: int = Field(10, ge=1, description="The stage fails if fewer shapes survive the checks.")
    test_fraction: float = Field(
        0.2663,
        gt=0,
        le=0.9,
        description="Share of shapes in the test split (0.2663 = the paper's 363 test : 1000 train).",
    )
    min_voxels: int = Field(
        8,
        ge=0,
        description=(
            "A shape whose solid grid at voxelize.resolution holds fewer occupied voxels is rejected (a thin shape, a "
            "fork, is empty at 16³); 0 keeps all."
        ),
    )
    surface: SurfaceSettings = Field(
        default_factory=SurfaceSettings, description="How each shape's closed outer surface is rebuilt and sized."
    )
