"""One pick-and-place attempt: drop the object, look, plan, pick, carry to the bin, release.

A trial runs in a fresh :class:`~graspaug.sim.scene.PickScene` so that its outcome depends only
on the object, the drop seed and the grasp: the same seed gives the same drop (and the same
noisy depth image: the sensor noise is drawn from the drop seed too) to every planner. The hand
travels from its rest pose to the pre-grasp pose and down to the grasp along straight lines;
a contact pressing harder than ``collision_force`` on the way, before the fingers close, ends
the trial as ``collision``. After the lift the held object is shaken (``shake_acceleration``:
loads at its center of mass, :meth:`~graspaug.sim.scene.PickScene.shake`) before it is carried.
The grasp comes from a grasp source (depth image → planned grasp,
:class:`graspaug.planning.PlannedGrasp`) or, for scripted tests, directly as a table-frame pose.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.planning.grasps import ImageGrasps
from graspaug.planning.planner import PlannedGrasp
from graspaug.render.camera import CameraPose
from graspaug.render.settings import Intrinsics
from graspaug.sim.objects import SimObject
from graspaug.sim.panda import HandSettings
from graspaug.sim.scene import CellLayout, PickScene, camera_pose
from graspaug.sim.sensor import sense_depth
from graspaug.sim.settings import DepthNoise, TrialSettings

OUTCOMES = ("success", "no_grasp", "collision", "not_lifted", "dropped", "outside_bin")

#: A static box in the cell: half extents (3,) m and center (3,) m, table frame (tests block the approach with one).
Obstacle = tuple[tuple[float, float, float], tuple[float, float, float]]


@dataclass
class TrialResult:
    """What happened; ``frames`` (RGB uint8) and ``depth`` only when recorded."""

    outcome: str
    success: bool
    drop_position: tuple[float, float, float]
    grasp_center: tuple[float, float, float] | None = None  # table frame (m)
    jaw_angle: float | None = None  # rad, from the table's x axis
    image_grasp: dict | None = None  # u, v, angle, depth, width_px
    quality: float | None = None  # GQ-CNN P(success)
    planning_time: float | None = None  # s
    candidates: int = 0
    contact_force: float = 0.0  # largest contact force (N) of the robot before the fingers closed
    #: the robot's contacts at that hardest-pressing step: (robot link, what it touched, normal force N) per pair
    contacts: list[tuple[str, str, float]] = field(default_factory=list)
    shake_grip: float | None = None  # the grip (N a finger) friction needs to hold the object through the shake
    hand_error: tuple[float, float, float] = (0.0, 0.0, 0.0)  # where the hand went off the grasp: x, y (m), angle (rad)
    depth: np.ndarray | None = None
    frames: list[tuple[str, np.ndarray]] = field(default_factory=list)


def shake_grip(mass: float, friction: float, settings: TrialSettings, layout: CellLayout) -> float:
    """The grip (N a finger) that holds an object of ``mass`` kg by pad ``friction`` alone through the shake of
    ``settings`` (its weight plus the peak load, both pads pulling): m g (1 + a) / (2 μ)."""
    return float(mass * layout.gravity * (1 + settings.shake_acceleration) / (2 * friction))


def contacts_text(contacts) -> str:
    """A trial's hardest contacts in a line: ``panda_leftfinger–object 12.3 N; ...`` (empty: none)."""
    return "; ".join(f"{link}–{other} {force:.1f} N" for link, other, force in contacts)


