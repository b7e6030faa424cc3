"""Shared by the fidelity studies (``roundtrip_ceiling``, ``paper_scale``): a mesh's graspness as the ``grasps``
stage labels it."""

from __future__ import annotations

import numpy as np

from graspaug.augment.scores import graspness
from graspaug.grasping.labelled import grasps_of_shape


def mesh_graspness(path, shape_id: str, grasps, seed: int) -> tuple[float, int]:
    """The share of positive grasps of the mesh file ``path`` and how many were labelled, as the ``grasps`` stage
    labels shape ``shape_id`` (its settings ``grasps`` and ``seed``;
    :func:`~graspaug.grasping.labelled.grasps_of_shape`)."""
    table, _ = grasps_of_shape(path, shape_id, grasps, seed)
    score, count = graspness(table.success.to_numpy(), np.zeros(len(table), dtype=np.int64), 1)
    return float(score[0]), int(count[0])
