"""Does the gripper hit the object or the table on its way to a grasp?

The Panda's two fingers (fully open) and its palm are boxes in the grasp frame (x: jaw axis,
z: approach direction, y = z × x, origin at the grasp center). A straight approach of length
``approach_distance`` along z sweeps each box into the same box stretched backward by that
length, so the approach is collision free when none of the three stretched boxes overlaps the
object (FCL, exact box-against-triangle-mesh tests) or reaches below the table plane z = 0.
"""

from __future__ import annotations

import fcl
import numpy as np
import trimesh
from trimesh.collision import mesh_to_BVH

from graspaug.grasping.gripper import ParallelJawGripper


def approach_directions(axes: np.ndarray, down: np.ndarray = np.array([0.0, 0.0, -1.0])) -> np.ndarray:
    """For each jaw axis (G, 3) (unit), the unit direction perpendicular to it that is closest to
    ``down``: the approach of a gripper coming from above."""
    axes = np.asarray(axes, dtype=float)
    approach = down - axes * (axes @ down)[:, None]
    return approach / np.linalg.norm(approach, axis=1, keepdims=True)


def swept_gripper_boxes(
    gripper: ParallelJawGripper, approach_distance: float, clearance: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Centers (3, 3) and full extents (3, 3) in the grasp frame of the left finger, right finger
    and palm, fingers open to ``gripper.max_width``, each stretched back along the approach; the
    palm's face toward the grasp comes ``clearance`` m closer (the gap the palm must keep above the
    object)."""
    g = gripper
    tip = g.fingertip_offset
    finger_x = g.max_width / 2 + g.finger_thickness / 2
    finger_z = tip - (g.finger_length + approach_distance) / 2
    palm_depth = g.palm_size[2] + approach_distance + clearance
    palm_z = -g.palm_offset + clearance - palm_depth / 2
    centers = np.array([[-finger_x, 0.0, finger_z], [finger_x, 0.0, finger_z], [0.0, 0.0, palm_z]])
    finger = [g.finger_thickness, g.finger_width, g.finger_length + approach_distance]
    palm = [g.palm_size[0], g.palm_size[1], palm_depth]
    return centers, np.array([finger, finger, palm])


class CollisionChecker:
    """Approach collisions of ``gripper`` with one object resting on the table.

    ``mesh``: the object (m) in its own frame; each query says where it rests on the table
    (the plane z = 0), so the collision structure is built once for all its poses. With
    ``palm_clearance`` (m) the palm must also stay that far from the object at the grasp.
    """

    def __init__(
        self,
        mesh: trimesh.Trimesh,
        gripper: ParallelJawGripper,
        approach_distance: float = 0.1,
        palm_clearance: float = 0.0,
    ) -> None:
        if approach_distance < 0 or palm_clearance < 0:
            raise ValueError(
                f"approach_distance and palm_clearance must be >= 0, got {approach_distance} and {palm_clearance}"
            )
        self.object = fcl.CollisionObject(mesh_to_BVH(mesh), fcl.Transform())
        self.box_centers, self.box_extents = swept_gripper_boxes(gripper, approach_distance, palm_clearance)
        self.boxes = [fcl.Box(*extents) for extents in self.box_extents]

    def collision_free(
        self, centers: np.ndarray, axes: np.ndarray, approaches: np.ndarray, pose: np.ndarray | None = None
    ) -> np.ndarray:
        """(G,) bool: True where the gripper reaches the grasp (centers (G, 3), unit axes and
        approach directions (G, 3), table frame) without touching object or table, for the
        object placed in the table frame by ``pose`` (4, 4; default identity)."""
        centers, axes, approaches = (np.asarray(a, dtype=float).reshape(-1, 3) for a in (centers, axes, approaches))
        pose = np.eye(4) if pose is None else np.asarray(pose, dtype=float)
        to_object, shift = pose[:3, :3].T, pose[:3, 3]
        free = np.ones(len(centers), dtype=bool)
        request = fcl.CollisionRequest()
        for g, (center, axis, approach) in enumerate(zip(centers, axes, approaches)):
            rotation = np.stack([axis, np.cross(approach, axis), approach], axis=1)
            box_centers = center + self.box_centers @ rotation.T
            lowest = box_centers[:, 2] - np.abs(rotation[2]) @ self.box_extents.T / 2
            if np.any(lowest < 0):
                free[g] = False
                continue
            box_rotation = to_object @ rotation
            for box, box_center in zip(self.boxes, (box_centers - shift) @ to_object.T):
                if fcl.collide(
                    fcl.CollisionObject(box, fcl.Transform(box_rotation, box_center)),
                    self.object,
                    request,
                    fcl.CollisionResult(),
                ):
                    free[g] = False
                    break
        return free
