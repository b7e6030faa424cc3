"""The pick-and-place cell: a table, the Panda beside it, a bin, a depth camera straight above.

Table frame: the table top is z = 0, objects are dropped around the origin, the camera looks
straight down at the origin from ``camera_height``; the robot's base stands at ``robot_base``
and the bin (pybullet_data's ``tray/traybox.urdf``, scaled) at ``bin_position``, both outside
the camera's view. One :class:`PickScene` is one pybullet DIRECT client; a trial builds a fresh
one so that the same seed always gives the same physics.
"""

from __future__ import annotations

import numpy as np
import pybullet
import pybullet_data

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.render.camera import CameraPose, look_at
from graspaug.render.pybullet_depth import render_depth
from graspaug.sim.objects import SimObject
from graspaug.sim.panda import HandSettings, Panda
from graspaug.sim.settings import CellLayout

#: The shake's load directions in turn (table frame): +x, −x, +y, −y, +z, −z.
SHAKE_DIRECTIONS = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)


def camera_pose(layout: CellLayout) -> CameraPose:
    """The overhead depth camera of ``layout``: ``camera_height`` m above the table origin, looking straight down."""
    return look_at(np.array([0.0, 0.0, layout.camera_height]), np.zeros(3))


class PickScene:
    """A fresh physics world with the cell of ``layout`` and a Panda with ``hand``, its fingers ``gripper``'s."""

    near, far = 0.05, 3.0  # depth camera clipping planes (m)

    def __init__(
        self,
        layout: CellLayout = CellLayout(),
        hand: HandSettings = HandSettings(),
        gripper: ParallelJawGripper = ParallelJawGripper(),
    ) -> None:
        self.layout = layout
        self.client = pybullet.connect(pybullet.DIRECT)
        c = self.client
        pybullet.setGravity(0, 0, -layout.gravity, physicsClientId=c)
        pybullet.setTimeStep(layout.time_step, physicsClientId=c)
        half = [layout.table_size[0] / 2, layout.table_size[1] / 2, 0.025]
        table = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half, physicsClientId=c)
        table_visual = pybullet.createVisualShape(
            pybullet.GEOM_BOX, halfExtents=half, rgbaColor=[0.8, 0.7, 0.55, 1], physicsClientId=c
        )
        self.table = pybullet.createMultiBody(0, table, table_visual, basePosition=[0, 0, -0.025], physicsClientId=c)
        pybullet.changeDynamics(self.table, -1, lateralFriction=layout.table_friction, physicsClientId=c)
        self.bin = pybullet.loadURDF(
            f"{pybullet_data.getDataPath()}/tray/traybox.urdf",
            basePosition=list(layout.bin_position),
            globalScaling=layout.bin_scale,
            useFixedBase=True,
            physicsClientId=c,
        )
        self.robot = Panda(c, layout.robot_base, hand, layout.time_step, gripper)
        self.object: int | None = None

    # --- the object --------------------------------------------------------------------------
    def add_object(self, obj: SimObject, position, orientation) -> int:
        """Put ``obj`` at ``position`` (3,) m with quaternion ``orientation`` (x, y, z, w). Its hulls collide
        where they lie: no collision margin (Bullet's default adds 1 mm around every convex mesh)."""
        c = self.client
        collision = pybullet.createCollisionShape(pybullet.GEOM_MESH, fileName=str(obj.collision), physicsClientId=c)
        visual = pybullet.createVisualShape(
            pybullet.GEOM_MESH, fileName=str(obj.visual), rgbaColor=[0.3, 0.5, 0.8, 1], physicsClientId=c
        )
        self.object = pybullet.createMultiBody(
            obj.mass,
            collision,
            visual,
            basePosition=list(position),
            baseOrientation=list(orientation),
            physicsClientId=c,
        )
        pybullet.changeDynamics(
            self.object,
            -1,
            lateralFriction=obj.lateral_friction,
            spinningFriction=obj.spinning_friction,
            rollingFriction=obj.rolling_friction,
            collisionMargin=0.0,
            physicsClientId=c,
        )
        return self.object

    def add_box(self, half_extents, position) -> int:
        """A static box with ``half_extents`` (3,) m centered at ``position`` (3,) m."""
        c = self.client
        shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=list(half_extents), physicsClientId=c)
        visual = pybullet.createVisualShape(
            pybullet.GEOM_BOX, halfExtents=list(half_extents), rgbaColor=[0.6, 0.2, 0.2, 1], physicsClientId=c
        )
        return pybullet.createMultiBody(0, shape, visual, basePosition=list(position), physicsClientId=c)

    def move_object(self, position, orientation) -> None:
        """Put the object at ``position`` (3,) m with quaternion (x, y, z, w) at once, at rest."""
        pybullet.resetBasePositionAndOrientation(
            self.object, list(position), list(orientation), physicsClientId=self.client
        )

    def object_pose(self) -> tuple[np.ndarray, np.ndarray]:
        position, orientation = pybullet.getBasePositionAndOrientation(self.object, physicsClientId=self.client)
        return np.array(position), np.array(orientation)

    def object_speed(self) -> float:
        """Largest of the object's linear (m/s) and angular (rad/s × 0.05 m) speeds."""
        linear, angular = pybullet.getBaseVelocity(self.object, physicsClientId=self.client)
        return max(float(np.linalg.norm(linear)), 0.05 * float(np.linalg.norm(angular)))

    def object_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        low, high = pybullet.getAABB(self.object, physicsClientId=self.client)
        return np.array(low), np.array(high)

    def settle(self, max_time: float = 2.0, speed: float = 0.005, hold: float = 0.3) -> float:
        """Step until the object has moved slower than ``speed`` for ``hold`` s (checked every 12 steps: a rocking
        object passes through rest at each turn and rolls on) or ``max_time`` s pass; the time taken."""
        steps = int(round(max_time / self.layout.time_step))
        slow, needed = 0, max(1, int(round(hold / (12 * self.layout.time_step))))
        for i in range(steps):
            self.robot.step(1)
            if i % 12 == 11:
                slow = slow + 1 if self.object_speed() < speed else 0
                if slow >= needed:
                    return (i + 1) * self.layout.time_step
        return max_time

    def shake(self, acceleration: float, pulse_time: float) -> None:
        """Load the held object as shaking the hand would: one half-sine pulse of ``pulse_time`` s
        along each of +x, −x, +y, −y, +z, −z (table frame), peaking at the object's mass ×
        ``acceleration`` (m/s²), applied at its center of mass while the arm holds still (in the
        hand's frame, accelerating the hand by a loads the object with −m·a at its center of mass)."""
        c = self.client
        mass = pybullet.getDynamicsInfo(self.object, -1, physicsClientId=c)[0]
        steps = max(1, int(round(pulse_time / self.layout.time_step)))
        arm = self.robot.arm_angles()
        for direction in SHAKE_DIRECTIONS:
            for i in range(steps):
                force = mass * acceleration * np.sin(np.pi * (i + 0.5) / steps) * direction
                position, _ = self.object_pose()
                pybullet.applyExternalForce(
                    self.object, -1, force.tolist(), position.tolist(), pybullet.WORLD_FRAME, physicsClientId=c
                )
                self.robot.step(1, arm)

    def object_in_bin(self) -> bool:
        """Whether the object's center lies inside the bin's walls, below its rim."""
        position, _ = self.object_pose()
        offset = position[:2] - np.asarray(self.layout.bin_position[:2])
        return bool(
            np.all(np.abs(offset) < self.layout.bin_half_extent)
            and position[2] < self.layout.bin_position[2] + self.layout.bin_height
        )

    def body_name(self, body: int) -> str:
        """What ``body`` is in the cell: ``object``, ``table``, ``bin``, ``robot`` or ``obstacle``."""
        names = {self.object: "object", self.table: "table", self.bin: "bin", self.robot.body: "robot"}
        return names.get(body, "obstacle")

    def object_touches_robot(self) -> bool:
        return len(pybullet.getContactPoints(self.object, self.robot.body, physicsClientId=self.client)) > 0

    # --- sensing -----------------------------------------------------------------------------
    def depth_image(self) -> np.ndarray:
        """The overhead camera's depth image (H, W) float64 m (TinyRenderer z-buffer → metric)."""
        return render_depth(self.client, camera_pose(self.layout), self.layout.intrinsics, self.near, self.far)

    def color_frame(self, width: int = 320, height: int = 240) -> np.ndarray:
        """An RGB picture (height, width, 3) uint8 of the cell from the front-left, for the reports."""
        view = pybullet.computeViewMatrix([0.35, -0.55, 0.45], [-0.15, 0.2, 0.08], [0, 0, 1])
        projection = pybullet.computeProjectionMatrixFOV(45, width / height, 0.05, 5.0)
        _, _, rgba, _, _ = pybullet.getCameraImage(
            width,
            height,
            view,
            projection,
            renderer=pybullet.ER_TINY_RENDERER,
            flags=pybullet.ER_NO_SEGMENTATION_MASK,
            physicsClientId=self.client,
        )
        return np.reshape(np.asarray(rgba, dtype=np.uint8), (height, width, 4))[..., :3]

    def close(self) -> None:
        pybullet.disconnect(physicsClientId=self.client)

    def __enter__(self) -> PickScene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
