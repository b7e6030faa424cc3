"""The Franka Emika Panda of ``pybullet_data`` (``franka_panda/panda.urdf``) as a pick-and-place arm.

Joints 0–6 are the arm, 9 and 10 the two fingers (prismatic, held centered by a gear constraint),
link 11 ``panda_grasptarget`` is the grasp center between the fingertips (the point every grasp in
the project is planned for). The hand that collides is the gripper every grasp is labelled for
(``grasps.gripper``, :class:`~graspaug.grasping.gripper.ParallelJawGripper`): :func:`hand_urdf` writes the
Panda's URDF with its finger and palm collision shapes replaced by that gripper's boxes and the fingers'
travel by its opening, so the label gripper and the executed hand are one geometry (the Panda's meshes stay as
its look). Boxes collide exactly in Bullet (a box's margin lies inside it; a mesh's adds 1 mm outside: the stock
fingers leave a 77.8 mm gap and reach 8.3 mm past the grasp center, :func:`probe_hand`). Motions are joint-space
position control toward inverse-kinematics targets along straight Cartesian lines, stepped at the simulation's
rate; nothing is teleported once an object is in contact.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

import numpy as np
import pybullet
import pybullet_data

from graspaug.grasping.gripper import ParallelJawGripper
from graspaug.sim.settings import HandSettings

ARM_JOINTS = tuple(range(7))
FINGER_JOINTS = (9, 10)
GRASP_TARGET_LINK = 11
LOWER_LIMITS = np.array([-2.9671, -1.8326, -2.9671, -3.1416, -2.9671, -0.0873, -2.9671])
UPPER_LIMITS = np.array([2.9671, 1.8326, 2.9671, 0.0, 2.9671, 3.8223, 2.9671])
ARM_EFFORT = np.array([87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0])  # N m, the URDF's limits
REST_POSE = np.array([0.0, -0.6, 0.0, -2.4, 0.0, 1.8, 0.785])  # arm folded back, hand down (rad)
FINGER_OPEN = 0.04  # each finger's travel at full opening of the stock Panda (m): 0.08 m between the jaws
GRASP_TARGET = 0.105  # the grasp center in front of the hand's frame (m; the URDF's panda_grasptarget)
FINGER_JOINT_Z = 0.0584  # the finger joints' origin in front of the hand's frame (m)


def _box(xyz, size) -> str:
    return (
        f'<origin rpy="0 0 0" xyz="{xyz[0]:.6f} {xyz[1]:.6f} {xyz[2]:.6f}"/>'
        f'<geometry><box size="{size[0]:.6f} {size[1]:.6f} {size[2]:.6f}"/></geometry>'
    )


def hand_urdf(gripper: ParallelJawGripper) -> str:
    """The text of pybullet_data's Panda URDF with the hand of ``gripper``: each finger's collision shape a box
    ``finger_width`` across the jaw (hand x), ``finger_thickness`` outward from its jaw face (hand y) and
    ``finger_length`` along the approach (hand z), its tip ``fingertip_offset`` past the grasp center; the palm's
    a box of ``palm_size`` ``palm_offset`` behind the grasp center; each finger's travel ``max_width`` / 2 (its
    jaw face on the grasp center's plane when closed). Mesh paths are absolute (the file may be written anywhere)."""
    import re

    data = pybullet_data.getDataPath()
    text = (Path(data) / "franka_panda" / "panda.urdf").read_text()
    text = text.replace("package://", f"{data}/franka_panda/")
    tip = GRASP_TARGET + gripper.fingertip_offset - FINGER_JOINT_Z  # fingertip in the finger joint's frame
    z = tip - gripper.finger_length / 2
    size = (gripper.finger_width, gripper.finger_thickness, gripper.finger_length)
    fingers = {"panda_leftfinger": 1.0, "panda_rightfinger": -1.0}
    for link, side in fingers.items():
        box = _box((0.0, side * gripper.finger_thickness / 2, z), size)
        text = re.sub(
            rf'(<link name="{link}">.*?<collision>).*?(</collision>)',
            lambda m, box=box: m.group(1) + box + m.group(2),
            text,
            count=1,
            flags=re.S,
        )
    palm_z = GRASP_TARGET - gripper.palm_offset - gripper.palm_size[2] / 2
    palm = _box((0.0, 0.0, palm_z), (gripper.palm_size[1], gripper.palm_size[0], gripper.palm_size[2]))
    text = re.sub(
        r'(<link name="panda_hand">.*?<collision>).*?(</collision>)',
        lambda m: m.group(1) + palm + m.group(2),
        text,
        count=1,
        flags=re.S,
    )
    travel = gripper.max_width / 2
    text = re.sub(r'(<limit effort="20" lower="0.0" upper=")0.04(")', rf"\g<1>{travel:.6f}\g<2>", text)
    return text


