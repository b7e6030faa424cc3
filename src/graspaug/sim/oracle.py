"""The cell's ceiling: the best grasp a planner could choose, found on the true mesh in the pose it rests in.

The ``oracle`` arm knows what no camera shows: the object's mesh and where it lies. Grasps are sampled on the mesh
once per object (the project's antipodal sampler, :func:`graspaug.grasping.antipodal.sample_antipodal_grasps`, with
the label gripper) and ranked by robust ε (:func:`graspaug.grasping.robust.robust_ferrari_canny`, the labels'
metric; it does not depend on the pose). For each drop, once the object rests, the grasps are carried into the
table frame; those whose jaw axis lies within ``max_tilt`` of level are executed as the cell executes any grasp
(the axis flattened onto the table, a straight top-down approach from the pre-grasp height) and are kept only
where that approach is collision free for the gripper's boxes against the mesh and the table
(:class:`graspaug.render.collision.CollisionChecker`). The best kept grasp by robust ε is the oracle's; none kept:
no grasp. Nothing here reads a pick's outcome.
"""

from __future__ import annotations

import numpy as np
import pybullet
import trimesh

from graspaug.grasping.antipodal import sample_antipodal_grasps
from graspaug.grasping.robust import robust_ferrari_canny
from graspaug.grasping.settings import GraspsSettings
from graspaug.render.collision import CollisionChecker

DOWN = np.array([0.0, 0.0, -1.0])


class MeshOracle:
    """Grasps of ``mesh`` (m, in the simulated body's frame: its origin the body's) for ``settings``' gripper,
    ranked once by robust ε from ``rng``; called with a resting pose it gives the best executable grasp."""

    def __init__(
        self,
        mesh: trimesh.Trimesh,
        settings: GraspsSettings,
        rng: np.random.Generator,
        max_tilt: float = np.deg2rad(10.0),
        approach_distance: float = 0.15,
    ) -> None:
        self.max_tilt = max_tilt
        grasps = sample_antipodal_grasps(mesh, settings.gripper, settings.sampler, rng)
        quality, _ = robust_ferrari_canny(
            mesh, grasps.center, grasps.axis, settings.gripper, settings.quality, settings.perturbations, rng
        )
        order = np.argsort(-quality, kind="stable")
        self.centers, self.axes, self.quality = grasps.center[order], grasps.axis[order], quality[order]
        self.checker = CollisionChecker(mesh, settings.gripper, approach_distance)
        self.chosen: dict | None = None  # the last call's grasp: its robust ε, tilt (rad), and candidates kept

    def __len__(self) -> int:
        return len(self.quality)

    def __call__(self, position, quaternion) -> tuple[np.ndarray, float] | None:
        """The best executable grasp for the body resting at ``position`` (3,) m with ``quaternion`` (x, y, z, w):
        table-frame center (3,) m and jaw angle (rad from the table's x axis), or None."""
        rotation = np.reshape(pybullet.getMatrixFromQuaternion(list(quaternion)), (3, 3))
        centers = np.asarray(position) + self.centers @ rotation.T
        axes = self.axes @ rotation.T
        level = np.abs(axes[:, 2]) <= np.sin(self.max_tilt)
        flat = axes.copy()
        flat[:, 2] = 0.0
        flat /= np.maximum(np.linalg.norm(flat, axis=1, keepdims=True), 1e-12)
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = rotation, position
        index = np.flatnonzero(level & (self.quality > 0))
        free = self.checker.collision_free(centers[index], flat[index], np.tile(DOWN, (len(index), 1)), pose)
        kept = index[free]
        if not len(kept):
            self.chosen = {"quality": None, "tilt": None, "kept": 0}
            return None
        best = kept[0]  # sorted by robust ε
        tilt = float(np.arcsin(min(1.0, abs(axes[best, 2]))))
        self.chosen = {"quality": float(self.quality[best]), "tilt": tilt, "kept": int(len(kept))}
        angle = float(np.arctan2(flat[best, 1], flat[best, 0]))
        return centers[best], float((angle + np.pi / 2) % np.pi - np.pi / 2)  # the jaw is symmetric: the wrist's way
