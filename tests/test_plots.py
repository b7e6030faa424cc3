"""The shared figure primitives, drawn to PNG files and read back: what a person sees."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from graspaug.plots import DPI, voxel_rows


def blank_below_title(png) -> int:
    """The height (pixels) of the blank (white) band between a figure's first line of text (its title) and whatever
    comes next: read from the PNG file ``png``."""
    import matplotlib.image

    image = matplotlib.image.imread(png)[..., :3]  # (H, W, 3) float in [0, 1]
    inked = (image < 0.9).any(axis=(1, 2))  # (H,) rows with anything drawn
    first = int(np.argmax(inked))  # the title's first row
    title_end = first + int(np.argmax(~inked[first:]))
    after = title_end + int(np.argmax(inked[title_end:]))
    return after - title_end


def _solid(shape: trimesh.Trimesh, resolution: int = 16) -> np.ndarray:
    """(R, R, R) bool: the filled voxel grid of ``shape``, padded to ``resolution`` per side."""
    grid = shape.voxelized(pitch=shape.extents.max() / (resolution - 2)).fill().matrix
    out = np.zeros((resolution,) * 3, dtype=bool)
    out[: grid.shape[0], : grid.shape[1], : grid.shape[2]] = grid[:resolution, :resolution, :resolution]
    return out


@pytest.mark.parametrize("n_rows", [1, 3, 8])
def test_voxel_rows_put_the_title_right_above_the_columns(tmp_path, n_rows):
    """generate's pairs.png opened with an empty band a fifth of its height under its title (issue #62, 14)."""
    shapes = [trimesh.creation.box(extents=(0.04, 0.03, 0.02)), trimesh.creation.capsule(height=0.03, radius=0.01)]
    cells = [(g, g) for g in map(_solid, shapes)]
    rows = [[cells[0], cells[1], cells[0]] for _ in range(n_rows)]
    path = tmp_path / "pairs.png"
    voxel_rows(rows, [f"row {i}" for i in range(n_rows)], ["parent a", "generated", "parent b"], path, "Title")
    assert blank_below_title(path) < 0.3 * DPI  # under 0.3 inch, whatever the number of rows