def hand_urdf_file(gripper: ParallelJawGripper, cache_dir: Path | None = None) -> Path:
    """:func:`hand_urdf` of ``gripper`` written once to the cache (``<cache>/hands/<sha256>.urdf``, atomically)."""
    from graspaug.sim.objects import default_cache_dir

    text = hand_urdf(gripper)
    folder = (default_cache_dir() if cache_dir is None else Path(cache_dir)) / "hands"
    path = folder / f"panda-{hashlib.sha256(text.encode()).hexdigest()[:16]}.urdf"
    if not path.exists():
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(suffix=".urdf", dir=folder)
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    return path


class Panda:
    """A Panda fixed at ``base_position`` (m) in pybullet client ``client``, its hand ``gripper``'s geometry."""

    def __init__(
        self,
        client: int,
        base_position,
        hand: HandSettings = HandSettings(),
        time_step: float = 1 / 240,
        gripper: ParallelJawGripper = ParallelJawGripper(),
    ) -> None:
        self.client, self.hand, self.time_step, self.gripper = client, hand, time_step, gripper
        self.open_width = gripper.max_width  # the jaw gap at full opening (m)
        self.body = pybullet.loadURDF(
            str(hand_urdf_file(gripper)),
            basePosition=list(base_position),
            useFixedBase=True,
            flags=pybullet.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT,
            physicsClientId=client,
        )
        gear = pybullet.createConstraint(
            self.body,
            FINGER_JOINTS[0],
            self.body,
            FINGER_JOINTS[1],
            pybullet.JOINT_GEAR,
            [1, 0, 0],
            [0, 0, 0],
            [0, 0, 0],
            physicsClientId=client,
        )
        pybullet.changeConstraint(gear, gearRatio=-1, erp=0.1, maxForce=hand.centering_force, physicsClientId=client)
        for link in FINGER_JOINTS:
            pybullet.changeDynamics(
                self.body,
                link,
                lateralFriction=hand.finger_friction,
                spinningFriction=hand.finger_spinning_friction,
                physicsClientId=client,
            )
        self.finger_target = self.open_width / 2
        #: the robot's contacts at the hardest-pressing step watched so far (:meth:`move_line` with ``max_force``):
        #: (robot link name, other body id, normal force N) per pair, and their total (N)
        self.hardest: list[tuple[str, int, float]] = []
        self.hardest_force = 0.0
        self.reset(REST_POSE)

    # --- state -------------------------------------------------------------------------------
    def reset(self, arm: np.ndarray, fingers: float | None = None) -> None:
        """Put the arm at joint angles ``arm`` (7,) rad and each finger at ``fingers`` m from the grasp center
        (default: fully open) at once (only before anything is grasped) and hold them there."""
        fingers = self.open_width / 2 if fingers is None else fingers
        for joint, angle in zip(ARM_JOINTS, arm):
            pybullet.resetJointState(self.body, joint, float(angle), physicsClientId=self.client)
        for joint in FINGER_JOINTS:
            pybullet.resetJointState(self.body, joint, fingers, physicsClientId=self.client)
        self.finger_target = fingers
        self._command(np.asarray(arm, dtype=float))

    def arm_angles(self) -> np.ndarray:
        return np.array([s[0] for s in pybullet.getJointStates(self.body, ARM_JOINTS, physicsClientId=self.client)])

    def grasp_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Position (3,) m and quaternion (x, y, z, w) of the grasp center link."""
        state = pybullet.getLinkState(
            self.body, GRASP_TARGET_LINK, computeForwardKinematics=True, physicsClientId=self.client
        )
        return np.array(state[4]), np.array(state[5])

    # --- kinematics --------------------------------------------------------------------------
    @staticmethod
    def top_down(jaw_angle: float) -> list[float]:
        """The hand's quaternion (x, y, z, w) for a straight-down approach with the jaw axis (the
        hand's y axis) at ``jaw_angle`` (rad) from the table's x axis, in the table plane."""
        return list(pybullet.getQuaternionFromEuler([np.pi, 0.0, jaw_angle - np.pi / 2]))

    def inverse_kinematics(self, position, orientation) -> np.ndarray:
        """Arm angles (7,) that put the grasp center at ``position`` (3,) m with ``orientation``
        (pybullet's damped least squares from the current angles, null space toward the rest pose)."""
        angles = pybullet.calculateInverseKinematics(
            self.body,
            GRASP_TARGET_LINK,
            list(position),
            orientation,
            lowerLimits=LOWER_LIMITS.tolist(),
            upperLimits=UPPER_LIMITS.tolist(),
            jointRanges=(UPPER_LIMITS - LOWER_LIMITS).tolist(),
            restPoses=REST_POSE.tolist(),
            maxNumIterations=100,
            residualThreshold=1e-5,
            physicsClientId=self.client,
        )
        return np.array(angles[:7])

    # --- motion ------------------------------------------------------------------------------
    def _command(self, arm: np.ndarray) -> None:
        pybullet.setJointMotorControlArray(
            self.body,
            ARM_JOINTS,
            pybullet.POSITION_CONTROL,
            targetPositions=arm.tolist(),
            forces=ARM_EFFORT.tolist(),
            physicsClientId=self.client,
        )
        pybullet.setJointMotorControlArray(
            self.body,
            FINGER_JOINTS,
            pybullet.POSITION_CONTROL,
            targetPositions=[self.finger_target] * 2,
            forces=[self.hand.grip_force] * 2,
            physicsClientId=self.client,
        )

    def step(self, n: int, arm: np.ndarray | None = None) -> None:
        arm = self.arm_angles() if arm is None else arm
        self._command(arm)
        for _ in range(n):
            pybullet.stepSimulation(physicsClientId=self.client)

    def contact_force(self) -> float:
        """Total normal force (N) of the robot's contacts with other bodies now."""
        return float(
            sum(
                c[9]
                for c in pybullet.getContactPoints(bodyA=self.body, physicsClientId=self.client)
                if c[2] != self.body
            )
        )

    def contacts(self) -> list[tuple[str, int, float]]:
        """The robot's contacts with other bodies now: (robot link name, other body id, normal force N) per pair
        of link and body, the forces of their contact points summed."""
        pairs: dict[tuple[int, int], float] = {}
        for c in pybullet.getContactPoints(bodyA=self.body, physicsClientId=self.client):
            if c[2] != self.body:
                pairs[(c[3], c[2])] = pairs.get((c[3], c[2]), 0.0) + c[9]
        return [(self.link_name(link), other, force) for (link, other), force in pairs.items()]

    def link_name(self, link: int) -> str:
        if link < 0:
            return "panda_link0"
        return pybullet.getJointInfo(self.body, link, physicsClientId=self.client)[12].decode()

    def move_line(
        self, target, jaw_angle: float, speed: float | None = None, settle: float = 0.1, max_force: float | None = None
    ) -> float:
        """Move the grasp center in a straight line to ``target`` (3,) m at ``speed`` m/s, the hand
        pointing down at ``jaw_angle``, then hold the last target for ``settle`` s. With
        ``max_force`` (N) the robot's contacts with other bodies are watched and the motion stops
        at the first step where they press harder; returns the largest contact force seen (N),
        0 when not watched. The watched contacts of the hardest-pressing step so far are kept in :attr:`hardest`."""
        start, _ = self.grasp_pose()
        target = np.asarray(target, dtype=float)
        orientation = self.top_down(jaw_angle)
        distance = float(np.linalg.norm(target - start))
        steps = max(1, int(np.ceil(distance / (speed or self.hand.speed) / self.time_step)))
        largest = 0.0

        def advance(arm: np.ndarray) -> bool:  # one step toward ``arm``; False once the contacts press too hard
            nonlocal largest
            self._command(arm)
            pybullet.stepSimulation(physicsClientId=self.client)
            if max_force is not None:
                force = self.contact_force()
                largest = max(largest, force)
                if force > self.hardest_force:
                    self.hardest, self.hardest_force = self.contacts(), force
            return max_force is None or largest <= max_force

        for i in range(1, steps + 1):
            if not advance(self.inverse_kinematics(start + (target - start) * i / steps, orientation)):
                return largest
        arm = self.inverse_kinematics(target, orientation)
        for _ in range(int(round(settle / self.time_step))):
            if not advance(arm):
                break
        return largest

    def set_fingers(self, gap: float) -> None:
        """Drive the fingers toward a jaw gap of ``gap`` m for the hand's close time."""
        self.finger_target = float(np.clip(gap / 2, 0.0, self.open_width / 2))
        self.step(int(self.hand.close_time / self.time_step))


def probe_hand(client: int, body: int) -> dict[str, float]:
    """The open hand of the Panda ``body`` as a contact sees it, measured in pybullet with exact box probes at its
    grasp center (Bullet's closest points, margins included): ``gap``, the free width between the two fingers'
    jaw faces (m), and ``tip_depth``, how far the fingertips reach past the grasp center along the approach (m)."""
    position, orientation = pybullet.getLinkState(body, GRASP_TARGET_LINK, physicsClientId=client)[4:6]
    rotation = np.reshape(pybullet.getMatrixFromQuaternion(orientation), (3, 3))  # columns: across, jaw, approach
    center = np.asarray(position)

    def closest(half_extents, offset) -> float:
        shape = pybullet.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half_extents, physicsClientId=client)
        probe = pybullet.createMultiBody(
            0, shape, basePosition=(center + rotation @ offset).tolist(), baseOrientation=orientation,
            physicsClientId=client,
        )  # fmt: skip
        found = [
            c[8]
            for link in FINGER_JOINTS
            for c in pybullet.getClosestPoints(body, probe, 0.2, linkIndexA=link, physicsClientId=client)
        ]
        pybullet.removeBody(probe, physicsClientId=client)
        return float(min(found))

    thin = 0.0005
    between = closest([0.005, thin, 0.005], [0.0, 0.0, 0.0])  # a thin plate across the jaw at the grasp center
    gap = 2 * thin + 2 * between  # the fingers are held symmetric about the grasp center
    plate = 0.05  # a plate this far past the grasp center, wide enough to lie under both fingers
    below = closest([0.05, 0.1, thin], [0.0, 0.0, plate + thin])
    return {"gap": gap, "tip_depth": plate - below}
