"""Pure geometry: convex-part solids, outer surfaces, normalization, voxel grids.

Nothing here reads params.yaml or knows the file layout; functions take arrays,
meshes and dataclasses. Units are meters outside the voxel grid.
"""
