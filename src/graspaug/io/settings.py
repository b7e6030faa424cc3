"""Where the shape corpus comes from."""

from __future__ import annotations

from typing import Literal

from graspaug.settings import Field, settings


@settings
class CorpusSettings:
    """Where the shape corpus comes from (params section ``data``)."""

    source: Literal["pybullet", "folder"] = Field(
        "pybullet",
        description=(
            "`pybullet`: the 1000 objects of pybullet_data/random_urdfs (URDF mesh scale applied); `folder`: every "
            ".obj/.stl/.ply/.off/.glb under `path`, recursively (e.g. a local 3DNet copy)."
        ),
    )
    path: str | None = Field(
        None,
        description=(
            "Folder of meshes when source is `folder`, relative to the project or absolute; its files are taken as "
            "meters times `unit_scale`."
        ),
    )
    unit_scale: float = Field(
        1.0, gt=0, description="Meters per file unit for `folder` sources (0.001 for millimeter files)."
    )
    limit: int | None = Field(None, ge=1, description="Use only the first `limit` files in sorted order (null: all).")

    def __post_init__(self) -> None:
        if self.source == "folder" and not self.path:
            raise ValueError("data.path: required when data.source is folder")
