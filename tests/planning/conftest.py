"""Depth images for the planner's tests."""

from __future__ import annotations

import numpy as np
import pytest


def _box_image(top: float = 0.62, box=(280, 220, 320, 280), table: float = 0.65) -> np.ndarray:
    """A flat table (H, W) = (480, 640) m with a box seen from above: columns u0..u1, rows v0..v1."""
    depth = np.full((480, 640), table)
    u0, v0, u1, v1 = box
    depth[v0:v1, u0:u1] = top
    return depth


@pytest.fixture
def box_image():
    """``box_image(top=0.62, box=(u0, v0, u1, v1), table=0.65)`` → depth (480, 640) m (default: a 40 × 60 px box)."""
    return _box_image
