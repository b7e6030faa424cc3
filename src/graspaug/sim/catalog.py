"""The everyday objects of the simulated trials: meshes that ship in ``pybullet_data``."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class CatalogEntry:
    """An object shipped in ``pybullet_data``: mesh file (relative to its data path) and the
    uniform scale that makes it fit the Panda's 0.08 m opening one way."""

    name: str
    mesh: str
    scale: float


#: Eight everyday objects that ship with pybullet, sized like small household things
#: (extents in cm after scaling).
EVERYDAY_OBJECTS: dict[str, CatalogEntry] = {
    entry.name: entry
    for entry in (
        CatalogEntry("mug", "objects/mug.obj", 0.7),  # 5.7 × 8.5 × 7.0, with a handle
        CatalogEntry("duck", "duck.obj", 0.04),  # 6.6 × 6.2 × 4.6, the rubber duck
        CatalogEntry("teddy", "teddy2_VHACD_CHs.obj", 0.08),  # 6.1 × 7.5 × 5.0, teddy bear
        CatalogEntry("bunny", "bunny.obj", 0.04),  # 3.7 × 5.8 × 7.9, Stanford bunny
        CatalogEntry("torus", "torus/torus_textured.obj", 0.045),  # 6.8 × 2.2 × 6.8, a ring
        CatalogEntry("cube", "toys/cube.obj", 0.6),  # 5.2 × 5.2 × 3.9, toy block
        CatalogEntry("cylinder", "toys/cylinder.obj", 0.6),  # 4.6 × 7.0 × 3.5, toy cylinder
        CatalogEntry("prism", "toys/prism.obj", 0.6),  # 5.0 × 3.8 × 7.1, toy triangular prism
    )
}