def random_orientation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly random unit quaternion (x, y, z, w)."""
    q = rng.normal(size=4)
    return q / np.linalg.norm(q)


#: What plans the grasp: the sensed depth image (H, W) m (0 where a pixel is lost), the camera's pose and
#: intrinsics → the planned grasp, or None when there is none.
GraspSource = Callable[[np.ndarray, CameraPose, Intrinsics], "PlannedGrasp | None"]


ScriptedGrasp = Callable[[np.ndarray, np.ndarray], "tuple[np.ndarray, float] | None"]


def grasp_in_table_frame(
    grasps: ImageGrasps, camera: CameraPose, intrinsics: Intrinsics
) -> tuple[np.ndarray, np.ndarray]:
    """Table-frame grasps of image grasps seen by ``camera`` with ``intrinsics``.

    Returns
    -------
    centers : (N, 3) float — grasp centers, m (the center pixel deprojected at the grasp depth)
    angles : (N,) float — jaw angles in the table plane from the table's x axis, rad (the image
        jaw direction carried to the table and flattened onto it)
    """
    rays = intrinsics.rays(grasps.centers[:, 0], grasps.centers[:, 1])
    centers = camera.to_table(rays * grasps.depths[:, None])
    direction_cam = np.stack([np.cos(grasps.angles), np.sin(grasps.angles), np.zeros(len(grasps))], axis=1)
    direction = direction_cam @ camera.rotation.T
    return centers, np.arctan2(direction[:, 1], direction[:, 0])


def resting_pose(
    obj: SimObject,
    drop_seed: int,
    layout: CellLayout = CellLayout(),
    settings: TrialSettings = TrialSettings(),
    gripper: ParallelJawGripper = ParallelJawGripper(),
) -> tuple[np.ndarray, np.ndarray]:
    """Where ``obj`` comes to rest when dropped as :func:`run_trial` drops it with ``drop_seed``: its body's
    position (3,) m and quaternion (x, y, z, w), a ``placement`` for attempts that all start from one pose."""
    rng = np.random.default_rng(drop_seed)
    with PickScene(layout, HandSettings(), gripper) as scene:
        xy = rng.uniform(-settings.drop_offset, settings.drop_offset, size=2)
        orientation = random_orientation(rng)
        scene.add_object(obj, [xy[0], xy[1], 1.0], orientation)
        low, _ = scene.object_bounds()
        scene.move_object([xy[0], xy[1], 1.0 - low[2] + settings.drop_clearance], orientation)
        scene.settle(settings.settle_time)
        return scene.object_pose()


def run_trial(
    obj: SimObject,
    drop_seed: int,
    planner: GraspSource | None = None,
    scripted: ScriptedGrasp | None = None,
    layout: CellLayout = CellLayout(),
    hand: HandSettings = HandSettings(),
    settings: TrialSettings = TrialSettings(),
    sensor: DepthNoise = DepthNoise(),
    record: bool = False,
    obstacles: tuple[Obstacle, ...] = (),
    placement: tuple[np.ndarray, np.ndarray] | None = None,
    gripper: ParallelJawGripper = ParallelJawGripper(),
) -> TrialResult:
    """Drop ``obj`` at the pose drawn from ``drop_seed``, then pick it with ``planner``'s grasp
    on the ``sensor``'s depth image (or the ``scripted`` one: the object's resting position (3,) m
    and quaternion (x, y, z, w) → table-frame grasp center (3,) m and jaw angle rad, or None: no grasp) and carry
    it to the bin. ``obstacles`` are static boxes added once the object rests. With ``placement``
    (position (3,) m, quaternion (x, y, z, w) of the object's body) the object is put there and
    left to settle instead of dropped (a stable pose on the table, as the rendered datasets have it). The hand's
    fingers and palm are ``gripper``'s (``grasps.gripper``: the gripper the grasps are labelled for)."""
    rng = np.random.default_rng(drop_seed)
    with PickScene(layout, hand, gripper) as scene:
        if placement is None:
            xy = rng.uniform(-settings.drop_offset, settings.drop_offset, size=2)
            orientation = random_orientation(rng)
            scene.add_object(obj, [xy[0], xy[1], 1.0], orientation)  # high up to measure its extent in that pose
            low, _ = scene.object_bounds()
            drop = np.array([xy[0], xy[1], 1.0 - low[2] + settings.drop_clearance])
            scene.move_object(drop, orientation)
        else:
            drop = np.asarray(placement[0], dtype=float)
            scene.add_object(obj, drop, placement[1])
        scene.settle(settings.settle_time)
        for half_extents, position in obstacles:
            scene.add_box(half_extents, position)
        result = TrialResult(outcome="no_grasp", success=False, drop_position=tuple(float(x) for x in drop))
        frames = result.frames
        if record:
            frames.append(("object dropped", scene.color_frame()))
        if scripted is None:
            depth = sense_depth(scene.depth_image(), layout.intrinsics, sensor, np.random.default_rng([drop_seed, 1]))
            if record:
                result.depth = depth
            camera = camera_pose(layout)
            planned = planner(depth, camera, layout.intrinsics) if planner is not None else None
            if planned is None:
                return result
            g: ImageGrasps = planned.grasp
            centers, angles = grasp_in_table_frame(g, camera, layout.intrinsics)
            center, jaw_angle = centers[0], float(angles[0])
            result.image_grasp = {
                "u": float(g.centers[0, 0]),
                "v": float(g.centers[0, 1]),
                "angle": float(g.angles[0]),
                "depth": float(g.depths[0]),
                "width_px": float(g.widths[0]),
            }
            result.quality, result.planning_time, result.candidates = (
                planned.quality,
                planned.planning_time,
                planned.candidates,
            )
        else:
            grasp = scripted(*scene.object_pose())
            if grasp is None:  # a scripted source may find no grasp (the oracle where nothing is reachable)
                return result
            center, jaw_angle = np.asarray(grasp[0], dtype=float), float(grasp[1])
        result.grasp_center, result.jaw_angle = tuple(float(x) for x in center), jaw_angle
        if settings.position_error > 0 or settings.angle_error > 0:  # where the hand really goes
            error = np.random.default_rng([drop_seed, 2]).normal(size=3)
            error *= [settings.position_error, settings.position_error, settings.angle_error]
            result.hand_error = tuple(float(e) for e in error)
            center, jaw_angle = center + [error[0], error[1], 0.0], jaw_angle + float(error[2])
        start_height = scene.object_pose()[0][2]

        robot = scene.robot
        limit = settings.collision_force
        result.contact_force = robot.move_line(
            center + [0, 0, settings.pregrasp_height], jaw_angle, speed=hand.transit_speed, max_force=limit
        )
        if record and result.contact_force <= limit:  # a collision on the way is drawn once, below
            frames.append(("pre-grasp", scene.color_frame()))
        if result.contact_force <= limit:
            result.contact_force = max(result.contact_force, robot.move_line(center, jaw_angle, max_force=limit))
        result.contacts = [(link, scene.body_name(b), round(f, 3)) for link, b, f in robot.hardest]
        if result.contact_force > limit:
            result.outcome = "collision"
            if record:
                frames.append(("collision", scene.color_frame()))
            return result
        robot.set_fingers(0.0)
        if record:
            frames.append(("closed", scene.color_frame()))
        robot.move_line(center + [0, 0, settings.lift_height], jaw_angle)
        lifted = scene.object_pose()[0][2] > start_height + 0.5 * settings.lift_height and scene.object_touches_robot()
        if record:
            frames.append(("lifted", scene.color_frame()))
        if not lifted:
            result.outcome = "not_lifted"
            return result
        if settings.shake_acceleration > 0:
            result.shake_grip = shake_grip(obj.mass, obj.lateral_friction * hand.finger_friction, settings, layout)
            scene.shake(settings.shake_acceleration * layout.gravity, settings.shake_pulse)
            if record:
                frames.append(("shaken", scene.color_frame()))
        above_bin = np.array(
            [layout.bin_position[0], layout.bin_position[1], layout.bin_position[2] + settings.carry_height]
        )
        robot.move_line(above_bin, jaw_angle, speed=settings.carry_speed)
        held = scene.object_touches_robot()
        if record:
            frames.append(("over the bin", scene.color_frame()))
        robot.set_fingers(robot.open_width)
        robot.step(int(settings.release_time / layout.time_step))
        if record:
            frames.append(("released", scene.color_frame()))
        result.success = scene.object_in_bin()
        result.outcome = "success" if result.success else ("outside_bin" if held else "dropped")
        return result
